"""The checking passes: arrays, properties that exist, properties set, races; nothing compiled."""
import pytest

from sphgen.codegen import passes
from sphgen.codegen.plan import SceneError, new_plan
from sphgen.equation import Equation, Group
from sphgen.equations.basic import SummationDensity
from sphgen.kernels import QuinticSpline

from conftest import lattice_cloud


class ReadsQ(Equation):
    def initialize(self, d_idx, d_p, d_q):
        d_p[d_idx] = d_q[d_idx]


class ReadsRhoOfNeighbours(Equation):
    def loop(self, d_idx, d_p, s_idx, s_rho, WIJ):
        d_p[d_idx] += s_rho[s_idx] * WIJ


def _plan(equations, upto, outputs=("p",), **q):
    pa = lattice_cloud(nx=3)
    pa.add_property("p")
    pa.add_property("q", **q)
    plan = new_plan([pa], equations, None, QuinticSpline(2), 2, outputs={"fluid": list(outputs)})
    return passes.run(plan, passes.until(upto))


def test_check_arrays_names_the_equation_and_suggests_an_array():
    plan = _plan([SummationDensity("fluid", ["fliud"])], "check_arrays")
    with pytest.raises(SceneError, match=r"SummationDensity\[fluid<-fliud\]: no particle array named "
                                         r"'fliud'; did you mean 'fluid'\?"):
        passes.check_arrays(plan)


def test_check_exist_refuses_an_undeclared_property_even_if_pruned():
    class Typo(Equation):
        def initialize(self, d_idx, d_rhoo):
            d_rhoo[d_idx] = 0.0

    plan = _plan([Typo("fluid")], "check_exist")
    with pytest.raises(SceneError, match=r"Typo\[fluid\] uses property 'rhoo' of array 'fluid', "
                                         r"which has no such property; did you mean 'rho'\?"):
        passes.check_exist(plan)
    assert passes.check_exist(_plan([ReadsQ("fluid")], "check_exist")) == []


def test_check_properties_wants_data_a_writer_or_a_default():
    with pytest.raises(SceneError, match=r"ReadsQ\[fluid\] reads property 'q' of array 'fluid', but "
                                         r"nothing sets it"):
        passes.check_properties(_plan([ReadsQ("fluid")], "check_properties"))
    assert passes.check_properties(_plan([ReadsQ("fluid")], "check_properties", default=2.0)) == []
    with pytest.raises(SceneError, match=r"output property 'nope' of array 'fluid' does not exist"):
        passes.check_properties(_plan([], "check_properties", outputs=("nope",)))


def test_check_races_refuses_reading_what_the_same_group_writes():
    group = Group([SummationDensity("fluid", ["fluid"]), ReadsRhoOfNeighbours("fluid", ["fluid"])])
    plan = _plan([group], "check_races")
    with pytest.raises(SceneError, match=r"ReadsRhoOfNeighbours\[fluid<-fluid\]\.loop reads s_rho of "
                                         r"'fluid' while this group writes 'rho' of 'fluid'"):
        passes.check_races(plan)
    split = [Group([SummationDensity("fluid", ["fluid"])]), Group([ReadsRhoOfNeighbours("fluid", ["fluid"])])]
    assert passes.check_races(_plan(split, "check_races")) == []
