"""Particle layouts: lattices, shapes, wall layers, perturbation.

Every generator returns a tuple of 1-D float arrays, ``(x, y)`` in 2D or ``(x, y, z)`` in 3D
(the wall generators add the unit normals).  Lattices are *cell-centred*: the particle of a
cell of side ``dx`` sits at its centre, so a block of fluid fills its rectangle with volume
``dx**dim`` per particle and touches a wall built by :func:`wall_layers_box` seamlessly.

Counting rule used throughout: an interval of length ``L`` holds ``cells(L, dx) =
floor(L/dx + 1e-9)`` whole cells of width ``dx`` (the 1e-9 absorbs round-off, so
``L = 10*dx`` gives 10); a leftover strip thinner than ``dx`` stays empty.
"""
import itertools
import math

import numpy as np

_TOL = 1e-9


def cells(length, dx):
    """Whole cells of width dx in an interval of the given length: floor(length/dx + 1e-9)."""
    return max(int(math.floor(length / dx + _TOL)), 0)


def _centres(lo, hi, dx, shift=0.5):
    """Cell centres lo + (i + shift) dx, i < cells(hi - lo, dx)."""
    return lo + (np.arange(cells(hi - lo, dx)) + shift) * dx


def _grid(*axes):
    """Tensor product of 1-D coordinate arrays, flattened (first axis slowest)."""
    return tuple(g.ravel() for g in np.meshgrid(*axes, indexing="ij"))


# ------------------------------------------------------------------ lattices
def square_lattice(dx, xmin, xmax, ymin, ymax):
    """Cell-centred square lattice of the rectangle; count cells(xmax-xmin) * cells(ymax-ymin)."""
    return _grid(_centres(xmin, xmax, dx), _centres(ymin, ymax, dx))


def cubic_lattice(dx, xmin, xmax, ymin, ymax, zmin, zmax):
    """Cell-centred cubic lattice of the box; count = product of cells() along x, y, z."""
    return _grid(_centres(xmin, xmax, dx), _centres(ymin, ymax, dx), _centres(zmin, zmax, dx))


def hexagonal_lattice(dx, xmin, xmax, ymin, ymax):
    """Isometric lattice, spacing dx, rows dy = dx*sqrt(3)/2; count cells(W, dx) * cells(H, dy).

    Row j sits at ymin + (j + 1/2) dy; its points at xmin + (i + 1/4) dx (j even) or
    xmin + (i + 3/4) dx (j odd).  Each particle owns an area dx*dy (use it for the mass).
    """
    dy = dx * math.sqrt(3.0) / 2.0
    ys = _centres(ymin, ymax, dy)
    xs = _centres(xmin, xmax, dx, shift=0.25)
    x = xs[None, :] + 0.5 * dx * (np.arange(ys.size) % 2)[:, None]
    return x.ravel(), np.repeat(ys, xs.size)


def bcc_lattice(dx, xmin, xmax, ymin, ymax, zmin, zmax):
    """Body-centred cubic lattice with particle volume dx**3; count 2 * prod(cells(L_i, a)).

    The cube edge is a = 2**(1/3) dx (two particles per cube, so a**3 / 2 = dx**3); corner
    particles sit at lo + (i + 1/4) a and body centres at lo + (i + 3/4) a along each axis.
    The nearest-neighbour distance is a*sqrt(3)/2 = 1.091 dx.
    """
    a = dx * 2.0 ** (1.0 / 3.0)
    lows = ((xmin, xmax), (ymin, ymax), (zmin, zmax))
    corner = _grid(*(_centres(lo, hi, a, 0.25) for lo, hi in lows))
    centre = _grid(*(_centres(lo, hi, a, 0.75) for lo, hi in lows))
    return tuple(np.concatenate(pair) for pair in zip(corner, centre))


# ------------------------------------------------------------------ shapes
def rectangle(xmin, xmax, ymin, ymax, dx, lattice="square"):
    """Rectangle on the 'square' or 'hexagonal' lattice (count rule of that lattice)."""
    makers = {"square": square_lattice, "hexagonal": hexagonal_lattice}
    if lattice not in makers:
        raise ValueError(f"lattice must be one of {sorted(makers)}, got {lattice!r}")
    return makers[lattice](dx, xmin, xmax, ymin, ymax)


def box(xmin, xmax, ymin, ymax, zmin, zmax, dx, lattice="cubic"):
    """Box on the 'cubic' or 'bcc' lattice (count rule of that lattice)."""
    makers = {"cubic": cubic_lattice, "bcc": bcc_lattice}
    if lattice not in makers:
        raise ValueError(f"lattice must be one of {sorted(makers)}, got {lattice!r}")
    return makers[lattice](dx, xmin, xmax, ymin, ymax, zmin, zmax)


def _centred_square(cx, cy, r, dx):
    """Square lattice (cx + (i + 1/2) dx, cy + (j + 1/2) dx), -n <= i, j < n, n = ceil(r/dx)."""
    n = int(math.ceil(r / dx - _TOL))
    offs = (np.arange(-n, n) + 0.5) * dx
    return _grid(cx + offs, cy + offs)


def disk(cx, cy, r, dx):
    """Disk: points of the square lattice (cx + (i+1/2)dx, cy + (j+1/2)dx) with distance <= r."""
    x, y = _centred_square(cx, cy, r, dx)
    keep = (x - cx) ** 2 + (y - cy) ** 2 <= r * r
    return x[keep], y[keep]


def annulus(cx, cy, r_in, r_out, dx):
    """Annulus r_in < distance <= r_out on the lattice of :func:`disk` (disk(r_in) + this = disk(r_out))."""
    x, y = _centred_square(cx, cy, r_out, dx)
    d2 = (x - cx) ** 2 + (y - cy) ** 2
    keep = (d2 > r_in * r_in) & (d2 <= r_out * r_out)
    return x[keep], y[keep]


def ring(cx, cy, r_in, r_out, dx):
    """Concentric circles r_k = r_in + (k+1/2) dx, k < cells(r_out - r_in, dx), of n_k = max(1, round(2 pi r_k/dx)) points.

    Particle k, j sits at angle 2 pi j / n_k; its area is 2 pi r_k dx / n_k (about dx**2).
    """
    radii = _centres(r_in, r_out, dx)
    counts = np.maximum(1, np.rint(2.0 * np.pi * radii / dx)).astype(int)
    r = np.repeat(radii, counts)
    theta = 2.0 * np.pi * (np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts))
    theta /= np.repeat(counts, counts)
    return cx + r * np.cos(theta), cy + r * np.sin(theta)


def cylinder(cx, cy, z0, z1, r, dx):
    """Cylinder along z: disk(cx, cy, r, dx) repeated at z0 + (k+1/2) dx, k < cells(z1 - z0, dx)."""
    x, y = disk(cx, cy, r, dx)
    zs = _centres(z0, z1, dx)
    return np.tile(x, zs.size), np.tile(y, zs.size), np.repeat(zs, x.size)


def l_shape(xmin, xmax, ymin, ymax, wx, wy, dx):
    """L: square_lattice of the rectangle minus the points with x > xmin + wx and y > ymin + wy.

    ``wx`` is the width of the vertical leg, ``wy`` the thickness of the horizontal leg; with
    multiples of dx the count is nx*ny - (nx - wx/dx)*(ny - wy/dx).
    """
    return remove_inside(square_lattice(dx, xmin, xmax, ymin, ymax),
                         lambda x, y: (x > xmin + wx) & (y > ymin + wy))


# ------------------------------------------------------------------ vertex lattices
def vertex_lattice(dx, *bounds):
    """Vertices lo + i dx, i = 0..cells(hi - lo, dx), of a box given as (lo, hi) pairs (any
    dimension): particles sit on the box's faces, unlike the cell-centred lattices."""
    axes = [lo + np.arange(cells(hi - lo, dx) + 1) * dx for lo, hi in zip(bounds[::2], bounds[1::2])]
    return _grid(*axes)


def vertex_fractions(points, inside, dx):
    """Fraction of each vertex's cell (side dx, centred on it) inside a body: the share of
    its 2^dim sub-cells whose centres satisfy ``inside`` (exact for unions of boxes aligned
    with the lattice: 1 inside, 1/2 on a face, 1/4 on an edge, 1/8 at a corner, 3/4 on a
    re-entrant edge).  In 2D with a face's in-plane coordinates it gives tributary areas."""
    points = [np.asarray(p, dtype=float) for p in points]
    frac = np.zeros(points[0].size)
    for signs in itertools.product((-0.25, 0.25), repeat=len(points)):
        frac += np.asarray(inside(*[p + s * dx for p, s in zip(points, signs)]), dtype=float)
    return frac / 2 ** len(points)


def l_block(dx, height=10.0, length=6.0, width=3.0, depth=3.0):
    """Vertices of the 3D L-shaped block [0, width] x [0, height] x [0, depth] U
    [width, length] x [0, width] x [0, depth] (the L-block of Ghavamian et al. 2021 sec. 7.2
    with the defaults) and their volumes dx^3 vertex_fractions: (x, y, z, V)."""
    x, y, z = vertex_lattice(dx, 0.0, length, 0.0, height, 0.0, depth)
    inside = inside_l_block(height, length, width, depth)
    keep = inside(x, y, z)
    x, y, z = x[keep], y[keep], z[keep]
    return x, y, z, dx ** 3 * vertex_fractions((x, y, z), inside, dx)


def inside_l_block(height=10.0, length=6.0, width=3.0, depth=3.0):
    """Shape function (x, y, z) -> mask of the closed L-block of :func:`l_block`."""
    tol = 1e-9 * max(height, length)
    return lambda x, y, z: ((x >= -tol) & (y >= -tol) & (z >= -tol) & (z <= depth + tol)
                            & (((x <= width + tol) & (y <= height + tol))
                               | ((x <= length + tol) & (y <= width + tol))))


# ------------------------------------------------------------------ masks
def remove_inside(points, shape_fn):
    """The points where ``shape_fn(*points)`` is False."""
    mask = np.asarray(shape_fn(*points), dtype=bool)
    return tuple(np.asarray(p)[~mask] for p in points)


def keep_inside(points, shape_fn):
    """The points where ``shape_fn(*points)`` is True."""
    mask = np.asarray(shape_fn(*points), dtype=bool)
    return tuple(np.asarray(p)[mask] for p in points)


def inside_rectangle(xmin, xmax, ymin, ymax):
    """Shape function (x, y) -> mask of xmin <= x <= xmax and ymin <= y <= ymax."""
    return lambda x, y, *z: (x >= xmin) & (x <= xmax) & (y >= ymin) & (y <= ymax)


def inside_box(xmin, xmax, ymin, ymax, zmin, zmax):
    """Shape function (x, y, z) -> mask of the closed box."""
    return lambda x, y, z: inside_rectangle(xmin, xmax, ymin, ymax)(x, y) & (z >= zmin) & (z <= zmax)


def inside_disk(cx, cy, r):
    """Shape function (x, y) -> mask of (x-cx)^2 + (y-cy)^2 <= r^2 (a cylinder along z in 3D)."""
    return lambda x, y, *z: (x - cx) ** 2 + (y - cy) ** 2 <= r * r


# ------------------------------------------------------------------ walls
def layers_for_support(kernel_radius_scale, hdx):
    """Wall layers needed to fill the kernel support: ceil(radius_scale * hdx) (a kernel is accepted too)."""
    scale = getattr(kernel_radius_scale, "radius_scale", kernel_radius_scale)
    return int(math.ceil(scale * hdx - _TOL))


def _wall_axis(lo, hi, dx, n_layers, closed_hi=True):
    """Coordinates and inward signs along one axis: n layers below lo, the interior, n above hi."""
    inner = lo + (np.arange(int(math.ceil((hi - lo) / dx - _TOL))) + 0.5) * dx
    k = np.arange(n_layers) + 0.5
    below, above = lo - k[::-1] * dx, (hi + k * dx if closed_hi else np.empty(0))
    coords = np.concatenate([below, inner, above])
    signs = np.concatenate([np.ones(below.size), np.zeros(inner.size), -np.ones(above.size)])
    return coords, signs


def _wall_layers(bounds, dx, n_layers, open_top):
    """Wall lattice around an axis-aligned box: coordinates then unit inward normals."""
    axes = [_wall_axis(lo, hi, dx, n_layers, closed_hi=not (open_top and i == len(bounds) - 1))
            for i, (lo, hi) in enumerate(bounds)]
    coords = _grid(*(c for c, _ in axes))
    signs = np.column_stack(_grid(*(s for _, s in axes)))
    wall = np.any(signs != 0, axis=1)
    normals = signs[wall] / np.linalg.norm(signs[wall], axis=1)[:, None]
    return tuple(c[wall] for c in coords) + tuple(normals.T.copy())


def wall_layers_box(xmin, xmax, ymin, ymax, dx, n_layers, open_top=True):
    """Wall particles (x, y, nx, ny) in n_layers square-lattice layers outside the box.

    Layer k (k = 0 nearest) of each face sits (k + 1/2) dx outside it; along a face the
    particles are at lo + (i + 1/2) dx, i < NX = ceil((xmax-xmin)/dx) (the fluid lattice; a side
    that is no multiple of dx gives one closer pair at the far corner).  Corners are filled.
    Count: n*(NX + 2n) for the bottom (and again for the top unless open_top) plus 2*n*NY for
    the sides, NY = ceil((ymax-ymin)/dx).  Normals are unit and point into the box; in the
    corner blocks they are the normalised diagonal.
    """
    return _wall_layers(((xmin, xmax), (ymin, ymax)), dx, n_layers, open_top)


def wall_layers_box3d(xmin, xmax, ymin, ymax, zmin, zmax, dx, n_layers, open_top=True):
    """3D :func:`wall_layers_box` -> (x, y, z, nx, ny, nz); 'top' is z = zmax, edges and corners filled."""
    return _wall_layers(((xmin, xmax), (ymin, ymax), (zmin, zmax)), dx, n_layers, open_top)


def _curve_normals(x, y, closed):
    """Unit left normals (-t_y, t_x) of a polyline from central-difference tangents."""
    if closed:
        tx, ty = np.roll(x, -1) - np.roll(x, 1), np.roll(y, -1) - np.roll(y, 1)
    else:
        tx, ty = np.gradient(x), np.gradient(y)
    norm = np.hypot(tx, ty)
    return -ty / norm, tx / norm


def _resample(x, y, dx, closed):
    """Points spaced ~dx along a polyline: n = max(1, round(L/dx)) segments; n (closed) or n+1 points."""
    if closed:
        x, y = np.append(x, x[0]), np.append(y, y[0])
    s = np.concatenate([[0.0], np.cumsum(np.hypot(np.diff(x), np.diff(y)))])
    n = max(1, int(np.rint(s[-1] / dx)))
    t = np.arange(n if closed else n + 1) * (s[-1] / n)
    return np.interp(t, s, x), np.interp(t, s, y)


def wall_layers_curve(xc, yc, dx, n_layers, side, closed=True):
    """Wall layers (x, y, nx, ny) parallel to a smooth polyline (the wall surface).

    ``side`` = +1 (or 'left') puts the wall to the left of the direction of travel (inside a
    counter-clockwise circle), -1 ('right') to the right.  Layer k is the curve offset by
    (k + 1/2) dx to that side, resampled with spacing ~dx: max(1, round(L_k/dx)) points if
    closed, one more if open, L_k the length of the offset curve.  The polyline should be
    sampled finer than dx (a repeated closing point is dropped).  Normals point away from the
    wall, i.e. into the fluid.
    """
    sign = {"left": 1, "right": -1, 1: 1, -1: -1}[side]
    xc, yc = np.asarray(xc, dtype=float), np.asarray(yc, dtype=float)
    if closed and np.hypot(xc[-1] - xc[0], yc[-1] - yc[0]) < _TOL * dx:
        xc, yc = xc[:-1], yc[:-1]
    nlx, nly = _curve_normals(xc, yc, closed)
    out = []
    for k in range(n_layers):
        d = sign * (k + 0.5) * dx
        x, y = _resample(xc + d * nlx, yc + d * nly, dx, closed)
        mx, my = _curve_normals(x, y, closed)
        out.append((x, y, -sign * mx, -sign * my))
    return tuple(np.concatenate(c) for c in zip(*out))


# ------------------------------------------------------------------ perturbation
def perturb(points, amplitude, seed=0):
    """New points, each coordinate moved by uniform(-amplitude, amplitude); same seed, same result."""
    rng = np.random.default_rng(seed)
    return tuple(np.asarray(p, dtype=float) + rng.uniform(-amplitude, amplitude, np.size(p))
                 for p in points)
