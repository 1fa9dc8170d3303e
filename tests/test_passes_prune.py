"""Pass ``prune``: liveness and dead stores to a fixed point; nothing compiled."""
import ast

from sphgen.codegen import passes
from sphgen.codegen.plan import new_plan
from sphgen.equation import Equation, Group
from sphgen.kernels import QuinticSpline

from conftest import lattice_cloud


class Pressure(Equation):
    """Writes p (needed) and a scratch c2 nothing reads."""

    def initialize(self, d_idx, d_p, d_c2, d_rho):
        c2 = 100.0
        d_c2[d_idx] = c2
        d_p[d_idx] = c2 * (d_rho[d_idx] - 1.0)


class Gradient(Equation):
    """Reads p, writes g."""

    def loop(self, d_idx, d_g, s_idx, s_p, WIJ):
        d_g[d_idx] += s_p[s_idx] * WIJ


class Smoothed(Equation):
    """Reads g, writes gs: the end of a chain."""

    def initialize(self, d_idx, d_gs, d_g):
        d_gs[d_idx] = d_g[d_idx]


class Minimum(Equation):
    """A reduction: kept for its own sake, and what it reads is needed."""

    def initialize(self, d_idx):
        pass

    def reduce(self, dst, t, dt):
        self.low = dst.q.min()


def _plan(equations, outputs):
    pa = lattice_cloud(nx=3)
    for p in ("p", "c2", "g", "gs", "q"):
        pa.add_property(p)
    plan = new_plan([pa], equations, None, QuinticSpline(2), 2, outputs={"fluid": outputs})
    return passes.run(plan, passes.until("prune"))


def _kept(plan):
    return {type(ep.eq).__name__: ep.kept for ep in plan.eqplans}


def test_a_chain_nothing_reads_is_pruned_from_its_end():
    eqs = [Pressure("fluid"), Gradient("fluid", ["fluid"]), Smoothed("fluid")]
    plan = _plan(eqs, ["p"])
    assert _kept(plan) == {"Pressure": True, "Gradient": True, "Smoothed": True}
    notes = passes.prune(plan)
    assert _kept(plan) == {"Pressure": True, "Gradient": False, "Smoothed": False}
    assert "prune Smoothed[fluid]: nothing reads what it writes (gs): no later equation, " \
           "integrator stage, output or diagnostic" in notes
    assert ("fluid", "g") not in plan.needed and ("fluid", "rho") in plan.needed
    plan = _plan(eqs, ["gs"])
    passes.prune(plan)
    assert all(_kept(plan).values())


def test_dead_stores_are_removed_and_the_method_specialised_again():
    plan = _plan([Pressure("fluid")], ["p"])
    before = ast.unparse(plan.eqplans[0].methods["initialize"].fdef)
    assert "d_c2[d_idx] = c2" in before
    notes = passes.prune(plan)
    ep = plan.eqplans[0]
    assert ast.unparse(ep.methods["initialize"].fdef) == (
        "def Pressure_0_initialize(d_idx, d_p, d_rho):\n"
        "    c2 = 100.0\n"
        "    d_p[d_idx] = c2 * (d_rho[d_idx] - 1.0)")
    assert ep.dead_stores == {"d_c2"} and ("fluid", "c2") not in ep.touched()
    assert "Pressure[fluid]: removed the stores to c2" in notes


def test_one_note_for_an_equation_used_in_several_groups():
    plan = _plan([Group([Pressure("fluid")]), Group([Pressure("fluid")])], ["p"])
    notes = passes.prune(plan)
    assert notes.count("Pressure[fluid]: removed the stores to c2 (in 2 places)") == 1
    assert not any(n == "Pressure[fluid]: removed the stores to c2" for n in notes)


class Scratch(Equation):
    def initialize(self, d_idx, d_q):
        d_q[d_idx] = 1.0


class Copier(Equation):
    """Writes p (needed); copies q into c2, a store nothing reads."""

    def initialize(self, d_idx, d_p, d_c2, d_q):
        d_c2[d_idx] = d_q[d_idx]
        d_p[d_idx] = 1.0


def test_a_removed_store_can_make_another_equation_dead():
    plan = _plan([Scratch("fluid"), Copier("fluid")], ["p"])
    assert plan.eqplans[1].reads() >= {("fluid", "q")}
    passes.prune(plan)
    assert _kept(plan) == {"Scratch": False, "Copier": True}
    assert plan.eqplans[1].dead_stores == {"d_c2"} and ("fluid", "q") not in plan.needed


def test_a_reduction_is_live_and_keeps_what_it_reads():
    plan = _plan([Minimum("fluid")], [])
    passes.prune(plan)
    assert _kept(plan) == {"Minimum": True} and ("fluid", "q") in plan.needed
