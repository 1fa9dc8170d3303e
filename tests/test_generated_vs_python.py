"""Every shipped equation: compiled module == plain-Python evaluator, to round-off."""
import numpy as np
import pytest

from sphgen.equation import Group
from sphgen.scene import Scene
from sphgen.schemes.edac import EDACScheme
from sphgen.equations.basic import Vorticity2D

from conftest import assert_close, lattice_cloud, periodic_box


def run_edac(backend, dim, pst, alpha, periodic, steps=None, extra_outputs=()):
    steps = steps or (2 if dim == 2 else 1)
    nx = {2: 10, 3: 7}[dim]
    pa = lattice_cloud(nx=nx, dim=dim, jitter=0.25, seed=3)
    rng = np.random.default_rng(4)
    pa.add_property("p", data=rng.uniform(-0.5, 0.5, pa.n))
    dx = 1.0 / nx
    s = EDACScheme(["fluid"], dim=dim, rho0=1.0, c0=10.0, nu=0.01, h=dx, dx=dx, pst=pst, alpha=alpha)
    s.setup_properties([pa])
    eqs = s.get_equations()
    if extra_outputs:
        eqs[1].append(Group([Vorticity2D("fluid", ["fluid"])]))
    integ = s.get_integrator()
    sc = Scene([pa], eqs, steppers=integ.steppers, kernel=s.kernel, dim=dim,
               domain=periodic_box(dim) if periodic else None,
               outputs={"fluid": list(s.output_props) + list(extra_outputs)}, backend=backend)
    integ.attach(sc)
    dt = s.get_timestep()
    integ.initial_accelerations(0.0, dt)
    t = 0.0
    for _ in range(steps):
        integ.one_timestep(t, dt)
        t += dt
    return pa, sc


@pytest.mark.parametrize("dim,pst,alpha,periodic", [
    (2, "sun2019", 0.0, True),
    (2, "tvf", 0.3, True),
    (2, "none", 0.3, False),
    (3, "sun2019", 0.2, True),
])
def test_edac_scheme_compiled_matches_python(dim, pst, alpha, periodic):
    extra = ("omega",) if dim == 2 else ()
    a, sca = run_edac("cython", dim, pst, alpha, periodic, extra_outputs=extra)
    b, scb = run_edac("python", dim, pst, alpha, periodic, extra_outputs=extra)
    assert sorted(a.data) == sorted(b.data)
    kept = {type(ep.eq).__name__ for ep in sca.plan.eqplans if ep.kept}
    if alpha:
        assert "ArtificialViscosity" in kept
    if extra:
        assert "Vorticity2D" in kept
    for name in a.data:
        assert_close(a.data[name], b.data[name], 1e-11, what=f"{pst} dim={dim}: {name}")
    # the run did something: particles moved and the pressure changed
    assert np.abs(a.ap).max() > 0 and np.abs(a.au).max() > 0
