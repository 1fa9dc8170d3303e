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

    def max_speed2(self, arrays):
        """[(array, largest |u|^2, its particle index)] over arrays with velocities."""
        out = []
        for pa in arrays:
            comps = [pa.data[u] for u in ("u", "v", "w")[:self.plan.dim] if u in pa.data]
            if comps and pa.n:
                s2 = sum(c * c for c in comps)
                i = int(np.argmax(s2))
                out.append((pa.name, float(s2[i]), i))
        return out

    def nonfinite_suspects(self, arrays):
        """[(array, property)] that may hold a non-finite value (a cheap first look)."""
        return [(pa, name) for pa in arrays for name in pa.data]
