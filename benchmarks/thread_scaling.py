"""1 -> 2 threads of one application, serial and two-thread runs interleaved, medians and best-of.

Each repetition runs ``sphgen run APP ... --no-openmp`` and ``--threads 2`` (thread tuning off,
no output) and reads the time loop's wall time from info.json.  ``--before DIR`` also runs
the checkout in DIR (its own ``.venv``, e.g. a clone of an earlier commit) alternately with
this one, so a change is measured against its parent in the same window.

    python benchmarks/thread_scaling.py [--repeat 7] [--before DIR] [APP ARGS ...]
    (default APP ARGS: dam_break_2d --tf 0.7)
"""
import argparse
import json
import os
import statistics
import subprocess
import tempfile

HERE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def wall_time(tree, app_args, threads, out):
    """The time loop's wall time of one run of the checkout ``tree``."""
    cmd = [os.path.join(tree, ".venv", "bin", "sphgen"), "run", *app_args, "--disable-output",
           "--no-progress", "--overwrite", "-d", out]
    cmd += ["--no-openmp"] if threads == 1 else ["--threads", str(threads)]
    subprocess.run(cmd, check=True, capture_output=True, cwd=tree,
                   env=dict(os.environ, SPHGEN_TUNE_THREADS="0"))
    with open(os.path.join(out, "info.json")) as f:
        return json.load(f)["wall_time"]


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--before", help="another checkout (with its .venv) to run alternately")
    ap.add_argument("app", nargs=argparse.REMAINDER)
    args = ap.parse_args()
    app_args = args.app or ["dam_break_2d", "--tf", "0.7"]
    trees = {"this": HERE, **({"before": os.path.abspath(args.before)} if args.before else {})}
    times = {(k, t): [] for k in trees for t in (1, 2)}
    with open("/proc/loadavg") as f:
        print("load average before:", f.read().split()[:3])
    with tempfile.TemporaryDirectory() as work:
        for _ in range(args.repeat):
            for name, tree in trees.items():
                for t in (1, 2):
                    times[(name, t)].append(wall_time(tree, app_args, t, os.path.join(work, f"{name}{t}")))
    print(f"sphgen run {' '.join(app_args)}: wall time of the time loop [s], {args.repeat} runs each")
    for name in trees:
        s, p = times[(name, 1)], times[(name, 2)]
        print(f"{name:7s} serial {statistics.median(s):.3f}, 2 threads {statistics.median(p):.3f}: "
              f"1 -> 2 threads {statistics.median(s) / statistics.median(p):.3f}x median, "
              f"{min(s) / min(p):.3f}x best-of  (2 threads: {', '.join(f'{x:.2f}' for x in p)})")


if __name__ == "__main__":
    main()
