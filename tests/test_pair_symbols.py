"""The pair-symbol table: its invariants, its code, and adding a symbol as one row."""
import math

import numpy as np
import pytest

from sphgen.codegen import pair_symbols
from sphgen.codegen.pair_symbols import CythonPair, PairGeometry, PairSymbol, PythonPair
from sphgen.equation import Equation
from sphgen.kernels import QuinticSpline
from sphgen.scene import Scene

from conftest import lattice_cloud, periodic_box


def test_every_row_comes_after_what_it_is_computed_from():
    seen = set()
    for name, row in pair_symbols.SYMBOLS.items():
        assert name == row.name and row.cost > 0 and row.doc
        assert set(row.depends) <= seen, f"{name} needs {set(row.depends) - seen} computed first"
        seen.add(name)


def test_closure_is_in_table_order_with_every_input():
    assert pair_symbols.closure({"DWIJ"}) == ("XIJ", "R2IJ", "RIJ", "HIJ", "DWIJ")
    assert pair_symbols.closure({"EPS", "VIJ"}) == ("HIJ", "EPS", "VIJ")
    assert pair_symbols.closure(()) == ()
    assert pair_symbols.cost({"RIJ"}) == sum(pair_symbols.SYMBOLS[s].cost for s in ("XIJ", "R2IJ", "RIJ"))


def test_properties_follow_dimension_and_reference_configuration():
    assert pair_symbols.properties({"VIJ"}, PairGeometry(2)) == {"u", "v"}
    assert pair_symbols.properties({"WIJ"}, PairGeometry(3)) == {"x", "y", "z", "h"}
    assert pair_symbols.properties({"R2IJ"}, PairGeometry(2, reference=True)) == {"x0", "y0"}


def test_cython_rows_fold_dimension_and_period():
    pair = CythonPair("fluid", "wall", 2, periodic_box(2, L=2.0))
    assert pair_symbols.SYMBOLS["XIJ"].cython(pair)[:2] == [     # minimum image without a branch
        "XIJ[0] = fluid_x[d_idx] - wall_x[s_idx]", "XIJ[0] -= 2.0 * rint(XIJ[0] * 0.5)"]
    assert pair_symbols.SYMBOLS["R2IJ"].cython(pair) == ["R2IJ = XIJ[0] * XIJ[0] + XIJ[1] * XIJ[1]"]
    assert pair_symbols.SYMBOLS["DWIJ"].declaration(2) == ["cdef double DWIJ[3]", "DWIJ[2] = 0.0"]
    ref = CythonPair("fluid", "fluid", 2, periodic_box(2), reference=True)
    assert pair_symbols.SYMBOLS["XIJ"].cython(ref) == ["XIJ[0] = fluid_x0[d_idx] - fluid_x0[s_idx]",
                                                       "XIJ[1] = fluid_y0[d_idx] - fluid_y0[s_idx]"]


def test_python_rows_give_minimum_image_geometry_and_kernel_values():
    pa = lattice_cloud(nx=4)
    kernel = QuinticSpline(2)
    pair = PythonPair(pa, pa, 0, 15, kernel, 2, periodic_box(2))
    for name in pair_symbols.closure({"DWIJ", "WIJ"}):
        pair.values[name] = pair_symbols.SYMBOLS[name].python(pair)
    dx = pa.x[0] - pa.x[15]
    dx -= round(dx)                                    # minimum image in the unit box
    assert pair["XIJ"][0] == pytest.approx(dx, abs=1e-15) and pair["XIJ"][2] == 0.0
    assert pair["WIJ"] == kernel.w(pair["RIJ"], pair["HIJ"])
    f = kernel.dwdr(pair["RIJ"], pair["HIJ"]) / pair["RIJ"]
    assert pair["DWIJ"][:2] == [f * pair["XIJ"][0], f * pair["XIJ"][1]]


# ---------------------------------------------------------------- a new symbol is one row
RHOIJ = PairSymbol(
    "RHOIJ", "(rho_i + rho_j) / 2", props=lambda pair: ("rho",), cost=2,
    cython=lambda c: [f"RHOIJ = 0.5 * ({c.d('rho')} + {c.s('rho')})"],
    python=lambda p: 0.5 * (p.d("rho") + p.s("rho")))
NIJ = PairSymbol(
    "NIJ", "x_ij / r_ij, the unit vector from j to i (0 at r = 0)", vector=True,
    depends=("XIJ", "RIJ"), cost=4,
    cython=lambda c: [f"NIJ[{k}] = XIJ[{k}] / RIJ if RIJ > 1e-12 else 0.0" for k in range(c.dim)],
    python=lambda p: [x / p["RIJ"] if p["RIJ"] > 1e-12 else 0.0 for x in p["XIJ"]])


class DensityWeighted(Equation):
    def initialize(self, d_idx, d_q, d_nw):
        d_q[d_idx] = 0.0
        d_nw[d_idx] = 0.0

    def loop(self, d_idx, d_q, d_nw, s_idx, s_m, RHOIJ, WIJ, NIJ, RIJ):
        if RIJ > 1e-12:
            d_q[d_idx] += s_m[s_idx] * RHOIJ * WIJ
            d_nw[d_idx] += (NIJ[0] + NIJ[2]) * WIJ


def _brute_force(pa, kernel):
    q, n = np.zeros(pa.n), np.zeros(pa.n)
    for i in range(pa.n):
        for j in range(pa.n):
            r = math.hypot(pa.x[i] - pa.x[j], pa.y[i] - pa.y[j])
            h = 0.5 * (pa.h[i] + pa.h[j])
            if 1e-12 < r < kernel.radius_scale * h:
                w = kernel.w(r, h)
                q[i] += pa.m[j] * 0.5 * (pa.rho[i] + pa.rho[j]) * w
                n[i] += (pa.x[i] - pa.x[j]) / r * w
    return q, n


@pytest.mark.parametrize("backend", ["cython", "python"])
def test_a_made_up_symbol_added_as_one_row_runs_on_both_backends(backend, monkeypatch):
    monkeypatch.setitem(pair_symbols.SYMBOLS, "RHOIJ", RHOIJ)
    monkeypatch.setitem(pair_symbols.SYMBOLS, "NIJ", NIJ)
    pa = lattice_cloud(nx=6, jitter=0.3, seed=1)
    pa.add_property("q")
    pa.add_property("nw")
    sc = Scene([pa], [DensityWeighted("fluid", ["fluid"])], dim=2, outputs={"fluid": ["q", "nw"]},
               backend=backend)
    assert "g0_fluid <- fluid: XIJ, R2IJ, RIJ, HIJ, WIJ, RHOIJ, NIJ" in sc.describe()
    if backend == "cython":
        assert "RHOIJ = 0.5 * (fluid_rho[d_idx] + fluid_rho[s_idx])" in sc.source
        assert "cdef double NIJ[3]" in sc.source and "NIJ[2] = XIJ" not in sc.source
    sc.compute(0, 0.0, 0.1)
    q, n = _brute_force(pa, sc.kernel)
    assert np.allclose(pa.q, q, rtol=1e-12, atol=1e-14)
    assert np.allclose(pa.nw, n, rtol=1e-12, atol=1e-12)
