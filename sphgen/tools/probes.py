"""Post-processing probes: SPH interpolation at points, lines, material points, the dam-break
front, the largest void.

Everything works on plain numpy arrays (from a live run or from output files), with a
vectorised cell search in numpy; fine for probes of a few thousand points on ~1e5 particles.
"""
import itertools

import numpy as np

from sphgen import io
from sphgen.kernels import QuinticSpline


# ------------------------------------------------------------------ neighbours
def pairs_within(points, positions, radius):
    """(i_point, j_particle, r) for every pair closer than radius (cell search, numpy only)."""
    P = np.column_stack([np.asarray(c, dtype=float).ravel() for c in points])
    X = np.column_stack([np.asarray(c, dtype=float).ravel() for c in positions])
    empty = (np.empty(0, int), np.empty(0, int), np.empty(0))
    if P.shape[0] == 0 or X.shape[0] == 0:
        return empty
    lo = X.min(axis=0)
    cell = np.floor((X - lo) / radius).astype(np.int64)
    nc = cell.max(axis=0) + 1
    key = np.ravel_multi_index(cell.T, nc)
    order = np.argsort(key, kind="stable")
    skey = key[order]
    pc = np.clip(np.floor((P - lo) / radius), -2, nc + 1).astype(np.int64)
    I, J = [], []
    for off in itertools.product((-1, 0, 1), repeat=P.shape[1]):
        c = pc + np.asarray(off)
        ok = np.all((c >= 0) & (c < nc), axis=1)
        k = np.ravel_multi_index(c[ok].T, nc)
        start = np.searchsorted(skey, k, "left")
        cnt = np.searchsorted(skey, k, "right") - start
        within = np.arange(cnt.sum()) - np.repeat(np.cumsum(cnt) - cnt, cnt)
        I.append(np.repeat(np.flatnonzero(ok), cnt))
        J.append(order[np.repeat(start, cnt) + within])
    I, J = np.concatenate(I), np.concatenate(J)
    r = np.linalg.norm(P[I] - X[J], axis=1)
    keep = r < radius
    return I[keep], J[keep], r[keep]


def kernel_values(kernel, r, h):
    """W(r, h) for arrays (a numpy formula for the quintic, else the kernel's w elementwise)."""
    r, h = np.broadcast_arrays(np.asarray(r, dtype=float), np.asarray(h, dtype=float))
    if type(kernel) is QuinticSpline:
        q = r / h
        val = sum(c * np.maximum(b - q, 0.0) ** 5 for c, b in ((1.0, 3.0), (-6.0, 2.0), (15.0, 1.0)))
        return kernel.fac / h ** kernel.dim * val
    return np.vectorize(kernel.w, otypes=[float])(r, h)


_COUNTER = {}    # (dim, radius, n) -> (ParticleArray, NeighbourSearch) of the last count


def count_neighbours(positions, radius):
    """Number of particles (itself included) closer than radius to each particle (the
    compiled cell list of :mod:`sphgen.nnps`: a probe called every few steps of a run, so
    the search of the last call is kept and reused for the same count and radius)."""
    from sphgen.nnps import NeighbourSearch
    from sphgen.particles import ParticleArray
    coords = [np.array(c, dtype=float).ravel() for c in positions]
    n = coords[0].size
    if n == 0:
        return np.zeros(0, dtype=np.int64)
    key = (len(coords), float(radius), n)
    held = _COUNTER.get(key)
    if held is None:
        pa = ParticleArray("probe", h=np.full(n, float(radius)), **dict(zip("xyz", coords)))
        held = (pa, NeighbourSearch([pa], len(coords), 1.0, sort=False))
        _COUNTER.clear()
        _COUNTER[key] = held
    else:
        for axis, c in zip("xyz", coords):
            held[0].get(axis)[:] = c
        held[1].update()
    return held[1].neighbour_counts("probe", "probe").astype(np.int64)


# ------------------------------------------------------------------ interpolation
def _parse_shepard(points, x, y, rest):
    dim = len(points)
    if dim not in (2, 3) or len(rest) != dim + 3:
        raise TypeError("use shepard(points, x, y, h, m, rho, values, kernel) in 2D or "
                        "shepard(points, x, y, z, h, m, rho, values, kernel) in 3D "
                        "(the probe points are a tuple of 2 or 3 coordinate arrays)")
    positions = (x, y) + tuple(rest[:dim - 2])
    return positions, rest[dim - 2:]


def shepard(points, x, y, *rest, order=0):
    """Shepard interpolation sum f_b W_ab V_b / sum W_ab V_b at points (order=1: linear MLS).

    Call as ``shepard((px, py), x, y, h, m, rho, values, kernel)`` or, in 3D,
    ``shepard((px, py, pz), x, y, z, h, m, rho, values, kernel)``; h, m, rho may be scalars,
    ``values`` is (n,) or (n, k).  ``W_ab = W(|r_a - r_b|, h_b)``, ``V_b = m_b/rho_b``.  order=0
    reproduces constants exactly; order=1 fits f_b ~ a + g.(r_b - r_a) by least squares with
    weights W_ab V_b and returns a, which reproduces linear fields exactly (falls back to
    order 0 where fewer than dim+1 non-collinear neighbours make the fit singular).  A point
    with no particle within the support gets NaN.
    """
    positions, (h, m, rho, values, kernel) = _parse_shepard(points, x, y, rest)
    npts, n = np.size(points[0]), np.size(x)
    values = np.asarray(values, dtype=float)
    f = values.reshape(n, -1)
    h = np.broadcast_to(np.asarray(h, dtype=float), (n,))
    vol = np.broadcast_to(np.asarray(m, dtype=float) / np.asarray(rho, dtype=float), (n,))
    radius = kernel.radius_scale * h.max()
    i, j, r = pairs_within(points, positions, radius)
    w = kernel_values(kernel, r, h[j]) * vol[j]
    sw = np.bincount(i, w, minlength=npts)
    with np.errstate(invalid="ignore", divide="ignore"):
        out = np.column_stack([np.bincount(i, w * fk[j], minlength=npts) for fk in f.T]) / sw[:, None]
    if order == 1:
        out = _linear_correction(points, positions, i, j, w, f, out, radius)
    elif order != 0:
        raise ValueError(f"order must be 0 or 1, got {order!r}")
    return out.reshape((npts,) + values.shape[1:])


def _linear_correction(points, positions, i, j, w, f, out0, scale):
    """Weighted least-squares fit of a + g.(r_b - r_a) at every point; a where solvable."""
    npts, dim = np.size(points[0]), len(points)
    basis = [np.ones(i.size)] + [(np.asarray(positions[d])[j] - np.asarray(points[d])[i]) / scale
                                 for d in range(dim)]
    M = np.empty((npts, dim + 1, dim + 1))
    for a, b in itertools.product(range(dim + 1), repeat=2):
        M[:, a, b] = np.bincount(i, w * basis[a] * basis[b], minlength=npts)
    rhs = np.stack([np.column_stack([np.bincount(i, w * pa * fk[j], minlength=npts) for fk in f.T])
                    for pa in basis], axis=1)                       # (npts, dim+1, k)
    ok = np.abs(np.linalg.det(M)) > 1e-10 * np.abs(M[:, 0, 0]) ** (dim + 1)
    out = out0.copy()
    if ok.any():
        out[ok] = np.linalg.solve(M[ok], rhs[ok])[:, 0, :]
    return out


def line_probe(p0, p1, n, x, y, *rest, order=0):
    """Shepard values at n equally spaced points from p0 to p1 (ends included) -> (points, values).

    The particle arguments follow :func:`shepard`: ``x, y, h, m, rho, values, kernel`` in 2D
    (p0, p1 of length 2) or ``x, y, z, h, m, rho, values, kernel`` in 3D.
    """
    pts = tuple(np.linspace(a, b, n) for a, b in zip(p0, p1))
    return pts, shepard(pts, x, y, *rest, order=order)


# ------------------------------------------------------------------ output series
def output_series(directory, prefix=None):
    """Iterate (t, {name: ParticleArray}) over the output files of a run, in step order."""
    for path in io.output_files(directory, prefix):
        data = io.load(path)
        yield float(data["solver_data"]["t"]), data["arrays"]


def _prop(pa, name):
    """Property of a ParticleArray or of a mapping, as a numpy array."""
    return np.asarray(pa[name] if isinstance(pa, dict) else pa.get(name))


class MaterialPoints:
    """Particles followed through a run, chosen by persistent id or by nearest initial particle.

    ``MaterialPoints('fluid', gids=[3, 17])`` follows the particles whose ``gid`` property is
    3 and 17.  ``MaterialPoints('fluid', points=(px, py))`` picks, in the first state it sees,
    the particle nearest to each point, and then follows it by ``gid`` (or by index when the
    array has no ``gid``: correct only if the run never reorders particles).
    """

    def __init__(self, array, gids=None, points=None):
        if (gids is None) == (points is None):
            raise ValueError("give exactly one of gids= or points=")
        self.array = array
        self.gids = None if gids is None else np.asarray(gids, dtype=np.int64)
        self.points = None if points is None else np.column_stack(points)
        self.index = None

    def _locate(self, pa):
        has_gid = (pa.has("gid") and "gid" in pa.data) if not isinstance(pa, dict) else "gid" in pa
        if self.gids is None and self.index is None:
            X = np.column_stack([_prop(pa, c) for c in "xyz"[:self.points.shape[1]]])
            d = np.linalg.norm(X[None, :, :] - self.points[:, None, :], axis=-1)
            idx = d.argmin(axis=1)
            if has_gid:
                self.gids = _prop(pa, "gid")[idx].astype(np.int64)
            else:
                self.index = idx
        if self.gids is None:
            return self.index
        if not has_gid:
            raise ValueError(f"array '{self.array}' has no 'gid' property to follow particles by")
        gid = _prop(pa, "gid")
        order = np.argsort(gid)
        pos = np.searchsorted(gid[order], self.gids)
        found = (pos < gid.size) & (gid[order][np.minimum(pos, gid.size - 1)] == self.gids)
        if not found.all():
            raise ValueError(f"gid(s) {self.gids[~found].tolist()} not in array '{self.array}'")
        return order[pos]

    def positions(self, arrays, dim=None):
        """Positions (n_points, dim) of the tracked particles in one state ({name: array} or the array).

        ``dim`` defaults to that of the points, else 3 if the array has a non-zero z, else 2.
        """
        pa = arrays[self.array] if isinstance(arrays, dict) and self.array in arrays else arrays
        idx = self._locate(pa)
        if dim is None and self.points is not None:
            dim = self.points.shape[1]
        elif dim is None:
            has_z = ("z" in pa) if isinstance(pa, dict) else ("z" in pa.data)
            dim = 3 if has_z and np.any(_prop(pa, "z") != 0) else 2
        return np.column_stack([_prop(pa, c)[idx] for c in "xyz"[:dim]])

    def track(self, series, dim=None):
        """(t, positions) over an output folder or an iterable of (t, arrays); positions (n_t, n_points, dim)."""
        if isinstance(series, (str, bytes)) or hasattr(series, "__fspath__"):
            series = output_series(series)
        ts, ps = [], []
        for t, arrays in series:
            ts.append(t)
            ps.append(self.positions(arrays, dim))
        return np.array(ts), np.array(ps)


# ------------------------------------------------------------------ dam break
def front_position(x, y, floor_y, dx, neighbour_counts=None, band=2.0, radius=None,
                   min_fraction=0.25):
    """Toe position: the largest x of fluid particles within band*dx of the floor, ejected ones ignored.

    A particle counts as ejected when it has fewer than ``min_fraction`` times the median
    (over all fluid particles) of ``neighbour_counts``; if these are not given they are the
    numbers of fluid particles (itself included) within ``radius`` (default 2.5 dx: 21 in the
    bulk of a square lattice), computed from x, y alone, so the front can be recomputed from
    output files.  The default fraction is a quarter: the tip of a wedge-shaped toe has about a
    quarter of the bulk count, so half the median would drop genuine toe particles, while
    droplets of up to 5 particles fall below it.  Returns NaN when no particle qualifies.
    """
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if x.size == 0:
        return float("nan")
    if neighbour_counts is None:
        neighbour_counts = count_neighbours((x, y), 2.5 * dx if radius is None else radius)
    counts = np.asarray(neighbour_counts, dtype=float)
    keep = (y - floor_y <= band * dx) & (counts >= min_fraction * np.median(counts))
    return float(x[keep].max()) if keep.any() else float("nan")


# ------------------------------------------------------------------ voids
def nearest_distance(points, positions, radius):
    """Distance from each point to its nearest particle (the search radius starts at
    ``radius`` and doubles for the points that found nobody); inf without particles."""
    P = [np.asarray(c, dtype=float).ravel() for c in points]
    npts = P[0].size
    d = np.full(npts, np.inf)
    if npts == 0 or np.size(positions[0]) == 0:
        return d
    pending = np.arange(npts)
    r = float(radius)
    extent = max(float(np.ptp(np.concatenate([P[k], np.asarray(positions[k], float).ravel()])))
                 for k in range(len(P)))
    while pending.size:
        i, _, rr = pairs_within(tuple(p[pending] for p in P), positions, r)
        best = np.full(pending.size, np.inf)
        np.minimum.at(best, i, rr)
        found = np.isfinite(best)
        d[pending[found]] = best[found]
        pending = pending[~found]
        if r > 2.0 * extent + radius:
            break
        r *= 2.0
    return d


def largest_empty_disc(positions, bounds, spacing=None, refine=8):
    """Radius of the largest disc (sphere in 3D) with its centre inside ``bounds`` =
    (xmin, xmax, ymin, ymax[, zmin, zmax]) that holds no particle: the size of a void.

    Candidate centres on a grid of ``spacing``/4 (default spacing: the mean particle
    spacing (volume / N)^(1/dim)); the best ``refine`` of them are improved by a compass
    search (step halved down to 1e-3 spacing) towards the local maximum of the distance
    to the nearest particle.  On a square lattice of spacing dx the result is dx/sqrt(2)
    (the centre of a cell); with a k x k block of particles removed (k odd), (k + 1)/2 dx.
    Pass the walls too, so that a void against a wall is bounded by them.
    """
    X = [np.asarray(c, dtype=float).ravel() for c in positions]
    dim = len(X)
    lo = np.array(bounds[0::2], dtype=float)
    hi = np.array(bounds[1::2], dtype=float)
    if len(lo) != dim or np.any(hi <= lo):
        raise ValueError(f"bounds {bounds!r} must be (min, max) pairs for {dim} dimensions")
    if X[0].size == 0:
        return float(np.linalg.norm(hi - lo))
    if spacing is None:
        spacing = float(np.prod(hi - lo) / X[0].size) ** (1.0 / dim)
    step = spacing / 4.0
    axes = [np.linspace(a, b, max(2, int(np.ceil((b - a) / step)) + 1)) for a, b in zip(lo, hi)]
    grid = [g.ravel() for g in np.meshgrid(*axes, indexing="ij")]
    d = nearest_distance(grid, X, 2.0 * spacing)
    order = np.argsort(d)[::-1][:refine]
    best = float(d[order[0]])
    dirs = np.array([v for v in itertools.product((-1.0, 0.0, 1.0), repeat=dim) if any(v)])
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    for k in order:
        c = np.array([g[k] for g in grid])
        dc = float(d[k])
        s = step
        while s > 1e-3 * spacing:
            trial = np.clip(c + s * dirs, lo, hi)
            dt = nearest_distance(tuple(trial.T), X, dc + 2.0 * s)
            j = int(np.argmax(dt))
            if dt[j] > dc:
                c, dc = trial[j], float(dt[j])
            else:
                s *= 0.5
        best = max(best, dc)
    return best
