"""The plain-Python reference evaluator: the same equations, run as written.

It calls the *original* methods (not the specialised ones) with numpy arrays and
Python floats, one particle and one pair at a time, in the order the compiled module
uses.  Slow by design; tests compare compiled results against it to round-off, and a
user can step through a new equation with a debugger.
"""
import inspect
import math

import numpy as np

from .equation import PAIR_METHODS


class PythonEvaluator:
    def __init__(self, plan, nnps):
        self.plan = plan
        self.nnps = nnps
        self.arrays = plan.arrays
        self.kernel = plan.kernel
        self._sig = {}
        self._scratch = {}

    def _args(self, func):
        if func not in self._sig:
            self._sig[func] = [a for a in inspect.signature(func).parameters]
        return self._sig[func]

    def _props(self, pa, name):
        if name in pa.data:
            return pa.data[name]
        if name in pa.constants:
            return pa.constants[name]
        # a store the generator removed as dead: give it scratch memory
        key = (pa.name, name)
        if key not in self._scratch:
            self._scratch[key] = np.zeros(pa.n * pa.props[name].stride, dtype=pa.props[name].np_dtype)
        return self._scratch[key]

    def _kwargs(self, func, dest, src, d_idx, s_idx, sym, t, dt, nbrs=None):
        kw = {}
        for a in self._args(func):
            if a == "d_idx":
                kw[a] = d_idx
            elif a == "s_idx":
                kw[a] = s_idx
            elif a.startswith("d_"):
                kw[a] = self._props(dest, a[2:])
            elif a.startswith("s_"):
                kw[a] = self._props(src, a[2:])
            elif a == "t":
                kw[a] = t
            elif a == "dt":
                kw[a] = dt
            elif a == "NBRS":
                kw[a] = nbrs
            elif a == "N_NBRS":
                kw[a] = len(nbrs)
            else:
                kw[a] = sym[a]
        return kw

    def pair_symbols(self, dest, src, i, j, reference):
        dim = self.plan.dim
        pos = ("x0", "y0", "z0") if reference else ("x", "y", "z")
        xij = [0.0, 0.0, 0.0]
        for k in range(dim):
            xij[k] = float(dest.data[pos[k]][i] - src.data[pos[k]][j])
            dom = self.plan.domain
            if dom is not None and dom.periodic[k] and not reference:
                L = float(dom.length[k])
                if xij[k] > 0.5 * L:
                    xij[k] -= L
                elif xij[k] < -0.5 * L:
                    xij[k] += L
        r2 = sum(x * x for x in xij[:dim])
        r = math.sqrt(r2)
        h = 0.5 * (dest.data["h"][i] + src.data["h"][j])
        vij = [0.0, 0.0, 0.0]
        if "u" in dest.data and "u" in src.data:
            for k, u in enumerate(("u", "v", "w")[:dim]):
                vij[k] = float(dest.data[u][i] - src.data[u][j])
        wd = self.kernel.dwdr(r, h)
        f = wd / r if r > 1e-12 else 0.0
        return {"XIJ": xij, "RIJ": r, "R2IJ": r2, "HIJ": h, "EPS": 0.01 * h * h, "VIJ": vij,
                "WIJ": self.kernel.w(r, h), "WDASHIJ": wd, "GHIJ": self.kernel.gradh(r, h),
                "DWIJ": [f * x for x in xij]}

    def run_pass(self, gp, dest_name, t, dt):
        dest = self.arrays[dest_name]
        eps = gp.dests[dest_name]
        sources = gp.sources(dest_name)
        ref = gp.group.reference
        lists = {s: (self.nnps.reference_neighbours(dest_name, s) if ref else self.nnps.neighbours(dest_name, s))
                 for s in sources}
        for i in range(dest.n):
            for ep in eps:
                if "initialize" in ep.methods:
                    f = ep.eq.initialize
                    f(**self._kwargs(f, dest, None, i, None, None, t, dt))
            for s, lps in sources.items():
                src = self.arrays[s]
                off, idx = lists[s]
                nb = idx[off[i]:off[i + 1]]
                for j in nb:
                    sym = self.pair_symbols(dest, src, i, int(j), ref)
                    for ep in lps:
                        if "loop" in ep.methods:
                            f = ep.eq.loop
                            f(**self._kwargs(f, dest, src, i, int(j), sym, t, dt))
                for ep in lps:
                    if "loop_all" in ep.methods:
                        f = ep.eq.loop_all
                        f(**self._kwargs(f, dest, src, i, None, None, t, dt, nbrs=nb))
            for ep in eps:
                if "post_loop" in ep.methods:
                    f = ep.eq.post_loop
                    f(**self._kwargs(f, dest, None, i, None, None, t, dt))

    def run_stage(self, st, name, t, dt):
        pa = self.arrays[st.array]
        f = getattr(st.stepper, name)
        for i in range(pa.n):
            f(**self._kwargs(f, pa, None, i, None, None, t, dt))


__all__ = ["PythonEvaluator", "PAIR_METHODS"]
