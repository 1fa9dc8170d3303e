"""Superfluid helium-4 (Kincl 2023, thesis ch. 3): time per particle-step of second sound and the fountain.

Two cases, each ``--steps`` steps, serial and with 2 threads, interleaved, ``--repeat``
times; medians of the time loop's wall time per particle-step are printed with the
neighbour pairs per second and the roofline line of the median run:

* ``sphgen run second_sound --N 300 --M 50`` (sec. 3.5: 90 000 fluid particles and the
  mirrored dummies, 97 344 in all);
* ``sphgen run fountain --preset paper --power 80`` (sec. 3.6: r_cap/dr = 8, 149 195
  particles; its per-step flux counter and probes run in Python and are included).

Then the projected wall time of the thesis-sized fountain (docs/superfluid.md, "Cost of
the paper preset"): steps = ceil(t_end / dt) with t_end = 0.3 s and the preset's dt
(221 199 steps), T_power = steps x particles x (time per particle-step), three powers.
It assumes the cost per particle-step of the first ``--steps`` steps holds for the whole
run (the jet adds no particles; the neighbour count per particle changes little).

    python benchmarks/bench_superfluid.py [--repeat 3] [--steps 200] [--check]
"""
import argparse
import math
import os
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from bench_dam_break import sphgen_app  # noqa: E402
from bench_solids import per_particle_step, print_per_particle_step, print_thread_scaling  # noqa: E402
from roofline import peak_gflops  # noqa: E402

from sphgen.applications.fountain import PRESETS  # noqa: E402

POWERS = (60, 80, 100)     # W/m, the thesis' three runs (Fig. 3.7)
CASES = {"second_sound N=300": ("second_sound", ["--N", "300", "--M", "50", "--A", "0.01"]),
         "fountain paper": ("fountain", ["--preset", "paper", "--power", "80"])}
# ``--check``: the same script on small cases (second sound N = 30, the quick fountain), to
# see that it runs; its numbers mean nothing for the paper preset
CHECK_CASES = {"second_sound N=300": ("second_sound", ["--N", "30", "--M", "50", "--A", "0.01"]),
               "fountain paper": ("fountain", ["--preset", "quick", "--power", "80"])}


def projected_hours(rows, tf=PRESETS["paper"]["tf"], runs=len(POWERS)):
    """(steps per run, hours per run, hours for ``runs`` runs): the fountain to ``tf`` at the
    measured time per particle-step (median of ``rows``) and the run's own dt."""
    info = rows[0]["info"]
    steps = math.ceil(tf / info["dt"] - 1e-9)
    per_run = steps * info["n_particles"] * per_particle_step(rows) * 1e-6 / 3600.0
    return steps, per_run, runs * per_run


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--steps", type=int, default=200, help="time steps per run (default %(default)s)")
    ap.add_argument("--check", action="store_true", help="small cases, to check the script runs")
    a = ap.parse_args()
    cases = CHECK_CASES if a.check else CASES
    print(f"load average before: {os.getloadavg()[0]:.2f}")
    if a.check:
        print("--check: second sound N = 30 and the quick fountain under the cases' labels; not a benchmark")
    work = tempfile.mkdtemp(prefix="sphgen_superfluid_")

    def run(label, threads, steps):
        app, args = cases[label]
        return sphgen_app(work, app, args + ["--max-steps", str(steps)], threads,
                          label.replace(" ", "_").replace("=", ""))

    for label in CASES:           # compile once, outside the timings
        run(label, 1, 2)
    res = {}
    for _ in range(a.repeat):
        for threads in (1, 2):
            for label in CASES:
                res.setdefault((label, threads), []).append(run(label, threads, a.steps))
    us = print_per_particle_step(res)
    peak = peak_gflops()
    for label in CASES:
        print_thread_scaling(res, label, us, peak)
    for threads in (1, 2):
        steps, hours, total = projected_hours(res[("fountain paper", threads)])
        print(f"projected paper fountain, {threads} thread(s): {steps} steps x "
              f"{res[('fountain paper', threads)][0]['n']} particles x {us[('fountain paper', threads)]:.3f} us "
              f"= {hours:.1f} h per power, {total:.1f} h for the {len(POWERS)} powers {POWERS} W/m")
    print(f"load average after: {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
