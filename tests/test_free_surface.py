"""Free-surface particles and normals (Adepu & Ramachandran 2021, section 3.4, Figs. 1-2):
a disc and a patch resting on a wall get all and only their free boundary layer flagged."""
import numpy as np
import pytest

from sphgen import geometry
from sphgen.equations.free_surface import free_surface_groups, setup_free_surface_properties
from sphgen.kernels import QuinticSpline
from sphgen.particles import ParticleArray
from sphgen.scene import Scene

from conftest import assert_close

DX = 0.1


def medium(x, y, name="fluid"):
    n = x.size
    pa = ParticleArray(name, x=x, y=y, m=np.full(n, DX * DX), rho=np.ones(n), h=np.full(n, DX))
    setup_free_surface_properties(pa)
    return pa


def detect(arrays, walls=(), backend="python", radius=2.0):
    Scene(arrays, free_surface_groups(["fluid"], walls, radius=radius), kernel=QuinticSpline(2), dim=2,
          backend=backend, outputs={"fluid": ["free_surface", "normal", "rho_s"]}).compute(0, 0.0, 0.0)
    return arrays[0]


def disc():
    """Concentric rings of particles (geometry.ring), radius 1: the outermost ring is the surface."""
    return medium(*geometry.ring(0.0, 0.0, 0.0, 1.0, DX))


def patch_on_wall():
    """A 1 x 0.6 block of fluid resting on a 3-layer floor wider than it."""
    f = medium(*geometry.rectangle(0.0, 1.0, 0.0, 0.6, DX))
    xw, yw, _, _ = geometry.wall_layers_box(-1.0, 2.0, 0.0, 2.0, DX, 3)
    floor = yw < 0
    n = int(floor.sum())
    w = ParticleArray("wall", x=xw[floor], y=yw[floor], m=np.full(n, DX * DX), rho=np.ones(n), h=np.full(n, DX))
    return f, w


def test_disc_flags_exactly_its_outer_ring_with_radial_normals():
    f = detect([disc()])
    r = np.hypot(f.x, f.y)
    outer = r > 1.0 - DX
    fs = f.free_surface > 0
    assert outer.sum() == 60 and np.array_equal(fs, outer)
    n = f.normal.reshape(-1, 3)
    has = np.linalg.norm(n, axis=1) > 0
    # three layers carry a normal (the paper's Fig. 1a), unit and radial
    assert np.array_equal(has, r > 1.0 - 3 * DX)
    np.testing.assert_allclose(np.linalg.norm(n[has], axis=1), 1.0, atol=1e-12)
    radial = (n[has, 0] * f.x[has] + n[has, 1] * f.y[has]) / r[has]
    assert radial.min() > np.cos(np.radians(1.0))


def test_patch_on_a_wall_flags_its_free_sides_and_not_the_particles_touching_the_wall():
    f, w = patch_on_wall()
    detect([f, w], ["wall"])
    fs = f.free_surface > 0
    free_layer = ((f.y > 0.6 - DX) | (f.x < DX) | (f.x > 1.0 - DX)) & (f.y > DX)
    assert free_layer.sum() == 18 and np.array_equal(fs, free_layer)
    # without the wall among the sources the bottom layer would look free
    g = detect([patch_on_wall()[0]])
    assert np.sum((g.free_surface > 0) & (g.y < DX)) == 10


def test_the_full_kernel_support_as_cone_radius_misses_particles_near_the_contact_line():
    """Why the cone test looks 2 h around (docs/ctvf.md): at 3 h the floor's particles fall
    into the 60 degree cone of the side particles one row above the wall."""
    f, w = patch_on_wall()
    detect([f, w], ["wall"], radius=3.0)
    fs = f.free_surface > 0
    missed = ((f.x < DX) | (f.x > 1.0 - DX)) & (f.y > DX) & (f.y < 2 * DX)
    assert missed.sum() == 2 and not fs[missed].any() and fs.sum() == 16


def test_isolated_particles_are_free_surface_particles():
    """A lone particle has no normal (n* = 0): only its summation density (m W(0) = 0.31
    rho0 at h = dx) marks it; a pair dx apart (0.43 rho0) is marked by both tests."""
    x, y = geometry.ring(0.0, 0.0, 0.0, 1.0, DX)
    x, y = np.append(x, [1.5, 1.5, 1.5 + DX]), np.append(y, [1.0, 0.0, 0.0])
    f = detect([medium(x, y)])
    lone = f.x > 1.2
    assert lone.sum() == 3 and np.all(f.free_surface[lone] == 1.0)
    assert np.all(f.rho_s[lone] < 0.5) and np.all(f.rho_s[~lone] > 0.5)
    single = lone & (f.y > 0.5)
    assert np.all(f.normal.reshape(-1, 3)[single] == 0.0)
    assert np.array_equal(f.free_surface[~lone] > 0, np.hypot(f.x, f.y)[~lone] > 1.0 - DX)


@pytest.mark.parametrize("case", ["disc", "patch"])
def test_free_surface_compiled_matches_python(case):
    out = {}
    for backend in ("cython", "python"):
        arrays, walls = ([disc()], []) if case == "disc" else (list(patch_on_wall()), ["wall"])
        rng = np.random.default_rng(3)
        arrays[0].set("x", arrays[0].x + 0.2 * DX * rng.uniform(-1, 1, arrays[0].n))
        out[backend] = detect(arrays, walls, backend)
    a, b = out["cython"], out["python"]
    for name in ("free_surface", "normal", "rho_s", "fs_blocked", "x"):
        assert_close(a.get(name), b.get(name), 1e-12, what=name)
    assert a.free_surface.sum() > 10


def test_h_b_and_the_shifting_filter_near_the_surface():
    """Algorithm 1: h_b = 0 on the surface, (distance to the nearest surface particle)/3
    within the support, h deeper; eq. 44: no shifting on the surface, no normal part
    where h_b < h, untouched deeper."""
    from sphgen.equation import Group
    from sphgen.equations.free_surface import SurfaceShiftingFilter
    f, w = patch_on_wall()
    for p in ("auhat", "avhat", "awhat"):
        f.add_property(p, data=np.full(f.n, 1.0) if p != "awhat" else np.zeros(f.n))
    groups = free_surface_groups(["fluid"], ["wall"], h_b_factor=3.0) + [Group([SurfaceShiftingFilter("fluid")])]
    Scene([f, w], groups, kernel=QuinticSpline(2), dim=2, backend="python",
          outputs={"fluid": ["free_surface", "normal", "h_b", "auhat", "avhat"]}).compute(0, 0.0, 0.0)
    fs = f.free_surface > 0
    pts = np.column_stack([f.x, f.y])
    d = np.linalg.norm(pts[:, None] - pts[fs][None], axis=2).min(axis=1)
    near = ~fs & (d < 3 * DX)
    assert np.all(f.h_b[fs] == 0.0)
    np.testing.assert_allclose(f.h_b[near], d[near] / 3.0, rtol=1e-12)
    assert np.all(f.h_b[~fs & ~near] == DX) and (~fs & ~near).sum() > 0
    a = np.column_stack([f.auhat, f.avhat])
    n = f.normal.reshape(-1, 3)[:, :2]
    assert np.all(a[fs] == 0.0)
    np.testing.assert_allclose(np.sum(a[near] * n[near], axis=1), 0.0, atol=1e-12)
    assert np.all(a[~fs & ~near] == 1.0)


@pytest.mark.parametrize("backend", ["python", "cython"])
def test_ipst_shift_is_filtered_near_the_surface(backend):
    """Eq. 45: every IPST iteration's shift gets the filter of eq. 44 (none on the surface,
    no normal part where h_b < h); deeper particles shift as without the filter."""
    from sphgen.equation import Group
    from sphgen.equations import shifting
    shifts = {}
    for near in (False, True):
        f, w = patch_on_wall()
        shifting.Shifting("ipst", 2, DX, DX, 10.0, 1.0, QuinticSpline(2)).setup_properties(f)
        groups = free_surface_groups(["fluid"], ["wall"], h_b_factor=3.0) + [
            Group([shifting.IPSTShift("fluid", ["fluid", "wall"], umax=1.0, near_surface=near)])]
        Scene([f, w], groups, kernel=QuinticSpline(2), dim=2, backend=backend,
              outputs={"fluid": ["free_surface", "normal", "h_b", "ipst_dx", "ipst_dy"]}).compute(0, 0.0, 1e-3)
        shifts[near] = np.column_stack([f.ipst_dx, f.ipst_dy])
    fs, near = f.free_surface > 0, ~(f.free_surface > 0) & (f.h_b < DX)
    deep = ~fs & ~near
    n = f.normal.reshape(-1, 3)[:, :2]
    assert fs.sum() > 10 and near.sum() > 10 and deep.sum() > 0
    assert np.all(shifts[True][fs] == 0.0) and np.abs(shifts[False][fs]).max() > 1e-8
    np.testing.assert_allclose(np.sum(shifts[True][near] * n[near], axis=1), 0.0, atol=1e-15)
    assert np.abs(np.sum(shifts[False][near] * n[near], axis=1)).max() > 1e-8
    np.testing.assert_array_equal(shifts[True][deep], shifts[False][deep])
