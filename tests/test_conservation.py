"""Identities on random particle clouds: linear momentum to round-off."""
import numpy as np
import pytest

from sphgen.scene import Scene
from sphgen.solver import Solver
from sphgen.schemes.edac import EDACScheme

from conftest import lattice_cloud, periodic_box


@pytest.mark.parametrize("pst,alpha", [("none", 0.5), ("sun2019", 0.0), ("tvf", 0.2)])
def test_linear_momentum_is_conserved_in_a_periodic_run(pst, alpha):
    """Seed 002 eq. 27 (bql off) is antisymmetric pair by pair: sum m u stays put."""
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
