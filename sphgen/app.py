"""Application base class and the ``sphgen`` command line.

``sphgen run NAME [options]`` imports ``sphgen.applications.NAME``, builds its
Application and runs it; ``sphgen list`` names the applications.  Every run writes
``info.json`` in its output folder (automan's notion of a finished case: ``completed``, or
``stopped`` by the blow-up guard).

Everything a user can get wrong is checked before compiling and before any file is
touched; a user mistake is one line on stderr and a non-zero exit (``--debug`` or
``SPHGEN_DEBUG=1`` shows the traceback).  See docs/reliability.md.
"""
import argparse
import difflib
import importlib
import math
import os
import pkgutil
import sys
import time

from . import __version__, io, run_folder
from .errors import BlowUpError, InputError, SphgenError, debug_requested, one_line
from .scene import Scene
from .solver import Solver


def _number(s, kind, ok, what):
    try:
        v = kind(s)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be {what}, got {s!r}") from None
    if not ok(v):
        raise argparse.ArgumentTypeError(f"must be {what}, got {s}")
    return v


def _positive_float(s):
    return _number(s, float, lambda v: math.isfinite(v) and v > 0, "a positive finite number")


def _nonneg_float(s):
    return _number(s, float, lambda v: math.isfinite(v) and v >= 0, "a non-negative finite number")


def _positive_int(s):
    return _number(s, int, lambda v: v >= 1, "a positive integer")


class _Parser(argparse.ArgumentParser):
    """argparse whose mistakes are an InputError (one line), not a usage dump and exit."""

    def error(self, message):
        raise InputError(f"{message} (see {self.prog} --help)")


class Application:
    """Subclass and override ``create_particles`` and ``create_scheme``.

    Optional: ``create_domain``, ``add_user_options(parser)``,
    ``consume_user_options(options)``, ``post_step(solver)``, ``post_process(outdir)``.
    Class attributes ``tf`` and ``pfreq`` give the defaults of ``--tf``/``--pfreq``.

    Time series: append rows (first column t) to ``self.history`` and name the columns in
    ``history_columns``; ``history.json`` is written with every output, continues across
    restarts, and carries ``history_meta()``.  Conserved quantities listed in
    ``diagnostics`` are sampled every ``diagnostics_every`` steps into ``diagnostics.json``
    (same rules) and plotted in ``diagnostics.png``.
    """

    tf = 1.0
    pfreq = 100
    dim = 2
    history_columns = None
    diagnostics = ()           # names in sphgen.tools.diagnostics.DIAGNOSTICS, or "energies"
    diagnostics_every = 10     # steps between diagnostic samples

    def __init__(self, name=None):
        self.name = name or type(self).__module__.rsplit(".", 1)[-1]
        self.options = None
        self.scene = self.solver = self.scheme = None
        self.history = []
        self.restarts = []
        self.diag = None
        self.timers = None      # sphgen.timing.Timers with --timing

    # ---------------------------------------------------------------- hooks
    def add_user_options(self, parser):
        pass

    def consume_user_options(self, options):
        pass

    def create_particles(self):
        raise NotImplementedError

    def create_scheme(self):
        raise NotImplementedError

    def create_domain(self):
        return None

    def post_step(self, solver):
        pass

    def post_process(self, outdir):
        pass

    def history_meta(self):
        """Extra keys of history.json (e.g. the case's parameters)."""
        return {}

    # ---------------------------------------------------------------- CLI
    @staticmethod
    def _run_options(p):
        g = p.add_argument_group("run")
        g.add_argument("--tf", type=_nonneg_float, help="final time (default %(default)s)")
        g.add_argument("--dt", type=_positive_float, default=None, help="time step (default: the scheme's)")
        g.add_argument("--dt-factor", type=_positive_float, default=1.0,
                       help="multiply the time step by this (default 1; above 1 needs --allow-unstable)")
        g.add_argument("--skin", type=_nonneg_float, default=0.1,
                       help="Verlet skin of the neighbour search, as a fraction of the support: "
                            "cells and candidate lists are kept while it covers the motion "
                            "(the neighbour lists, and so the results, are the same; default "
                            "%(default)s)")
        g.add_argument("--tune-skin", action="store_true",
                       help="choose the skin of each rebuild by timing the neighbour upkeep, "
                            "starting from --skin (the results are the same)")
        g.add_argument("--max-steps", type=_positive_int, default=None, help="stop after this many steps")
        g.add_argument("--openmp", dest="openmp", action="store_true", default=True,
                       help="use all cores (default)")
        g.add_argument("--no-openmp", dest="openmp", action="store_false", help="run serial (one thread)")
        g.add_argument("--threads", type=_positive_int, default=None, help="number of threads")
        g.add_argument("-d", "--directory", default=None, help="output folder (default NAME_output)")
        g.add_argument("--overwrite", action="store_true",
                       help="replace the files of another run in the output folder")
        g.add_argument("--pfreq", type=_positive_int, help="output every N steps")
        g.add_argument("--disable-output", action="store_true", help="write no particle files")
        g.add_argument("--restart", metavar="FILE", default=None, help="continue from an output file")
        g.add_argument("--allow-unstable", action="store_true",
                       help="run even outside the scheme's stability bounds (a warning is printed)")
        g.add_argument("--show-plan", action="store_true", help="print the generator's plan and exit")
        g.add_argument("--backend", choices=("cython", "python"), default="cython",
                       help="compiled (default) or the slow plain-Python evaluator")
        g.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
        g.add_argument("--timing", action="store_true",
                       help="after the run, print where the time loop's wall time went (per pass, stage, "
                       "neighbour search, guard, callbacks) and keep it in info.json")
        g.add_argument("--debug", action="store_true", help="show tracebacks of errors")

    def parser(self):
        p = _Parser(prog=f"sphgen run {self.name}", description=(type(self).__doc__ or "").strip())
        self._run_options(p)
        p.set_defaults(tf=self.tf, pfreq=self.pfreq)
        run_dests = set(vars(p.parse_args([])))
        self.add_user_options(p.add_argument_group(self.name))
        self._user_dests = sorted(set(vars(p.parse_known_args([])[0])) - run_dests)
        return p

    def run(self, argv=None):
        """Parse options, check them, build the scene, run, write info.json, post-process.

        A user mistake prints one line to stderr and exits non-zero (SystemExit);
        with ``--debug`` (or SPHGEN_DEBUG=1) the exception propagates with its traceback.
        """
        argv = sys.argv[1:] if argv is None else list(argv)
        try:
            return self._run(argv)
        except SphgenError as e:
            if debug_requested(argv):
                raise
            print(f"sphgen: {one_line(e)}", file=sys.stderr)
            raise SystemExit(e.exit_code) from None

    def _run(self, argv):
        parser = self.parser()
        opts = self.options = parser.parse_args(argv)
        if opts.tune_skin and opts.skin <= 0:
            parser.error("--tune-skin chooses among skins: give --skin above 0")
        self.consume_user_options(opts)
        self.outdir = outdir = opts.directory or f"{self.name}_output"
        restart = run_folder.read_restart(opts.restart) if opts.restart else None
        if not opts.show_plan:
            run_folder.check_output_folder(outdir, opts.overwrite, opts.restart)
        arrays = self.create_particles()
        self.scheme = self.create_scheme()
        self.scheme.setup_properties(arrays)
        dt = (opts.dt or self.scheme.get_timestep()) * opts.dt_factor
        for warning in self.scheme.check_stability(dt, opts.allow_unstable):
            print(f"sphgen: warning: {warning}", file=sys.stderr)
        self.signature = self._signature(arrays)
        if restart is not None:
            run_folder.check_restart(opts.restart, restart, self.signature, opts.tf)
        integrator = self.scheme.get_integrator()
        self.scene = self._scene(arrays, integrator)
        if opts.show_plan:
            print(self.scene.describe())
            if self.scene.source is not None:
                print(f"generated source: {self.scene.source_path}")
            return None
        self.solver = self._solver(integrator, dt)
        if restart is not None:
            self._restart(opts.restart, restart, dt)
        run_folder.prepare_output_folder(outdir, opts.overwrite, opts.restart)
        return self._execute()

    def _scene(self, arrays, integrator):
        opts = self.options
        outputs = {pa.name: self.scheme.output_properties(pa) for pa in arrays}
        return Scene(arrays, self.scheme.get_equations(), steppers=integrator.steppers,
                     kernel=getattr(self.scheme, "kernel", None), dim=self.dim,
                     domain=self.create_domain(), outputs=outputs, backend=opts.backend,
                     threads=1 if not opts.openmp else opts.threads, skin=opts.skin,
                     evaluated=integrator.evaluated_sets(), tune_skin=opts.tune_skin)

    def _solver(self, integrator, dt):
        opts = self.options
        # a scheme with adaptive_dt = (dt_props, cfl) takes every step from the per-particle
        # limits its equations write (at most dt), unless --dt fixes the step
        adaptive = getattr(self.scheme, "adaptive_dt", None) if opts.dt is None else None
        steps = dict(adaptive=True, dt_props=tuple(adaptive[0]), cfl=adaptive[1] * opts.dt_factor) \
            if adaptive else {}
        solver = Solver(self.scene, integrator, dt, opts.tf, max_steps=opts.max_steps,
                        pfreq=opts.pfreq, outdir=self.outdir, prefix=self.name,
                        disable_output=opts.disable_output, progress=opts.progress,
                        speed_limit=self.scheme.speed_limit,
                        density_bounds=self.scheme.density_bounds(),
                        metadata={"signature": self.signature, "tf": opts.tf}, **steps)
        solver.neighbour_exempt = set(getattr(self.scheme, "neighbour_exempt", ()))
        solver.post_step_callbacks.append(self.post_step)
        solver.output_callbacks.append(lambda s, path: self._write_progress())
        if self.diagnostics:
            from .tools.diagnostics import Diagnostics
            self.diag = Diagnostics(self.diagnostics, self.dim, self.scheme)
            solver.post_step_callbacks.append(self._sample)
        return solver

    def _sample(self, solver):
        if solver.step % self.diagnostics_every == 0 or solver.t >= solver.tf - 1e-12 * max(1.0, solver.tf):
            self.diag.sample(solver.t, self.scene.arrays)

    def _restart(self, path, data, dt):
        """Continue the run of ``path``: its state, history and record of restarts."""
        self.solver.restart_from(path)
        for note in run_folder.restart_notes(data, dt, self.options.tf):
            print(f"sphgen: restart: {note}")
        hist = run_folder.earlier_history(path, self.solver.t)
        if hist is not None:
            self.history = [list(r) for r in hist["rows"]]
        else:
            print(f"sphgen: restart: no history.json beside {path}; the time series starts here")
        diag = run_folder.earlier_history(path, self.solver.t, "diagnostics.json")
        if self.diag is not None and diag is not None:
            self.diag.rows = [list(r) for r in diag["rows"]]
        if run_folder.same_folder(path, self.outdir):
            self.restarts = list(run_folder.earlier_info(self.outdir).get("restarts", []))
        self.restarts.append({"from": os.path.abspath(path), "t": self.solver.t, "step": self.solver.step,
                              "at": time.strftime("%Y-%m-%dT%H:%M:%S")})

    def _execute(self):
        """Run the solver with info.json and history.json kept current; then post-process."""
        outdir = self.outdir
        if self.diag is not None and not self.solver.restarted:
            self.diag.sample(self.solver.t, self.scene.arrays)
        self._write_progress()
        error = None
        if self.options.timing:
            from .timing import Timers
            self.timers = Timers()
            self.timers.attach(self.solver)
        try:
            self.solver.run()
        except SphgenError as e:
            error = str(e)
            self._write_progress(error=error, stopped=isinstance(e, BlowUpError))
            raise
        finally:
            if error is None:
                self._write_progress(completed=True)
        print(f"{self.name}: {self.solver.step} steps to t={self.solver.t:.6g} in {self.solver.wall_time:.2f} s "
              f"(compile {self.scene.compile_time:.2f} s, {self.scene.threads} thread(s)); output in {outdir}")
        if self.timers is not None:
            print(self.timing_report()[0])
        self.post_process(outdir)
        if self.diag is not None:
            from .tools.plots import plot_series
            plot_series(os.path.join(outdir, "diagnostics.json"), os.path.join(outdir, "diagnostics.png"))
        return self._info(True)

    def timing_report(self):
        """(text, dict) of :meth:`sphgen.timing.Timers.report` for the run so far."""
        return self.timers.report(self.solver.wall_time, self.solver.step, self.scene.threads)

    def _write_progress(self, completed=False, error=None, stopped=False):
        """info.json and history.json as they stand now (both atomic); ``stopped``: the
        blow-up guard ended the run (a Ctrl-C is not a stop)."""
        if self.history_columns is not None:
            io.write_json(os.path.join(self.outdir, "history.json"),
                          {"columns": list(self.history_columns), "rows": self.history, **self.history_meta()})
        if self.diag is not None:
            io.write_json(os.path.join(self.outdir, "diagnostics.json"),
                          {"columns": self.diag.columns(self.scene.arrays), "rows": self.diag.rows})
        io.write_json(os.path.join(self.outdir, "info.json"), self._info(completed, error, stopped))

    def _signature(self, arrays):
        """What defines the scene: a restart must agree on all of it."""
        opts = self.options
        kernel = getattr(self.scheme, "kernel", None)
        return {"application": self.name, "scheme": type(self.scheme).__name__,
                "scheme_parameters": self.scheme.parameters(),
                "options": {k: getattr(opts, k) for k in self._user_dests},
                "particles": {pa.name: pa.n for pa in arrays},
                "kernel": type(kernel).__name__ if kernel is not None else None,
                "dim": self.dim, "sphgen_version": __version__}

    def neighbour_pairs_per_step(self, flops=False):
        """Neighbour pairs visited in one step (all evaluations and passes), on the last
        neighbour lists; with ``flops``, the estimated floating-point operations they cost
        (:func:`sphgen.codegen.describe.loop_flops`).  Each equation set counts as often as
        the integrator ran it per step (start-up sets and fixed-point iterations included),
        or once per step before any step."""
        from .codegen.describe import loop_flops
        integ = self.solver.integrator
        rows = self.scene.plan.group_plans
        if integ.steps_taken:
            per_step = {k: n / integ.steps_taken for k, n in integ.set_runs.items()}
        else:
            per_step = {k: 1.0 for k in range(integ.n_evaluations)}
        total = 0.0
        for k, times in sorted(per_step.items()):
            row = rows[k] if len(rows) > 1 else rows[0]
            for gp in row:
                for dest, npass in gp.passes.items():
                    for loop in npass.sources:
                        off, _ = (self.scene.nnps.reference_neighbours(dest, loop.source) if gp.group.reference
                                  else self.scene.nnps.neighbours(dest, loop.source))
                        pairs = int(off[-1]) * max(1, gp.group.iterations)
                        total += times * pairs * (loop_flops(npass, loop) if flops else 1)
        return int(round(total))

    def _info(self, completed, error=None, stopped=False):
        s, sc, opts = self.solver, self.scene, self.options
        n = sum(pa.n for pa in sc.arrays)
        steps = max(s.step, 1)
        return {
            "completed": completed, "stopped": stopped, "error": error, "t": s.t, "steps": s.step, "dt": s.dt,
            "n_particles": n, "particles": {pa.name: pa.n for pa in sc.arrays},
            "wall_time": s.wall_time, "compile_time": sc.compile_time, "setup_time": sc.setup_time,
            "threads": s.tuner.most if s.tuner else sc.threads, "backend": sc.backend,
            "thread_choices": s.tuner.choices if s.tuner else [],
            "time_per_particle_step": s.wall_time / (steps * max(n, 1)),
            "neighbour_pairs_per_step": self.neighbour_pairs_per_step() if completed else None,
            "estimated_pair_flops_per_step": self.neighbour_pairs_per_step(flops=True) if completed else None,
            "neighbour_updates": sc.nnps.n_updates, "neighbour_builds": sc.nnps.n_builds,
            "skin": sc.nnps.skin, "skin_choices": sc.skin_tuner.choices if sc.skin_tuner else [],
            "generated_source": getattr(sc, "source_path", None),
            "restarts": self.restarts, "options": vars(opts),
            **({"timing": self.timing_report()[1]} if self.timers is not None else {}),
            "finished_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        }


def list_applications():
    import sphgen.applications as apps
    return sorted(m.name for m in pkgutil.iter_modules(apps.__path__) if not m.name.startswith("_"))


def unknown_application(name):
    """The one line for a name that is no application: the nearest names (difflib) and the count."""
    names = list_applications()
    near = [f"'{n}'" for n in difflib.get_close_matches(name, names, n=3)]
    count = f"('sphgen list' names all {len(names)})"
    if not near:
        return f"no application '{name}' {count}"
    either = " or ".join([", ".join(near[:-1]), near[-1]] if len(near) > 1 else near)
    return f"no application '{name}'; did you mean {either}? {count}"


def load_application(name):
    """The Application class of ``sphgen.applications.NAME``; an unknown name is an InputError."""
    if name not in list_applications():
        raise InputError(unknown_application(name))
    mod = importlib.import_module(f"sphgen.applications.{name}")
    classes = [v for v in vars(mod).values() if isinstance(v, type) and issubclass(v, Application)
               and v is not Application and v.__module__ == mod.__name__]
    if len(classes) != 1:
        raise SystemExit(f"sphgen: module {mod.__name__} must define exactly one Application")
    return classes[0]


class _PipeTolerant:
    """sys.stdout for the command line: once its reader has gone (``sphgen run ... | head``),
    the rest goes to /dev/null (Python's own advice) instead of failing the command with a
    traceback half-way through writing its results."""

    def __init__(self, stream):
        self._stream = stream

    def write(self, text):
        try:
            return self._stream.write(text)
        except BrokenPipeError:
            self._drop()
            return len(text)

    def flush(self):
        try:
            self._stream.flush()
        except BrokenPipeError:
            self._drop()

    def _drop(self):
        os.dup2(os.open(os.devnull, os.O_WRONLY), self._stream.fileno())

    def __getattr__(self, name):
        return getattr(self._stream, name)


def _print_to_pipe(text):
    print(text, flush=True)
    return 0


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not isinstance(sys.stdout, _PipeTolerant):
        sys.stdout = _PipeTolerant(sys.stdout)
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: sphgen run NAME [options] | sphgen precision NAME ... | sphgen stress NAME ... "
              "| sphgen list\n"
              "  run NAME        run an application (sphgen run NAME --help for its options)\n"
              "  precision NAME  error against run time over resolutions (sphgen precision --help)\n"
              "  stress NAME     perturbed runs at several dt factors (sphgen stress --help)\n"
              "  list            list the applications")
        return 0
    if argv[0] == "list":
        return _print_to_pipe("\n".join(list_applications()))
    if argv[0] in ("precision", "stress"):
        from . import studies
        try:
            return studies.main(argv[0], argv[1:])
        except SphgenError as e:
            if debug_requested(argv):
                raise
            raise SystemExit(f"sphgen: {one_line(e)}") from None
    if argv[0] != "run" or len(argv) < 2:
        raise SystemExit(f"sphgen: unknown command {' '.join(argv)!r}; try 'sphgen run NAME', "
                         "'sphgen precision NAME', 'sphgen stress NAME' or 'sphgen list'")
    try:
        app = load_application(argv[1])
    except InputError as e:
        print(f"sphgen: {one_line(e)}", file=sys.stderr)
        raise SystemExit(e.exit_code) from None
    app().run(argv[2:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
