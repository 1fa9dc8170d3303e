"""Identities on random particle clouds: linear momentum to round-off."""
import numpy as np
import pytest

from sphgen.scene import Scene
from sphgen.solver import Solver
from sphgen.schemes.edac import EDACScheme

from conftest import lattice_cloud, periodic_box


@pytest.mark.parametrize("pst,alpha", [("none", 0.5), ("sun2019", 0.0), ("tvf", 0.2)])
def test_linear_momentum_is_conserved_in_a_periodic_run(pst, alpha):
    """Adepu & Ramachandran (2024) eq. 27 (bql off) is antisymmetric pair by pair: sum m u stays put."""
    pa = lattice_cloud(nx=16, jitter=0.3, seed=7)
    rng = np.random.default_rng(1)
    pa.add_property("p", data=rng.uniform(-1, 1, pa.n))
    dx = 1 / 16
    s = EDACScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.02, h=dx, dx=dx, pst=pst,
                   alpha=alpha, bql=False)
    s.setup_properties([pa])
    integ = s.get_integrator()
    sc = Scene([pa], s.get_equations(), steppers=integ.steppers, kernel=s.kernel, dim=2,
               domain=periodic_box(2), outputs={"fluid": list(s.output_props)})
    p0 = np.array([np.sum(pa.m * pa.u), np.sum(pa.m * pa.v)])
    scale = np.sum(pa.m * np.hypot(pa.u, pa.v))
    solver = Solver(sc, integ, dt=s.get_timestep(), tf=1.0, max_steps=50, progress=False)
    solver.run()
    p1 = np.array([np.sum(pa.m * pa.u), np.sum(pa.m * pa.v)])
    assert solver.step == 50
    assert np.abs(p1 - p0).max() / scale < 1e-12
    assert np.abs(pa.au).max() > 1.0  # forces were not trivially zero


def test_adaptive_time_step_follows_the_limits_equations_write():
    from sphgen.equation import Group
    from sphgen.equations.timestep import TimeStepLimits
    pa = lattice_cloud(nx=12, jitter=0.2, seed=2)
    pa.add_property("p", data=np.zeros(pa.n))
    pa.add_property("w", data=np.zeros(pa.n))
    pa.add_property("dt_cfl")
    dx = 1 / 12
    s = EDACScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.05, h=dx, dx=dx, pst="none")
    s.setup_properties([pa])
    eqs = s.get_equations()
    eqs[1].append(Group([TimeStepLimits("fluid", c0=10.0, nu=0.05)]))
    integ = s.get_integrator()
    sc = Scene([pa], eqs, steppers=integ.steppers, kernel=s.kernel, dim=2, domain=periodic_box(2),
               outputs={"fluid": list(s.output_props) + ["dt_cfl"]})
    # the equation writes the three limits of Adepu & Ramachandran (2024) eq. 61 per particle
    sc.compute(1, 0.0, 1e-3)
    speed, acc = np.hypot(pa.u, pa.v), np.hypot(pa.au, pa.av)
    lim = np.minimum(dx / (10.0 + speed), dx * dx / 0.05)
    lim = np.minimum(lim, np.sqrt(dx / np.where(acc > 0, acc, np.inf)))
    np.testing.assert_allclose(pa.dt_cfl, lim, rtol=1e-12)
    seen, expected = [], []
    solver = Solver(sc, integ, dt=1.0, tf=0.05, adaptive=True, dt_props=("dt_cfl",), cfl=0.25,
                    progress=False)
    solver.post_step_callbacks.append(lambda s: seen.append(s.last_dt))
    orig = integ.one_timestep

    def step(t, dt):
        expected.append(min(0.25 * pa.dt_cfl.min(), 0.05 - t))
        orig(t, dt)
    integ.one_timestep = step
    solver.run()
    assert solver.t == pytest.approx(0.05)
    assert len(seen) == len(expected) > 5
    np.testing.assert_allclose(seen, expected, rtol=1e-12)
    assert max(seen) < 0.25 * dx / 10.0 + 1e-15   # the CFL limit binds: dt << the 1.0 asked for
    pruned = Scene([lattice_cloud(nx=4)], [], dim=2)
    with pytest.raises(ValueError, match="adaptive time step reads dt_cfl, which no array"):
        Solver(pruned, integ.__class__(), dt=1.0, tf=1.0, adaptive=True)
