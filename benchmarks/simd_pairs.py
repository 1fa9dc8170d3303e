"""The neighbour search's AVX2 loops (``sphgen_simd.h``) against the scalar ones, on the same work.

Like ``thread_pairs.py``: one process runs the application in windows of ``--steps`` steps;
each window is computed twice from the same saved state, once with the scalar loops (the
reach tests, the periodic wrap's look) and once with the AVX2 ones
(``sphgen.nnps._cell_list.set_simd``), in alternating order, with ``--threads`` threads.  Both give the same neighbour rows, so both runs take the
same steps through the same states; the times differ by those loops and the host's drift.

    python benchmarks/simd_pairs.py [--steps 200] [--threads 1] [APP ARGS ...]
    (default APP ARGS: dam_break_2d --tf 0.7)
"""
import argparse
import os
import statistics
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from roofline import host_line  # noqa: E402
from thread_pairs import Saved, start, window  # noqa: E402


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200, help="steps per window")
    ap.add_argument("--threads", type=int, default=1, help="threads of both runs")
    ap.add_argument("app", nargs=argparse.REMAINDER)
    args = ap.parse_args()
    app_args = args.app or ["dam_break_2d", "--tf", "0.7"]
    os.environ["SPHGEN_TUNE_THREADS"] = "0"
    from sphgen.nnps import _cell_list
    if not _cell_list.simd_available():
        sys.exit("simd_pairs: this machine has no AVX2; only the scalar loops run")
    print(host_line())
    app, work = start(app_args, args.threads, "simd_pairs_")
    s = app.solver
    tf = s.tf
    rows = []
    while s.t < tf - 1e-12 * max(1.0, tf):
        saved = Saved(app)
        order = (False, True) if len(rows) % 2 == 0 else (True, False)
        times = {}
        for k, simd in enumerate(order):
            if k:
                saved.restore()
            _cell_list.set_simd(simd)
            step0 = s.step
            times[simd] = window(app, args.threads, args.steps)
            steps = s.step - step0
        rows.append((steps, times[False], times[True]))
    n = sum(r[0] for r in rows)
    t0, t1 = sum(r[1] for r in rows), sum(r[2] for r in rows)
    ratios = [r[1] / r[2] for r in rows]
    print(f"sphgen run {' '.join(app_args)}, {args.threads} thread(s): {len(rows)} windows, {n} steps")
    print(f"scalar loops {1e3 * t0 / n:.4f} ms/step, four at a time {1e3 * t1 / n:.4f} ms/step: "
          f"{t0 / t1:.3f}x (windows: median {statistics.median(ratios):.3f}x)")
    print(host_line())


if __name__ == "__main__":
    main()
