"""Probes: Shepard interpolation (order 0 and 1), line probe, front tracker, material points."""
import os

import numpy as np
import pytest

from sphgen import geometry, io
from sphgen.kernels import QuinticSpline
from sphgen.particles import ParticleArray
from sphgen.tools import probes


def jittered(dim=2, dx=0.05, seed=1):
    """Jittered lattice on the unit square/cube with per-particle h, m, rho."""
    bounds = [0.0, 1.0] * dim
    pts = (geometry.square_lattice(dx, *bounds) if dim == 2 else geometry.cubic_lattice(dx, *bounds))
    pts = geometry.perturb(pts, 0.25 * dx, seed=seed)
    rng = np.random.default_rng(seed + 10)
    n = pts[0].size
    h = dx * (1.0 + 0.2 * rng.random(n))
    rho = 1000.0 * (1.0 + 0.05 * rng.uniform(-1, 1, n))
    m = rho * dx ** dim
    return pts, h, m, rho


def probe_points(dim, n=200, seed=5):
    """Random probe points, including some within a smoothing length of the boundary."""
    rng = np.random.default_rng(seed)
    return tuple(rng.uniform(0.0, 1.0, n) for _ in range(dim))


def test_pairs_within_matches_brute_force():
    rng = np.random.default_rng(0)
    parts = (rng.random(300), rng.random(300))
    pts = (rng.uniform(-0.2, 1.2, 50), rng.uniform(-0.2, 1.2, 50))
    i, j, r = probes.pairs_within(pts, parts, 0.13)
    d = np.hypot(pts[0][:, None] - parts[0][None], pts[1][:, None] - parts[1][None])
    bi, bj = np.nonzero(d < 0.13)
    assert sorted(zip(i, j)) == sorted(zip(bi, bj))
    assert np.allclose(r, d[i, j])


def test_kernel_values_match_scalar_kernel():
    k = QuinticSpline(2)
    r = np.linspace(0, 3.5, 71)
    assert np.allclose(probes.kernel_values(k, r, 0.7), [k.w(ri, 0.7) for ri in r], rtol=1e-13, atol=0)

    class Wrapped(QuinticSpline):       # a kernel without a numpy formula: elementwise path
        pass

    assert np.allclose(probes.kernel_values(Wrapped(2), r, 0.7), probes.kernel_values(k, r, 0.7))


@pytest.mark.parametrize("dim", [2, 3])
def test_shepard_order0_exact_for_constants(dim):
    dx = 0.05 if dim == 2 else 0.125
    pts, h, m, rho = jittered(dim, dx)
    k = QuinticSpline(dim)
    probe = probe_points(dim, 100)
    vals = probes.shepard(probe, *pts, h, m, rho, np.full(pts[0].size, 3.25), k)
    assert np.allclose(vals, 3.25, rtol=0, atol=1e-12)


@pytest.mark.parametrize("dim", [2, 3])
def test_shepard_order1_exact_for_linear_fields(dim):
    dx = 0.05 if dim == 2 else 0.125
    pts, h, m, rho = jittered(dim, dx)
    k = QuinticSpline(dim)
    coef = np.array([2.0, 3.0, -5.0, 0.5][:dim + 1])

    def lin(p):
        return coef[0] + sum(c * q for c, q in zip(coef[1:], p))

    probe = probe_points(dim, 200)
    fields = np.column_stack([lin(pts), np.full(pts[0].size, -1.5)])     # several fields at once
    vals = probes.shepard(probe, *pts, h, m, rho, fields, k, order=1)
    assert vals.shape == (200, 2)
    assert np.max(np.abs(vals[:, 0] - lin(probe))) < 1e-12
    assert np.max(np.abs(vals[:, 1] + 1.5)) < 1e-12
    # order 0 is not exact for a linear field near the boundary
    v0 = probes.shepard(probe, *pts, h, m, rho, lin(pts), k)
    assert np.max(np.abs(v0 - lin(probe))) > 1e-3


def test_shepard_scalar_h_and_outside_point_nan():
    x, y = geometry.square_lattice(0.1, 0, 1, 0, 1)
    k = QuinticSpline(2)
    vals = probes.shepard((np.array([0.5, 5.0]), np.array([0.5, 5.0])), x, y, 0.1, 0.01, 1.0,
                          x + 2 * y, k, order=1)
    assert np.isclose(vals[0], 1.5, atol=1e-12) and np.isnan(vals[1])


def test_shepard_bad_arguments():
    x, y = geometry.square_lattice(0.1, 0, 1, 0, 1)
    with pytest.raises(TypeError, match="shepard"):
        probes.shepard((x, y), x, y, 0.1, 1.0, x, QuinticSpline(2))
    with pytest.raises(ValueError, match="order"):
        probes.shepard((x, y), x, y, 0.1, 0.01, 1.0, x, QuinticSpline(2), order=2)


def test_line_probe_centre_line_profile():
    pts, h, m, rho = jittered(2, 0.05)
    u = 1.0 - 2.0 * pts[1]
    (px, py), vals = probes.line_probe((0.5, 0.0), (0.5, 1.0), 11, *pts, h, m, rho, u,
                                       QuinticSpline(2), order=1)
    assert np.allclose(px, 0.5) and np.allclose(py, np.linspace(0, 1, 11))
    assert np.allclose(vals, 1.0 - 2.0 * py, atol=1e-12)


def dam_block(dx=0.02):
    """A 1 x 0.5 block of water on the floor y = 0, with a two-row toe out to x = 1.4."""
    x, y = geometry.rectangle(0.0, 1.0, 0.0, 0.5, dx)
    tx, ty = geometry.rectangle(1.0, 1.4, 0.0, 2 * dx, dx)
    return np.concatenate([x, tx]), np.concatenate([y, ty])


def test_front_position_ignores_ejected_particles():
    dx = 0.02
    x, y = dam_block(dx)
    toe = 1.4 - dx / 2
    assert np.isclose(probes.front_position(x, y, 0.0, dx), toe)
    # one ejected droplet (and a pair) on the floor ahead of the toe
    xe = np.concatenate([x, [2.0, 2.5, 2.5 + dx]])
    ye = np.concatenate([y, [dx / 2, dx / 2, dx / 2]])
    assert np.isclose(probes.front_position(xe, ye, 0.0, dx), toe)
    # a particle ahead but high above the floor is not in the band either
    xh, yh = np.concatenate([x, geometry.rectangle(1.6, 1.8, 0.2, 0.4, dx)[0]]), \
        np.concatenate([y, geometry.rectangle(1.6, 1.8, 0.2, 0.4, dx)[1]])
    assert np.isclose(probes.front_position(xh, yh, 0.0, dx), toe)
    # given counts are used as they are
    counts = probes.count_neighbours((xe, ye), 2.5 * dx)
    assert np.median(counts) == 21
    assert np.isclose(probes.front_position(xe, ye, 0.0, dx, neighbour_counts=counts), toe)
    assert np.isclose(probes.front_position(xe, ye, 0.0, dx, neighbour_counts=np.ones(xe.size)), 2.5 + dx)


def write_series(folder, n_out=3):
    """A fluid array whose particles move and get reordered between outputs."""
    x, y = geometry.square_lattice(0.1, 0, 1, 0, 1)
    n = x.size
    rng = np.random.default_rng(0)
    for step in range(n_out):
        perm = rng.permutation(n)
        gid = np.arange(n)[perm]
        pa = ParticleArray("fluid", x=x[perm] + 0.1 * step, y=y[perm])
        pa.add_property("gid", dtype="int", data=gid)
        io.write(os.path.join(folder, f"run_{step:06d}.h5"), [pa],
                 {"t": 0.5 * step, "dt": 0.1, "step": step})
    return x, y


def test_material_points_by_gid_and_by_point(tmp_path):
    x, y = write_series(str(tmp_path))
    t, pos = probes.MaterialPoints("fluid", gids=[0, 57]).track(str(tmp_path))
    assert np.allclose(t, [0.0, 0.5, 1.0])
    assert pos.shape == (3, 2, 2)
    for k, g in enumerate([0, 57]):
        assert np.allclose(pos[:, k, 0], x[g] + 0.1 * np.arange(3))
        assert np.allclose(pos[:, k, 1], y[g])
    # by the particle nearest to a point at the first output
    t, pos = probes.MaterialPoints("fluid", points=([0.26], [0.74])).track(probes.output_series(str(tmp_path)))
    assert np.allclose(pos[:, 0, 0], 0.25 + 0.1 * np.arange(3)) and np.allclose(pos[:, 0, 1], 0.75)
    with pytest.raises(ValueError, match="gid"):
        probes.MaterialPoints("fluid", gids=[1000]).track(str(tmp_path))


def test_output_series_order_and_content(tmp_path):
    write_series(str(tmp_path), n_out=2)
    out = list(probes.output_series(str(tmp_path)))
    assert [t for t, _ in out] == [0.0, 0.5]
    assert out[1][1]["fluid"].n == 100


def test_front_position_from_output_files(tmp_path):
    dx = 0.02
    x, y = dam_block(dx)
    pa = ParticleArray("fluid", x=x, y=y)
    path = os.path.join(str(tmp_path), "db_000000.h5")
    io.write(path, [pa], {"t": 0.0, "dt": 1e-4, "step": 0})
    f = io.load(path)["arrays"]["fluid"]
    assert np.isclose(probes.front_position(f.x, f.y, 0.0, dx), 1.4 - dx / 2)


# ------------------------------------------------------------------ voids
def test_nearest_distance_matches_brute_force():
    rng = np.random.default_rng(7)
    X = (rng.uniform(0, 1, 300), rng.uniform(0, 1, 300))
    P = (rng.uniform(-0.5, 1.5, 50), rng.uniform(-0.5, 1.5, 50))
    brute = np.hypot(P[0][:, None] - X[0][None], P[1][:, None] - X[1][None]).min(axis=1)
    np.testing.assert_allclose(probes.nearest_distance(P, X, 0.01), brute, rtol=1e-14)


@pytest.mark.parametrize("k", [0, 1, 3])
def test_largest_empty_disc_of_a_lattice_with_a_hole(k):
    """Square lattice: dx/sqrt(2) (a cell's centre); a k x k block removed (k odd): (k + 1)/2 dx."""
    dx = 0.05
    x, y = geometry.square_lattice(dx, 0.0, 1.0, 0.0, 1.0)
    cx, cy = x[210], y[210]   # an interior particle
    hole = (np.abs(x - cx) < 0.5 * k * dx) & (np.abs(y - cy) < 0.5 * k * dx)
    assert hole.sum() == k * k
    r = probes.largest_empty_disc((x[~hole], y[~hole]), (0.0, 1.0, 0.0, 1.0)) / dx
    expect = 1.0 / np.sqrt(2.0) if k == 0 else 0.5 * (k + 1)
    assert abs(r - expect) < 1e-3, (k, r)


def test_largest_empty_disc_3d_and_bad_bounds():
    dx = 0.1
    x, y, z = geometry.cubic_lattice(dx, 0.0, 1.0, 0.0, 1.0, 0.0, 1.0)
    r = probes.largest_empty_disc((x, y, z), (0.0, 1.0, 0.0, 1.0, 0.0, 1.0))
    assert abs(r / dx - np.sqrt(3.0) / 2.0) < 1e-3
    with pytest.raises(ValueError, match="bounds"):
        probes.largest_empty_disc((x, y, z), (0.0, 1.0, 0.0, 1.0))


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_count_neighbours_is_brute_force(dim):
    """The cell-list count equals all-pairs distances (itself included), 1-3D."""
    rng = np.random.default_rng(dim)
    pts = tuple(rng.uniform(0, 1, 300) for _ in range(dim))
    r = 0.17
    X = np.column_stack(pts)
    brute = (np.linalg.norm(X[:, None, :] - X[None, :, :], axis=2) < r).sum(axis=1)
    assert np.array_equal(probes.count_neighbours(pts, r), brute)
    assert probes.count_neighbours(tuple(np.empty(0) for _ in range(dim)), r).size == 0


def test_count_neighbours_reuses_its_search_with_fresh_positions():
    """Calls with the same count and radius reuse the last search: each still counts the
    positions it is given (moved, spread, then a different count), and a non-finite
    position is refused without spoiling the next call."""
    rng = np.random.default_rng(9)
    r = 0.15

    def brute(pts):
        X = np.column_stack(pts)
        return (np.linalg.norm(X[:, None, :] - X[None, :, :], axis=2) < r).sum(axis=1)

    for n, spread in ((200, 1.0), (200, 0.5), (200, 3.0), (150, 1.0)):
        pts = tuple(rng.uniform(0, spread, n) for _ in range(2))
        assert np.array_equal(probes.count_neighbours(pts, r), brute(pts))
    bad = (pts[0].copy(), pts[1])
    bad[0][7] = np.nan
    with pytest.raises(ValueError, match="non-finite"):
        probes.count_neighbours(bad, r)
    assert np.array_equal(probes.count_neighbours(pts, r), brute(pts))
