"""Passes ``fuse`` and ``allocate``: one neighbour pass per group and destination; memory."""
from sphgen.codegen import passes
from sphgen.codegen.plan import new_plan
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
