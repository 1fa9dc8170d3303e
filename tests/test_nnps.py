"""Neighbour search against a brute-force O(N^2) numpy reference."""
import numpy as np
import pytest

from sphgen.nnps import Domain, NeighbourSearch, NotFrozenError, _cell_list
from sphgen.particles import ParticleArray

AXES = ("x", "y", "z")


# ----------------------------------------------------------------- helpers
def make_array(name, n, dim, rng, lo=(0.0, 0.0, 0.0), hi=(1.0, 1.0, 1.0), h=0.05,
               hvar=0.0, ids=None):
    """Random cloud in the box; h uniform in [h*(1-hvar), h*(1+hvar)]; tagged by id."""
    props = {}
    for a in range(3):
        props[AXES[a]] = rng.uniform(lo[a], hi[a], n) if a < dim else np.zeros(n)
    props["h"] = h * (1.0 + hvar * rng.uniform(-1.0, 1.0, n))
    pa = ParticleArray(name, n=n, **props)
    ids = np.arange(n) if ids is None else ids
    pa.add_property("id", data=np.asarray(ids, dtype=np.float64))
    return pa


def brute_force(dest, src, dim, k, domain=None):
    """Reference CSR lists: |r_ij| < k max(h_i, h_j), minimum image on periodic axes."""
    r2 = np.zeros((dest.n, src.n))
    for a in range(dim):
        d = dest.get(AXES[a])[:, None] - src.get(AXES[a])[None, :]
        if domain is not None and domain.periodic[a]:
            L = domain.length[a]
            d = np.where(d > 0.5 * L, d - L, np.where(d < -0.5 * L, d + L, d))
        r2 = r2 + d * d
    rc = k * np.maximum(dest.get("h")[:, None], src.get("h")[None, :])
    mask = r2 < rc * rc
    counts = mask.sum(axis=1)
    offsets = np.zeros(dest.n + 1, dtype=np.int64)
    np.cumsum(counts, out=offsets[1:])
    nbrs = np.nonzero(mask)[1]          # row-major: rows in order, j ascending
    return offsets, nbrs


def assert_same_lists(got, ref):
    offsets, nbrs = got
    assert offsets.dtype == np.int32 and nbrs.dtype == np.int32
    np.testing.assert_array_equal(offsets, ref[0])
    np.testing.assert_array_equal(nbrs, ref[1])


def rows_ascending(offsets, nbrs):
    d = np.diff(nbrs.astype(np.int64))
    row_start = np.zeros(nbrs.size, dtype=bool)
    row_start[offsets[:-1][offsets[:-1] < nbrs.size]] = True
    return bool(np.all((d > 0) | row_start[1:]))


def id_pairs(nn, dest, src, lists=None):
    """The neighbour pairs as a set of (id_i, id_j)."""
    offsets, nbrs = nn.neighbours(dest, src) if lists is None else lists
    di, sj = dest.get("id").astype(int), src.get("id").astype(int)
    rows = np.repeat(np.arange(dest.n), np.diff(offsets))
    return set(zip(di[rows].tolist(), sj[nbrs].tolist()))


PERIODIC_CASES = {
    1: [(False,), (True,)],
    2: [(False, False), (True, False), (False, True), (True, True)],
    3: [(False, False, False), (True, False, True), (True, True, True)],
}


def domain_for(periodic, lo=(0.0, 0.0, 0.0), hi=(1.0, 1.0, 1.0)):
    p = tuple(periodic) + (False,) * (3 - len(periodic))
    return Domain(lo[0], hi[0], lo[1], hi[1], lo[2], hi[2], *p)


# ----------------------------------------------------------------- Domain
def test_domain_attributes():
    d = Domain(-1, 2, 0, 1, periodic_in_x=True)
    assert d.lo == (-1.0, 0.0, 0.0) and d.hi == (2.0, 1.0, 0.0)
    assert d.length == (3.0, 1.0, 0.0)
    assert d.periodic == (True, False, False)


@pytest.mark.parametrize("kwargs, words", [
    (dict(xmin=0.0, xmax=0.0, periodic_in_x=True), "periodic in x"),
    (dict(ymin=1.0, ymax=0.5, periodic_in_y=True), "ymax"),
    (dict(zmin=0.0, zmax=np.inf), "finite"),
    (dict(xmin=np.nan, xmax=1.0), "finite"),
])
def test_domain_validation(kwargs, words):
    with pytest.raises(ValueError, match=words):
        Domain(**kwargs)


# ------------------------------------------------------- brute-force checks
@pytest.mark.parametrize("dim, periodic", [(d, p) for d in (1, 2, 3) for p in PERIODIC_CASES[d]])
def test_random_cloud_matches_brute_force(dim, periodic):
    rng = np.random.default_rng(10 * dim + sum(periodic))
    n = {1: 300, 2: 800, 3: 1200}[dim]
    h = {1: 0.01, 2: 0.02, 3: 0.05}[dim]
    pa = make_array("fluid", n, dim, rng, h=h)
    dom = domain_for(periodic)
    nn = NeighbourSearch([pa], dim, 3.0, dom, sort=False)
    got = nn.neighbours("fluid", "fluid")
    ref = brute_force(pa, pa, dim, 3.0, dom)
    assert_same_lists(got, ref)
    # self is included, rows are ascending, and there is something to compare
    offsets, nbrs = got
    for i in range(0, n, 37):
        assert i in nbrs[offsets[i]:offsets[i + 1]]
    assert rows_ascending(offsets, nbrs)
    assert nbrs.size > 3 * n
    if any(periodic):      # the minimum image found pairs across the box
        assert nbrs.size > brute_force(pa, pa, dim, 3.0, None)[1].size


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_variable_h_and_dest_not_src(dim):
    rng = np.random.default_rng(7 + dim)
    h = {1: 0.005, 2: 0.02, 3: 0.05}[dim]
    fluid = make_array("fluid", 500, dim, rng, h=h, hvar=0.6)
    solid = make_array("solid", 250, dim, rng, lo=(0.3, 0.2, 0.1), hi=(1.4, 0.9, 1.2),
                       h=1.5 * h, hvar=0.3)
    periodic = (True,) + (False,) * (dim - 1)
    dom = domain_for(periodic, hi=(1.5, 1.0, 1.0))
    nn = NeighbourSearch([fluid, solid], dim, 2.0, dom, sort=False)
    for d, s in [(fluid, solid), (solid, fluid), (fluid, fluid), (solid, solid)]:
        got = nn.neighbours(d.name, s.name)
        assert got[0].size == d.n + 1
        assert_same_lists(got, brute_force(d, s, dim, 2.0, dom))
    # arrays can be passed instead of names; the result is the cached one
    assert nn.neighbours(fluid, solid)[1] is nn.neighbours("fluid", "solid")[1]
    # variable h makes the relation asymmetric only through max(h_i, h_j): it stays symmetric
    assert id_pairs(nn, fluid, solid) == {(i, j) for j, i in id_pairs(nn, solid, fluid)}


def test_unsorted_rows_are_sorted_and_dense_3d():
    """Random particle order with ~100+ neighbours per row (exercises the row sort)."""
    rng = np.random.default_rng(3)
    pa = make_array("fluid", 2000, 3, rng, h=0.06, hvar=0.2)
    nn = NeighbourSearch([pa], 3, 3.0, domain_for((True, True, True)), sort=False)
    got = nn.neighbours("fluid", "fluid")
    assert np.diff(got[0]).max() > 64
    assert_same_lists(got, brute_force(pa, pa, 3, 3.0, nn.domain))


@pytest.mark.parametrize("dim, n, h", [(2, 1500, 0.02), (3, 2500, 0.06)])
def test_sorted_then_moved_rows_stay_ascending(dim, n, h):
    """After a sort, particles move a little: rows are nearly sorted and get fixed
    up (insertion for short rows, run merging for long 3D rows)."""
    rng = np.random.default_rng(40 + dim)
    pa = make_array("fluid", n, dim, rng, h=h, hvar=0.2)
    dom = domain_for((True,) * dim)
    nn = NeighbourSearch([pa], dim, 3.0, dom, sort=True)
    for step in range(2):
        for a in range(dim):
            pa.get(AXES[a])[:] += rng.uniform(-0.3 * h, 0.3 * h, n)
        nn.update()
        got = nn.neighbours("fluid", "fluid")
        if dim == 3:
            assert np.median(np.diff(got[0])) > 48    # mostly long rows: the merge path
        assert_same_lists(got, brute_force(pa, pa, dim, 3.0, dom))


def test_particles_on_box_boundary():
    """Particles exactly on lo and hi of periodic axes and on the bounding box."""
    lattice = np.linspace(0.0, 1.0, 21)        # includes 0 and 1 exactly
    X, Y = np.meshgrid(lattice, lattice)
    n = X.size
    pa = ParticleArray("fluid", x=X.ravel(), y=Y.ravel(), z=np.zeros(n), h=np.full(n, 0.05))
    pa.add_property("id", data=np.arange(n, dtype=float))
    dom = Domain(0.0, 1.0, 0.0, 1.0, periodic_in_x=True)
    nn = NeighbourSearch([pa], 2, 2.0, dom, sort=False)
    x = pa.get("x")
    assert x.min() == 0.0 and x.max() < 1.0          # x = 1 wrapped to 0
    assert np.count_nonzero(x == 0.0) == 2 * lattice.size
    assert_same_lists(nn.neighbours("fluid", "fluid"), brute_force(pa, pa, 2, 2.0, dom))
    # the two copies of the wrapped column are neighbours of each other (distance 0)
    offsets, nbrs = nn.neighbours("fluid", "fluid")
    assert np.all(np.diff(offsets) >= 2)


def test_wrap_into_box_and_outside_particles():
    rng = np.random.default_rng(5)
    pa = make_array("fluid", 600, 2, rng, lo=(-3.0, -0.5, 0.0), hi=(4.0, 1.5, 0.0), h=0.03)
    dom = Domain(0.0, 1.0, 0.0, 1.0, periodic_in_x=True, periodic_in_y=False)
    x_before = pa.get("x").copy()
    y_before = pa.get("y").copy()
    nn = NeighbourSearch([pa], 2, 3.0, dom, sort=False)
    x = pa.get("x")
    assert np.all((x >= 0.0) & (x < 1.0))
    np.testing.assert_allclose(np.mod(x_before, 1.0), x, atol=1e-12)
    np.testing.assert_array_equal(pa.get("y"), y_before)         # open axis untouched
    assert_same_lists(nn.neighbours("fluid", "fluid"), brute_force(pa, pa, 2, 3.0, dom))


@pytest.mark.parametrize("length", [2.05, 2.5, 2.99, 3.5])
def test_small_periodic_box(length):
    """Fewer than 3 cells on a periodic axis: slower path, still minimum image."""
    rng = np.random.default_rng(int(length * 100))
    cutoff = 2.0 * 0.1
    L = length * cutoff
    pa = make_array("fluid", 300, 2, rng, hi=(L, 1.0, 0.0), h=0.1, hvar=0.0)
    dom = Domain(0.0, L, 0.0, 1.0, periodic_in_x=True, periodic_in_y=True)
    nn = NeighbourSearch([pa], 2, 2.0, dom, sort=True)
    assert_same_lists(nn.neighbours("fluid", "fluid"), brute_force(pa, pa, 2, 2.0, dom))


def test_periodic_box_shorter_than_two_cutoffs_is_an_error():
    rng = np.random.default_rng(0)
    pa = make_array("fluid", 50, 2, rng, hi=(0.3, 1.0, 0.0), h=0.1)
    dom = Domain(0.0, 0.3, 0.0, 1.0, periodic_in_x=True)
    with pytest.raises(ValueError, match="minimum image is not unique"):
        NeighbourSearch([pa], 2, 2.0, dom)


def test_one_dimensional_array_without_y_z():
    x = np.linspace(0.0, 1.0, 101)
    pa = ParticleArray("rod", x=x, h=np.full(x.size, 0.0125))
    assert "y" not in pa.data and "z" not in pa.data
    nn = NeighbourSearch([pa], 1, 2.0, sort=False)
    offsets, nbrs = nn.neighbours("rod", "rod")
    counts = np.diff(offsets)
    # spacing 0.01, cut-off 0.025: self + 2 on each side, fewer at the ends
    assert counts[:2].tolist() == [3, 4] and counts[-2:].tolist() == [4, 3]
    assert np.all(counts[2:-2] == 5)
    np.testing.assert_array_equal(nbrs[offsets[50]:offsets[51]], [48, 49, 50, 51, 52])


def test_far_outliers_coarsen_the_grid():
    rng = np.random.default_rng(11)
    pa = make_array("fluid", 400, 3, rng, h=0.03)
    pa.get("x")[:3] = [1e4, -2e4, 5e3]
    nn = NeighbourSearch([pa], 3, 2.0, sort=False)
    assert np.prod(nn.n_cells) <= max(8 * pa.n, 4096)
    assert_same_lists(nn.neighbours("fluid", "fluid"), brute_force(pa, pa, 3, 2.0))


def test_empty_array():
    rng = np.random.default_rng(2)
    fluid = make_array("fluid", 100, 2, rng, h=0.05)
    empty = make_array("empty", 0, 2, rng)
    nn = NeighbourSearch([fluid, empty], 2, 2.0, sort=True)
    off, nb = nn.neighbours("empty", "fluid")
    assert off.tolist() == [0] and nb.size == 0
    off, nb = nn.neighbours("fluid", "empty")
    assert off.shape == (101,) and not off.any() and nb.size == 0


def test_large_3d_cloud_sampled_rows():
    """20k particles in 3D: sampled rows against brute force."""
    rng = np.random.default_rng(20)
    n = 20000
    pa = make_array("fluid", n, 3, rng, h=1.2 * n ** (-1.0 / 3.0))
    dom = domain_for((True, True, False))
    nn = NeighbourSearch([pa], 3, 2.0, dom, sort=True)
    offsets, nbrs = nn.neighbours("fluid", "fluid")
    assert offsets.size == n + 1 and rows_ascending(offsets, nbrs)
    rows = rng.choice(n, 300, replace=False)
    sub = ParticleArray("sub", x=pa.x[rows], y=pa.y[rows], z=pa.z[rows], h=pa.h[rows])
    ref_off, ref_nbrs = brute_force(sub, pa, 3, 2.0, dom)
    for r, i in enumerate(rows):
        np.testing.assert_array_equal(nbrs[offsets[i]:offsets[i + 1]],
                                      ref_nbrs[ref_off[r]:ref_off[r + 1]])


# ------------------------------------------------------- update / caching
def test_update_rebuilds_and_caches():
    rng = np.random.default_rng(4)
    pa = make_array("fluid", 400, 2, rng, h=0.03)
    dom = domain_for((True, True))
    nn = NeighbourSearch([pa], 2, 3.0, dom, sort=False)
    assert nn.n_updates == 0
    first = nn.neighbours("fluid", "fluid")
    assert nn.neighbours("fluid", "fluid")[1] is first[1]
    pa.get("x")[:] += 0.37                      # move out of the box: update wraps
    pa.get("y")[:] += rng.uniform(-0.02, 0.02, pa.n)
    nn.update()
    assert nn.n_updates == 1
    second = nn.neighbours("fluid", "fluid")
    assert second[1] is not first[1]
    assert np.all(pa.get("x") < 1.0)
    assert_same_lists(second, brute_force(pa, pa, 2, 3.0, dom))


def test_changed_particle_count_needs_update():
    rng = np.random.default_rng(4)
    pa = make_array("fluid", 100, 2, rng, h=0.03)
    nn = NeighbourSearch([pa], 2, 3.0, sort=False)
    object.__setattr__(pa, "n", 90)
    for p in ("x", "y", "z", "h", "id"):
        pa.data[p] = pa.data[p][:90].copy()
    with pytest.raises(RuntimeError, match="call update"):
        nn.neighbours("fluid", "fluid")
    nn.update()
    assert nn.neighbours("fluid", "fluid")[0].size == 91


# ------------------------------------------------------- errors
@pytest.mark.parametrize("prop, value", [("x", np.nan), ("y", np.inf), ("h", np.nan)])
def test_non_finite_values_are_reported(prop, value):
    rng = np.random.default_rng(1)
    fluid = make_array("fluid", 50, 2, rng)
    solid = make_array("solid", 50, 2, rng)
    nn = NeighbourSearch([fluid, solid], 2, 2.0, domain_for((True, False)), sort=False)
    solid.get(prop)[17] = value                 # bypasses ParticleArray.set's check
    with pytest.raises(ValueError, match=rf"array 'solid': particle 17 has a non-finite {prop}"):
        nn.update()


def test_bad_arguments():
    rng = np.random.default_rng(1)
    pa = make_array("fluid", 10, 2, rng)
    with pytest.raises(ValueError, match="dim"):
        NeighbourSearch([pa], 4, 2.0)
    with pytest.raises(ValueError, match="radius_scale"):
        NeighbourSearch([pa], 2, 0.0)
    with pytest.raises(ValueError, match="periodic in z"):
        NeighbourSearch([pa], 2, 2.0, Domain(zmax=1.0, periodic_in_z=True))
    with pytest.raises(ValueError, match="distinct"):
        NeighbourSearch([pa, pa], 2, 2.0)
    pa.get("h")[3] = 0.0
    with pytest.raises(ValueError, match="particle 3 has h = 0"):
        NeighbourSearch([pa], 2, 2.0)
    pa.get("h")[3] = 0.05
    nn = NeighbourSearch([pa], 2, 2.0)
    with pytest.raises(KeyError, match="no array 'solid'"):
        nn.neighbours("fluid", "solid")
    with pytest.raises(NotFrozenError, match=r"call freeze\('fluid', 'fluid'\)"):
        nn.reference_neighbours("fluid", "fluid")
    assert isinstance(NotFrozenError("x"), KeyError)


# ------------------------------------------------------- freeze / sort
def test_freeze_keeps_reference_list_while_particles_move():
    rng = np.random.default_rng(8)
    fluid = make_array("fluid", 400, 2, rng, h=0.03)
    solid = make_array("solid", 200, 2, rng, h=0.03)
    dom = domain_for((True, True))
    nn = NeighbourSearch([fluid, solid], 2, 3.0, dom, sort=False)
    nn.freeze("fluid", "solid")
    nn.freeze(fluid, fluid)
    ref_fs = [a.copy() for a in nn.neighbours("fluid", "solid")]
    ref_ff = [a.copy() for a in nn.neighbours("fluid", "fluid")]
    for step in range(3):
        fluid.get("x")[:] += rng.uniform(-0.05, 0.05, fluid.n)
        fluid.get("y")[:] += 0.1
        nn.update()
        assert_same_lists(nn.reference_neighbours("fluid", "solid"), ref_fs)
        assert_same_lists(nn.reference_neighbours("fluid", "fluid"), ref_ff)
    now = nn.neighbours("fluid", "solid")
    assert_same_lists(now, brute_force(fluid, solid, 2, 3.0, dom))
    assert not np.array_equal(now[1], ref_fs[1])       # the current list did change
    assert nn.is_frozen("fluid", "solid") and not nn.is_frozen("solid", "fluid")


@pytest.mark.parametrize("dim", [2, 3])
def test_sort_keeps_pairs_and_remaps_frozen_lists(dim):
    rng = np.random.default_rng(30 + dim)
    n_f, n_s = (900, 300) if dim == 2 else (1500, 400)
    h = 0.02 if dim == 2 else 0.05
    fluid = make_array("fluid", n_f, dim, rng, h=h, hvar=0.3, ids=rng.permutation(n_f))
    solid = make_array("solid", n_s, dim, rng, h=h, ids=1000 + np.arange(n_s))
    dom = domain_for((True,) * dim)
    nn = NeighbourSearch([fluid, solid], dim, 3.0, dom, sort=False)
    before = {(d, s): id_pairs(nn, nn._array(d), nn._array(s))
              for d in ("fluid", "solid") for s in ("fluid", "solid")}
    nn.freeze("fluid", "solid")
    nn.freeze("solid", "fluid")
    frozen_before = id_pairs(nn, fluid, solid, nn.reference_neighbours("fluid", "solid"))
    # move the fluid so that the frozen list differs from the current one
    fluid.get("x")[:] += rng.uniform(-0.03, 0.03, fluid.n)
    nn.update()
    frozen_sf = id_pairs(nn, solid, fluid, nn.reference_neighbours("solid", "fluid"))
    ids_before = {name: nn._array(name).get("id").copy() for name in ("fluid", "solid")}
    x_before = fluid.get("x").copy()
    current = {(d, s): id_pairs(nn, nn._array(d), nn._array(s))
               for d in ("fluid", "solid") for s in ("fluid", "solid")}
    assert current != before

    perms = nn.sort()

    # every property moved with its particle
    for name, pa in (("fluid", fluid), ("solid", solid)):
        perm = perms[name]
        assert sorted(perm.tolist()) == list(range(pa.n))
        np.testing.assert_array_equal(pa.get("id"), ids_before[name][perm])
    np.testing.assert_array_equal(fluid.get("x"), x_before[perms["fluid"]])
    assert not np.array_equal(perms["fluid"], np.arange(n_f))
    # particles of one cell are contiguous: the cell order is now the identity
    for name in ("fluid", "solid"):
        np.testing.assert_array_equal(nn._bins[name][1], np.arange(nn._array(name).n))
    # same pairs, rows ascending, lists still match brute force
    for (d, s), pairs in current.items():
        lists = nn.neighbours(d, s)
        assert rows_ascending(*lists)
        assert id_pairs(nn, nn._array(d), nn._array(s)) == pairs
        assert_same_lists(lists, brute_force(nn._array(d), nn._array(s), dim, 3.0, dom))
    # frozen lists describe the same particle pairs, rows ascending
    ref = nn.reference_neighbours("fluid", "solid")
    assert rows_ascending(*ref)
    assert id_pairs(nn, fluid, solid, ref) == frozen_before
    assert id_pairs(nn, solid, fluid, nn.reference_neighbours("solid", "fluid")) == frozen_sf
    assert frozen_before != current[("fluid", "solid")]


def test_sort_on_construction_and_locality():
    rng = np.random.default_rng(9)
    pa = make_array("fluid", 3000, 2, rng, h=0.01)
    ids = pa.get("id").copy()
    nn = NeighbourSearch([pa], 2, 2.0, domain_for((True, True)), sort=True)
    assert not np.array_equal(pa.get("id"), ids)
    assert sorted(pa.get("id").astype(int).tolist()) == list(range(3000))
    # consecutive particles are close: mean jump far below that of random order
    jump = np.hypot(np.diff(pa.get("x")), np.diff(pa.get("y"))).mean()
    assert jump < 0.1
    offsets, nbrs = nn.neighbours("fluid", "fluid")
    # after the sort, the neighbours of i are mostly near i in memory
    rows = np.repeat(np.arange(pa.n), np.diff(offsets))
    assert np.median(np.abs(nbrs - rows)) < 200


def test_sort_rejects_a_frozen_list_of_another_particle_count():
    rng = np.random.default_rng(12)
    pa = make_array("fluid", 100, 2, rng, h=0.05)
    nn = NeighbourSearch([pa], 2, 2.0, sort=False)
    nn.freeze("fluid", "fluid")
    object.__setattr__(pa, "n", 80)
    for p in ("x", "y", "z", "h", "id", "gid"):
        pa.data[p] = pa.data[p][:80].copy()
    with pytest.raises(ValueError, match="particle count change since freeze"):
        nn.sort()


# ----------------------------------------------------------------- Verlet skin
def packed(starts, ends, nbrs):
    """The CSR lists of rows nbrs[starts[i]:ends[i]]."""
    counts = np.asarray(ends, dtype=np.int64) - starts
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int32)
    rows = [nbrs[a:b] for a, b in zip(starts, ends)]
    return offsets, (np.concatenate(rows) if rows else np.zeros(0, np.int32)).astype(np.int32)


def _drift(pa, dim, step, scale):
    """A smooth, particle-dependent motion and a slow growth of h."""
    idx = np.arange(pa.n)
    for a in range(dim):
        pa.get(AXES[a])[:] += scale * (1.0 + np.sin(0.37 * idx + a + 0.1 * step))
    pa.get("h")[:] *= 1.0005


@pytest.mark.parametrize("threads", [1, 2])
@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("periodic", [False, True])
def test_skin_gives_the_exact_lists_and_rebuilds_only_when_needed(dim, periodic, threads,
                                                                   monkeypatch):
    """Lists cut from a skin list equal a fresh exact build (and brute force), entry for
    entry, through motion, growth of h, rebuilds and reuse; two arrays, variable h; one
    list at a time or all at once with thread parts."""
    monkeypatch.setenv("OMP_NUM_THREADS", str(threads))
    rng = np.random.default_rng(40 + dim)
    n = {1: 150, 2: 500, 3: 800}[dim]
    h = {1: 0.02, 2: 0.04, 3: 0.08}[dim]
    dom = domain_for((periodic,) * dim)
    skinned = [make_array(nm, n, dim, rng, h=h, hvar=0.2) for nm in ("f", "w")]
    exact = [ParticleArray(pa.name, **{k: pa.get(k).copy() for k in AXES + ("h", "id")})
             for pa in skinned]
    with_skin = NeighbourSearch(skinned, dim, 2.0, dom, sort=False, skin=0.15)
    fresh = NeighbourSearch(exact, dim, 2.0, dom, sort=False)
    for step in range(30):
        for group in (skinned, exact):
            _drift(group[0], dim, step, 0.001 * h / 0.04)    # only f moves
            group[1].get("h")[:] *= 1.0005
        with_skin.update()
        fresh.update()
        keys = (("f", "f"), ("f", "w"), ("w", "f"))
        if step % 2:      # all three lists in one call, the rows cut by uneven thread parts
            parts = {"f": np.array([0, n // 3, n]), "w": np.array([0, 2 * n // 3, n])}
            together = dict(zip(keys, with_skin.rows_of(keys, parts)))
        for d, s in keys:
            # cut in place, with gaps
            starts, ends, nbrs, pairs = together[(d, s)] if step % 2 else with_skin.rows(d, s)
            assert_same_lists(packed(starts, ends, nbrs), fresh.neighbours(d, s))
            assert pairs == fresh.pair_totals()[(d, s)]
            assert_same_lists(with_skin.neighbours(d, s), fresh.neighbours(d, s))
            assert with_skin.rows(d, s)[3] == pairs
    assert_same_lists(with_skin.neighbours("f", "w"),
                      brute_force(skinned[0], skinned[1], dim, 2.0, dom))
    assert with_skin.skin_distance > 0
    assert 2 <= with_skin.n_builds < with_skin.n_updates // 2    # reused, and rebuilt
    assert fresh.n_builds == fresh.n_updates + 1


@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("periodic", [False, True])
def test_reach_tests_four_at_a_time_give_the_scalar_lists_entry_for_entry(dim, periodic):
    """The AVX2 reach tests (sphgen_simd.h: the build's scan of a cell, the cut of a skin
    row) keep exactly the candidates the scalar loops keep, in the same order: a lattice
    whose spacing is the reach (pairs exactly at the cut-off, where one rounding decides)
    jittered by a few ulps, two sizes of h, rows of every length modulo 4."""
    if not _cell_list.simd_available():
        pytest.skip("this machine has no AVX2: only the scalar loops run")
    rng = np.random.default_rng(7 + dim)
    side = {1: 60, 2: 24, 3: 9}[dim]
    grid = np.stack(np.meshgrid(*[np.arange(side)] * dim, indexing="ij"), -1).reshape(-1, dim)
    dx = 1.0 / side
    n = grid.shape[0]
    props = {AXES[a]: (grid[:, a] + 0.5) * dx * (1.0 + 1e-15 * rng.integers(-3, 4, n))
             if a < dim else np.zeros(n) for a in range(3)}
    scale = {1: 5.0, 2: 2.0, 3: 1.0}[dim]         # the reach 2h: scale dx or 1.5 scale dx
    props["h"] = np.where(rng.random(n) < 0.5, 0.5, 0.75) * scale * dx
    dom = domain_for((periodic,) * dim)
    results = {}
    old = _cell_list.set_simd(True)
    try:
        for simd in (True, False):
            _cell_list.set_simd(simd)
            pa = ParticleArray("f", n=n, **{k: v.copy() for k, v in props.items()})
            nn = NeighbourSearch([pa], dim, 2.0, dom, sort=False, skin=0.3)
            lists = [nn.neighbours("f", "f")]        # the build's scan
            for step in range(3):                    # the cut of the skin rows
                pa.get("x")[:] += 0.02 * dx * np.sin(np.arange(n) + step)
                nn.update()
                lists.append(packed(*nn.rows("f", "f")[:3]))
            assert nn.n_builds == 1
            results[simd] = lists
    finally:
        _cell_list.set_simd(old)
    for got, ref in zip(results[True], results[False]):
        assert_same_lists(got, ref)
    lengths = np.concatenate([np.diff(offsets) for offsets, _ in results[True]])
    assert np.unique(lengths % 4).size == 4 and lengths.max() >= 8


@pytest.mark.parametrize("n", [1, 3, 4, 5, 8, 11])
def test_the_periodic_wraps_look_four_at_a_time_finds_every_value_outside(n):
    """wrap_periodic's AVX2 look (no value outside: nothing to do) misses no value outside
    [lo, hi), at its ends, NaN or inf, in any lane or the tail; both paths leave the
    same values and name the same non-finite index."""
    if not _cell_list.simd_available():
        pytest.skip("this machine has no AVX2: only the scalar loop runs")
    lo, length = -0.5, 2.0
    inside = np.linspace(lo, lo + length, n, endpoint=False) + 0.25 * length / n
    cases = [inside]
    for i in range(n):
        for bad in (lo + length, np.nextafter(lo, -np.inf), lo + 3.7 * length, np.nan, np.inf, -np.inf):
            x = inside.copy()
            x[i] = bad
            cases.append(x)
    old = _cell_list.set_simd(True)
    try:
        for x in cases:
            got = {}
            for simd in (True, False):
                _cell_list.set_simd(simd)
                y = x.copy()
                got[simd] = (_cell_list.wrap_periodic(y, lo, length), y)
            assert got[True][0] == got[False][0]
            np.testing.assert_array_equal(got[True][1], got[False][1])
            finite = np.isfinite(x).all()
            assert (got[True][0] == -1) == finite
            if finite:
                assert ((got[True][1] >= lo) & (got[True][1] < lo + length)).all()
    finally:
        _cell_list.set_simd(old)


@pytest.mark.parametrize("periodic", [False, True])
def test_an_update_checks_the_skin_and_cuts_the_rows_in_one_call(periodic, monkeypatch):
    """Once an update's lists have been cut, each following update (while the skin lists
    stand) checks the skin and cuts the same lists in one compiled call of a CutPlan read
    once (no cut_rows, no separate skin check); the rows equal a fresh build through
    motion, a rebuild, a replaced coordinate array (the plan is dropped, never used on
    stale memory), and a non-finite position is still named by the rebuild."""
    import sphgen.nnps as nnps_mod
    calls = {"cut": 0, "motion": 0, "plans": 0, "runs": 0}
    real_cut, real_motion = nnps_mod.cut_rows, nnps_mod.largest_motion

    def cut(*args, **kw):
        calls["cut"] += 1
        return real_cut(*args, **kw)

    def motion(*args, **kw):
        calls["motion"] += 1
        return real_motion(*args, **kw)

    class CountedPlan(nnps_mod.CutPlan):
        def __init__(self, *args):
            calls["plans"] += 1

        def run(self, *args):
            calls["runs"] += 1
            return super().run(*args)
    monkeypatch.setattr(nnps_mod, "cut_rows", cut)
    monkeypatch.setattr(nnps_mod, "largest_motion", motion)
    monkeypatch.setattr(nnps_mod, "CutPlan", CountedPlan)
    rng = np.random.default_rng(31)
    dim, h = 2, 0.04
    dom = domain_for((periodic,) * dim)
    skinned = [make_array(nm, 400, dim, rng, h=h, hvar=0.2) for nm in ("f", "w")]
    exact = [ParticleArray(pa.name, **{k: pa.get(k).copy() for k in AXES + ("h", "id")}) for pa in skinned]
    nn = NeighbourSearch(skinned, dim, 2.0, dom, sort=False, skin=0.2)
    fresh = NeighbourSearch(exact, dim, 2.0, dom, sort=False)
    keys = (("f", "f"), ("f", "w"), ("w", "f"))
    parts = {"f": np.array([0, 150, 400]), "w": np.array([0, 300, 400])}

    def check():
        fresh.update()
        for (d, s), (starts, ends, nbrs, pairs) in zip(keys, nn.rows_of(keys, parts)):
            assert_same_lists(packed(starts, ends, nbrs), fresh.neighbours(d, s))
            assert pairs == fresh.pair_totals()[(d, s)]
    nn.update()
    check()                                  # cut the usual way: the plan is made
    assert calls["plans"] == 1
    builds, planned = nn.n_builds, 0
    for step in range(12):
        for group in (skinned, exact):
            _drift(group[0], dim, step, 2e-5)
        calls.update(cut=0, motion=0, runs=0)
        nn.update()
        assert nn.n_builds == builds and calls == {"cut": 0, "motion": 0, "plans": 1, "runs": 1}
        check()
        assert calls["cut"] == 0 and calls["runs"] == 1    # nothing left to cut
        planned += 1
    assert planned == 12
    for group in (skinned, exact):           # beyond the skin: a rebuild, then the usual cut
        group[0].get("x")[3] += nn.skin_distance
    nn.update()
    assert nn.n_builds == builds + 1
    check()
    for pa in (skinned[0], exact[0]):        # new memory for x: the plan is not used on the old
        pa.data["x"] = pa.get("x") + 0.15 * nn.skin_distance
    calls.update(cut=0, motion=0)
    nn.update()
    assert calls["motion"] >= 1
    check()
    skinned[1].get("y")[7] = np.nan
    with pytest.raises(ValueError, match="'w'.*y|y.*'w'"):
        nn.update()


def test_skin_rebuilds_at_once_for_a_large_jump_or_a_new_particle_count():
    rng = np.random.default_rng(9)
    pa = make_array("f", 300, 2, rng, h=0.03)
    nn = NeighbourSearch([pa], 2, 3.0, sort=False, skin=0.2)
    builds = nn.n_builds
    pa.get("x")[:] += 1e-6
    nn.update()
    assert nn.n_builds == builds                   # tiny motion: the lists are reused
    pa.get("x")[0] += 0.5 * nn.skin_distance + 1e-9
    nn.update()
    assert nn.n_builds == builds + 1               # one particle beyond half the skin
    assert_same_lists(nn.neighbours("f", "f"), brute_force(pa, pa, 2, 3.0))
    pa.get("y")[5] = np.nan                        # a non-finite position is never skipped
    with pytest.raises(ValueError, match="y"):
        nn.update()
    with pytest.raises(ValueError, match="skin"):
        NeighbourSearch([pa], 2, 3.0, skin=-0.1)


@pytest.mark.parametrize("skin", [0.0, 0.2])
def test_neighbour_counts_without_the_lists(skin):
    rng = np.random.default_rng(5)
    f, w = make_array("f", 400, 2, rng, h=0.04, hvar=0.2), make_array("w", 200, 2, rng, h=0.04)
    nn = NeighbourSearch([f, w], 2, 2.0, domain_for((True, False)), sort=False, skin=skin)
    for d, s in (("f", "f"), ("f", "w"), ("w", "f")):
        counts = nn.neighbour_counts(d, s)
        assert counts.dtype == np.int32
        np.testing.assert_array_equal(counts, np.diff(brute_force(nn._array(d), nn._array(s), 2, 2.0,
                                                                  domain_for((True, False)))[0]))


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_largest_motion_matches_numpy_in_every_lane_and_catches_non_finite(dim):
    """The skin check's reduction (four lanes and a remainder in an open box) equals the
    plain maxima, wherever the largest motion sits, and is NaN for a non-finite value."""
    from sphgen.nnps._cell_list import largest_motion
    rng = np.random.default_rng(dim)
    for n in (1, 3, 4, 5, 11, 64):
        for lane in range(n):
            ref = [rng.random(n) for _ in range(dim)]
            x = [r + 1e-3 * rng.standard_normal(n) for r in ref]
            x[-1][lane] += 0.5                          # the largest motion, in this lane
            h_ref = rng.random(n) + 1.0
            h = h_ref.copy()
            h[(lane + 1) % n] += 0.25
            m2, mh = largest_motion(x, ref, h, h_ref, [0.0] * dim)
            assert m2 == max(sum((a - b) ** 2 for a, b in zip(x, ref)))
            assert mh == np.abs(h - h_ref).max()
            periodic = largest_motion(x, ref, h, h_ref, [100.0] * dim)
            assert periodic[0] == pytest.approx(m2, rel=1e-12) and periodic[1] == mh
        for bad in (np.nan, np.inf):
            x[0][n - 1] = bad
            assert all(np.isnan(v) for v in largest_motion(x, ref, h, h_ref, [0.0] * dim))


def test_cut_of_many_lists_with_thread_parts_is_repeatable():
    """All lists cut in one call by thread parts cut anywhere (40 layouts, from one row in
    the first part to one in the last): every cut equals the fresh build."""
    rng = np.random.default_rng(5)
    n = 4000
    arrays = [make_array(nm, n, 2, rng, h=0.012, hvar=0.2) for nm in ("f", "w")]
    nn = NeighbourSearch(arrays, 2, 2.0, sort=False, skin=0.2)
    fresh = NeighbourSearch([ParticleArray(pa.name, **{k: pa.get(k).copy() for k in AXES + ("h", "id")})
                             for pa in arrays], 2, 2.0, sort=False)
    keys = (("f", "f"), ("f", "w"), ("w", "f"))
    expected = {k: fresh.neighbours(*k) for k in keys}
    for trial in range(40):
        cut = 1 + trial * (n - 2) // 40
        parts = {"f": np.array([0, cut, n]), "w": np.array([0, n - cut, n])}
        nn._row_cache, nn._points = {}, {}
        for key, (starts, ends, nbrs, pairs) in zip(keys, nn.rows_of(keys, parts)):
            assert_same_lists(packed(starts, ends, nbrs), expected[key])
            assert pairs == int(expected[key][0][-1])


def test_the_cut_gives_the_same_rows_whatever_rows_a_thread_takes_at_a_time():
    """cut_rows' threads take their own part's rows CUT_CLAIM at a time, then what is left
    of the others' parts: the rows and pair counts do not depend on the claim size (1 row,
    a few, a whole part: the static cut) nor on where the parts are cut."""
    from sphgen.nnps._cell_list import set_cut_claim
    rng = np.random.default_rng(77)
    f = make_array("f", 700, 2, rng, h=0.04, hvar=0.2)
    nn = NeighbourSearch([f], 2, 2.0, sort=False, skin=0.2)
    _drift(f, 2, 0, 1e-4)
    nn.update()
    expected = packed(*nn.rows("f", "f")[:3])
    old = set_cut_claim(64)
    try:
        for claim in (1, 7, 64, 1 << 40):
            set_cut_claim(claim)
            for cut in (0, 1, 350, 699, 700):
                nn._row_cache = {}
                nn._points = {}
                starts, ends, nbrs, pairs = nn.rows_of([("f", "f")], {"f": np.array([0, cut, 700])})[0]
                assert_same_lists(packed(starts, ends, nbrs), expected)
                assert pairs == expected[0][-1]
    finally:
        set_cut_claim(old)
