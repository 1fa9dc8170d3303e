"""The compiled backend: the plan rendered, built (or loaded from the cache) and driven."""
import numpy as np

from .backend import Backend
from .build import load_or_build
from .passes.specialise import check_switches
from .render import render


class CompiledBackend(Backend):
    """One Cython/OpenMP module for the scene; entry points named by the renderer.

    Two live scenes whose generated source is the same share one loaded module (its
    array pointers and parameters are module globals).  Each backend therefore claims
    the module before running it: if another scene bound it last, this one binds its
    own arrays, parameters, neighbour lists and threads again (pointer updates only).
    """

    name = "cython"

    def __init__(self, plan, nnps):
        self.rendered = render(plan)
        self.source = self.rendered.source
        self.module, self.compile_time = load_or_build(self.source, self.rendered.origin)
        super().__init__(plan, nnps)
        self.source_path = self.module.__sphgen_source__
        self._passes = {k: getattr(self.module, v) for k, v in self.rendered.pass_entries.items()}
        self._stages = {k: getattr(self.module, v) for k, v in self.rendered.stage_entries.items()}
        self._arrays, self._threads = None, 1
        self._bound_lists = None      # the lists the module holds (taken again only if they change)
        self._bound_rows = None       # the search's row_version when they were bound
        self._reference_rows = {}     # key -> row views of a frozen list
        self._parts = None            # {array: the module's thread parts}, taken at each rebind

    def _claim(self):
        if getattr(self.module, "_sphgen_owner", None) is not self and self._arrays is not None:
            self.module.set_threads(self._threads)
            self.bind(self._arrays)

    def set_threads(self, n):
        self._threads = n
        self.module.set_threads(n)
        self._parts = self._thread_parts()

    def _thread_parts(self):
        """{array: int64 thread parts of the module} (for the neighbour search's row cuts)."""
        if self._arrays is None:
            return None
        out = {}
        for pa in self._arrays:
            try:
                out[pa.name] = np.asarray(self.module.parts(pa.name), dtype=np.int64)
            except KeyError:      # an array no loop of the module walks
                pass
        return out

    def bind(self, arrays):
        check_switches(self.plan)
        self._arrays = arrays
        self._bound_lists = None
        self._bound_rows = None
        self.module._sphgen_owner = self
        self.module.bind_arrays({pa.name: (pa.n, {**pa.data, **pa.constants}) for pa in arrays})
        self.module.set_parameters({g: float(getattr(o, a)) for g, (o, a) in self.rendered.parameters.items()})
        self.bind_neighbours()

    def bind_neighbours(self):
        if getattr(self.module, "_sphgen_owner", None) is not self and self._arrays is not None:
            return self._claim()     # binds everything, these neighbour lists included
        if self._bound_rows is not None and self.nnps.rows_unchanged(self._bound_rows, self._parts):
            return                   # cut anew inside the very arrays the module holds
        lists = {}
        exact = [(key, dest, src) for key, (dest, src, reference) in self.rendered.neighbour_lists.items()
                 if not reference]
        # every exact list of this update cut in one call, each row by the thread whose pass walks it
        for (key, _, _), rows in zip(exact, self.nnps.rows_of([(d, s) for _, d, s in exact], self._parts)):
            lists[key] = rows[:3]
        for key, (dest, src, reference) in self.rendered.neighbour_lists.items():
            if reference:
                off, nbrs = self.nnps.reference_neighbours(dest, src)
                rows = self._reference_rows.get(key)
                if rows is None or rows[3] is not off or rows[2] is not nbrs:
                    rows = self._reference_rows[key] = (off[:-1], off[1:], nbrs, off)
                lists[key] = rows[:3]
        bound = self._bound_lists
        if bound is None or bound.keys() != lists.keys() or any(
                any(a is not b for a, b in zip(lists[k], bound[k])) for k in lists):
            self.module.bind_neighbours(lists)    # else the module holds these very arrays
            self._bound_lists = lists
            self._parts = self._thread_parts()    # the module cut them anew
        self._bound_rows = self.nnps.row_version

    def run_pass(self, npass, t, dt):
        self._claim()
        self._passes[npass.label](t, dt)

    def run_stage(self, st, name, t, dt):
        self._claim()
        self._stages[(st.array, name)](t, dt)

    def parts(self, name):
        """Thread k's particles of array ``name`` in every loop: ``parts[k] .. parts[k+1]-1``."""
        self._claim()
        return self.module.parts(name)

    def copy_arrays(self, arrays, out, save):
        return self.module.copy_arrays(arrays, out, save)

    def extremes(self, arrays):
        self._claim()
        return self.module.extremes()

    def set_guard_limits(self, speed_limit, density_bounds):
        names = self.module.SWEPT_ARRAYS
        self._speed2_max = np.inf if speed_limit is None else float(speed_limit) ** 2
        self._rho_lo = np.array([density_bounds.get(a, (-np.inf, np.inf))[0] for a in names] or [0.0])
        self._rho_hi = np.array([density_bounds.get(a, (-np.inf, np.inf))[1] for a in names] or [0.0])

    def state_is_good(self, arrays):
        self._claim()
        return self.module.state_is_good(self._speed2_max, self._rho_lo, self._rho_hi)

    def nonfinite_suspects(self, arrays):
        self._claim()
        by_name = {pa.name: pa for pa in arrays}
        return [(by_name[a], p) for a, p, _ in self.module.count_nonfinite()]
