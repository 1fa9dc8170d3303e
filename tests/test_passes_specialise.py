"""Pass ``specialise``: switches, dimension and constants folded; nothing compiled."""
import ast

import pytest

from sphgen.codegen import passes
from sphgen.codegen.passes.specialise import check_switches
from sphgen.codegen.plan import SceneError, new_plan
from sphgen.equation import Equation
from sphgen.equations.momentum import ArtificialViscosity
from sphgen.integrators import IntegratorStep
from sphgen.kernels import QuinticSpline

from conftest import lattice_cloud


class Dot(Equation):
    def loop(self, d_idx, d_s, s_idx, XIJ, DWIJ):
        d_s[d_idx] += XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1] + XIJ[2] * DWIJ[2]


class Scatter(Equation):
    def loop(self, d_idx, s_idx, s_rho, WIJ):
        s_rho[s_idx] += WIJ


class Step(IntegratorStep):
    def stage1(self, d_idx, d_x, d_u, dt):
        d_x[d_idx] += dt * d_u[d_idx]

    def stage2(self, d_idx):
        pass


def _specialised(equations, dim=2, steppers=None):
    pa = lattice_cloud(nx=3, dim=dim)
    pa.add_property("s")
    plan = new_plan([pa], equations, steppers, QuinticSpline(dim), dim)
    return plan, passes.specialise(plan)


def test_dimension_folds_the_third_component_away():
    plan, _ = _specialised([Dot("fluid", ["fluid"])])
    assert ast.unparse(plan.eqplans[0].methods["loop"].fdef) == (
        "def Dot_0_loop(d_idx, d_s, XIJ, DWIJ):\n"
        "    d_s[d_idx] += XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1]")   # and s_idx, now unused, is gone
    plan3, _ = _specialised([Dot("fluid", ["fluid"])], dim=3)
    assert "XIJ[2] * DWIJ[2]" in ast.unparse(plan3.eqplans[0].methods["loop"].fdef)


def test_a_zero_switch_drops_the_equation_and_a_nonzero_float_stays_a_parameter():
    plan, notes = _specialised([ArtificialViscosity("fluid", ["fluid"], alpha=0.0, c0=10.0)])
    ep = plan.eqplans[0]
    assert (ep.kept, ep.methods, ep.reason) == (False, {}, "switched off (alpha=0.0)")
    assert "drop ArtificialViscosity[fluid<-fluid]: switched off (alpha=0.0)" in notes
    plan, _ = _specialised([ArtificialViscosity("fluid", ["fluid"], alpha=0.5, c0=10.0)])
    src = ast.unparse(plan.eqplans[0].methods["loop"].fdef)
    assert "-ArtificialViscosity_0_alpha * ArtificialViscosity_0_c0 * phi" in src and "self" not in src
    assert plan.eqplans[0].methods["loop"].params_used == {"alpha", "c0"}


def test_the_test_of_a_nonzero_switch_is_folded_away_its_value_stays_a_parameter():
    """``if self.alpha != 0.0:`` around the only loads of a property kept gcc from
    vectorising the pair loop; a non-zero switch now folds the test, not the value."""
    plan, _ = _specialised([ArtificialViscosity("fluid", ["fluid"], alpha=0.5, c0=10.0)])
    src = ast.unparse(plan.eqplans[0].methods["loop"].fdef)
    assert "!= 0" not in src and "ArtificialViscosity_0_alpha != " not in src
    assert src.splitlines()[1].startswith("    vr = ")          # the body, no longer under an if
    assert "if vr < 0.0:" in src                                # the physics' own branch stays
    assert plan.switches[0][1] == {"alpha": "non-zero"}


class Switched(Equation):
    switches = ("k",)

    def loop(self, d_idx, d_s, s_idx, WIJ):
        if self.k == 0.0:
            d_s[d_idx] += WIJ
        elif 0 != self.k:
            d_s[d_idx] += self.k * WIJ


@pytest.mark.parametrize("k, body", [(2.5, "d_s[d_idx] += Switched_0_k * WIJ"), (0.0, "d_s[d_idx] += WIJ")])
def test_either_order_and_both_tests_of_a_switch_fold(k, body):
    plan, _ = _specialised([Switched("fluid", ["fluid"], k=k)])
    assert ast.unparse(plan.eqplans[0].methods["loop"].fdef).splitlines()[1:] == ["    " + body]


def test_a_switch_changed_after_generation_is_refused():
    eq = Switched("fluid", ["fluid"], k=2.5)
    plan, _ = _specialised([eq])
    eq.k = 3.0
    check_switches(plan)    # another non-zero value: the same code
    eq.k = 0.0
    with pytest.raises(SceneError, match="Switched.k is 0.0, but the scene was generated for k = 'non-zero'"):
        check_switches(plan)


class Cone(Equation):
    def loop(self, d_idx, d_s, s_idx, s_m, RIJ, HIJ):
        c = RIJ / HIJ
        if RIJ > 1e-12 and c < 2.0 and (c > 0.5 or -c > 0.5):
            d_s[d_idx] += 1.0
        if RIJ > 1e-12 and s_m[s_idx] > 0.0:
            d_s[d_idx] += 2.0
        if RIJ > 1e-12 and HIJ / RIJ < 3.0:
            d_s[d_idx] += 3.0


def test_tests_on_plain_values_are_eager_and_loads_keep_their_guard():
    """``and``/``or`` of comparisons of names and arithmetic become ``&``/``|`` (gcc
    if-converts those: the free-surface cone test's pair loop vectorises); a test that
    loads from memory keeps its short circuit, so a guarded load stays guarded."""
    plan, _ = _specialised([Cone("fluid", ["fluid"])])
    src = ast.unparse(plan.eqplans[0].methods["loop"].fdef)
    assert "if (RIJ > 1e-12) & (c < 2.0) & ((c > 0.5) | (-c > 0.5)):" in src
    assert "if RIJ > 1e-12 and s_m[s_idx] > 0.0:" in src
    assert "if RIJ > 1e-12 and HIJ / RIJ < 3.0:" in src          # nor a division


class Moments(Equation):
    def loop(self, d_idx, d_s, d_lmat, s_idx, XIJ, DWIJ):
        for i in range(3):
            for j in range(3):
                d_lmat[9 * d_idx + 3 * i + j] -= XIJ[i] * DWIJ[j]
        for k in range(3):
            d_s[d_idx] += XIJ[k]
        d_s[d_idx] += k


def test_constant_loops_are_unrolled_and_the_components_past_the_dimension_fold():
    """In 2D the 3 x 3 moment keeps 4 of its 9 terms; a loop whose counter is read after it
    stays a loop."""
    pa = lattice_cloud(nx=3, dim=2)
    pa.add_property("s")
    pa.add_property("lmat", stride=9)
    plan = new_plan([pa], [Moments("fluid", ["fluid"])], None, QuinticSpline(2), 2)
    passes.specialise(plan)
    src = ast.unparse(plan.eqplans[0].methods["loop"].fdef)
    terms = [line.strip() for line in src.splitlines() if "d_lmat" in line and "+=" not in line][1:]
    assert terms == ["d_lmat[9 * d_idx] -= XIJ[0] * DWIJ[0]", "d_lmat[9 * d_idx + 1] -= XIJ[0] * DWIJ[1]",
                     "d_lmat[9 * d_idx + 3] -= XIJ[1] * DWIJ[0]", "d_lmat[9 * d_idx + 3 + 1] -= XIJ[1] * DWIJ[1]"]
    assert "for k in range(3):" in src and "for i in" not in src


def test_pair_loops_must_be_gather_only():
    with pytest.raises(SceneError, match=r"Scatter\[fluid<-fluid\]\.loop writes s_rho: pair loops"):
        _specialised([Scatter("fluid", ["fluid"])])


def test_stage_methods_are_specialised_and_empty_ones_dropped():
    plan, notes = _specialised([], steppers={"fluid": Step()})
    (st,) = plan.steppers
    assert list(st.stages) == ["stage1"]
    assert ast.unparse(st.stages["stage1"].fdef).startswith("def Step_0_stage1(d_idx, d_x, d_u, dt):")
    assert notes == ["1 methods specialised for dim=2"]
