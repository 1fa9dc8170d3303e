"""Elastic solids: CTVF rings and the SHTC beryllium plate against PySPH 1.0b2's ``solid_mech.rings``.

PySPH's closest case is ``pysph run solid_mech.rings`` (Gray et al. elastic dynamics,
cubic spline at h = 1.5 dx, 17 592 particles in one array, dt = 1e-8 s).  ``sphgen run
rings --dx 0.0005 --one-body`` is the same two rings on the same lattice in one array
(17 584 particles; CTVF + SPST, quintic spline at h = dx: different physics, the same kind
of work; the default two-body run adds the contact pass); ``sphgen run beryllium_plate``
(SHTC, Wendland C2 at h = 1.5 dr, two neighbour-list builds per step) is a solid of similar
cost.  ``sphgen run shtc_cavity --nx 80`` (SHTC fluid, the lid-driven cavity of issue 10,
7 360 particles with the walls) is timed beside them, without a PySPH counterpart.  Each code runs ``--steps`` steps, serial and with 2 threads, interleaved,
``--repeat`` times; medians of the time loop's wall time per particle-step are printed,
with the ratio against PySPH at the same thread count.

    python benchmarks/bench_solids.py [--repeat 3] [--steps 300]
"""
import argparse
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_dam_break import pysph_app, sphgen_app  # noqa: E402
from pysph_baseline import find_pysph_python  # noqa: E402
from roofline import median_run_line, peak_gflops  # noqa: E402

PYSPH_DT = 1e-8     # solid_mech.rings' fixed step
CASES = {"sphgen rings": ("rings", ["--dx", "0.0005", "--one-body"]),
         "sphgen beryllium_plate": ("beryllium_plate", []),
         "sphgen shtc_cavity": ("shtc_cavity", ["--nx", "80", "--cs", "10", "--dt", "2e-4"])}
SOLIDS = ("sphgen rings", "sphgen beryllium_plate")     # compared with PySPH's rings


def per_particle_step(rows):
    return statistics.median(r["wall"] / (r["steps"] * r["n"]) for r in rows) * 1e6


def print_per_particle_step(res):
    """One line per (case, threads) of res {(case, threads): [run rows]}: particles, steps,
    median wall time, us per particle-step, neighbour pairs/s; returns {(case, threads): us}."""
    us = {}
    for (label, threads), rows in sorted(res.items()):
        us[(label, threads)] = per_particle_step(rows)
        r = rows[0]
        pairs = f", {statistics.median(x['pairs_per_s'] for x in rows):.3g} neighbour pairs/s" if "pairs_per_s" in r else ""
        print(f"{label:24s} {threads} thread(s): {r['n']} particles, {r['steps']} steps, "
              f"{statistics.median(x['wall'] for x in rows):.2f} s, {us[(label, threads)]:.3f} us/particle-step{pairs}")
    return us


def print_thread_scaling(res, label, us, peak):
    """The roofline line of the median run of one case at 1 and 2 threads, and its 1 -> 2 thread speed-up."""
    for threads in (1, 2):
        print(median_run_line(res[(label, threads)], peak, f"{label}, {threads} thread(s)"))
    print(f"{label}: 1 -> 2 threads {us[(label, 1)] / us[(label, 2)]:.2f}x")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--steps", type=int, default=300, help="time steps per run (default %(default)s)")
    a = ap.parse_args()
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    py = find_pysph_python()
    work = tempfile.mkdtemp(prefix="sphgen_solids_")

    def sphgen(label, threads, steps):
        app, args = CASES[label]
        return sphgen_app(work, app, args + ["--max-steps", str(steps)], threads, label.replace(" ", "_"))

    def pysph(threads, steps):   # its step is fixed: tf = steps dt (plus a little, for rounding)
        return pysph_app(py, work, "solid_mech.rings", ["--tf", repr((steps + 0.5) * PYSPH_DT)], threads)

    for label in CASES:           # compile once, outside the timings
        sphgen(label, 1, 2)
    if py:
        pysph(1, 2)
        pysph(2, 2)
    res = {}
    for _ in range(a.repeat):
        for threads in (1, 2):
            for label in CASES:
                res.setdefault((label, threads), []).append(sphgen(label, threads, a.steps))
            if py:
                res.setdefault(("pysph solid_mech.rings", threads), []).append(pysph(threads, a.steps))
    us = print_per_particle_step(res)
    peak = peak_gflops()
    for label in CASES:
        print_thread_scaling(res, label, us, peak)
        for threads in (1, 2):
            if label in SOLIDS and ("pysph solid_mech.rings", threads) in us:
                print(f"PySPH rings / {label}, {threads} thread(s): "
                      f"{us[('pysph solid_mech.rings', threads)] / us[(label, threads)]:.2f}x per particle-step")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
