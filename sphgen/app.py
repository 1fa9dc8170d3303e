"""Application base class and the ``sphgen`` command line.

``sphgen run NAME [options]`` imports ``sphgen.applications.NAME``, builds its
Application and runs it; ``sphgen list`` names the applications.  Every run writes
``info.json`` in its output folder (automan's notion of a finished case).
"""
import argparse
import importlib
import math
import os
import pkgutil
import sys
import time

from . import io
from .scene import Scene
from .solver import BlowUpError, Solver


def _positive_float(s):
    v = float(s)
    if not (math.isfinite(v) and v > 0):
        raise argparse.ArgumentTypeError(f"must be a positive finite number, got {s}")
    return v


def _nonneg_float(s):
    v = float(s)
    if not (math.isfinite(v) and v >= 0):
        raise argparse.ArgumentTypeError(f"must be a non-negative finite number, got {s}")
    return v


def _positive_int(s):
    v = int(s)
    if v < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {s}")
    return v


class Application:
    """Subclass and override ``create_particles`` and ``create_scheme``.

    Optional: ``create_domain``, ``add_user_options(parser)``,
    ``consume_user_options(options)``, ``post_step(solver)``, ``post_process(outdir)``.
    Class attributes ``tf`` and ``pfreq`` give the defaults of ``--tf``/``--pfreq``.
    """

    tf = 1.0
    pfreq = 100
    dim = 2

    def __init__(self, name=None):
        self.name = name or type(self).__module__.rsplit(".", 1)[-1]
        self.options = None
        self.scene = self.solver = self.scheme = None

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

    # ---------------------------------------------------------------- CLI
    def parser(self):
        p = argparse.ArgumentParser(prog=f"sphgen run {self.name}", description=(type(self).__doc__ or "").strip())
        g = p.add_argument_group("run")
        g.add_argument("--tf", type=_nonneg_float, default=self.tf, help="final time (default %(default)s)")
        g.add_argument("--dt", type=_positive_float, default=None, help="time step (default: the scheme's)")
        g.add_argument("--max-steps", type=_positive_int, default=None, help="stop after this many steps")
        g.add_argument("--openmp", dest="openmp", action="store_true", default=True,
                       help="use all cores (default)")
        g.add_argument("--no-openmp", dest="openmp", action="store_false", help="run serial (one thread)")
        g.add_argument("--threads", type=_positive_int, default=None, help="number of threads")
        g.add_argument("-d", "--directory", default=None, help="output folder (default NAME_output)")
        g.add_argument("--pfreq", type=_positive_int, default=self.pfreq, help="output every N steps")
        g.add_argument("--disable-output", action="store_true", help="write no particle files")
        g.add_argument("--restart", metavar="FILE", default=None, help="continue from an output file")
        g.add_argument("--show-plan", action="store_true", help="print the generator's plan and exit")
        g.add_argument("--backend", choices=("cython", "python"), default="cython",
                       help="compiled (default) or the slow plain-Python evaluator")
        g.add_argument("--no-progress", dest="progress", action="store_false", help="no progress bar")
        self.add_user_options(p.add_argument_group(self.name))
        return p

    def run(self, argv=None):
        """Parse options, build the scene, run, write info.json, post-process."""
        opts = self.parser().parse_args(argv)
        self.options = opts
        self.consume_user_options(opts)
        outdir = opts.directory or f"{self.name}_output"
        self.outdir = outdir
        arrays = self.create_particles()
        self.scheme = self.create_scheme()
        self.scheme.setup_properties(arrays)
        outputs = {pa.name: [p for p in self.scheme.output_props if pa.has(p)] for pa in arrays}
        threads = 1 if not opts.openmp else opts.threads
        integrator = self.scheme.get_integrator()
        self.scene = Scene(arrays, self.scheme.get_equations(), steppers=integrator.steppers,
                           kernel=getattr(self.scheme, "kernel", None), dim=self.dim,
                           domain=self.create_domain(), outputs=outputs, backend=opts.backend,
                           threads=threads)
        if opts.show_plan:
            print(self.scene.describe())
            if self.scene.source is not None:
                print(f"generated source: {self.scene.source_path}")
            return None
        dt = opts.dt or self.scheme.get_timestep()
        self.solver = Solver(self.scene, integrator, dt, opts.tf, max_steps=opts.max_steps,
                             pfreq=opts.pfreq, outdir=outdir, prefix=self.name,
                             disable_output=opts.disable_output, progress=opts.progress,
                             speed_limit=getattr(self.scheme, "speed_limit", None))
        if opts.restart:
            self.solver.restart_from(opts.restart)
        self.solver.post_step_callbacks.append(self.post_step)
        os.makedirs(outdir, exist_ok=True)
        info = self._info(opts, completed=False)
        io.write_json(os.path.join(outdir, "info.json"), info)
        error = None
        try:
            self.solver.run()
        except BlowUpError as e:
            error = str(e)
        info = self._info(opts, completed=error is None, error=error)
        io.write_json(os.path.join(outdir, "info.json"), info)
        print(f"{self.name}: {self.solver.step} steps to t={self.solver.t:.6g} in {self.solver.wall_time:.2f} s "
              f"(compile {self.scene.compile_time:.2f} s, {self.scene.threads} thread(s)); output in {outdir}")
        if error:
            raise BlowUpError(error)
        self.post_process(outdir)
        return info

    def neighbour_pairs_per_step(self):
        """Neighbour pairs visited in one step (all evaluations and passes)."""
        plan = self.scene.plan
        n_eval = self.solver.integrator.n_evaluations
        rows = plan.group_plans
        total = 0
        for k in range(n_eval):
            row = rows[k] if len(rows) > 1 else rows[0]
            for gp in row:
                for dest in gp.dests:
                    for src in gp.sources(dest):
                        off, _ = (self.scene.nnps.reference_neighbours(dest, src) if gp.group.reference
                                  else self.scene.nnps.neighbours(dest, src))
                        total += int(off[-1]) * max(1, gp.group.iterations)
        return total

    def _info(self, opts, completed, error=None):
        s, sc = self.solver, self.scene
        n = sum(pa.n for pa in sc.arrays)
        steps = max(s.step, 1)
        return {
            "completed": completed, "error": error, "t": s.t, "steps": s.step, "dt": s.dt,
            "n_particles": n, "particles": {pa.name: pa.n for pa in sc.arrays},
            "wall_time": s.wall_time, "compile_time": sc.compile_time, "setup_time": sc.setup_time,
            "threads": sc.threads, "backend": sc.backend,
            "time_per_particle_step": s.wall_time / (steps * max(n, 1)),
            "neighbour_pairs_per_step": self.neighbour_pairs_per_step() if completed else None,
            "generated_source": getattr(sc, "source_path", None),
            "options": vars(opts), "finished_at": time.strftime("%Y-%m-%dT%H:%M:%S"),
        }


def list_applications():
    import sphgen.applications as apps
    return sorted(m.name for m in pkgutil.iter_modules(apps.__path__) if not m.name.startswith("_"))


def load_application(name):
    try:
        mod = importlib.import_module(f"sphgen.applications.{name}")
    except ModuleNotFoundError as e:
        if e.name == f"sphgen.applications.{name}":
            raise SystemExit(f"sphgen: no application '{name}'; known: {', '.join(list_applications())}")
        raise
    classes = [v for v in vars(mod).values() if isinstance(v, type) and issubclass(v, Application)
               and v is not Application and v.__module__ == mod.__name__]
    if len(classes) != 1:
        raise SystemExit(f"sphgen: module {mod.__name__} must define exactly one Application")
    return classes[0]


def main(argv=None):
    argv = sys.argv[1:] if argv is None else argv
    if not argv or argv[0] in ("-h", "--help"):
        print("usage: sphgen run NAME [options] | sphgen list\n"
              "  run NAME   run an application (sphgen run NAME --help for its options)\n"
              "  list       list the applications")
        return 0
    if argv[0] == "list":
        print("\n".join(list_applications()))
        return 0
    if argv[0] != "run" or len(argv) < 2:
        raise SystemExit(f"sphgen: unknown command {' '.join(argv)!r}; try 'sphgen run NAME' or 'sphgen list'")
    app = load_application(argv[1])()
    try:
        app.run(argv[2:])
    except BlowUpError as e:
        raise SystemExit(f"sphgen: the run blew up: {e}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
