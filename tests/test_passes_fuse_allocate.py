"""Passes ``fuse`` and ``allocate``: one neighbour pass per group and destination; memory."""
import pytest

from sphgen.codegen import passes
from sphgen.codegen.plan import SceneError, new_plan
from sphgen.equation import Equation, Group
from sphgen.equations.basic import SummationDensity
from sphgen.kernels import QuinticSpline

from conftest import lattice_cloud


class Count(Equation):
    def loop(self, d_idx, d_n, s_idx, WIJ):
        d_n[d_idx] += 1.0


class Reset(Equation):
    def initialize(self, d_idx, d_n):
        d_n[d_idx] = 0.0


def _plan(groups, outputs, upto):
    fluid, wall = lattice_cloud(nx=3), lattice_cloud("wall", nx=2)
    for pa in (fluid, wall):
        pa.add_property("n")
        pa.add_property("spare")
    plan = new_plan([fluid, wall], groups, None, QuinticSpline(2), 2, outputs=outputs)
    return passes.run(plan, passes.until(upto))


def test_fuse_gives_one_pass_per_group_and_destination_with_sources_in_order():
    groups = [Group([Reset("fluid"), Count("fluid", ["wall", "fluid"]), SummationDensity("fluid", ["fluid"]),
                     Reset("wall")])]
    plan = _plan(groups, {"fluid": ["n", "rho"], "wall": ["n"]}, "fuse")
    assert plan.group_plans == []
    notes = passes.fuse(plan)
    (gp,) = plan.group_plans[0]
    table = {dest: ([type(ep.eq).__name__ for ep in p.equations],
                    [(loop.source, [type(ep.eq).__name__ for ep in loop.equations]) for loop in p.sources])
             for dest, p in gp.passes.items()}
    assert table == {"fluid": (["Reset", "Count", "SummationDensity"],
                               [("wall", ["Count"]), ("fluid", ["Count", "SummationDensity"])]),
                     "wall": (["Reset"], [])}
    assert notes == ["g0_fluid: 3 equation(s) in one pass over wall, fluid",
                     "g0_wall: 1 equation(s) in one pass over no neighbours"]
    assert plan.neighbour_lists() == [("fluid", "wall", False), ("fluid", "fluid", False)]


def test_allocate_gives_memory_to_what_the_kept_scene_touches_only():
    plan = _plan([Group([Reset("fluid"), Count("fluid", ["fluid"])])], {"fluid": ["n"]}, "allocate")
    notes = passes.allocate(plan)
    fluid = plan.arrays["fluid"]
    assert plan.allocation["fluid"] - set(fluid.data) == {"n"}     # data, plus what Count writes
    assert "spare" not in plan.allocation["wall"] and "n" not in plan.allocation["wall"]
    assert notes[0] == f"fluid: {len(fluid.data) + 1} properties; not allocated: spare, w, z"


def _two_sets(evaluated):
    fluid = lattice_cloud(nx=3)
    fluid.add_property("n")
    shared = Group([SummationDensity("fluid", ["fluid"])])
    only_0 = Group([Reset("fluid"), Count("fluid", ["fluid"])])
    sets = [[only_0, shared], [shared]]
    return new_plan([fluid], sets, None, QuinticSpline(2), 2, outputs={"fluid": ["n", "rho"]},
                    evaluated=evaluated)


def test_drop_unevaluated_empties_the_sets_the_integrator_never_runs():
    plan = _two_sets(evaluated={1})
    notes = passes.drop_unevaluated(plan)
    assert notes == ["set 0: never evaluated by the integrator; nothing generated"]
    assert plan.evaluations[0] == [] and plan.dropped == {0}
    assert [type(ep.eq).__name__ for ep in plan.eqplans] == ["SummationDensity"]
    passes.run(plan, passes.PASSES[1:])                          # n is an output nobody writes now
    assert [p.label for p in plan.neighbour_passes()] == ["g0_fluid"]
    assert "never evaluated by the integrator; nothing generated" in plan.describe()


def test_drop_unevaluated_keeps_every_set_when_the_integrator_does_not_say():
    for evaluated in (None, {0, 1}):
        plan = _two_sets(evaluated)
        assert passes.drop_unevaluated(plan) == [] and plan.dropped == set()
        assert len(plan.eqplans) == 3


def test_drop_unevaluated_refuses_a_set_the_scheme_did_not_give():
    with pytest.raises(SceneError, match=r"set\(s\) \[2\], but the scheme gave 2 set\(s\)"):
        passes.drop_unevaluated(_two_sets(evaluated={0, 2}))


def test_a_group_shared_by_two_sets_is_planned_and_compiled_once():
    plan = passes.run(_two_sets(None))
    assert plan.group_plans[0][1] is plan.group_plans[1][0]
    assert [p.label for p in plan.neighbour_passes()] == ["g0_fluid", "g1_fluid"]
