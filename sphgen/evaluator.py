"""The plain-Python reference evaluator: the same equations, run as written.

It calls the *original* methods (not the specialised ones) with numpy arrays and
Python floats, one particle and one pair at a time, in the order the compiled module
uses, and computes the pair symbols with the Python code of the pair-symbol table.
Slow by design; tests compare compiled results against it to round-off, and a user
can step through a new equation with a debugger.
"""
import inspect

import numpy as np

from .codegen.backend import Backend
from .codegen.pair_symbols import SYMBOLS, PythonPair


class PythonEvaluator(Backend):
    """Runs a plan's passes and stages in plain Python (``backend='python'``)."""

    name = "python"

    def __init__(self, plan, nnps):
        super().__init__(plan, nnps)
        self.arrays = plan.arrays
        self._sig = {}
        self._scratch = {}

    def _args(self, func):
        if func not in self._sig:
            self._sig[func] = list(inspect.signature(func).parameters)
        return self._sig[func]

    def _props(self, pa, name):
        if name in pa.data:
            return pa.data[name]
        if name in pa.constants:
            return pa.constants[name]
        if name not in pa.props:
            # not even declared: an argument a switched-off branch uses (the compiled
            # stage drops it); a real use fails at once on None
            return None
        # a store the generator removed as dead: give it scratch memory
        key = (pa.name, name)
        if key not in self._scratch:
            self._scratch[key] = np.zeros(pa.n * pa.props[name].stride, dtype=pa.props[name].np_dtype)
        return self._scratch[key]

    def _call(self, owner, method, dest, src, i, j=None, sym=None, t=0.0, dt=0.0, nbrs=None):
        """Call a method of an equation (or stepper) with arguments found by name."""
        f = getattr(owner, method)
        special = {"d_idx": i, "s_idx": j, "t": t, "dt": dt, "NBRS": nbrs,
                   "N_NBRS": None if nbrs is None else len(nbrs)}
        kw = {}
        for a in self._args(f):
            if a in special:
                kw[a] = special[a]
            elif a.startswith("d_"):
                kw[a] = self._props(dest, a[2:])
            elif a.startswith("s_"):
                kw[a] = self._props(src, a[2:])
            else:
                kw[a] = sym[a]
        f(**kw)

    def pair_symbols(self, loop, dest, src, i, j, reference):
        """The pair symbols a source loop computes, for particle i of dest and j of src."""
        pair = PythonPair(dest, src, i, j, self.plan.kernel, self.plan.dim, self.plan.domain, reference)
        for name in loop.symbols:
            pair.values[name] = SYMBOLS[name].python(pair)
        return pair.values

    def _neighbours(self, npass, src):
        if npass.reference:
            return self.nnps.reference_neighbours(npass.dest, src)
        return self.nnps.neighbours(npass.dest, src)

    def _source_loop(self, npass, loop, offsets, i, t, dt):
        dest, src = self.arrays[npass.dest], self.arrays[loop.source]
        off, idx = offsets
        nb = idx[off[i]:off[i + 1]]
        for j in nb:
            sym = self.pair_symbols(loop, dest, src, i, int(j), npass.reference)
            for ep in loop.calls("loop"):
                self._call(ep.eq, "loop", dest, src, i, int(j), sym, t, dt)
        for ep in loop.calls("loop_all"):
            self._call(ep.eq, "loop_all", dest, src, i, t=t, dt=dt, nbrs=nb)

    def run_pass(self, npass, t, dt):
        dest = self.arrays[npass.dest]
        lists = [self._neighbours(npass, loop.source) for loop in npass.sources]
        for i in range(dest.n):
            for ep in npass.calls("initialize"):
                self._call(ep.eq, "initialize", dest, None, i, t=t, dt=dt)
            for loop, offsets in zip(npass.sources, lists):
                self._source_loop(npass, loop, offsets, i, t, dt)
            for ep in npass.calls("post_loop"):
                self._call(ep.eq, "post_loop", dest, None, i, t=t, dt=dt)

    def run_stage(self, st, name, t, dt):
        pa = self.arrays[st.array]
        for i in range(pa.n):
            self._call(st.stepper, name, pa, None, i, t=t, dt=dt)
