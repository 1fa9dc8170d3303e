"""1 -> 2 threads measured on the same work: each window of a run computed twice, serially and
with two threads, from the same saved state, in alternating order.

Whole runs interleaved (``thread_scaling.py``, ``bench_dam_break.py``) compare a serial run
and a two-thread run taken seconds apart; on a shared VM the host's speed drifts by more
than 10 % over such spans, more than the differences being measured.  Here one process runs
the application in windows of ``--steps`` steps.  Before each window it saves the state
(every array, the solver's time and step, the application's record schedule) and rebuilds
the neighbour lists; it runs the window with one thread count, restores the state, rebuilds,
and runs it again with the other (the order alternates from window to window).  The loops
compute each particle whole on one thread, so both runs take the same steps through the
same states: every part of the time loop (passes, neighbour upkeep, rebuilds, guard,
probes) is in both, and the two times of a window differ only by the threads and by the
host's drift over a few hundred milliseconds.

Printed: the sums over all windows (the whole run's 1 -> 2 threads) and the median and
quartiles of the windows' own ratios; with ``--parts``, the ``--timing`` table of both
thread counts side by side, summed over the windows (its wrappers cost a little in both).

    python benchmarks/thread_pairs.py [--steps 200] [--parts] [APP ARGS ...]
    (default APP ARGS: dam_break_2d --tf 0.7)
"""
import argparse
import contextlib
import io
import os
import statistics
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from roofline import host_line  # noqa: E402


class Saved:
    """The state a window starts from, put back by :meth:`restore`."""

    def __init__(self, app):
        s = app.solver
        self.app = app
        self.arrays = [(pa, {k: v.copy() for k, v in pa.data.items()}) for pa in app.scene.arrays]
        self.solver = (s.t, s.step, s.last_dt)
        self.record = getattr(app, "_next_record", None)
        self.history = len(getattr(app, "history", []) or [])

    def restore(self):
        app, s = self.app, self.app.solver
        for pa, data in self.arrays:
            for k, v in data.items():
                pa.data[k][...] = v
        s.t, s.step, s.last_dt = self.solver
        if self.record is not None:
            app._next_record = self.record
        if getattr(app, "history", None) is not None:
            del app.history[self.history:]


def rebuild(app):
    """Neighbour lists built anew from the current positions (both runs of a window start so)."""
    app.scene.nnps._build()
    app.scene.engine.bind_neighbours()


def start(app_args, threads, prefix):
    """The application of ``app_args`` run in-process for one step (no output, its run folder
    in a temporary directory, returned too: removed when it is dropped)."""
    from sphgen.app import load_application
    app = load_application(app_args[0])()
    app.post_process = lambda outdir: None
    work = tempfile.TemporaryDirectory(prefix=prefix)
    with contextlib.redirect_stdout(io.StringIO()):
        app.run(list(app_args[1:]) + ["--max-steps", "1", "--disable-output", "--no-progress",
                                      "--overwrite", "-d", os.path.join(work.name, "run"),
                                      "--threads", str(threads)])
    return app, work


def window(app, threads, steps):
    """Run ``steps`` steps with ``threads`` threads; the time loop's wall time."""
    s = app.solver
    app.scene.set_threads(threads)
    rebuild(app)
    s.max_steps = s.step + steps
    wall0 = s.wall_time
    s.run()
    return s.wall_time - wall0


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--steps", type=int, default=200, help="steps per window")
    ap.add_argument("--parts", action="store_true", help="time the parts of the loop too")
    ap.add_argument("app", nargs=argparse.REMAINDER)
    args = ap.parse_args()
    app_args = args.app or ["dam_break_2d", "--tf", "0.7"]
    os.environ["SPHGEN_TUNE_THREADS"] = "0"
    print(host_line())
    app, work = start(app_args, 2, "thread_pairs_")
    s = app.solver
    tf = s.tf
    timers, parts = None, {1: {}, 2: {}}
    if args.parts:
        from sphgen.timing import Timers
        timers = Timers()
        timers.attach(s)            # reset as each window's run starts
    rows = []
    while s.t < tf - 1e-12 * max(1.0, tf):
        saved = Saved(app)
        order = (1, 2) if len(rows) % 2 == 0 else (2, 1)
        times = {}
        for k, threads in enumerate(order):
            if k:
                saved.restore()
            step0 = s.step
            times[threads] = window(app, threads, args.steps)
            steps = s.step - step0
            for label, sec in (timers.seconds.items() if timers else ()):
                parts[threads][label] = parts[threads].get(label, 0.0) + sec
        rows.append((s.t, steps, times[1], times[2]))
    t1 = sum(r[2] for r in rows)
    t2 = sum(r[3] for r in rows)
    ratios = sorted(r[2] / r[3] for r in rows)
    q = statistics.quantiles(ratios, n=4) if len(ratios) > 1 else ratios * 3
    print(f"sphgen run {' '.join(app_args)}: {len(rows)} windows of {args.steps} steps "
          f"({sum(r[1] for r in rows)} steps), each run serially and with 2 threads from the same state")
    print(f"sums: serial {t1:.2f} s, 2 threads {t2:.2f} s: 1 -> 2 threads {t1 / t2:.3f}x")
    print(f"windows: median {statistics.median(ratios):.3f}x, quartiles {q[0]:.3f}x - {q[2]:.3f}x, "
          f"lowest {ratios[0]:.3f}x, highest {ratios[-1]:.3f}x")
    if timers:
        n = sum(r[1] for r in rows)
        print(f"{'part':38s} {'1 thread':>10s} {'2 threads':>10s}  [ms/step]")
        for label in parts[1]:
            a, b = parts[1][label], parts[2].get(label, 0.0)
            print(f"{label:38s} {1e3 * a / n:10.4f} {1e3 * b / n:10.4f}  {a / b if b else 0.0:5.2f}x")
        a, b = t1 - sum(parts[1].values()), t2 - sum(parts[2].values())
        print(f"{'other (integrator, reductions, dt)':38s} {1e3 * a / n:10.4f} {1e3 * b / n:10.4f}  {a / b:5.2f}x")
    print(host_line())


if __name__ == "__main__":
    main()
