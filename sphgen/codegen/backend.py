"""What a scene needs of a backend: one interface for the compiled module and the evaluator.

A :class:`~sphgen.scene.Scene` holds one backend and calls only these methods, so it
never knows which one runs.  The defaults suit a backend that works on the arrays'
numpy memory directly (the Python evaluator); the compiled backend overrides them.
"""
import numpy as np


class Backend:
    """Runs the neighbour passes and integrator stages of a finished plan."""

    name = "?"
    source = None          # generated source, if any
    source_path = None     # where it was written, if anywhere
    compile_time = 0.0     # seconds spent compiling (0.0 when nothing was compiled)

    def __init__(self, plan, nnps):
        self.plan = plan
        self.nnps = nnps
        self.set_guard_limits(None, {})

    def set_threads(self, n):
        """Threads of the parallel loops."""

    def bind(self, arrays):
        """Take the arrays' memory and the equations' parameter values."""

    def bind_neighbours(self):
        """Take the neighbour lists (after every neighbour update or sort)."""

    def run_pass(self, npass, t, dt):
        """Run one neighbour pass (a :class:`~sphgen.codegen.plan.NeighbourPass`)."""
        raise NotImplementedError

    def run_stage(self, st, name, t, dt):
        """Run stage ``name`` of one stepper (a :class:`~sphgen.codegen.plan.StepperPlan`)."""
        raise NotImplementedError

    def copy_arrays(self, arrays, out, save):
        """The guard's snapshot: the bytes of every (C-contiguous) array of ``arrays``, one
        after the other, into the uint8 buffer ``out`` (``save``) or back from it."""
        start = 0
        for v in arrays:
            end = start + v.nbytes
            if save:
                out[start:end] = np.ascontiguousarray(v).reshape(-1).view(np.uint8)
            else:
                np.copyto(v, out[start:end].view(v.dtype).reshape(v.shape))
            start = end
        return start

    def extremes(self, arrays):
        """[(array, largest |u|^2, its particle, smallest rho, its particle, largest rho,
        its particle)] over the arrays with velocities or a density (-1: none)."""
        out = []
        for pa in arrays:
            comps = [pa.data[u] for u in ("u", "v", "w")[:self.plan.dim] if u in pa.data]
            rho = pa.data.get("rho")
            rho = rho if rho is not None and rho.dtype == np.float64 else None
            if not (comps or rho is not None):
                continue
            row = [pa.name, 0.0, -1, np.inf, -1, -np.inf, -1]
            if comps and pa.n:
                s2 = sum(c * c for c in comps)
                i = int(np.argmax(s2))
                if s2[i] > 0.0:
                    row[1:3] = float(s2[i]), i
            if rho is not None and pa.n:
                i, j = int(np.argmin(rho)), int(np.argmax(rho))
                row[3:] = float(rho[i]), i, float(rho[j]), j
            out.append(tuple(row))
        return out

    def set_guard_limits(self, speed_limit, density_bounds):
        """The limits :meth:`state_is_good` holds the arrays to: the largest speed (None:
        none) and {array: (smallest rho, largest rho)}."""
        self._speed2_max = np.inf if speed_limit is None else float(speed_limit) ** 2
        self._density_bounds = dict(density_bounds)

    def state_is_good(self, arrays):
        """True when every float is finite and no speed or density is beyond the limits of
        :meth:`set_guard_limits` (the guard's per-step look; it need not say where)."""
        for pa, name in self.nonfinite_suspects(arrays):
            v = pa.data[name]
            if v.dtype.kind == "f" and not np.isfinite(v).all():
                return False
        for name, s2, _, rmin, i, rmax, j in self.extremes(arrays):
            lo, hi = self._density_bounds.get(name, (-np.inf, np.inf))
            if s2 > self._speed2_max or (i >= 0 and rmin < lo) or (j >= 0 and rmax > hi):
                return False
        return True

    def nonfinite_suspects(self, arrays):
        """[(array, property)] that may hold a non-finite value (a cheap first look)."""
        return [(pa, name) for pa in arrays for name in pa.data]
