"""Particle layouts: counts, spacing, wall layers and normals, perturbation."""
import math

import numpy as np
import pytest

from sphgen import geometry as g
from sphgen.kernels import QuinticSpline


def nearest_distances(*coords):
    """Distance of each point to its nearest other point (brute force)."""
    p = np.column_stack(coords)
    d = np.linalg.norm(p[:, None, :] - p[None, :, :], axis=-1)
    np.fill_diagonal(d, np.inf)
    return d.min(axis=1)


def test_cells_rule_absorbs_round_off():
    assert g.cells(1.0, 0.1) == 10
    assert g.cells(0.3, 0.1) == 3
    assert g.cells(0.35, 0.1) == 3
    assert g.cells(0.0, 0.1) == 0


def test_square_lattice_count_and_spacing():
    x, y = g.square_lattice(0.1, 0.0, 2.0, -1.0, 0.0)
    assert x.size == 20 * 10
    assert np.isclose(x.min(), 0.05) and np.isclose(x.max(), 1.95)
    assert np.isclose(y.min(), -0.95) and np.isclose(y.max(), -0.05)
    assert np.allclose(nearest_distances(x, y), 0.1)


def test_cubic_lattice_count_and_spacing():
    x, y, z = g.cubic_lattice(0.25, 0, 1, 0, 0.5, 0, 0.75)
    assert x.size == 4 * 2 * 3
    assert np.isclose(z.min(), 0.125)
    assert np.allclose(nearest_distances(x, y, z), 0.25)


def test_hexagonal_lattice():
    dx = 0.1
    dy = dx * math.sqrt(3) / 2
    x, y = g.hexagonal_lattice(dx, 0.0, 1.0, 0.0, 1.0)
    ny = math.floor(1.0 / dy)
    assert x.size == 10 * ny
    assert np.allclose(nearest_distances(x, y), dx)
    rows = np.unique(np.round(y, 12))
    assert np.allclose(np.diff(rows), dy)
    assert np.isclose(x[np.isclose(y, rows[1])].min() - x[np.isclose(y, rows[0])].min(), dx / 2)
    assert x.min() >= 0 and x.max() <= 1 and y.max() <= 1


def test_bcc_lattice_volume_and_spacing():
    dx = 0.1
    a = dx * 2 ** (1 / 3)
    L = 4 * a
    x, y, z = g.bcc_lattice(dx, 0, L, 0, L, 0, L)
    assert x.size == 2 * 4 ** 3
    assert np.isclose(L ** 3 / x.size, dx ** 3)
    assert np.allclose(nearest_distances(x, y, z), a * math.sqrt(3) / 2)
    assert min(x.min(), y.min(), z.min()) > 0 and max(x.max(), y.max(), z.max()) < L


def test_rectangle_and_box_aliases():
    assert all(np.array_equal(a, b) for a, b in
               zip(g.rectangle(0, 1, 0, 2, 0.1), g.square_lattice(0.1, 0, 1, 0, 2)))
    assert all(np.array_equal(a, b) for a, b in
               zip(g.rectangle(0, 1, 0, 2, 0.1, lattice="hexagonal"),
                   g.hexagonal_lattice(0.1, 0, 1, 0, 2)))
    assert g.box(0, 1, 0, 1, 0, 1, 0.5)[0].size == 8
    assert g.box(0, 1, 0, 1, 0, 1, 0.5, lattice="bcc")[0].size == 2
    with pytest.raises(ValueError, match="lattice"):
        g.rectangle(0, 1, 0, 1, 0.1, lattice="triangle")


def test_disk_annulus_partition():
    dx = 0.05
    x, y = g.disk(1.0, 2.0, 0.5, dx)
    assert np.all(np.hypot(x - 1.0, y - 2.0) <= 0.5)
    assert abs(x.size * dx * dx - math.pi * 0.25) < 0.02 * math.pi * 0.25
    assert np.isclose(x.mean(), 1.0) and np.isclose(y.mean(), 2.0)   # symmetric lattice
    assert np.allclose(nearest_distances(x, y), dx)
    ax, ay = g.annulus(1.0, 2.0, 0.3, 0.5, dx)
    r = np.hypot(ax - 1.0, ay - 2.0)
    assert np.all((r > 0.3) & (r <= 0.5))
    assert g.disk(1.0, 2.0, 0.3, dx)[0].size + ax.size == x.size


def test_ring_concentric_circles():
    dx = 0.02
    x, y = g.ring(0.0, 0.0, 0.4, 0.5, dx)
    radii = 0.4 + (np.arange(5) + 0.5) * dx
    counts = np.rint(2 * np.pi * radii / dx).astype(int)
    assert x.size == counts.sum()
    r = np.hypot(x, y)
    for rk, nk in zip(radii, counts):
        on = np.isclose(r, rk)
        assert on.sum() == nk
    # spacing ~dx along (chord 2 r sin(pi/n)) and exactly dx across
    assert np.allclose(nearest_distances(x, y), dx, rtol=0.03)


def test_cylinder_count():
    dx = 0.1
    x, y, z = g.cylinder(0, 0, 0.0, 1.0, 0.3, dx)
    nd = g.disk(0, 0, 0.3, dx)[0].size
    assert x.size == 10 * nd
    assert np.allclose(np.unique(np.round(z, 12)), (np.arange(10) + 0.5) * dx)


def test_l_shape_count():
    dx = 0.1
    x, y = g.l_shape(0, 1, 0, 2, 0.3, 0.4, dx)
    assert x.size == 10 * 20 - 7 * 16
    assert not np.any((x > 0.3) & (y > 0.4))


def test_l_block_vertex_lattice_volumes():
    """Vertices of the 3D L-block (Ghavamian et al. 2021 sec. 7.2) with cell-fraction
    volumes: they add up to the block's 117 m^3; 1/8 at a corner, 3/4 on the re-entrant edge."""
    x, y, z, V = g.l_block(0.5)
    assert x.size == 13 * 21 * 7 - 6 * 14 * 7 and V.sum() == pytest.approx(117.0, rel=1e-14)
    at = lambda X, Y, Z: V[(x == X) & (y == Y) & (z == Z)][0]  # noqa: E731
    assert at(0, 0, 0) == 0.125 * 0.125 and at(0, 5, 1) == 0.0625 and at(3, 3, 0) == 0.75 * 0.125 / 2
    assert at(3, 3, 1) == 0.75 * 0.125 and at(6, 1, 1) == 0.0625 and not np.any((x > 3) & (y > 3))
    frac = g.vertex_fractions(g.vertex_lattice(0.5, 0, 1, 0, 1), g.inside_rectangle(0, 1, 0, 1), 0.5)
    assert sorted(set(frac)) == [0.25, 0.5, 1.0] and frac.sum() * 0.25 == pytest.approx(1.0)


def test_masks():
    pts = g.square_lattice(0.1, 0, 1, 0, 1)
    hole = g.inside_disk(0.5, 0.5, 0.2)
    out = g.remove_inside(pts, hole)
    inn = g.keep_inside(pts, hole)
    assert out[0].size + inn[0].size == 100
    assert inn[0].size == g.disk(0.5, 0.5, 0.2, 0.1)[0].size
    sq = g.keep_inside(pts, g.inside_rectangle(0, 0.5, 0, 0.3))
    assert sq[0].size == 5 * 3
    cube = g.keep_inside(g.cubic_lattice(0.1, 0, 1, 0, 1, 0, 1), g.inside_box(0, 0.5, 0, 0.5, 0, 0.2))
    assert cube[0].size == 5 * 5 * 2


def test_layers_for_support():
    assert g.layers_for_support(3.0, 1.0) == 3
    assert g.layers_for_support(3.0, 1.2) == 4
    assert g.layers_for_support(2.0, 1.5) == 3
    assert g.layers_for_support(QuinticSpline(2), 1.0) == 3


@pytest.mark.parametrize("open_top", [True, False])
def test_wall_layers_box(open_top):
    dx, n = 0.1, 3
    x, y, nx, ny = g.wall_layers_box(0.0, 1.0, 0.0, 0.6, dx, n, open_top=open_top)
    NX, NY = 10, 6
    expected = n * (NX + 2 * n) * (1 if open_top else 2) + 2 * n * NY
    assert x.size == expected
    # outside the box, first layer dx/2 from each face
    inside = (x > 0) & (x < 1) & (y > 0) & (y < 0.6)
    assert not inside.any()
    assert np.isclose(y[y < 0].max(), -dx / 2)
    assert np.isclose(x[x < 0].max(), -dx / 2) and np.isclose(x[x > 1].min(), 1 + dx / 2)
    assert np.isclose(y.min(), -(n - 0.5) * dx)
    if open_top:
        assert np.isclose(y.max(), 0.6 - dx / 2)
    else:
        assert np.isclose(y[y > 0.6].min(), 0.6 + dx / 2)
    # wall + fluid form one lattice of spacing dx (no overlap, no gap)
    fx, fy = g.square_lattice(dx, 0.0, 1.0, 0.0, 0.6)
    allx, ally = np.concatenate([x, fx]), np.concatenate([y, fy])
    assert np.allclose(nearest_distances(allx, ally), dx)
    # unit normals pointing into the box
    assert np.allclose(np.hypot(nx, ny), 1.0)
    assert np.all(nx[x < 0] > 0) and np.all(nx[x > 1] < 0)
    assert np.all(ny[y < 0] > 0) and np.all(nx[(x > 0) & (x < 1)] == 0)
    corner = (x < 0) & (y < 0)
    assert corner.sum() == n * n
    assert np.allclose(nx[corner], 1 / math.sqrt(2)) and np.allclose(ny[corner], 1 / math.sqrt(2))
    # every normal points towards the box centre
    assert np.all((0.5 - x) * nx + (0.3 - y) * ny > 0)


def test_wall_layers_box3d():
    dx, n = 0.25, 2
    x, y, z, nx, ny, nz = g.wall_layers_box3d(0, 1, 0, 1, 0, 1, dx, n, open_top=True)
    full = (4 + 2 * n) ** 2 * (4 + n)
    assert x.size == full - 4 ** 3
    assert np.allclose(nx ** 2 + ny ** 2 + nz ** 2, 1.0)
    assert np.all(nz[z < 0] > 0)


def test_wall_layers_curve_circle():
    dx, n, R = 0.05, 3, 1.0
    t = np.linspace(0, 2 * np.pi, 2001)          # closed, with repeated end point
    xc, yc = R * np.cos(t), R * np.sin(t)
    # wall outside the fluid disk (Taylor-Couette outer cylinder): right of a CCW circle
    x, y, nx, ny = g.wall_layers_curve(xc, yc, dx, n, side="right")
    r = np.hypot(x, y)
    radii = R + (np.arange(n) + 0.5) * dx
    counts = [round(2 * np.pi * rk / dx) for rk in radii]
    assert abs(x.size - sum(counts)) <= n      # polygon length vs circle: round-off of a point
    assert np.allclose(np.sort(np.unique(np.round(r, 4))), radii, atol=1e-4)
    assert np.allclose(np.hypot(nx, ny), 1.0)
    assert np.all(nx * x + ny * y < 0)         # normals point to the centre (the fluid)
    # inner rotating cylinder: wall inside, left of a CCW circle, normals outward
    x, y, nx, ny = g.wall_layers_curve(xc, yc, dx, n, side=1)
    assert np.all(np.hypot(x, y) < R) and np.all(nx * x + ny * y > 0)


def test_wall_layers_curve_open_line():
    dx = 0.1
    xc = np.linspace(0, 1, 11)
    x, y, nx, ny = g.wall_layers_curve(xc, np.zeros(11), dx, 2, side="right", closed=False)
    assert x.size == 2 * 11
    assert np.allclose(np.sort(np.unique(y)), [-0.15, -0.05])
    assert np.allclose(ny, 1.0) and np.allclose(nx, 0.0)


def test_perturb_reproducible_and_bounded():
    pts = g.square_lattice(0.1, 0, 1, 0, 1)
    a = g.perturb(pts, 0.01, seed=3)
    b = g.perturb(pts, 0.01, seed=3)
    c = g.perturb(pts, 0.01, seed=4)
    assert all(np.array_equal(p, q) for p, q in zip(a, b))
    assert not np.array_equal(a[0], c[0])
    for p, q in zip(a, pts):
        assert np.all(np.abs(p - q) <= 0.01) and np.abs(p - q).max() > 0.005
    assert np.array_equal(pts[0], g.square_lattice(0.1, 0, 1, 0, 1)[0])   # input untouched
