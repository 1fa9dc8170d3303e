"""Scene: particle arrays + equations + integrator steppers, planned and compiled.

``Scene(...).compute(i, t, dt)`` runs the i-th equation set, ``stage('stage1', t, dt)``
the steppers' stage kernels, ``update_nnps()`` rebuilds neighbour lists.  The same
interface runs on the compiled module (``backend='cython'``) or on the plain-Python
evaluator (``backend='python'``), which is how generated code is checked.
"""
import os
import time

import numpy as np

from .codegen.build import load_or_build
from .codegen.plan import Plan, normalise_stages
from .codegen.render import nbr_key, render
from .evaluator import PythonEvaluator
from .kernels import QuinticSpline
from .nnps import NeighbourSearch


class Scene:
    """Everything one simulation computes, specialised and compiled once."""

    def __init__(self, arrays, equations, steppers=None, kernel=None, dim=2, domain=None,
                 outputs=None, backend="cython", threads=None):
        if backend not in ("cython", "python"):
            raise ValueError(f"backend must be 'cython' or 'python', got {backend!r}")
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
        self.plan = Plan(self.arrays, normalise_stages(equations), self.steppers, self.kernel, dim,
                         domain, outputs)
        for pa in self.arrays:
            for p in self.plan.allocation[pa.name]:
                pa.allocate(p)
        self.nnps = NeighbourSearch(self.arrays, dim, self.kernel.radius_scale, domain)
        self.backend = backend
        self.compile_time = 0.0
        self.source = None
        if backend == "cython":
            self.source, self._params = render(self.plan)
            origin = {}
            for ep in self.plan.eqplans:
                for m, sp in ep.methods.items():
                    origin[sp.fdef.name] = f"{type(ep.eq).__name__}.{m}"
            for st in self.plan.steppers:
                for m, sp in st.stages.items():
                    origin[sp.fdef.name] = f"{type(st.stepper).__name__}.{m}"
            self.module, self.compile_time = load_or_build(self.source, origin)
            self.source_path = self.module.__sphgen_source__
        else:
            self.module = None
            self.evaluator = PythonEvaluator(self.plan, self.nnps)
        self.setup_time = time.perf_counter() - t0
        self.set_threads(threads)
        self.nnps.update()
        self._freeze_reference_lists()
        self.bind()

    # ---------------------------------------------------------------- binding
    def set_threads(self, threads=None):
        """Threads for the parallel loops (default: all cores; 1 = serial)."""
        if threads is None:
            threads = int(os.environ.get("OMP_NUM_THREADS", os.cpu_count() or 1))
        self.threads = max(1, int(threads))
        if self.module is not None:
            self.module.set_threads(self.threads)

    def bind(self):
        """Hand array memory and parameter values to the compiled module."""
        if self.module is None:
            return
        self.module.bind_arrays({pa.name: (pa.n, {**pa.data, **pa.constants}) for pa in self.arrays})
        self.module.set_parameters({g: float(getattr(o, a)) for g, (o, a) in self._params.items()})
        self._bind_neighbours()

    def _freeze_reference_lists(self):
        for row in self.plan.group_plans:
            for gp in row:
                if gp.group.reference:
                    for dest in gp.dests:
                        for src in gp.sources(dest):
                            if not self.nnps.is_frozen(dest, src):
                                self.nnps.freeze(dest, src)

    def _bind_neighbours(self):
        if self.module is None:
            return
        lists = {}
        for row in self.plan.group_plans:
            for gp in row:
                for dest in gp.dests:
                    for src in gp.sources(dest):
                        ref = gp.group.reference
                        key = nbr_key(dest, src, ref)
                        if key not in lists:
                            lists[key] = (self.nnps.reference_neighbours(dest, src) if ref
                                          else self.nnps.neighbours(dest, src))
        self.module.bind_neighbours(lists)

    # ---------------------------------------------------------------- running
    def update_nnps(self):
        """Rebuild neighbour lists after positions changed."""
        self.nnps.update()
        self._bind_neighbours()

    def compute(self, index, t, dt):
        """Evaluate equation set ``index`` (any index if there is only one set)."""
        rows = self.plan.group_plans
        row = rows[index] if len(rows) > 1 else rows[0]
        for gp in row:
            self.run_group(gp, t, dt)

    def run_group(self, gp, t, dt):
        g = gp.group
        if g.condition is not None and not g.condition(t, dt):
            g.iterations = 0
            return
        eqs = [ep.eq for ep in gp.eqplans if ep.kept]
        for it in range(g.max_iterations):
            for dest in gp.dests:
                if self.module is not None:
                    getattr(self.module, f"pass_g{gp.index}_{dest}")(t, dt)
                else:
                    self.evaluator.run_pass(gp, dest, t, dt)
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
                if self.module is not None:
                    getattr(self.module, f"stage_{st.array}_{name}")(t, dt)
                else:
                    self.evaluator.run_stage(st, name, t, dt)

    def sort(self):
        """Spatially sort particles for cache locality (memory is permuted in place)."""
        self.nnps.sort()
        self._bind_neighbours()

    def describe(self):
        return self.plan.describe()

    def max_speed2(self):
        """[(array, largest |u|^2, its particle index)] over arrays with velocities."""
        if self.module is not None:
            return self.module.max_speed2()
        out = []
        for pa in self.arrays:
            comps = [pa.data[u] for u in ("u", "v", "w")[:self.dim] if u in pa.data]
            if comps and pa.n:
                s2 = sum(c * c for c in comps)
                i = int(np.argmax(s2))
                out.append((pa.name, float(s2[i]), i))
        return out

    def check_finite(self):
        """None if all allocated float data is finite, else (array, prop, particle index).

        The compiled module scans in parallel; numpy finds the particle only on failure.
        """
        if self.module is not None:
            bad = self.module.count_nonfinite()
            candidates = [(self.by_name[a], p) for a, p, _ in bad]
        else:
            candidates = [(pa, name) for pa in self.arrays for name in pa.data]
        for pa, name in candidates:
            arr = pa.data[name]
            if arr.dtype.kind == "f" and not np.isfinite(arr.sum()):
                i = int(np.flatnonzero(~np.isfinite(arr))[0]) // pa.props[name].stride
                return pa.name, name, i
        return None
