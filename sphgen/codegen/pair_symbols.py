"""The pair symbols (``XIJ``, ``RIJ``, ``WIJ``, ``DWIJ``, ...): one table, one row each.

A row says what a symbol is (scalar or 3-vector), which other symbols and which
particle properties it is computed from, the Cython lines that compute it in the
compiled module, the Python that computes it in the reference evaluator, and a rough
cost in floating-point operations per pair.  Every other part of the generator reads
this table, so adding a symbol is adding one row (its dependencies must be rows above
it: the table order is the order of computation).
"""
import math
from dataclasses import dataclass
from typing import Callable


@dataclass(frozen=True)
class PairSymbol:
    """One pair symbol: its type, what it is computed from, its code on each backend."""

    name: str
    doc: str
    cython: Callable       # CythonPair -> [lines of Cython] that set the symbol
    python: Callable       # PythonPair -> the value (a float, or a list of 3 floats)
    depends: tuple = ()    # pair symbols it is computed from
    props: Callable = lambda pair: ()   # properties it reads on the destination and sources
    vector: bool = False   # a double[3] whose components past the dimension stay 0
    scratch: tuple = ()    # local doubles its Cython uses
    cost: int = 1          # floating-point operations per pair, roughly
    kernel_methods: tuple = ()   # kernel ``extra_methods`` its Cython calls

    @property
    def dtype(self):
        return "double[3]" if self.vector else "double"

    @property
    def arg_type(self):
        """Its C type as an argument of a generated method."""
        return "double*" if self.vector else "double"

    def declaration(self, dim):
        """Cython lines declaring it in a neighbour pass (vector tails zeroed once)."""
        if not self.vector:
            return [f"cdef double {self.name} = 0.0"]
        return [f"cdef double {self.name}[3]"] + [f"{self.name}[{k}] = 0.0" for k in range(dim, 3)]


class PairGeometry:
    """What a row's code may ask of a pair, whichever backend: dimension, axes, periods."""

    def __init__(self, dim, domain=None, reference=False):
        self.dim = dim
        self.domain = domain
        self.reference = reference

    def axes(self, names):
        """The first ``dim`` of three per-axis names."""
        return tuple(names[:self.dim])

    @property
    def position(self):
        """Position properties: the reference ones (x0, y0, z0) in a reference group."""
        return self.axes(("x0", "y0", "z0") if self.reference else ("x", "y", "z"))

    def period(self, k):
        """The box length of axis k if separations wrap there (minimum image), else None."""
        dom = self.domain
        if dom is None or self.reference or not dom.periodic[k]:
            return None
        return float(dom.length[k])


class CythonPair(PairGeometry):
    """A pair in the compiled module: properties are C arrays indexed by d_idx / s_idx."""

    def __init__(self, dest, src, dim, domain=None, reference=False):
        super().__init__(dim, domain, reference)
        self.dest, self.src = dest, src

    def d(self, prop):
        return f"{self.dest}_{prop}[d_idx]"

    def s(self, prop):
        return f"{self.src}_{prop}[s_idx]"


class PythonPair(PairGeometry):
    """A pair in the Python evaluator: particle i of dest, j of src, the symbols so far."""

    def __init__(self, dest, src, i, j, kernel, dim, domain=None, reference=False):
        super().__init__(dim, domain, reference)
        self.dest, self.src, self.i, self.j, self.kernel = dest, src, i, j, kernel
        self.values = {}

    def d(self, prop):
        return self.dest.data[prop][self.i]

    def s(self, prop):
        return self.src.data[prop][self.j]

    def __getitem__(self, name):
        return self.values[name]


# ------------------------------------------------------------------ the rows' code
# Minimum image on a periodic axis of length L: x - L rint(x / L), rounding half to even
# (C's rint in the default mode, Python's round), exact for |x| < 1.5 L, which wrapped
# positions guarantee.  No branch, so the compiler can vectorise the pair loop.
def _xij_cython(c):
    lines = []
    for k, x in enumerate(c.position):
        lines.append(f"XIJ[{k}] = {c.d(x)} - {c.s(x)}")
        L = c.period(k)
        if L is not None:
            lines.append(f"XIJ[{k}] -= {L!r} * rint(XIJ[{k}] * {1.0 / L!r})")
    return lines


def _xij_python(p):
    xij = [0.0, 0.0, 0.0]
    for k, x in enumerate(p.position):
        xij[k] = float(p.d(x) - p.s(x))
        L = p.period(k)
        if L is not None:
            xij[k] -= L * round(xij[k] * (1.0 / L))
    return xij


def _vij_cython(c):
    return [f"VIJ[{k}] = {c.d(u)} - {c.s(u)}" for k, u in enumerate(c.axes("uvw"))]


def _vij_python(p):
    vij = [0.0, 0.0, 0.0]
    for k, u in enumerate(p.axes("uvw")):
        vij[k] = float(p.d(u) - p.s(u))
    return vij


def _dwij_python(p):
    f = p.kernel.dwdr_over_r(p["RIJ"], p["HIJ"])
    return [f * x for x in p["XIJ"]]


def _kernel_row(name, method, doc, cost, extra=False):
    """A row that evaluates a kernel method at (RIJ, HIJ) (``extra``: one of its extra_methods)."""
    return PairSymbol(
        name, doc, cost=cost, depends=("RIJ", "HIJ"), kernel_methods=(method,) if extra else (),
        cython=lambda c: [f"{name} = kernel_{method}(RIJ, HIJ)"],
        python=lambda p: getattr(p.kernel, method)(p["RIJ"], p["HIJ"]))


ROWS = (
    PairSymbol("XIJ", "x_i - x_j, minimum image on periodic axes", vector=True, cost=3,
               props=lambda pair: pair.position, cython=_xij_cython, python=_xij_python),
    PairSymbol("R2IJ", "|x_ij|^2", depends=("XIJ",), cost=5,
               cython=lambda c: ["R2IJ = " + " + ".join(f"XIJ[{k}] * XIJ[{k}]" for k in range(c.dim))],
               python=lambda p: sum(x * x for x in p["XIJ"][:p.dim])),
    PairSymbol("RIJ", "|x_ij|", depends=("R2IJ",), cost=10,
               cython=lambda c: ["RIJ = sqrt(R2IJ)"], python=lambda p: math.sqrt(p["R2IJ"])),
    PairSymbol("HIJ", "(h_i + h_j) / 2", props=lambda pair: ("h",), cost=2,
               cython=lambda c: [f"HIJ = 0.5 * ({c.d('h')} + {c.s('h')})"],
               python=lambda p: 0.5 * (p.d("h") + p.s("h"))),
    PairSymbol("EPS", "0.01 h_ij^2, the usual guard against r = 0", depends=("HIJ",), cost=2,
               cython=lambda c: ["EPS = 0.01 * HIJ * HIJ"], python=lambda p: 0.01 * p["HIJ"] * p["HIJ"]),
    PairSymbol("VIJ", "u_i - u_j", vector=True, cost=3, props=lambda pair: pair.axes("uvw"),
               cython=_vij_cython, python=_vij_python),
    _kernel_row("WIJ", "w", "W(r_ij, h_ij)", 30),
    _kernel_row("WDASHIJ", "dwdr", "dW/dr at (r_ij, h_ij)", 30),
    _kernel_row("GHIJ", "gradh", "h dW/dh at (r_ij, h_ij)", 60),
    _kernel_row("MIXEDIJ", "mixed", "(h/r) d2W/(dr dh) at (r_ij, h_ij): grad_i (h dW/dh) = MIXEDIJ x_ij",
                40, extra=True),
    PairSymbol("DWIJ", "grad_i W = (W'(r_ij) / r_ij) x_ij (0 at r = 0), the kernel's dwdr_over_r",
               vector=True, cost=35, depends=("RIJ", "HIJ", "XIJ"), scratch=("_f",),
               cython=lambda c: ["_f = kernel_dwdr_over_r(RIJ, HIJ)"] +
               [f"DWIJ[{k}] = _f * XIJ[{k}]" for k in range(c.dim)],
               python=_dwij_python),
)

# name -> row, in the order of computation.  Tests add rows to it (monkeypatch.setitem).
SYMBOLS = {row.name: row for row in ROWS}


def names():
    """Every pair symbol, in the order of computation."""
    return tuple(SYMBOLS)


def is_vector(name):
    return name in SYMBOLS and SYMBOLS[name].vector


def closure(requested):
    """The requested symbols with everything they are computed from, in table order."""
    need = set(requested)
    for row in reversed(tuple(SYMBOLS.values())):
        if row.name in need:
            need.update(row.depends)
    return tuple(name for name in SYMBOLS if name in need)


def properties(requested, pair):
    """Properties (on destination and sources) the requested symbols read, given a pair."""
    return {p for name in closure(requested) for p in SYMBOLS[name].props(pair)}


def kernel_methods(symbols):
    """The kernel extra methods the given symbols call."""
    return {m for name in symbols for m in SYMBOLS[name].kernel_methods}


def cost(requested):
    """Rough floating-point operations per pair of computing the requested symbols."""
    return sum(SYMBOLS[name].cost for name in closure(requested))
