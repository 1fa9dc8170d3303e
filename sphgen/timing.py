"""Where a run's wall time goes: per-pass, per-stage, neighbour-search and guard timers.

``sphgen run APP --timing`` wraps the solver's parts on the instances it runs (nothing
changes when it is off) and prints, after the run, one row per part: its wall time, its
share of the time loop, milliseconds per step and calls per step.  Times are exclusive
(a timed part called inside another, such as ``refine`` inside the neighbour lists, is
subtracted from the outer one), so the rows add up; "other" is the loop's time outside
every row (the integrator's Python, reductions, ``dt`` control).  The same table goes
into ``info.json`` under ``"timing"``.

The parts that run outside the compiled, threaded loops (Python, the guard, application
callbacks) bound the speed-up from threads: with that serial share ``s`` of a serial
run, 2 threads give at most ``1 / (s + (1 - s) / 2)`` (Amdahl), which
:meth:`Timers.report` prints for a serial run.
"""
import time
from collections import OrderedDict

# parts whose work runs in the compiled, threaded loops
# (the lists' and cells' rows also hold some Python: the bound is an upper one)
PARALLEL = ("pass ", "stage ", "neighbours: ")


class Timers:
    """Exclusive wall time and calls per label, accumulated by the callables :meth:`wrap` returns."""

    clock = staticmethod(time.perf_counter)

    def __init__(self):
        self.seconds = OrderedDict()
        self.calls = OrderedDict()
        self._inner = []          # per open timed call: the time of the timed calls inside it

    def reset(self):
        self.seconds.clear()
        self.calls.clear()

    def add(self, label, seconds):
        self.seconds[label] = self.seconds.get(label, 0.0) + seconds
        self.calls[label] = self.calls.get(label, 0) + 1

    def wrap(self, fn, label):
        """``fn`` timed under ``label`` (a string, or a function of the call's arguments)."""
        def timed(*args, **kwargs):
            start = self.clock()
            self._inner.append(0.0)
            try:
                return fn(*args, **kwargs)
            finally:
                elapsed, inner = self.clock() - start, self._inner.pop()
                if self._inner:
                    self._inner[-1] += elapsed
                self.add(label(*args) if callable(label) else label, elapsed - inner)
        timed.__wrapped__ = fn
        return timed

    def attach(self, solver):
        """Time the parts of ``solver``'s loop (instance attributes; the classes are untouched)."""
        scene, engine, nnps = solver.scene, solver.scene.engine, solver.scene.nnps
        if hasattr(engine, "run_pass"):
            engine.run_pass = self.wrap(engine.run_pass, lambda npass, t, dt: f"pass {npass.label}")
        if hasattr(engine, "run_stage"):
            engine.run_stage = self.wrap(engine.run_stage, lambda st, name, t, dt: f"stage {st.array}.{name}")
        if hasattr(engine, "bind_neighbours"):
            engine.bind_neighbours = self.wrap(engine.bind_neighbours, "neighbours: lists")
        nnps.update = self.wrap(nnps.update, "neighbours: cells")
        for cut in ("_refine", "_cut_rows"):
            if hasattr(nnps, cut):
                setattr(nnps, cut, self.wrap(getattr(nnps, cut), "neighbours: refine"))
        scene.sort = self.wrap(scene.sort, "spatial sort")
        solver._check = self.wrap(solver._check, "blow-up guard")
        solver.write_output = self.wrap(solver.write_output, "output files")
        solver.post_step_callbacks[:] = [self.wrap(cb, "application callbacks")
                                         for cb in solver.post_step_callbacks]
        prepare = solver._prepare

        def prepare_then_reset():     # the time loop starts after it: count from there
            prepare()
            self.reset()
        solver._prepare = prepare_then_reset

    def table(self, loop_seconds, steps):
        """Rows ``(label, seconds, share of the loop, ms per step, calls per step)``, the
        "other" row last, and the Amdahl bound of 2 threads from the serial share."""
        steps = max(steps, 1)
        kinds = ("pass ", "stage ", "neighbours: ")
        order = sorted(self.seconds, key=lambda k: next((i for i, p in enumerate(kinds) if k.startswith(p)),
                                                        len(kinds)))
        rows = [(k, self.seconds[k], self.seconds[k] / loop_seconds if loop_seconds > 0 else 0.0,
                 1e3 * self.seconds[k] / steps, self.calls[k] / steps) for k in order]
        counted = sum(self.seconds.values())
        other = max(loop_seconds - counted, 0.0)
        rows.append(("other (integrator, reductions, dt)", other,
                     other / loop_seconds if loop_seconds > 0 else 0.0, 1e3 * other / steps, 0.0))
        parallel = sum(s for k, s in self.seconds.items() if k.startswith(PARALLEL))
        serial = max(loop_seconds - parallel, 0.0) / loop_seconds if loop_seconds > 0 else 1.0
        return rows, serial

    def report(self, loop_seconds, steps, threads=1):
        """The table as text, and as a dict for info.json."""
        rows, serial = self.table(loop_seconds, steps)
        lines = [f"{'part':38s} {'s':>8s} {'share':>7s} {'ms/step':>9s} {'calls/step':>10s}"]
        for label, s, share, ms, calls in rows:
            lines.append(f"{label:38s} {s:8.3f} {100 * share:6.1f}% {ms:9.4f} {calls:10.2f}")
        line = f"outside passes, stages and neighbour search: {100 * serial:.1f}% of the loop"
        if threads == 1:
            line += f"; 2 threads can make this run at most {1.0 / (serial + (1.0 - serial) / 2.0):.2f}x faster"
        lines.append(line)
        as_dict = {"loop_seconds": loop_seconds, "steps": steps, "threads": threads, "serial_share": serial,
                   "rows": [dict(part=lab, seconds=s, share=sh, ms_per_step=ms, calls_per_step=c)
                            for lab, s, sh, ms, c in rows]}
        return "\n".join(lines), as_dict
