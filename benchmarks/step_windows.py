"""Time per step of one run, window by window, serial and with 2 threads in turn.

A whole run's wall time mixes the case's phases with the machine's moods.  This script
runs the application in-process up to each window's end time (``solver.tf`` raised, the
solver's ``wall_time`` read before and after) and prints the microseconds per step of
every window, for ``--rounds`` alternating serial / two-thread processes: the same window
of the same case in two processes shows how much of a difference is the host's.

``--load F`` runs, beside it, a process busy for the fraction F of every 2 ms on the last
core (a neighbour that takes a core now and then), for the "graceful under load" question.

    python benchmarks/step_windows.py [--rounds 2] [--window 0.1] [--load 0.5] [APP ARGS ...]
    (default APP ARGS: dam_break_2d --tf 0.7)
"""
import argparse
import multiprocessing as mp
import os
import sys
import time


def duty_load(fraction, stop, period=0.002):
    """Busy for ``fraction`` of every ``period`` on the last core until ``stop`` is set."""
    os.sched_setaffinity(0, {os.cpu_count() - 1})
    while not stop.is_set():
        start = time.perf_counter()
        while time.perf_counter() - start < fraction * period:
            pass
        time.sleep((1.0 - fraction) * period)


def windows(app_args, threads, window):
    """[(window end, steps, us per step)] of one in-process run of APP."""
    import numpy as np
    from sphgen.app import load_application
    os.environ["SPHGEN_TUNE_THREADS"] = "0"
    name, rest = app_args[0], list(app_args[1:])
    tf = float(rest[rest.index("--tf") + 1]) if "--tf" in rest else 0.7
    if "--tf" in rest:
        del rest[rest.index("--tf"):rest.index("--tf") + 2]
    app = load_application(name)()
    app.run(rest + ["--tf", str(window * 1e-3), "--disable-output", "--no-progress", "--overwrite",
                    "-d", os.path.join("/tmp", f"step_windows_{os.getpid()}")]
            + (["--no-openmp"] if threads == 1 else ["--threads", str(threads)]))
    s, out = app.solver, []
    for end in np.arange(window, tf + 0.5 * window, window):
        s.tf = float(end)
        step0, wall0 = s.step, s.wall_time
        s.run()
        if s.step > step0:
            out.append((end, s.step - step0, 1e6 * (s.wall_time - wall0) / (s.step - step0)))
    return out


def _child(app_args, threads, window, queue):
    import contextlib
    import io
    with contextlib.redirect_stdout(io.StringIO()):
        queue.put(windows(app_args, threads, window))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--window", type=float, default=0.1, help="simulated time per window")
    ap.add_argument("--load", type=float, default=0.0, help="busy fraction of the last core beside the runs")
    ap.add_argument("app", nargs=argparse.REMAINDER)
    args = ap.parse_args()
    app_args = args.app or ["dam_break_2d", "--tf", "0.7"]
    with open("/proc/loadavg") as f:
        print("load average before:", " ".join(f.read().split()[:3]))
    stop = mp.Event()
    load = mp.Process(target=duty_load, args=(args.load, stop), daemon=True) if args.load > 0 else None
    if load:
        load.start()
    ctx = mp.get_context("spawn")      # a fresh process (and OpenMP runtime) per run
    try:
        for r in range(args.rounds):
            for threads in (1, 2):
                q = ctx.Queue()
                p = ctx.Process(target=_child, args=(app_args, threads, args.window, q))
                p.start()
                rows = q.get()
                p.join()
                total = sum(n for _, n, _ in rows)
                mean = sum(n * us for _, n, us in rows) / total
                print(f"round {r + 1}, {threads} thread(s): " + "  ".join(f"t<={e:.3g}: {us:.0f}" for e, _, us in rows)
                      + f"  | all: {mean:.0f} us/step")
    finally:
        if load:
            stop.set()
            load.join()
    sys.stdout.flush()


if __name__ == "__main__":
    main()
