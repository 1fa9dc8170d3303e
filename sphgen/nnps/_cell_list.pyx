# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True
# cython: initializedcheck=False, nonecheck=False
"""Cell-linked-list kernels of the neighbour search (compiled, OpenMP).

The Python side (``sphgen.nnps.NeighbourSearch``) decides the grid; this module does
the per-particle work:

* ``wrap_periodic`` / ``scan``: wrap coordinates into a periodic box, find bounds and
  the first non-finite value;
* ``bin_particles``: assign every particle to a cell and counting-sort the particle
  indices by cell (``cell_start``/``cell_index``, a CSR of cells);
* ``build_csr``: for every destination particle, the source particles closer than
  ``k * max(h_i, h_j)`` (minimum image on periodic axes), as CSR int32 lists, built
  in three steps: a parallel count pass, a prefix sum, a parallel fill pass;
* ``remap_csr``: rewrite a CSR list after both arrays were permuted.

Cells are stored in *rank* order (the grid's linear index ``ix + nx*(iy + ny*iz)``
is mapped through ``rank``, a Morton/Z-order ranking chosen in Python), so particles
binned by rank are in a cache-friendly order, and a spatial sort is simply the
``cell_index`` permutation.  Neighbour cells are visited in ascending rank, so after a
sort the rows come out already ascending; otherwise each row is sorted.
"""
from cython.parallel cimport prange
from libc.math cimport floor, isfinite

import numpy as np

# ---------------------------------------------------------------------- structs

ctypedef struct Grid:
    int dim              # number of coordinates that count
    double lo[3]         # lower corner of cell (0, 0, 0)
    double cs[3]         # cell edge along each axis
    double length[3]     # box length along periodic axes
    double half[3]       # length / 2
    int n[3]             # cells along each axis (1 for unused axes)
    int periodic[3]      # 1 if the axis is periodic (minimum image)
    int all_cells[3]     # periodic axis with < 3 cells: visit every cell once
    const int* rank      # linear cell index -> storage rank


ctypedef struct Points:
    const double* x[3]   # coordinates (unused axes point at x[0], never read)
    const double* h      # smoothing lengths
    Py_ssize_t n


cdef class GridSpec:
    """The cell grid shared by all arrays of one neighbour search.

    Parameters are length-3 sequences (unused axes: ``n = 1``); ``rank`` is an
    int32 array of ``prod(n)`` entries, the storage rank of each linear cell index.
    """
    cdef Grid c
    cdef int[::1] _rank
    cdef readonly Py_ssize_t ncells

    def __init__(self, int dim, lo, cs, length, n, periodic, int[::1] rank):
        cdef int a
        if dim < 1 or dim > 3:
            raise ValueError(f"dim must be 1, 2 or 3, got {dim}")
        self.c.dim = dim
        self.ncells = 1
        for a in range(3):
            self.c.lo[a] = lo[a]
            self.c.cs[a] = cs[a]
            self.c.length[a] = length[a]
            self.c.half[a] = 0.5 * length[a]
            self.c.n[a] = n[a]
            self.c.periodic[a] = 1 if (periodic[a] and a < dim) else 0
            self.c.all_cells[a] = 1 if (self.c.periodic[a] and n[a] < 3) else 0
            if n[a] < 1 or not (cs[a] > 0.0):
                raise ValueError(f"axis {a}: need n >= 1 and cell size > 0")
            self.ncells *= n[a]
        if rank.shape[0] != self.ncells:
            raise ValueError(f"rank has {rank.shape[0]} entries, the grid {self.ncells} cells")
        self._rank = rank
        self.c.rank = &self._rank[0]


cdef Points _points(list coords, double[::1] h) except *:
    """Points view of coordinate arrays (``coords`` has 3 entries) and ``h``."""
    cdef Points p
    cdef double[::1] xa
    cdef int a
    p.n = h.shape[0]
    for a in range(3):
        xa = coords[a]
        if xa.shape[0] != p.n:
            raise ValueError(f"coordinate {a} has {xa.shape[0]} values, h has {p.n}")
        p.x[a] = &xa[0] if p.n > 0 else NULL
    p.h = &h[0] if p.n > 0 else NULL
    return p


cdef inline int* _iptr(int[::1] v) noexcept:
    """Pointer to the first element, NULL for an empty view."""
    return &v[0] if v.shape[0] > 0 else NULL

# ------------------------------------------------------------ scalar helpers

cdef inline int _cell_coord(const Grid* g, int a, double x) noexcept nogil:
    """Cell coordinate of ``x`` along axis ``a``, clamped into the grid."""
    cdef double t
    cdef int c
    if a >= g.dim:
        return 0
    t = floor((x - g.lo[a]) / g.cs[a])
    if not (t >= 0.0):          # also catches NaN
        return 0
    if t >= g.n[a] - 1:
        return g.n[a] - 1
    c = <int>t
    return c


cdef inline double _min_image(const Grid* g, int a, double d) noexcept nogil:
    """Minimum-image separation along a periodic axis (|d| < length on input)."""
    if d > g.half[a]:
        return d - g.length[a]
    if d < -g.half[a]:
        return d + g.length[a]
    return d


cdef int _axis_candidates(const Grid* g, int a, int c, int* out) noexcept nogil:
    """Distinct cell coordinates along axis ``a`` that may hold neighbours of cell ``c``."""
    cdef int m = 0, k, q
    if a >= g.dim:
        out[0] = 0
        return 1
    if g.all_cells[a]:
        for k in range(g.n[a]):
            out[k] = k
        return g.n[a]
    for k in range(-1, 2):
        q = c + k
        if g.periodic[a]:
            if q < 0:
                q += g.n[a]
            elif q >= g.n[a]:
                q -= g.n[a]
        elif q < 0 or q >= g.n[a]:
            continue
        out[m] = q
        m += 1
    return m


cdef void _insertion_sort(int* v, Py_ssize_t n) noexcept nogil:
    cdef Py_ssize_t i, j
    cdef int key
    for i in range(1, n):
        key = v[i]
        j = i - 1
        while j >= 0 and v[j] > key:
            v[j + 1] = v[j]
            j -= 1
        v[j + 1] = key


cdef void _sift_down(int* v, Py_ssize_t root, Py_ssize_t end) noexcept nogil:
    """Restore the max-heap property of ``v[root:end]`` below ``root``."""
    cdef Py_ssize_t child
    cdef int tmp
    while 2 * root + 1 < end:
        child = 2 * root + 1
        if child + 1 < end and v[child] < v[child + 1]:
            child += 1
        if v[root] >= v[child]:
            return
        tmp = v[root]
        v[root] = v[child]
        v[child] = tmp
        root = child


cdef void _heap_sort(int* v, Py_ssize_t n) noexcept nogil:
    cdef Py_ssize_t start, end
    cdef int tmp
    start = n // 2 - 1
    while start >= 0:
        _sift_down(v, start, n)
        start -= 1
    end = n - 1
    while end > 0:
        tmp = v[0]
        v[0] = v[end]
        v[end] = tmp
        _sift_down(v, 0, end)
        end -= 1


cdef void _sort_row(int* v, Py_ssize_t n) noexcept nogil:
    """Sort one row ascending: free if already sorted, O(n log n) worst case."""
    cdef Py_ssize_t i
    for i in range(1, n):
        if v[i] < v[i - 1]:
            break
    else:
        return
    if n <= 32:
        _insertion_sort(v, n)
    else:
        _heap_sort(v, n)


cdef int _neighbour_cells(const Grid* g, const Points* d, Py_ssize_t i,
                          int* cells) noexcept nogil:
    """Storage ranks of the (at most 27, distinct) cells around particle ``i`` of
    ``d``, ascending; returns their number."""
    cdef int cand[3][3]
    cdef int m[3]
    cdef int a, p, q, r, nc = 0
    for a in range(3):
        m[a] = _axis_candidates(g, a, _cell_coord(g, a, d.x[a][i]), cand[a])
    for r in range(m[2]):
        for q in range(m[1]):
            for p in range(m[0]):
                cells[nc] = g.rank[cand[0][p] + g.n[0] * (cand[1][q] + g.n[1] * cand[2][r])]
                nc += 1
    _insertion_sort(cells, nc)
    return nc


cdef Py_ssize_t _scan_row(const Grid* g, const Points* d, const Points* s,
                          const int* cell_start, const int* cell_index,
                          double k, Py_ssize_t i, int* out) noexcept nogil:
    """Neighbours of destination particle ``i`` among the sources.

    Counts them, and writes their indices to ``out`` unless it is NULL."""
    cdef int cells[27]
    cdef int nc, c, a, j
    cdef Py_ssize_t p, count = 0
    cdef double xi[3]
    cdef double hi = d.h[i], hj, dx, r2, rc
    for a in range(g.dim):
        xi[a] = d.x[a][i]
    nc = _neighbour_cells(g, d, i, cells)
    for c in range(nc):
        for p in range(cell_start[cells[c]], cell_start[cells[c] + 1]):
            j = cell_index[p]
            r2 = 0.0
            for a in range(g.dim):
                dx = xi[a] - s.x[a][j]
                if g.periodic[a]:
                    dx = _min_image(g, a, dx)
                r2 = r2 + dx * dx
            hj = s.h[j]
            rc = k * (hi if hi > hj else hj)
            if r2 < rc * rc:
                if out != NULL:
                    out[count] = j
                count = count + 1
    return count


cdef int _prefix_sum(const int* counts, Py_ssize_t n, int[::1] offsets) except -1:
    """offsets[0] = 0, offsets[i+1] = offsets[i] + counts[i]; error on int32 overflow."""
    cdef Py_ssize_t i
    cdef long long total = 0
    offsets[0] = 0
    for i in range(n):
        total += counts[i]
        if total > 2147483647:
            raise OverflowError("more than 2**31-1 neighbour pairs: the int32 CSR cannot "
                                "hold them (reduce the particle count or the support radius)")
        offsets[i + 1] = <int>total
    return 0

# ------------------------------------------------------------- Python API


def wrap_periodic(double[::1] x, double lo, double length):
    """Wrap ``x`` in place into ``[lo, lo + length)``.

    Returns the index of the first non-finite value (left unchanged), or -1."""
    cdef Py_ssize_t i, n = x.shape[0]
    cdef double v, hi = lo + length
    for i in range(n):
        v = x[i]
        if not isfinite(v):
            return i
        if v < lo or v >= hi:
            v = v - length * floor((v - lo) / length)
            if v >= hi:          # rounding of a value just below lo
                v = lo
            elif v < lo:
                v = lo
            x[i] = v
    return -1


def scan(double[::1] x):
    """(min, max, first non-finite index or -1) of ``x`` (min = +inf if empty)."""
    cdef Py_ssize_t i, n = x.shape[0]
    cdef double v, lo = float("inf"), hi = -float("inf")
    for i in range(n):
        v = x[i]
        if not isfinite(v):
            return lo, hi, i
        if v < lo:
            lo = v
        if v > hi:
            hi = v
    return lo, hi, -1


def bin_particles(GridSpec grid, list coords, double[::1] h):
    """Bin particles into the grid's cells (counting sort, stable).

    Returns ``(cell_start, cell_index)``, int32: the particles of the cell of rank
    ``r`` are ``cell_index[cell_start[r]:cell_start[r+1]]``, ascending."""
    cdef Points pts = _points(coords, h)
    cdef const Grid* g = &grid.c
    cdef Py_ssize_t n = pts.n, ncells = grid.ncells, i
    cdef int a, c, lin
    cdef int[::1] cell_of = np.empty(n, dtype=np.int32)
    cdef int[::1] cell_start = np.zeros(ncells + 1, dtype=np.int32)
    cdef int[::1] cell_index = np.empty(n, dtype=np.int32)
    cdef int[::1] fill
    for i in prange(n, nogil=True, schedule="static"):
        lin = 0
        for a in range(2, -1, -1):
            lin = lin * g.n[a] + _cell_coord(g, a, pts.x[a][i])
        cell_of[i] = g.rank[lin]
    for i in range(n):
        cell_start[cell_of[i] + 1] += 1
    for i in range(ncells):
        cell_start[i + 1] += cell_start[i]
    fill = np.array(cell_start[:ncells], dtype=np.int32)
    for i in range(n):
        c = cell_of[i]
        cell_index[fill[c]] = <int>i
        fill[c] += 1
    return np.asarray(cell_start), np.asarray(cell_index)


def build_csr(GridSpec grid, list dest_coords, double[::1] dest_h,
              list src_coords, double[::1] src_h,
              int[::1] cell_start, int[::1] cell_index, double radius_scale):
    """CSR neighbour lists of every destination particle among the source particles.

    ``cell_start``/``cell_index`` are the source's bins from ``bin_particles`` with
    the same grid.  Returns ``(offsets, nbrs)``, int32, each row ascending."""
    cdef Points d = _points(dest_coords, dest_h)
    cdef Points s = _points(src_coords, src_h)
    cdef const Grid* g = &grid.c
    cdef Py_ssize_t nd = d.n, i, cnt
    cdef int[::1] counts = np.empty(nd, dtype=np.int32)
    cdef int[::1] offsets = np.empty(nd + 1, dtype=np.int32)
    cdef int[::1] nbrs
    cdef int* pn
    cdef const int* cst = _iptr(cell_start)
    cdef const int* cix = _iptr(cell_index)
    cdef double k = radius_scale
    if cell_start.shape[0] != grid.ncells + 1 or cell_index.shape[0] != s.n:
        raise ValueError("source bins do not match the grid or the source array")
    for i in prange(nd, nogil=True, schedule="guided"):
        counts[i] = <int>_scan_row(g, &d, &s, cst, cix, k, i, NULL)
    _prefix_sum(_iptr(counts), nd, offsets)
    nbrs = np.empty(offsets[nd], dtype=np.int32)
    pn = _iptr(nbrs)
    for i in prange(nd, nogil=True, schedule="guided"):
        cnt = _scan_row(g, &d, &s, cst, cix, k, i, pn + offsets[i])
        _sort_row(pn + offsets[i], cnt)
    return np.asarray(offsets), np.asarray(nbrs)


def remap_csr(int[::1] offsets, int[::1] nbrs, int[::1] perm_dest, int[::1] inv_src):
    """Rewrite a CSR list after the arrays were permuted.

    ``perm_dest[new] = old`` for the destination rows, ``inv_src[old] = new`` for the
    source indices.  Returns the new ``(offsets, nbrs)``, rows ascending."""
    cdef Py_ssize_t nd = perm_dest.shape[0], i, p, o, start, cnt
    cdef int[::1] counts = np.empty(nd, dtype=np.int32)
    cdef int[::1] new_off = np.empty(nd + 1, dtype=np.int32)
    cdef int[::1] new_nbrs
    cdef int* pn
    if offsets.shape[0] != nd + 1:
        raise ValueError(f"the list has {offsets.shape[0] - 1} rows, the permutation {nd}")
    for i in prange(nd, nogil=True, schedule="static"):
        counts[i] = offsets[perm_dest[i] + 1] - offsets[perm_dest[i]]
    _prefix_sum(_iptr(counts), nd, new_off)
    new_nbrs = np.empty(new_off[nd], dtype=np.int32)
    pn = _iptr(new_nbrs)
    for i in prange(nd, nogil=True, schedule="static"):
        start = offsets[perm_dest[i]]
        cnt = counts[i]
        o = new_off[i]
        for p in range(cnt):
            pn[o + p] = inv_src[nbrs[start + p]]
        _sort_row(pn + o, cnt)
    return np.asarray(new_off), np.asarray(new_nbrs)
