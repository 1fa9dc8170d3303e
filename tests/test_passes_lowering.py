"""The lowering passes: pair symbols, registers, functions, argument types, helpers; nothing compiled."""
import ast

import pytest

from sphgen.codegen import passes
from sphgen.codegen.plan import new_plan
from sphgen.codegen.translate import TranslationError
from sphgen.equation import Equation, Group, helper
from sphgen.integrators import IntegratorStep
from sphgen.kernels import QuinticSpline

from conftest import lattice_cloud


@helper
def square(x=0.0):
    return x * x


@helper
def energy(u=0.0, v=0.0):
    return 0.5 * (square(u) + square(v))


def not_a_helper(x):
    return x


class Viscous(Equation):
    """au += nu * ... over neighbours (register), grad into a strided property (no register)."""

    def initialize(self, d_idx, d_au, d_grad):
        d_au[d_idx] = 0.0
        for i in range(3):
            d_grad[3 * d_idx + i] = 0.0

    def loop(self, d_idx, d_au, d_grad, s_idx, s_m, VIJ, DWIJ, R2IJ, EPS):
        d_au[d_idx] += self.nu * s_m[s_idx] * VIJ[0] / (R2IJ + EPS)
        for i in range(3):
            d_grad[3 * d_idx + i] += s_m[s_idx] * DWIJ[i]


class Energy(Equation):
    def initialize(self, d_idx, d_e, d_u, d_v):
        d_e[d_idx] = energy(d_u[d_idx], d_v[d_idx])


class Bad(Equation):
    def initialize(self, d_idx, d_e, d_u):
        d_e[d_idx] = not_a_helper(d_u[d_idx])


class Flags(Equation):
    def loop(self, d_idx, d_e, s_idx, s_flag, WIJ, mystery):
        d_e[d_idx] += s_flag[s_idx] * WIJ * mystery


class Largest(Equation):
    """e: the largest W over neighbours (a register that is read: not a sum)."""

    def loop(self, d_idx, d_e, d_au, s_idx, WIJ):
        d_au[d_idx] += WIJ
        if WIJ > d_e[d_idx]:
            d_e[d_idx] = WIJ


class Kick(IntegratorStep):
    def stage1(self, d_idx, d_u, d_au, dt):
        d_u[d_idx] += dt * d_au[d_idx]


def _plan(equations, upto, outputs=("au", "grad", "e"), steppers=None):
    pa = lattice_cloud(nx=3)
    pa.add_property("au")
    pa.add_property("e")
    pa.add_property("grad", stride=3)
    pa.add_property("flag", dtype="int", data=[1] * pa.n)
    plan = new_plan([pa], equations, steppers, QuinticSpline(2), 2, outputs={"fluid": list(outputs)})
    return passes.run(plan, passes.until(upto))


def test_choose_pair_symbols_computes_what_the_loops_ask_for_and_its_inputs():
    plan = _plan([Viscous("fluid", ["fluid"], nu=0.1)], "choose_pair_symbols")
    notes = passes.choose_pair_symbols(plan)
    (loop,) = plan.neighbour_passes()[0].sources
    assert loop.symbols == ("XIJ", "R2IJ", "RIJ", "HIJ", "EPS", "VIJ", "DWIJ")
    assert notes == ["g0_fluid <- fluid: XIJ, R2IJ, RIJ, HIJ, EPS, VIJ, DWIJ (~60 flops per pair)"]


def test_assign_registers_only_for_doubles_indexed_by_d_idx():
    plan = _plan([Viscous("fluid", ["fluid"], nu=0.1)], "assign_registers")
    (p,) = plan.neighbour_passes()
    ep = p.equations[0]
    assert p.registers == () and p.spec(ep, "loop") is ep.methods["loop"]
    assert passes.assign_registers(plan) == ["g0_fluid: au, grad accumulated in registers (summed per pair: au, grad)"]
    assert p.registers == ("au", "grad") and p.sums == ("au", "grad")
    assert "d_au[0] += Viscous_0_nu" in ast.unparse(p.spec(ep, "loop").fdef)
    assert "d_au[d_idx] +=" in ast.unparse(ep.methods["loop"].fdef)     # the plain form is kept
    loop = ast.unparse(p.spec(ep, "loop").fdef)        # a strided register: its row (the loop
    assert "d_grad[0] +=" in loop and "d_grad[1] +=" in loop and "d_grad[2]" not in loop   # unrolled, 2D)


def test_assign_registers_sums_only_what_the_pair_loops_only_add_to():
    plan = _plan([Largest("fluid", ["fluid"]), Viscous("fluid", ["fluid"], nu=0.1)], "assign_registers")
    (p,) = plan.neighbour_passes()
    assert passes.assign_registers(plan) == ["g0_fluid: au, e, grad accumulated in registers (summed per pair: au, grad)"]
    assert p.registers == ("au", "e", "grad") and p.sums == ("au", "grad")


def test_rendered_pass_adds_each_pairs_partial_sum_once():
    from sphgen.codegen.render import render
    plan = passes.run(_plan([Largest("fluid", ["fluid"]), Viscous("fluid", ["fluid"], nu=0.1)], "allocate"),
                      passes.PASSES[passes.PASSES.index(passes.choose_pair_symbols):])
    src = render(plan).source
    loop = src[src.index("cdef void _pass_g0_fluid"):src.index("def pass_g0_fluid")]
    assert "_p_au = 0.0\n" in loop and loop.count("_r_au += _p_au") == 1
    assert "Largest_0_loop(d_idx, &_r_e, &_p_au," in loop and "&_p_e" not in loop
    assert "Viscous_1_loop(d_idx, &_p_au, _p_grad," in loop      # a strided register: a local row
    assert "_p_grad[2] = 0.0" in loop and "_r_grad[2] += _p_grad[2]" in loop
    assert "fluid_grad[3 * d_idx + 2] = _r_grad[2]" in loop


@pytest.mark.parametrize("index, stride, offset", [
    ("d_idx", 1, "0"), ("9 * d_idx + 3 * i + j", 9, "3 * i + j"), ("j + d_idx * 3", 3, "j"),
    ("3 * d_idx", 3, "0"), ("3 * d_idx + i", 9, None), ("3 * d_idx + d_idx", 3, None), ("d_idx + 1", 1, None)])
def test_row_offset_of_a_strided_index(index, stride, offset):
    from sphgen.codegen.translate import _row_offset
    got = _row_offset(ast.parse(index, mode="eval").body, stride)
    assert (None if got is None else ast.unparse(got)) == offset


def test_collect_functions_orders_passes_then_stages_and_lists_parameters():
    eqs = [Group([Viscous("fluid", ["fluid"], nu=0.1)]), Group([Energy("fluid")])]
    plan = _plan(eqs, "collect_functions", steppers={"fluid": Kick()})
    notes = passes.collect_functions(plan)
    assert [fp.spec.fdef.name for fp in plan.functions] == [
        "Viscous_0_initialize", "Viscous_0_loop", "Energy_1_initialize", "Kick_0_stage1"]
    assert [fp.origin for fp in plan.functions][-1] == "Kick.stage1"
    assert plan.parameters == {"Viscous_0_nu": (eqs[0].equations[0], "nu")}
    assert [sp.fdef.name for sp in plan.kernel_functions] == ["kernel_sigma", "kernel_w", "kernel_dwdr", "kernel_dwdr_over_r",
                                                              "kernel_gradh"]
    assert notes == ["4 functions, 1 run-time parameters (Viscous_0_nu)"]


def test_type_arguments_from_dtypes_and_the_pair_symbol_table():
    plan = _plan([Viscous("fluid", ["fluid"], nu=0.1)], "type_arguments")
    passes.type_arguments(plan)
    assert plan.functions[1].arg_types == {
        "d_idx": "long", "d_au": "double*", "d_grad": "double*", "s_idx": "long", "s_m": "double*",
        "VIJ": "double*", "DWIJ": "double*", "R2IJ": "double", "EPS": "double"}
    plan = _plan([Flags("fluid", ["fluid"])], "type_arguments")
    with pytest.raises(TranslationError, match=r"Flags\.loop: argument 'mystery' is neither a property"):
        passes.type_arguments(plan)


def test_collect_helpers_translates_each_helper_once_callees_first():
    plan = _plan([Energy("fluid")], "collect_helpers")
    assert passes.collect_helpers(plan) == ["helpers: square, energy"]
    assert ast.unparse(plan.helpers[0].fdef) == "def square(x=0.0):\n    return x * x"
    plan = _plan([Bad("fluid")], "collect_helpers")
    with pytest.raises(TranslationError, match=r"Bad\.initialize: not_a_helper\(\) is a Python function, "
                                               r"not a sphgen helper"):
        passes.collect_helpers(plan)


def test_loop_flops_is_the_symbols_cost_plus_the_loop_arithmetic():
    """The roofline estimate: pair-symbol costs plus +, -, *, / of the loop methods."""
    import ast
    from sphgen.codegen import pair_symbols
    from sphgen.codegen.describe import _arithmetic_ops, loop_flops
    fdef = ast.parse("def f(a, b):\n    a[0] += 2.0 * b / (b - 1.0)\n    c = -b\n    return sqrt(c)\n").body[0]
    assert _arithmetic_ops(fdef) == 4            # +=, *, /, - (unary minus and calls not counted)
    plan = _plan([Viscous("fluid", ["fluid"], nu=0.1)], "choose_pair_symbols")
    passes.choose_pair_symbols(plan)
    npass = plan.neighbour_passes()[0]
    (loop,) = npass.sources
    assert loop_flops(npass, loop) > pair_symbols.cost(loop.symbols)
