"""Free-slip ghost velocities of the transport-velocity schemes (Adepu & Ramachandran 2021,
eqs. 46-49) and the CTVF scheme with walls: exactness, compiled == Python."""
import numpy as np
import pytest

from sphgen.equation import Group
from sphgen.equations.transport_walls import WallSlipVelocity
from sphgen.equations.walls import WallPressure
from sphgen.geometry import rectangle, wall_layers_box
from sphgen.kernels import QuinticSpline
from sphgen.particles import ParticleArray
from sphgen.scene import Scene
from sphgen.schemes.ctvf import CTVFScheme
from sphgen.schemes.gtvf import GTVFScheme

from conftest import assert_close

DX = 0.1


def box(jitter=0.2, seed=0, moving=True, normals=True):
    """A jittered unit block of fluid inside a closed 3-layer wall box; random u, u~, p."""
    rng = np.random.default_rng(seed)
    x, y = rectangle(0.0, 1.0, 0.0, 1.0, DX)
    x = x + jitter * DX * rng.uniform(-1, 1, x.size)
    y = y + jitter * DX * rng.uniform(-1, 1, y.size)
    n = x.size
    fluid = ParticleArray("fluid", x=x, y=y, u=rng.uniform(-1, 1, n), v=rng.uniform(-1, 1, n),
                          rho=1.0 + 0.01 * rng.uniform(-1, 1, n), m=np.full(n, DX * DX), h=np.full(n, DX))
    fluid.add_property("p", data=rng.uniform(-1, 1, n))
    for p in ("uhat", "vhat"):
        fluid.add_property(p, data=rng.uniform(-1, 1, n))
    fluid.add_property("what")
    xw, yw, nx, ny = wall_layers_box(0.0, 1.0, 0.0, 1.0, DX, 3, open_top=False)
    nw = xw.size
    wall = ParticleArray("wall", x=xw, y=yw, m=np.full(nw, DX * DX), h=np.full(nw, DX), rho=np.ones(nw))
    if normals:
        wall.add_property("normal", stride=3, data=np.column_stack([nx, ny, 0 * nx]).ravel())
    for p in ("p", "wij", "uhat", "vhat", "what"):
        wall.add_property(p)
    for p in ("uw", "vw", "ww", "auw", "avw", "aww"):   # declared; values only on a moving wall
        wall.add_property(p)
    if moving:
        wall.add_property("uw", data=rng.uniform(-1, 1, nw))
        wall.add_property("vw", data=rng.uniform(-1, 1, nw))
    return fluid, wall


def slip(backend, fluid, wall, moving=True):
    eqs = [Group([WallPressure("wall", ["fluid"], dim=2),
                  WallSlipVelocity("wall", ["fluid"], moving=moving, dim=2)])]
    Scene([fluid, wall], eqs, kernel=QuinticSpline(2), dim=2, backend=backend,
          outputs={"wall": ["u", "v", "uhat", "vhat"]}).compute(0, 0.0, 0.0)
    return wall


@pytest.mark.parametrize("moving", [False, True])
def test_slip_velocity_keeps_the_tangential_part_and_mirrors_the_normal_part(moving):
    """Uniform u and u~: the ghost keeps their tangential parts and mirrors their normal
    parts about the wall velocity (eqs. 48-49), so (u + u_G)/2 . n = u_p . n at the wall."""
    fluid, wall = box(moving=moving)
    U, Ut = np.array([0.7, -0.4]), np.array([0.75, -0.3])
    for k, val in (("u", U[0]), ("v", U[1]), ("uhat", Ut[0]), ("vhat", Ut[1])):
        fluid.set(k, val)
    slip("python", fluid, wall, moving)
    near = wall.wij > 1e-12   # the equation's "no fluid neighbour" threshold
    assert near.sum() > 100
    n = wall.normal.reshape(-1, 3)[near, :2]
    t = np.column_stack([-n[:, 1], n[:, 0]])
    up = np.column_stack([wall.uw, wall.vw])[near] if moving else np.zeros((near.sum(), 2))
    for (a, b), V in ((("u", "v"), U), (("uhat", "vhat"), Ut)):
        g = np.column_stack([wall.get(a), wall.get(b)])[near]
        np.testing.assert_allclose(np.sum(g * t, axis=1), V @ t.T, atol=1e-12)
        np.testing.assert_allclose(np.sum((g + V) * n, axis=1), 2 * np.sum(up * n, axis=1), atol=1e-12)
    assert np.all(wall.u[~near] == 0.0) or moving


def test_slip_velocity_compiled_matches_python():
    a = slip("cython", *box(seed=1))
    b = slip("python", *box(seed=1))
    for name in ("u", "v", "uhat", "vhat", "wij"):
        assert_close(a.get(name), b.get(name), 1e-12, what=name)
    assert np.abs(a.u).max() > 0.1


def run_scheme(scheme, backend, steps=3):
    fluid, wall = box(seed=2)
    arrays = [fluid, wall]
    scheme.setup_properties(arrays)
    integ = scheme.get_integrator()
    sc = Scene(arrays, scheme.get_equations(), steppers=integ.steppers, kernel=scheme.kernel, dim=2,
               outputs={"fluid": list(scheme.output_props)}, backend=backend)
    integ.attach(sc)
    dt = scheme.get_timestep()
    integ.initial_accelerations(0.0, dt)
    for k in range(steps):
        integ.one_timestep(k * dt, dt)
    return fluid, wall, sc


@pytest.mark.parametrize("make", [
    lambda: CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=DX, dx=DX, walls=["wall"],
                       moving_walls=["wall"]),
    lambda: CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=DX, dx=DX, walls=["wall"],
                       density="continuity", alpha=0.1, gy=-1.0),
    lambda: GTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=DX, dx=DX, walls=["wall"]),
], ids=["ctvf-moving", "ctvf-continuity-gravity", "gtvf"])
def test_schemes_with_walls_compiled_match_python(make):
    a, aw, sca = run_scheme(make(), "cython")
    b, bw, _ = run_scheme(make(), "python")
    kept = {type(ep.eq).__name__ for ep in sca.plan.eqplans if ep.kept}
    assert {"WallPressure", "WallSlipVelocity", "WallGhostVelocity", "WallViscosity"} <= kept
    for name in ("x", "y", "u", "v", "p", "rho"):
        assert_close(a.get(name), b.get(name), 1e-10, what=f"fluid.{name}")
    for name in ("u", "v", "uhat", "vhat", "p"):
        assert_close(aw.get(name), bw.get(name), 1e-10, what=f"wall.{name}")
    assert np.all(np.isfinite(a.u)) and np.abs(aw.uhat).max() > 0


def test_walls_need_normals():
    fluid, wall = box(normals=False)
    s = CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=DX, dx=DX, walls=["wall"])
    with pytest.raises(ValueError, match="normal"):
        s.setup_properties([fluid, wall])
    with pytest.raises(ValueError, match="moving_walls"):
        CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=DX, dx=DX, walls=["wall"], moving_walls=["lid"])


def test_wall_alpha_switch():
    """``wall_alpha=False`` leaves the walls out of the artificial viscosity (and only that)."""
    def names(**kw):
        s = CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=DX, dx=DX, walls=["wall"],
                       density="continuity", alpha=0.1, gy=-1.0, **kw)
        def flat(x):
            return [e for y in x for e in flat(y)] if isinstance(x, list) else \
                [type(e).__name__ for e in x.equations]
        return flat(s.get_equations())
    on, off = names(), names(wall_alpha=False)
    assert "WallArtificialViscosity" in on and "WallArtificialViscosity" not in off
    assert [n for n in on if n != "WallArtificialViscosity"] == off
