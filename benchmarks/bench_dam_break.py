"""Dam break: sphgen's WCSPH against PySPH 1.0b2's ``pysph run dam_break_2d``, same case.

Both codes run the Koshizuka-Oka / Martin-Moyce column (L x 2L in a 4L tank) to
t = 0.7 s with WCSPH (Tait, artificial viscosity, predictor-corrector), serial and with 2
threads, interleaved, ``--repeat`` times; medians are printed.  Time per particle-step is
the time loop's wall time over (steps x all particles, fluid and wall); per fluid
particle-step too, since the codes lay different numbers of wall layers.  PySPH's steps
are its time-step computations (profile_info.csv, minus the initial one).

sphgen runs twice: with its defaults (quintic spline, support 3 dx, delta-SPH: three pair
passes, ~2.5x the pairs of PySPH's case) and with PySPH's physics (``--delta 0 --kernel
wendland --hdx 1.3``: plain WCSPH with the Wendland C2 kernel at h = 1.3 dx, as
``pysph run dam_break_2d``).  The second is the same-case comparison.

``--dx`` sets the spacing of both codes (default 0.03, both codes' default: 3384
particles here); at that size the serial part of a step (Python around the compiled
loops) bounds the thread speed-up, which ``--timing`` shows (docs/performance.md).

    python benchmarks/bench_dam_break.py [--repeat 3] [--tf 0.7] [--dx 0.03]
"""
import argparse
import csv
import json
import os
import statistics
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pysph_baseline import find_pysph_python  # noqa: E402
from roofline import host_line, median_run_line, peak_gflops  # noqa: E402

SPHGEN = os.path.join(os.path.dirname(sys.executable), "sphgen")


CONFIGS = {"sphgen": [], "sphgen-pysph-physics": ["--delta", "0", "--kernel", "wendland", "--hdx", "1.3"]}


def sphgen_app(work, app, args, threads, label):
    """One ``sphgen run APP`` as a subprocess: wall time of the time loop, steps, particles, pairs/s."""
    out = os.path.join(work, f"{label}_t{threads}")
    cmd = [SPHGEN, "run", app, "--disable-output", "--no-progress", "--overwrite", "-d", out] + list(args)
    cmd += ["--no-openmp"] if threads == 1 else ["--threads", str(threads)]
    subprocess.run(cmd, check=True, capture_output=True, env=dict(os.environ, SPHGEN_TUNE_THREADS="0"))
    info = json.load(open(os.path.join(out, "info.json")))
    n, steps, wall = info["n_particles"], info["steps"], info["wall_time"]
    return {"wall": wall, "steps": steps, "n": n, "fluid": info["particles"].get("fluid", n),
            "pairs_per_s": info["neighbour_pairs_per_step"] * steps / wall, "info": info}


def sphgen_run(work, tf, threads, config="sphgen", dx=None):
    size = ["--dx", str(dx)] if dx else []
    return sphgen_app(work, "dam_break_2d", ["--tf", str(tf)] + size + CONFIGS[config], threads, config)


def pysph_app(py, work, app, args, threads, label="pysph"):
    """One ``pysph run APP`` (PySPH 1.0b2): wall time it prints, steps from its profile, particles."""
    out = os.path.join(work, f"{label}_t{threads}")
    exe = os.path.join(os.path.dirname(py), "pysph")
    cmd = [exe, "run", app, "--disable-output", "-d", out] + list(args)
    cmd += ["--openmp", "--omp-schedule", "static"] if threads > 1 else []
    env = dict(os.environ, OMP_NUM_THREADS=str(threads))
    p = subprocess.run(cmd, check=True, capture_output=True, text=True, env=env, cwd=work)
    wall = float(p.stdout.split("Run took:")[1].split()[0])
    counts = particle_counts(p.stdout)
    n = int(p.stdout.split("Total:")[1].split()[0]) if "Total:" in p.stdout else sum(counts.values())
    fluid = counts.get("fluid", n)
    with open(os.path.join(out, "profile_info.csv")) as f:
        calls = {r["function"]: int(r["calls"]) for r in csv.DictReader(f)}
    steps = calls["Solver._get_timestep"] - 1
    return {"wall": wall, "steps": steps, "n": n, "fluid": fluid}


def particle_counts(stdout):
    """{array: particles} from PySPH's "No of particles:" block."""
    block = stdout.split("No of particles:")[1].split("-----")[0]
    return {k.strip(): int(v) for k, v in (line.split(":") for line in block.splitlines() if ":" in line)}


def pysph_run(py, work, tf, threads, dx=None):
    size = ["--dx", str(dx)] if dx else []
    return pysph_app(py, work, "dam_break_2d", ["--tf", str(tf)] + size, threads)


def med(rows, key):
    return statistics.median(r[key] for r in rows)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tf", type=float, default=0.7)
    ap.add_argument("--dx", type=float, default=None, help="particle spacing of both codes (default: theirs, 0.03)")
    ap.add_argument("--no-pysph", action="store_true")
    a = ap.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    print(host_line())
    py = None if a.no_pysph else find_pysph_python()
    work = tempfile.mkdtemp(prefix="sphgen_db_")
    for config in CONFIGS:
        sphgen_run(work, 0.001, 1, config, a.dx)  # compile once
    if py:
        pysph_run(py, work, 0.001, 1, a.dx)
        pysph_run(py, work, 0.001, 2, a.dx)
    res = {}
    for _ in range(a.repeat):
        for threads in (1, 2):
            for config in CONFIGS:
                res.setdefault((config, threads), []).append(sphgen_run(work, a.tf, threads, config, a.dx))
            if py:
                try:
                    res.setdefault(("pysph", threads), []).append(pysph_run(py, work, a.tf, threads, a.dx))
                except subprocess.CalledProcessError as e:   # PySPH 1.0b2 dies (SIGSEGV) at dx = 0.015
                    print(f"PySPH failed ({' '.join(e.cmd[1:])}: exit {e.returncode}); sphgen only from here")
                    py = None
                    for t in (1, 2):
                        res.pop(("pysph", t), None)
    us = {}
    for (code, threads), rows in sorted(res.items()):
        r = rows[0]
        t_ps = statistics.median(x["wall"] / (x["steps"] * x["n"]) for x in rows) * 1e6
        t_fs = statistics.median(x["wall"] / (x["steps"] * x["fluid"]) for x in rows) * 1e6
        us[(code, threads)] = (t_ps, t_fs)
        pairs = f", {med(rows, 'pairs_per_s'):.3g} neighbour pairs/s" if "pairs_per_s" in r else ""
        print(f"{code:20s} {threads} thread(s): {r['fluid']} fluid + {r['n'] - r['fluid']} wall, "
              f"{r['steps']} steps, {med(rows, 'wall'):.2f} s, {t_ps:.3f} us/particle-step, "
              f"{t_fs:.3f} us/fluid-particle-step{pairs}")
    peak = peak_gflops()
    for config in CONFIGS:
        for threads in (1, 2):
            print(median_run_line(res[(config, threads)], peak, f"{config}, {threads} thread(s)"))
    for config in CONFIGS:
        s1, s2 = us[(config, 1)], us[(config, 2)]
        print(f"{config}: 1 -> 2 threads {s1[0] / s2[0]:.2f}x")
        for threads in (1, 2):
            if ("pysph", threads) in us:
                p, s = us[("pysph", threads)], us[(config, threads)]
                print(f"PySPH / {config}, {threads} thread(s): {p[0] / s[0]:.2f}x per particle-step, "
                      f"{p[1] / s[1]:.2f}x per fluid particle-step")

    print(host_line())
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
