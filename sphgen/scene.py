"""Scene: particle arrays + equations + integrator steppers, planned and compiled.

``Scene(...).compute(i, t, dt)`` runs the i-th evaluation (equation set),
``stage('stage1', t, dt)`` the steppers' stage kernels, ``update_nnps()`` rebuilds
neighbour lists.  The same interface runs on the compiled module (``backend='cython'``)
or on the plain-Python evaluator (``backend='python'``), which is how generated code is
checked; the scene only talks to the backend's interface
(:class:`~sphgen.codegen.backend.Backend`).
"""
import os
import time

import numpy as np

from .codegen.compiled import CompiledBackend
from .codegen.passes import plan_scene
from .evaluator import PythonEvaluator
from .kernels import QuinticSpline
from .nnps import NeighbourSearch
from .nnps.skin_tuner import SkinTuner

BACKENDS = {"cython": CompiledBackend, "python": PythonEvaluator}


class Scene:
    """Everything one simulation computes, specialised and compiled once."""

    def __init__(self, arrays, equations, steppers=None, kernel=None, dim=2, domain=None,
                 outputs=None, backend="cython", threads=None, skin=0.0, evaluated=None,
                 tune_skin=False):
        if backend not in BACKENDS:
            raise ValueError(f"backend must be {' or '.join(map(repr, BACKENDS))}, got {backend!r}")
        self.arrays = list(arrays)
        self.by_name = {pa.name: pa for pa in self.arrays}
        self.dim = dim
        self.kernel = kernel or QuinticSpline(dim)
        if self.kernel.dim != dim:
            raise ValueError(f"kernel is {self.kernel.dim}D but the scene is {dim}D")
        self.domain = domain
        self.steppers = dict(steppers or {})
        for name in self.steppers:
            if name not in self.by_name:
                raise ValueError(f"integrator stepper for unknown array '{name}'")
        t0 = time.perf_counter()
        self.plan = plan_scene(self.arrays, equations, self.steppers, self.kernel, dim, domain, outputs,
                               evaluated)
        for pa in self.arrays:
            for p in self.plan.allocation[pa.name]:
                pa.allocate(p)
        self.nnps = NeighbourSearch(self.searched_arrays(), dim, self.kernel.radius_scale, domain,
                                    skin=skin)
        # the skin of the next rebuilds chosen by timing (results unchanged: exact lists)
        self.skin_tuner = (SkinTuner(skin, dim, lowest=min(0.025, skin), highest=max(0.5, skin))
                           if tune_skin and skin > 0 else None)
        self._builds_seen = 0    # rebuilds the tuner has seen (a sort rebuilds too)
        self._clock = time.perf_counter    # the tuner's clock
        self.backend = backend
        self.engine = BACKENDS[backend](self.plan, self.nnps)
        self.setup_time = time.perf_counter() - t0
        self.set_threads(threads)
        self.nnps.update()
        self._freeze_reference_lists()
        self.bind()

    def searched_arrays(self):
        """The arrays some neighbour loop visits; an array that interacts with nothing gets
        no neighbour search (nor periodic wrapping or sorting).  All, if none interacts."""
        used = {a for d, s, _ in self.plan.neighbour_lists() for a in (d, s)}
        return [pa for pa in self.arrays if pa.name in used] or self.arrays

    # the generated module, if the backend has one
    compile_time = property(lambda self: self.engine.compile_time)
    source = property(lambda self: self.engine.source)
    source_path = property(lambda self: self.engine.source_path)

    # ---------------------------------------------------------------- binding
    def set_threads(self, threads=None):
        """Threads for the parallel loops (default: all cores; 1 = serial)."""
        if threads is None:
            threads = int(os.environ.get("OMP_NUM_THREADS", os.cpu_count() or 1))
        self.threads = max(1, int(threads))
        self.engine.set_threads(self.threads)

    def bind(self):
        """Hand array memory, parameter values and neighbour lists to the backend."""
        self.engine.bind(self.arrays)

    def _freeze_reference_lists(self):
        for dest, src, reference in self.plan.neighbour_lists():
            if reference and not self.nnps.is_frozen(dest, src):
                self.nnps.freeze(dest, src)

    # ---------------------------------------------------------------- running
    def update_nnps(self):
        """Rebuild neighbour lists after positions changed (timed for the skin tuner, if any,
        which then sets the skin of the next rebuilds)."""
        tuner = self.skin_tuner
        if tuner is None:
            self.nnps.update()
            self.engine.bind_neighbours()
            return
        nnps, before, skin = self.nnps, self.nnps.n_builds, self.nnps.skin
        if before != self._builds_seen:     # a sort rebuilt the lists since the last update
            tuner.interrupt()
        start = self._clock()
        nnps.update()
        self.engine.bind_neighbours()
        self._builds_seen = nnps.n_builds
        nnps.skin = tuner.record(self._clock() - start, nnps.n_builds != before, skin)

    def compute(self, index, t, dt):
        """Run evaluation ``index`` (any index if there is only one equation set)."""
        if index in self.plan.dropped:
            raise ValueError(f"equation set {index} was declared never evaluated (Scene(evaluated=...)); "
                             "nothing was generated for it")
        rows = self.plan.group_plans
        row = rows[index] if len(rows) > 1 else rows[0]
        for gp in row:
            self.run_group(gp, t, dt)

    def run_group(self, gp, t, dt):
        """One group: its passes, then reductions and neighbour update, iterated if asked."""
        g = gp.group
        if g.condition is not None and not g.condition(t, dt):
            g.iterations = 0
            return
        eqs = [ep.eq for ep in gp.eqplans if ep.kept]
        for it in range(g.max_iterations):
            for npass in gp.passes.values():
                self.engine.run_pass(npass, t, dt)
            for eq in eqs:
                if callable(getattr(eq, "reduce", None)):
                    eq.reduce(self.by_name[eq.dest], t, dt)
            if g.update_nnps:
                self.update_nnps()
            if g.iterate and it + 1 >= g.min_iterations and \
                    all(eq.converged() > 0 for eq in eqs if callable(getattr(eq, "converged", None))):
                break
        g.iterations = it + 1

    def stage(self, name, t, dt):
        """Run stage ``name`` (e.g. 'stage1') of every stepper that defines it."""
        for st in self.plan.steppers:
            if name in st.stages:
                self.engine.run_stage(st, name, t, dt)

    def sort(self):
        """Spatially sort particles for cache locality (memory is permuted in place)."""
        self.nnps.sort()
        self.engine.bind_neighbours()

    def describe(self):
        return self.plan.describe()

    def extremes(self):
        """[(array, largest |u|^2, its particle, smallest rho, its particle, largest rho, its
        particle)] over the arrays with velocities or a density (-1 where there is none)."""
        return self.engine.extremes(self.arrays)

    def set_guard_limits(self, speed_limit, density_bounds):
        """The largest speed (None: none) and the {array: (lo, hi)} density bounds that
        :meth:`state_is_good` checks."""
        self.engine.set_guard_limits(speed_limit, density_bounds)

    def state_is_good(self):
        """True when all float data is finite and within the guard's limits: one sweep,
        which does not say where (:meth:`check_finite` and :meth:`extremes` do)."""
        return self.engine.state_is_good(self.arrays)

    def check_finite(self):
        """None if all allocated float data is finite, else (array, prop, particle index).

        The backend names the suspects (the compiled module scans in parallel); numpy
        finds the particle only on failure.
        """
        for pa, name in self.engine.nonfinite_suspects(self.arrays):
            arr = pa.data[name]
            if arr.dtype.kind == "f" and not np.isfinite(arr.sum()):
                i = int(np.flatnonzero(~np.isfinite(arr))[0]) // pa.props[name].stride
                return pa.name, name, i
        return None
