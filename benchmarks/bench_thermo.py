"""Thermo-elastic upwind TLSPH (Ghavamian et al. 2021): the L-block's cost per particle-step and per pair.

``sphgen run l_block`` (sec. 7.2, the default reduced {p, F, H, E} scheme, paper load) on the
vertex lattices dx = 0.2 (16 896 particles; the paper's 17 600), dx = 1/3 (4000; its 5400)
and dx = 0.5 (1323; its 1900): ``--steps`` steps each, ``--repeat`` times, interleaved; the
finest serial and with 2 threads, the coarser two serial.  Medians of the time loop's wall
time per particle-step and per neighbour pair (all pair loops of a step: the two RK2 stages'
gradient and flux loops on the reference neighbour lists) are printed, with the ratio of the
largest to the smallest serial cost per particle-step over the three sizes (the paper's
linear cost: within 2x).  PySPH has no such scheme; its ``solid_mech.rings`` (2-D,
isothermal) is in ``bench_solids.py`` for scale only.

    python benchmarks/bench_thermo.py [--repeat 3] [--steps 200]
"""
import argparse
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_dam_break import sphgen_app  # noqa: E402
from bench_solids import per_particle_step  # noqa: E402
from roofline import median_run_line, peak_gflops  # noqa: E402

LEVELS = {"dx=0.2": "0.2", "dx=1/3": repr(1.0 / 3.0), "dx=0.5": "0.5"}   # finest first
FINEST = "dx=0.2"


def per_pair(rows):
    """Median wall time per neighbour pair visited [ns]."""
    return statistics.median(1e9 / r["pairs_per_s"] for r in rows)


def options():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200, help="time steps per run (default %(default)s)")
    ap.add_argument("--repeat", type=int, default=3, help="runs per case, interleaved (default %(default)s)")
    return ap.parse_args()


def main():
    a = options()
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    work = tempfile.mkdtemp(prefix="sphgen_thermo_")

    def run(label, threads, steps):
        return sphgen_app(work, "l_block", ["--dx", LEVELS[label], "--max-steps", str(steps)], threads,
                          label.replace("=", "").replace("/", "_"))

    todo = [(FINEST, 1), (FINEST, 2)] + [(label, 1) for label in LEVELS if label != FINEST]
    for label, threads in todo:       # compile once, outside the timings
        run(label, threads, 2)
    res = {}
    for _ in range(a.repeat):
        for label, threads in todo:
            res.setdefault((label, threads), []).append(run(label, threads, a.steps))
    us = {}
    for (label, threads), rows in res.items():
        us[(label, threads)] = per_particle_step(rows)
        r = rows[0]
        print(f"l_block {label:7s} {threads} thread(s): {r['n']} particles, {r['steps']} steps, "
              f"{statistics.median(x['wall'] for x in rows):.2f} s, {us[(label, threads)]:.3f} us/particle-step, "
              f"{per_pair(rows):.2f} ns/pair ({r['info']['neighbour_pairs_per_step'] / r['n']:.0f} pairs per "
              f"particle-step)")
    peak = peak_gflops()
    for key, rows in res.items():
        print(median_run_line(rows, peak, f"l_block {key[0]}, {key[1]} thread(s)"))
    print(f"l_block {FINEST}: 1 -> 2 threads {us[(FINEST, 1)] / us[(FINEST, 2)]:.2f}x")
    serial = [us[(label, 1)] for label in LEVELS]
    print(f"serial cost per particle-step over {', '.join(LEVELS)}: largest / smallest "
          f"{max(serial) / min(serial):.2f}x (linear cost: within 2x)")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
