# cython: language_level=3, boundscheck=False, wraparound=False, cdivision=True
# cython: initializedcheck=False, nonecheck=False
"""Cell-linked-list kernels of the neighbour search (compiled, OpenMP).

The Python side (``sphgen.nnps.NeighbourSearch``) chooses the grid; this module does
the per-particle work:

* ``wrap_periodic`` / ``scan``: wrap coordinates into a periodic box; bounds and the
  first non-finite value of an array;
* ``bin_particles``: put every particle in a cell and counting-sort the particles by
  cell.  A bin is ``cell_start`` (CSR over cells), ``cell_index`` (particle indices
  in cell order) and ``pts``, records ``(x, y, z, (k h)**2)`` in cell order (unused
  axes zero) so that the distance loops read contiguous memory;
* ``build_csr``: for every destination particle ``i``, the source particles ``j``
  with ``|r_ij| < k * max(h_i, h_j)`` as int32 CSR lists.  Three steps:

  1. parallel *count pass* over blocks of destination cells: each block scans its
     particles and keeps their rows in a private buffer (so every distance is
     computed once), recording the count of each row;
  2. prefix sum of the counts -> ``offsets``;
  3. parallel *fill pass*: each block copies its rows to ``nbrs[offsets[i]:]``.

* ``remap_csr``: rewrite a CSR list after both arrays were permuted.

Cells are stored in *rank* order: the linear grid index ``ix + nx*(iy + ny*iz)`` is
mapped through ``rank`` (a Morton/Z-order ranking chosen in Python), so particles
binned by rank are in a cache-friendly order and a spatial sort is the
``cell_index`` permutation.  Neighbour cells are visited in ascending rank, so rows of
a sorted source come out ascending; otherwise each row is sorted (insertion sort for
short rows, merging of the per-cell runs for long ones).  Each particle skips the
neighbour cells whose box lies out of its reach (mostly corner cells).

Periodic axes with at least 3 cells use one image shift per neighbour cell (the
minimum image, computed as ``(x_i - x_j) -/+ L`` like the usual formula); an axis
with fewer cells visits every cell once and takes the minimum image pair by pair.
"""
from cython.parallel cimport prange
from libc.math cimport INFINITY, fabs, floor, isfinite, round, sqrt
from libc.stdlib cimport free, malloc, realloc
from libc.string cimport memcpy

import numpy as np

# ---------------------------------------------------------------------- structs

# cells are skipped only if farther than the cut-off by this factor (rounding safety)
cdef double _REACH_MARGIN = 1.000002
# rows up to this length are sorted by insertion, longer ones by merging runs
cdef Py_ssize_t _SHORT_ROW = 48
# A loop over the particles of one array runs on every OpenMP thread in static parts,
# however short it is: thread k then touches about the particles that the passes and
# stages of the generated module give it (their parts are cut by neighbour candidates, a
# few per cent off equal counts), and the data stay in its core's cache.  A
# serial scan was cheaper by itself (a parallel region's start and join cost a few
# microseconds) but pulled the other core's half over, and that core's next write paid
# for it (dam break: the stage after a serial read of x, y, h took 26 us instead of 7).
cdef extern from *:
    """
    #ifdef _OPENMP
    #include <omp.h>
    static int sphgen_max_threads(void) { return omp_get_max_threads(); }
    #else
    static int sphgen_max_threads(void) { return 1; }
    #endif
    """
    int sphgen_max_threads() noexcept nogil
cdef extern from "sphgen_claim.h":
    long sphgen_claim(long* counter, long n) noexcept nogil

cdef extern from "sphgen_simd.h":
    int sphgen_simd_available() noexcept nogil
    long sphgen_cut_open_avx2(const int* nbrs, long k0, long k1, double xi, double yi, double zi,
                              double ri2, const double* pts, int* out, int three_d) noexcept nogil
    long sphgen_scan_cell_avx2(const double* xi, const double* pts, const int* index, long p0,
                               long p1, const double* shift, int* out, int three_d) noexcept nogil
    long sphgen_cut_image_avx2(const int* nbrs, long k0, long k1, double xi, double yi, double zi,
                               double ri2, const double* pts, int* out, int three_d,
                               const double* half, const double* length) noexcept nogil
    int sphgen_outside_avx2(const double* x, long n, double lo, double hi) noexcept nogil

# the reach tests four candidates at a time, and the periodic wrap's look, where the machine
# has AVX2 (sphgen_simd.h)
cdef bint _SIMD_AVAILABLE = sphgen_simd_available()
cdef bint _SIMD = _SIMD_AVAILABLE


def set_simd(bint on):
    """Use the four-at-a-time loops (``sphgen_simd.h``: the reach tests, the periodic
    wrap's look) if ``on`` and the machine has AVX2, the scalar loops otherwise; returns
    the previous setting.  The lists and positions are the same either way (for tests
    and measurements)."""
    global _SIMD
    old = _SIMD
    _SIMD = on and _SIMD_AVAILABLE
    return old


def simd_available():
    """Whether this machine runs the four-at-a-time loops (AVX2)."""
    return bool(_SIMD_AVAILABLE)


# rows of a list a thread of cut_rows takes at a time
cdef Py_ssize_t CUT_CLAIM = 64


def set_cut_claim(Py_ssize_t rows):
    """Set the rows a thread of :func:`cut_rows` takes at a time (at least 1; a huge
    value gives each thread its own part whole, the static cut); returns the previous
    value.  For tests and measurements."""
    global CUT_CLAIM
    old = CUT_CLAIM
    CUT_CLAIM = max(1, rows)
    return old


cdef Py_ssize_t _static_parts(Py_ssize_t n) noexcept nogil:
    """How many parts a per-particle reduction of ``n`` items is cut into: one per thread."""
    cdef Py_ssize_t nt = sphgen_max_threads()
    return max(1, min(nt, n, 64))


ctypedef struct Grid:
    int dim              # number of coordinates that count
    double lo[3]         # lower corner of cell (0, 0, 0)
    double cs[3]         # cell edge along each axis
    double inv_cs[3]     # 1 / cs
    double length[3]     # box length along periodic axes
    double half[3]       # length / 2
    int n[3]             # cells along each axis (1 for unused axes)
    int periodic[3]      # 1 if the axis is periodic
    int all_cells[3]     # periodic axis with < 3 cells: visit every cell, pair image
    int any_all_cells    # some axis has all_cells
    const int* rank      # linear cell index -> storage rank
    const int* unrank    # storage rank -> linear cell index


ctypedef struct Bins:
    const int* start     # cell_start, ncells + 1 entries
    const int* index     # particle index at each cell-order position
    const double* pts    # (x, y, z, (k h)**2) at each cell-order position
    Py_ssize_t n


cdef enum:
    MAX_CELLS = 27       # a cell and its neighbours


ctypedef struct Stencil:
    int nc                       # number of neighbour cells
    int cells[MAX_CELLS]         # their ranks, ascending
    double shift[MAX_CELLS][3]   # image shift added to x_i - x_j for each cell
    int side[MAX_CELLS][3]       # 0: the cell is below on that axis, 2: above,
                                 # 1: same (or cannot prune)
    double corner[3]             # lower corner of the centre cell


ctypedef struct Row:
    int* data            # growable buffer of one block of rows
    Py_ssize_t used
    Py_ssize_t cap
    int* tmp             # scratch for sorting one row
    Py_ssize_t tmp_cap


cdef class RowBuffers:
    """Per-block row buffers of :func:`build_csr`, kept from one call to the next.

    Allocating them anew for every list made each step grow (realloc) and first-touch
    fresh memory in both threads at once; a search keeps one ``RowBuffers`` per
    (dest, src) pair so that, after the first step, the count pass writes into memory
    that is already mapped and large enough."""
    cdef Row* rows
    cdef Py_ssize_t n

    def __cinit__(self):
        self.rows = NULL
        self.n = 0

    cdef int reserve(self, Py_ssize_t nb) except -1:
        """At least ``nb`` buffers, each emptied (capacity kept)."""
        cdef Row* rows
        cdef Py_ssize_t b
        if nb > self.n:
            rows = <Row*>realloc(self.rows, nb * sizeof(Row))
            if rows == NULL:
                raise MemoryError()
            for b in range(self.n, nb):
                rows[b].data = NULL
                rows[b].cap = 0
                rows[b].tmp = NULL
                rows[b].tmp_cap = 0
            self.rows = rows
            self.n = nb
        for b in range(nb):
            self.rows[b].used = 0
        return 0

    def __dealloc__(self):
        cdef Py_ssize_t b
        for b in range(self.n):
            free(self.rows[b].data)
            free(self.rows[b].tmp)
        free(self.rows)


cdef class GridSpec:
    """The cell grid shared by all arrays of one neighbour search.

    ``lo``, ``cs`` (cell edges), ``length`` (periodic box lengths), ``n`` (cells) and
    ``periodic`` are length-3 sequences (unused axes: ``n = 1``); ``rank`` is an
    int32 array of ``prod(n)`` entries, the storage rank of each linear cell index.
    Cell edges are at least the largest cut-off: neighbours are in adjacent cells.
    """
    cdef Grid c
    cdef int[::1] _rank
    cdef int[::1] _unrank
    cdef readonly Py_ssize_t ncells

    def __init__(self, int dim, lo, cs, length, n, periodic, int[::1] rank):
        cdef int a
        cdef Py_ssize_t i
        if dim < 1 or dim > 3:
            raise ValueError(f"dim must be 1, 2 or 3, got {dim}")
        self.c.dim = dim
        self.c.any_all_cells = 0
        self.ncells = 1
        for a in range(3):
            if n[a] < 1 or not (cs[a] > 0.0):
                raise ValueError(f"axis {a}: need n >= 1 and cell size > 0")
            self.c.lo[a] = lo[a]
            self.c.cs[a] = cs[a]
            self.c.inv_cs[a] = 1.0 / cs[a]
            self.c.length[a] = length[a]
            self.c.half[a] = 0.5 * length[a]
            self.c.n[a] = n[a]
            self.c.periodic[a] = 1 if (periodic[a] and a < dim) else 0
            self.c.all_cells[a] = 1 if (self.c.periodic[a] and n[a] < 3) else 0
            self.c.any_all_cells |= self.c.all_cells[a]
            self.ncells *= n[a]
        if rank.shape[0] != self.ncells:
            raise ValueError(f"rank has {rank.shape[0]} entries, the grid {self.ncells} cells")
        self._rank = rank
        self._unrank = np.empty(self.ncells, dtype=np.int32)
        for i in range(self.ncells):
            self._unrank[rank[i]] = <int>i
        self.c.rank = &self._rank[0]
        self.c.unrank = &self._unrank[0]


cdef Bins _bins(int[::1] cell_start, int[::1] cell_index, double[:, ::1] pts) except *:
    """C view of one array's bins (checks the shapes agree)."""
    cdef Bins b
    b.n = cell_index.shape[0]
    if pts.shape[0] != b.n or pts.shape[1] != 4 or cell_start.shape[0] < 2:
        raise ValueError("inconsistent bins: cell_index, pts (n, 4) and cell_start disagree")
    b.start = &cell_start[0]
    b.index = &cell_index[0] if b.n > 0 else NULL
    b.pts = &pts[0, 0] if b.n > 0 else NULL
    return b


cdef const double* _coord_ptr(double[::1] v, Py_ssize_t n) except? NULL:
    """Pointer to the data of a coordinate array of ``n`` values (NULL if empty);
    the caller keeps the array alive."""
    if v.shape[0] != n:
        raise ValueError(f"a coordinate array has {v.shape[0]} values, h has {n}")
    return &v[0] if n > 0 else NULL


cdef inline int* _iptr(int[::1] v) noexcept:
    """Pointer to the first element, NULL for an empty view."""
    return &v[0] if v.shape[0] > 0 else NULL

# ------------------------------------------------------------ scalar helpers

cdef inline int _cell_coord(const Grid* g, int a, double x) noexcept nogil:
    """Cell coordinate of ``x`` along axis ``a``, clamped into the grid.  (Rounding
    may put a particle a hair outside its cell; distances are exact regardless.)"""
    cdef double t
    if a >= g.dim:
        return 0
    t = (x - g.lo[a]) * g.inv_cs[a]
    if not (t >= 0.0):          # also catches NaN
        return 0
    if t >= g.n[a] - 1:
        return g.n[a] - 1
    return <int>t               # truncation is floor for t >= 0


cdef inline double _min_image(const Grid* g, int a, double d) noexcept nogil:
    """Minimum-image separation along a periodic axis (|d| < length on input)."""
    if d > g.half[a]:
        return d - g.length[a]
    if d < -g.half[a]:
        return d + g.length[a]
    return d


cdef int _axis_candidates(const Grid* g, int a, int c, int* out, double* shift,
                          int* side) noexcept nogil:
    """Distinct cell coordinates along axis ``a`` that may hold neighbours of cell
    ``c``; for each, the image shift to add to ``x_i - x_j`` and the side (0 below,
    2 above, 1 same or cannot prune).  Returns the count (at most 3)."""
    cdef int nout = 0, k, q
    cdef double s
    if a >= g.dim:
        out[0] = 0
        shift[0] = 0.0
        side[0] = 1
        return 1
    if g.all_cells[a]:          # pair-by-pair minimum image instead of a shift
        for k in range(g.n[a]):
            out[k] = k
            shift[k] = 0.0
            side[k] = 1
        return g.n[a]
    for k in range(-1, 2):
        q = c + k
        s = 0.0
        if q < 0:
            if not g.periodic[a]:
                continue
            q += g.n[a]
            s = g.length[a]     # the cell's particles are seen at x - L
        elif q >= g.n[a]:
            if not g.periodic[a]:
                continue
            q -= g.n[a]
            s = -g.length[a]    # ... at x + L
        out[nout] = q
        shift[nout] = s
        side[nout] = k + 1
        nout += 1
    return nout


cdef void _swap_cells(Stencil* st, int p, int q) noexcept nogil:
    """Swap entries ``p`` and ``q`` of the stencil (rank, shift, side)."""
    cdef int a, ti
    cdef double td
    ti = st.cells[p]
    st.cells[p] = st.cells[q]
    st.cells[q] = ti
    for a in range(3):
        td = st.shift[p][a]
        st.shift[p][a] = st.shift[q][a]
        st.shift[q][a] = td
        ti = st.side[p][a]
        st.side[p][a] = st.side[q][a]
        st.side[q][a] = ti


cdef void _stencil(const Grid* g, int rank, Stencil* st) noexcept nogil:
    """The (at most 27, distinct) cells around the cell of rank ``rank``, sorted by
    rank, with their image shifts and sides; and the cell's lower corner."""
    cdef int cand[3][3]
    cdef double sh[3][3]
    cdef int sd[3][3]
    cdef int m[3]
    cdef int c[3]
    cdef int a, p, q, r, lin = g.unrank[rank]
    c[0] = lin % g.n[0]
    c[1] = (lin // g.n[0]) % g.n[1]
    c[2] = lin // (g.n[0] * g.n[1])
    for a in range(3):
        m[a] = _axis_candidates(g, a, c[a], cand[a], sh[a], sd[a])
        st.corner[a] = g.lo[a] + c[a] * g.cs[a]
    st.nc = 0
    for r in range(m[2]):
        for q in range(m[1]):
            for p in range(m[0]):
                st.cells[st.nc] = g.rank[cand[0][p] + g.n[0] * (cand[1][q] + g.n[1] * cand[2][r])]
                st.shift[st.nc][0] = sh[0][p]
                st.shift[st.nc][1] = sh[1][q]
                st.shift[st.nc][2] = sh[2][r]
                st.side[st.nc][0] = sd[0][p]
                st.side[st.nc][1] = sd[1][q]
                st.side[st.nc][2] = sd[2][r]
                st.nc += 1
    for p in range(1, st.nc):       # insertion sort by rank (<= 27 cells)
        q = p
        while q > 0 and st.cells[q - 1] > st.cells[q]:
            _swap_cells(st, q - 1, q)
            q -= 1


# ----------------------------------------------------------------- row sorting

cdef Py_ssize_t _run_end(const int* v, Py_ssize_t i, Py_ssize_t n) noexcept nogil:
    """End of the ascending run of ``v`` that starts at ``i``."""
    i += 1
    while i < n and v[i - 1] <= v[i]:
        i += 1
    return i


cdef void _merge(const int* a, Py_ssize_t na, const int* b, Py_ssize_t nb,
                 int* out) noexcept nogil:
    """Merge the ascending ``a`` and ``b`` into ``out``."""
    cdef Py_ssize_t i = 0, j = 0, k = 0
    while i < na and j < nb:
        if b[j] < a[i]:
            out[k] = b[j]
            j += 1
        else:
            out[k] = a[i]
            i += 1
        k += 1
    while i < na:
        out[k] = a[i]
        i += 1
        k += 1
    while j < nb:
        out[k] = b[j]
        j += 1
        k += 1


cdef void _insertion_sort(int* v, Py_ssize_t n) noexcept nogil:
    """O(n + inversions): the fastest for short, nearly sorted rows."""
    cdef Py_ssize_t i, j
    cdef int key
    for i in range(1, n):
        key = v[i]
        j = i - 1
        while j >= 0 and v[j] > key:
            v[j + 1] = v[j]
            j -= 1
        v[j + 1] = key


cdef void _sort_row(int* v, Py_ssize_t n, int* tmp) noexcept nogil:
    """Sort one row ascending; free if already sorted.

    Rows are concatenations of ascending runs (one per cell), nearly sorted when the
    arrays were spatially sorted not long ago.  Short rows: insertion sort.  Long
    rows: a natural merge sort that merges neighbouring runs pass after pass,
    O(n log(runs)).  ``tmp`` has room for ``n`` entries."""
    cdef int* src = v
    cdef int* dst = tmp
    cdef int* swap
    cdef Py_ssize_t i, j, k, runs
    if _run_end(v, 0, n) >= n:
        return
    if n <= _SHORT_ROW:
        _insertion_sort(v, n)
        return
    while True:
        runs = 0
        i = 0
        while i < n:
            j = _run_end(src, i, n)
            k = _run_end(src, j, n) if j < n else n
            _merge(src + i, j - i, src + j, k - j, dst + i)
            runs += 1
            i = k
        swap = src
        src = dst
        dst = swap
        if runs == 1:
            break
    if src != v:
        memcpy(v, src, n * sizeof(int))


# ------------------------------------------------------------ scanning cells

cdef Py_ssize_t _scan_cell(int dim, const double* xi, const Bins* s, int cell,
                           const double* shift, int* out) noexcept nogil:
    """Append to ``out`` the sources of ``cell`` within reach of ``xi`` (a ``pts``
    record), the cell seen through the image ``shift``; returns how many.

    A pair is in reach if ``r2 < max(reach2_i, reach2_j)``, which is exactly
    ``r2 < (k max(h_i, h_j))**2``.  Branch-free: ``out`` must have room for every
    particle of the cell."""
    cdef Py_ssize_t p, cnt = 0
    cdef const double* q
    cdef double dx, dy, dz, r2, rc2
    cdef double x0 = xi[0], y0 = xi[1], z0 = xi[2], ri2 = xi[3]
    cdef double sx = shift[0], sy = shift[1], sz = shift[2]
    if _SIMD:
        return sphgen_scan_cell_avx2(xi, s.pts, s.index, s.start[cell], s.start[cell + 1], shift,
                                     out, dim == 3)
    if dim == 3:
        for p in range(s.start[cell], s.start[cell + 1]):
            q = s.pts + 4 * p
            dx = (x0 - q[0]) + sx
            dy = (y0 - q[1]) + sy
            dz = (z0 - q[2]) + sz
            rc2 = ri2 if ri2 > q[3] else q[3]
            r2 = dx * dx + dy * dy + dz * dz
            out[cnt] = s.index[p]
            cnt += r2 < rc2
    else:                       # 1D and 2D: y is 0 in 1D
        for p in range(s.start[cell], s.start[cell + 1]):
            q = s.pts + 4 * p
            dx = (x0 - q[0]) + sx
            dy = (y0 - q[1]) + sy
            rc2 = ri2 if ri2 > q[3] else q[3]
            r2 = dx * dx + dy * dy
            out[cnt] = s.index[p]
            cnt += r2 < rc2
    return cnt


cdef Py_ssize_t _scan_cell_pair_image(const Grid* g, const double* xi, const Bins* s,
                                      int cell, const double* shift,
                                      int* out) noexcept nogil:
    """``_scan_cell`` for grids with a periodic axis of < 3 cells: the minimum image
    is taken pair by pair on those axes."""
    cdef Py_ssize_t p, cnt = 0
    cdef const double* q
    cdef double d[3]
    cdef double r2, rc2
    cdef int a
    for p in range(s.start[cell], s.start[cell + 1]):
        q = s.pts + 4 * p
        r2 = 0.0
        for a in range(g.dim):
            d[a] = (xi[a] - q[a]) + shift[a]
            if g.all_cells[a]:
                d[a] = _min_image(g, a, d[a])
            r2 = r2 + d[a] * d[a]
        rc2 = xi[3] if xi[3] > q[3] else q[3]
        out[cnt] = s.index[p]
        cnt += r2 < rc2
    return cnt


cdef int _reserve(Row* buf, Py_ssize_t extra) noexcept nogil:
    """Make room for ``extra`` more entries (and a row of ``extra`` in the sorting
    scratch); 0 on success, -1 if out of memory."""
    cdef Py_ssize_t cap
    cdef int* data
    if extra > buf.tmp_cap:
        data = <int*>realloc(buf.tmp, extra * sizeof(int))
        if data == NULL:
            return -1
        buf.tmp = data
        buf.tmp_cap = extra
    if buf.used + extra <= buf.cap:
        return 0
    cap = 2 * buf.cap
    if cap < buf.used + extra:
        cap = buf.used + extra
    data = <int*>realloc(buf.data, cap * sizeof(int))
    if data == NULL:
        return -1
    buf.data = data
    buf.cap = cap
    return 0


cdef void _gaps(const Grid* g, const Stencil* st, const double* xi,
               double gap2[3][3]) noexcept nogil:
    """``gap2[a][side]``: squared distance along axis ``a`` from ``xi`` to the cells
    below (side 0), level with (1: zero) and above (2) the centre cell."""
    cdef int a
    cdef double below, above
    for a in range(3):
        below = xi[a] - st.corner[a]
        above = st.corner[a] + g.cs[a] - xi[a]
        gap2[a][0] = below * below if below > 0.0 else 0.0
        gap2[a][1] = 0.0
        gap2[a][2] = above * above if above > 0.0 else 0.0


cdef int _block_rows(const Grid* g, const Bins* d, const Bins* s, double reach2_s,
                     bint src_in_cell_order, int cell_lo, int cell_hi, int* counts,
                     Row* shared) noexcept nogil:
    """Count pass of one block of destination cells ``[cell_lo, cell_hi)``: the rows
    of its particles (in cell order) go to ``buf``, their lengths to ``counts``.
    ``reach2_s`` is the largest source ``(k h)**2``; if ``src_in_cell_order`` the
    rows come out ascending (cells are visited by rank).  Returns 0, or -1 if out
    of memory.  The block's ``Row`` is worked on in a local copy: the ``Row`` records of
    neighbouring blocks share cache lines, and two threads updating them row by row
    slowed the pass by ~12 % (false sharing)."""
    cdef Stencil st
    cdef double gap2[3][3]
    cdef int c, r, i
    cdef Py_ssize_t p, upper, cnt
    cdef const double* xi
    cdef double reach2
    cdef int* out
    cdef Row local = shared[0]
    cdef Row* buf = &local
    for r in range(cell_lo, cell_hi):
        if d.start[r] == d.start[r + 1]:
            continue
        _stencil(g, r, &st)
        upper = 0
        for c in range(st.nc):
            upper += s.start[st.cells[c] + 1] - s.start[st.cells[c]]
        for p in range(d.start[r], d.start[r + 1]):
            if _reserve(buf, upper) != 0:
                shared[0] = local
                return -1
            xi = d.pts + 4 * p
            reach2 = (xi[3] if xi[3] > reach2_s else reach2_s) * _REACH_MARGIN
            _gaps(g, &st, xi, gap2)
            out = buf.data + buf.used
            cnt = 0
            for c in range(st.nc):
                if (gap2[0][st.side[c][0]] + gap2[1][st.side[c][1]]
                        + gap2[2][st.side[c][2]]) >= reach2:
                    continue        # every point of the cell is out of reach
                if g.any_all_cells:
                    cnt += _scan_cell_pair_image(g, xi, s, st.cells[c], st.shift[c], out + cnt)
                else:
                    cnt += _scan_cell(g.dim, xi, s, st.cells[c], st.shift[c], out + cnt)
            if not src_in_cell_order:
                _sort_row(out, cnt, buf.tmp)
            i = d.index[p]
            counts[i] = <int>cnt
            buf.used += cnt
    shared[0] = local
    return 0


cdef void _block_fill(const Bins* d, int cell_lo, int cell_hi, const int* offsets,
                      const Row* buf, int* nbrs) noexcept nogil:
    """Fill pass of one block: copy its rows from ``buf`` to their CSR place."""
    cdef Py_ssize_t p, pos = 0, cnt
    cdef int i
    for p in range(d.start[cell_lo], d.start[cell_hi]):
        i = d.index[p]
        cnt = offsets[i + 1] - offsets[i]
        if cnt > 0:
            memcpy(nbrs + offsets[i], buf.data + pos, cnt * sizeof(int))
        pos += cnt


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


cdef Py_ssize_t _make_blocks(const Bins* d, Py_ssize_t ncells, Py_ssize_t target,
                             int[::1] bounds):
    """Split the destination cells into consecutive blocks of about ``target``
    particles; ``bounds[b]:bounds[b+1]`` are the cells of block ``b``.  Returns the
    number of blocks (``bounds`` needs ``ncells + 1`` entries)."""
    cdef Py_ssize_t r, nb = 0, acc = 0
    bounds[0] = 0
    for r in range(ncells):
        acc += d.start[r + 1] - d.start[r]
        if acc >= target:
            nb += 1
            bounds[nb] = <int>(r + 1)
            acc = 0
    if bounds[nb] != ncells:
        nb += 1
        bounds[nb] = <int>ncells
    return nb

# ------------------------------------------------------------- Python API


def wrap_periodic(double[::1] x, double lo, double length):
    """Wrap ``x`` in place into ``[lo, lo + length)``.

    Returns the index of the first non-finite value (left unchanged), or -1.  With AVX2,
    a branch-free look first: at most updates no value is outside."""
    cdef Py_ssize_t i, n = x.shape[0]
    cdef double v, hi = lo + length
    if _SIMD and n and not sphgen_outside_avx2(&x[0], n, lo, hi):
        return -1
    for i in range(n):
        v = x[i]
        if not isfinite(v):
            return i
        if v < lo or v >= hi:
            v = v - length * floor((v - lo) / length)
            if v >= hi or v < lo:    # rounding of a value a hair below lo
                v = lo
            x[i] = v
    return -1


cdef void _open_motion_chunk(int dim, const double** x, const double** r, const double* h,
                             const double* h_ref, Py_ssize_t lo, Py_ssize_t hi,
                             double* out) noexcept nogil:
    """:func:`_motion_chunk` without periodic axes, branch-free: four particles per turn
    into four independent maxima (the loop is bound by its dependency chains otherwise);
    a non-finite value is caught once at the end through a running sum, which NaN and
    inf propagate (an overflow of that sum only makes the caller rebuild, which is
    always safe)."""
    cdef Py_ssize_t i, k
    cdef int a
    cdef double m[4]
    cdef double mh[4]
    cdef double d, d2, e, bad = 0.0
    for k in range(4):
        m[k] = 0.0
        mh[k] = 0.0
    i = lo
    while i + 4 <= hi:
        for k in range(4):
            d2 = 0.0
            for a in range(dim):
                d = x[a][i + k] - r[a][i + k]
                d2 = d2 + d * d
            e = fabs(h[i + k] - h_ref[i + k])
            bad = bad + (d2 + e)
            m[k] = d2 if d2 > m[k] else m[k]
            mh[k] = e if e > mh[k] else mh[k]
        i = i + 4
    while i < hi:
        d2 = 0.0
        for a in range(dim):
            d = x[a][i] - r[a][i]
            d2 = d2 + d * d
        e = fabs(h[i] - h_ref[i])
        bad = bad + (d2 + e)
        m[0] = d2 if d2 > m[0] else m[0]
        mh[0] = e if e > mh[0] else mh[0]
        i = i + 1
    if not isfinite(bad):
        out[0] = bad - bad   # NaN
        out[1] = out[0]
        return
    out[0] = max(max(m[0], m[1]), max(m[2], m[3]))
    out[1] = max(max(mh[0], mh[1]), max(mh[2], mh[3]))


cdef void _motion_chunk(int dim, const double** x, const double** r, const double* L,
                        const double* h, const double* h_ref, Py_ssize_t lo, Py_ssize_t hi,
                        double* out) noexcept nogil:
    """out = (largest |x - x_ref|^2, largest |h - h_ref|) over particles lo..hi-1 (NaN if
    a value is not finite)."""
    cdef Py_ssize_t i
    cdef int a
    cdef double d, d2, m2 = 0.0, mh = 0.0
    if not (L[0] > 0.0 or (dim > 1 and L[1] > 0.0) or (dim > 2 and L[2] > 0.0)):
        _open_motion_chunk(dim, x, r, h, h_ref, lo, hi, out)
        return
    for i in range(lo, hi):
        d2 = 0.0
        for a in range(dim):
            d = x[a][i] - r[a][i]
            if L[a] > 0.0:
                d = d - L[a] * round(d / L[a])
            d2 = d2 + d * d
        d = fabs(h[i] - h_ref[i])
        if not (isfinite(d2) and isfinite(d)):
            m2 = d2 + d          # NaN or inf: stop
            mh = m2
            break
        if d2 > m2:
            m2 = d2
        if d > mh:
            mh = d
    out[0] = m2
    out[1] = mh


def largest_motion(list coords, list refs, double[::1] h, double[::1] h_ref, lengths):
    """``(largest |x - x_ref|^2, largest |h - h_ref|)`` over the particles of one array;
    ``lengths[a] > 0`` makes axis ``a`` periodic (minimum image).  NaN for both as soon
    as a value is not finite (the caller then rebuilds, which names it).  Thread k scans
    the k-th of the OpenMP threads' equal parts (about the particles whose positions it
    updates in the stages: a serial scan would pull the other core's half to this one and
    make its next write pay for it); the parts' maxima are compared after."""
    cdef Py_ssize_t n = h.shape[0], c, nchunks
    cdef int a, dim = len(coords)
    cdef const double* x[3]
    cdef const double* r[3]
    cdef double L[3]
    cdef double m2 = 0.0, mh = 0.0
    if h_ref.shape[0] != n or len(refs) != dim or dim > 3:
        raise ValueError("largest_motion: the arrays do not match")
    for a in range(dim):
        x[a] = _coord_ptr(coords[a], n)
        r[a] = _coord_ptr(refs[a], n)
        L[a] = float(lengths[a])
    if n == 0:
        return 0.0, 0.0
    nchunks = _static_parts(n)
    cdef double[:, ::1] part = np.empty((nchunks, 2))
    if nchunks == 1:
        _motion_chunk(dim, x, r, L, &h[0], &h_ref[0], 0, n, &part[0, 0])
    for c in prange(nchunks if nchunks > 1 else 0, nogil=True, schedule="static", num_threads=nchunks):
        _motion_chunk(dim, x, r, L, &h[0], &h_ref[0], n * c // nchunks, n * (c + 1) // nchunks,
                      &part[c, 0])
    for c in range(nchunks):
        if not (isfinite(part[c, 0]) and isfinite(part[c, 1])):
            return float("nan"), float("nan")
        m2 = max(m2, part[c, 0])
        mh = max(mh, part[c, 1])
    return m2, mh


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


def bin_particles(GridSpec grid, list coords, double[::1] h, double radius_scale,
                  double skin=0.0):
    """Bin particles into the grid's cells (stable counting sort).

    ``coords`` holds the x, y, z arrays (entries past ``dim`` are not read).
    Returns ``(cell_start, cell_index, pts)``: the particles of the cell of rank ``r``
    are ``cell_index[cell_start[r]:cell_start[r+1]]`` (ascending) and ``pts[p]`` is
    ``(x, y, z, (k h + skin)**2)`` of particle ``cell_index[p]`` (unused axes 0), with
    ``k`` the radius scale: lists built from these bins hold the pairs closer than
    ``k max(h_i, h_j) + skin``."""
    cdef const Grid* g = &grid.c
    cdef Py_ssize_t n = h.shape[0], ncells = grid.ncells, i, p
    cdef int a, c, lin
    cdef const double* x[3]
    start_arr = np.zeros(ncells + 1, dtype=np.int32)
    index_arr = np.empty(n, dtype=np.int32)
    pts_arr = np.zeros((n, 4), dtype=np.float64)
    cdef int[::1] cell_of = np.empty(n, dtype=np.int32)
    cdef int[::1] cell_start = start_arr
    cdef int[::1] cell_index = index_arr
    cdef int[::1] fill
    cdef double[:, ::1] pts = pts_arr
    for a in range(g.dim):
        x[a] = _coord_ptr(coords[a], n)
    for i in prange(n, nogil=True, schedule="static"):
        lin = 0
        for a in range(g.dim - 1, -1, -1):
            lin = lin * g.n[a] + _cell_coord(g, a, x[a][i])
        cell_of[i] = g.rank[lin]
    for i in range(n):
        cell_start[cell_of[i] + 1] += 1
    for i in range(ncells):
        cell_start[i + 1] += cell_start[i]
    fill = np.empty(ncells, dtype=np.int32)
    for i in range(ncells):
        fill[i] = cell_start[i]
    for i in range(n):
        c = cell_of[i]
        cell_index[fill[c]] = <int>i
        fill[c] += 1
    for p in prange(n, nogil=True, schedule="static"):
        i = cell_index[p]
        for a in range(g.dim):
            pts[p, a] = x[a][i]
        pts[p, 3] = (radius_scale * h[i] + skin) * (radius_scale * h[i] + skin)
    return start_arr, index_arr, pts_arr


def build_csr(GridSpec grid, dest_bins, src_bins, Py_ssize_t block_size=128,
              RowBuffers buffers=None, bint counts_only=False):
    """CSR neighbour lists of every destination particle among the source particles.

    ``dest_bins``/``src_bins`` are ``bin_particles`` results on the same grid;
    ``buffers``, if given, are reused (and kept) as the blocks' scratch rows.
    Returns ``(offsets, nbrs)``, int32, each row ascending; with ``counts_only`` the
    number of neighbours of each destination (int32; the count pass alone, rows
    unsorted)."""
    cdef int[::1] d_start, d_index, s_start, s_index
    cdef double[:, ::1] d_pts, s_pts
    d_start, d_index, d_pts = dest_bins
    s_start, s_index, s_pts = src_bins
    cdef Bins d = _bins(d_start, d_index, d_pts)
    cdef Bins s = _bins(s_start, s_index, s_pts)
    cdef const Grid* g = &grid.c
    cdef Py_ssize_t nd = d.n, ncells = grid.ncells, nb, b
    cdef int[::1] counts = np.zeros(nd, dtype=np.int32)
    offsets_arr = np.empty(nd + 1, dtype=np.int32)
    cdef int[::1] offsets = offsets_arr
    cdef int[::1] bounds = np.empty(ncells + 1, dtype=np.int32)
    cdef int[::1] nbrs
    cdef int* pn
    cdef int* pc = _iptr(counts)
    cdef Row* bufs
    cdef int failed = 0
    cdef double reach2_s = 0.0
    cdef bint in_order = True
    for b in range(s.n):
        if s.pts[4 * b + 3] > reach2_s:
            reach2_s = s.pts[4 * b + 3]
        if s.index[b] != b:
            in_order = False
    if counts_only:
        in_order = True      # no row is kept: its order does not matter
    nb = _make_blocks(&d, ncells, block_size, bounds)
    if buffers is None:
        buffers = RowBuffers()
    buffers.reserve(nb)
    bufs = buffers.rows
    for b in prange(nb, nogil=True, schedule="dynamic"):
        failed += _block_rows(g, &d, &s, reach2_s, in_order, bounds[b], bounds[b + 1], pc, &bufs[b]) != 0
    if failed:
        raise MemoryError("out of memory while building neighbour lists")
    if counts_only:
        return np.asarray(counts)
    _prefix_sum(pc, nd, offsets)
    nbrs_arr = np.empty(offsets[nd], dtype=np.int32)
    nbrs = nbrs_arr
    pn = _iptr(nbrs)
    for b in prange(nb, nogil=True, schedule="static"):
        _block_fill(&d, bounds[b], bounds[b + 1], &offsets[0], &bufs[b], pn)
    return offsets_arr, nbrs_arr


def remap_csr(int[::1] offsets, int[::1] nbrs, int[::1] perm_dest, int[::1] inv_src):
    """Rewrite a CSR list after the arrays were permuted.

    ``perm_dest[new] = old`` for the destination rows, ``inv_src[old] = new`` for the
    source indices.  Returns the new ``(offsets, nbrs)``, rows ascending."""
    cdef Py_ssize_t nd = perm_dest.shape[0], i, p, o, start, cnt
    cdef int failed = 0
    cdef int* tmp
    cdef int[::1] counts = np.empty(nd, dtype=np.int32)
    new_off_arr = np.empty(nd + 1, dtype=np.int32)
    cdef int[::1] new_off = new_off_arr
    cdef int[::1] new_nbrs
    cdef int* pn
    if offsets.shape[0] != nd + 1:
        raise ValueError(f"the list has {offsets.shape[0] - 1} rows, the permutation {nd}")
    for i in prange(nd, nogil=True, schedule="static"):
        counts[i] = offsets[perm_dest[i] + 1] - offsets[perm_dest[i]]
    _prefix_sum(_iptr(counts), nd, new_off)
    new_nbrs_arr = np.empty(new_off[nd], dtype=np.int32)
    new_nbrs = new_nbrs_arr
    pn = _iptr(new_nbrs)
    for i in prange(nd, nogil=True, schedule="static"):
        start = offsets[perm_dest[i]]
        cnt = counts[i]
        o = new_off[i]
        for p in range(cnt):
            pn[o + p] = inv_src[nbrs[start + p]]
        if _run_end(pn + o, 0, cnt) < cnt:
            tmp = <int*>malloc(cnt * sizeof(int))
            if tmp == NULL:
                failed += 1
            else:
                _sort_row(pn + o, cnt, tmp)
                free(tmp)
    if failed:
        raise MemoryError("out of memory while remapping a neighbour list")
    return new_off_arr, new_nbrs_arr


def gather_points(list coords, double[::1] h, double radius_scale, double[:, ::1] out):
    """Fill ``out[i] = (x, y, z, (k h)**2)`` of every particle (0 on axes past ``len(coords)``):
    the source records of :func:`refine_csr`, one cache line per two candidates."""
    cdef Py_ssize_t n = h.shape[0], i
    cdef int a, dim = len(coords)
    cdef const double* x[3]
    if out.shape[0] < n or out.shape[1] != 4:
        raise ValueError("gather_points: out must have (n, 4) entries")
    for a in range(3):
        x[a] = _coord_ptr(coords[a], n) if a < dim else NULL
    if n == 0:
        return out
    cdef double* po = &out[0, 0]
    cdef const double* ph = &h[0]
    # static parts, as the stages that wrote x: each thread gathers its own particles
    for i in prange(n, nogil=True, schedule="static"):
        _record(po, x, ph, i, radius_scale)
    return out


cdef inline void _record(double* out, const double** x, const double* h, Py_ssize_t i,
                         double radius_scale) noexcept nogil:
    """Source record i of :func:`gather_points`: (x, y, z, (k h)**2), 0 on missing axes."""
    cdef int a
    cdef double kh = radius_scale * h[i]
    for a in range(3):
        out[4 * i + a] = x[a][i] if x[a] != NULL else 0.0
    out[4 * i + 3] = kh * kh


cdef inline Py_ssize_t _cut_open(const int* nbrs, Py_ssize_t k0, Py_ssize_t k1, double xi,
                                 double yi, double zi, double ri2, const double* pts,
                                 int* out, bint three_d) noexcept nogil:
    """:func:`_refine_row` where no candidate is across a periodic edge: no per-candidate
    axis tests; in 2D the z terms are 0 - 0 (pts holds 0 there), and adding 0.0 leaves
    the build's sum unchanged."""
    cdef Py_ssize_t k, cnt = 0
    cdef const double* q
    cdef double dx, dy, dz, r2
    if _SIMD:
        return sphgen_cut_open_avx2(nbrs, k0, k1, xi, yi, zi, ri2, pts, out, three_d)
    for k in range(k0, k1):
        q = pts + 4 * nbrs[k]
        dx = xi - q[0]
        dy = yi - q[1]
        dz = zi - q[2]
        r2 = dx * dx + dy * dy + dz * dz
        out[cnt] = nbrs[k]
        cnt = cnt + (r2 < (ri2 if ri2 > q[3] else q[3]))
    return cnt


cdef inline bint _off_the_edges(const Grid* g, double xi, double yi, double zi) noexcept nogil:
    """True if ``(xi, yi, zi)`` lies more than a cell inside every periodic edge (of an
    axis of three cells or more).  No pair of a skin list that is in reach now is then
    across an edge, so the plain difference of the wrapped coordinates is the minimum
    image: such a pair is closer than the cut-off now, which is at most the cut-off plus
    the skin at the build (the skin check bounds the growth of h), at most a cell.  A
    candidate out of reach stays out: the plain difference is never shorter than the
    minimum image."""
    cdef double x[3]
    cdef int a
    x[0] = xi
    x[1] = yi
    x[2] = zi
    for a in range(g.dim):
        if g.periodic[a] and (g.all_cells[a] or not (g.lo[a] + g.cs[a] < x[a] < g.lo[a] + g.length[a] - g.cs[a])):
            return False
    return True


cdef inline Py_ssize_t _refine_row(const Grid* g, bint open_box, Py_ssize_t i, const int* nbrs,
                                   Py_ssize_t k0, Py_ssize_t k1, const double* xd0, const double* xd1,
                                   const double* xd2, double ri2, const double* pts,
                                   int* out) noexcept nogil:
    """Copy to ``out`` the candidates ``nbrs[k0:k1]`` of destination ``i`` in reach now
    (``|r_ij|^2 < max((k h_i)^2, (k h_j)^2)``, the test of :func:`build_csr` term for
    term); returns how many.  The candidates must come from a skin list whose skin still
    covers the motion (rows off the periodic edges skip the minimum image)."""
    cdef Py_ssize_t k, cnt = 0
    cdef const double* q
    cdef double dx, dy, dz, r2, xi, yi, zi, hx, hy, hz, lx, ly, lz
    cdef double half[3]
    if k1 <= k0:      # most rows of a wall list are empty: no loads for them
        return 0
    xi = xd0[i]
    yi = xd1[i] if g.dim >= 2 else 0.0
    zi = xd2[i] if g.dim == 3 else 0.0
    if open_box or _off_the_edges(g, xi, yi, zi):
        return _cut_open(nbrs, k0, k1, xi, yi, zi, ri2, pts, out, g.dim == 3)
    # near a periodic edge: the minimum image on periodic axes (half = inf on the others,
    # so their tests never fire), the z terms 0 in 2D and y, z in 1D as above.  The box is
    # read into locals first: with -fno-strict-aliasing every store to ``out`` would
    # otherwise reload g's fields
    hx = g.half[0] if g.periodic[0] else INFINITY
    hy = g.half[1] if g.periodic[1] else INFINITY
    hz = g.half[2] if g.periodic[2] else INFINITY
    lx = g.length[0]
    ly = g.length[1]
    lz = g.length[2]
    if _SIMD:
        half[0] = hx
        half[1] = hy
        half[2] = hz
        return sphgen_cut_image_avx2(nbrs, k0, k1, xi, yi, zi, ri2, pts, out, g.dim == 3, half,
                                     g.length)
    for k in range(k0, k1):
        q = pts + 4 * nbrs[k]
        dx = xi - q[0]
        if dx > hx:
            dx = dx - lx
        elif dx < -hx:
            dx = dx + lx
        dy = yi - q[1]
        if dy > hy:
            dy = dy - ly
        elif dy < -hy:
            dy = dy + ly
        dz = zi - q[2]
        if dz > hz:
            dz = dz - lz
        elif dz < -hz:
            dz = dz + lz
        r2 = dx * dx + dy * dy + dz * dz
        out[cnt] = nbrs[k]
        cnt = cnt + (r2 < (ri2 if ri2 > q[3] else q[3]))
    return cnt


ctypedef struct CutJob:
    const int* off       # the skin list: offsets and candidates
    const int* nbrs
    const double* xd[3]  # the destination's coordinates now
    const double* h
    const double* pts    # the source's records (gather_points)
    int* out             # the rows, in place: row i is out[off[i]:ends[i]]
    int* ends
    Py_ssize_t nd
    const long* parts    # thread k cuts rows parts[k] .. parts[k+1]-1 (NULL: equal parts)
    const long* given    # the parts as given, and their length (resolved for each run)
    Py_ssize_t ngiven


ctypedef struct GatherJob:
    const double* x[3]
    const double* h
    double* out
    Py_ssize_t n
    const long* parts
    const long* given
    Py_ssize_t ngiven


ctypedef struct MotionJob:
    const double* x[3]   # one array's coordinates and h now ...
    const double* r[3]   # ... and at the build of the skin lists
    const double* h
    const double* h_ref
    Py_ssize_t n
    const long* parts
    const long* given
    Py_ssize_t ngiven


cdef inline Py_ssize_t _cut(const long* parts, Py_ssize_t n, int k, int nt) noexcept nogil:
    """Where thread k's items of n start (k = nt: n): ``parts`` (cut by the generated
    module) or equal counts.  Assigned to a loop variable, never written through a
    pointer: a prange makes private only what its body assigns."""
    if parts != NULL:
        return parts[k]
    return n * k // nt


cdef Py_ssize_t _cut_part(const Grid* g, bint open_box, CutJob* job, Py_ssize_t lo, Py_ssize_t hi,
                          double radius_scale) noexcept nogil:
    """The rows lo..hi-1 of one :func:`cut_rows` list; returns their pairs (counted in a
    local: a shared per-thread slot written per row would bounce between the cores)."""
    cdef Py_ssize_t i, cnt, total = 0
    cdef double kh
    for i in range(lo, hi):
        kh = radius_scale * job.h[i]
        cnt = _refine_row(g, open_box, i, job.nbrs, job.off[i], job.off[i + 1], job.xd[0], job.xd[1],
                          job.xd[2], kh * kh, job.pts, job.out + job.off[i])
        job.ends[i] = <int>(job.off[i] + cnt)
        total += cnt
    return total


cdef const long* _given_parts(object parts, Py_ssize_t* length) except? NULL:
    """The int64 thread parts as given (NULL for None), their length in ``length``."""
    cdef const long[::1] v
    length[0] = 0
    if parts is None:
        return NULL
    v = parts
    length[0] = v.shape[0]
    return &v[0] if v.shape[0] else NULL


cdef inline const long* _parts_for(const long* given, Py_ssize_t ngiven, Py_ssize_t n, int nt) noexcept nogil:
    """The given parts of n items if they cut all of them into nt, else NULL (equal counts)."""
    if given == NULL or ngiven != nt + 1 or given[0] != 0 or given[nt] != n:
        return NULL
    return given


def cut_rows(GridSpec grid, list jobs, list gathers, double radius_scale, list motions=None,
             double skin_distance=0.0, lengths=None):
    """The exact lists (``|r_ij| < k max(h_i, h_j)`` now) of several (dest, src) pairs, cut
    from their lists with a skin, as rows in place; returns the number of pairs of each.

    ``gathers``: ``(coords, h, out, parts)`` per source whose records (:func:`gather_points`)
    are not gathered yet; ``jobs``: ``(offsets, nbrs, dest_coords, dest_h, src_points, out,
    ends, parts)`` per list: the skin list, the destination now, the source's records, and
    where the rows go (row ``i`` is ``out[offsets[i]:ends[i]]``; ``out`` needs ``len(nbrs)``
    entries, ``ends`` one per destination).  Each row keeps its order and equals the row of
    a fresh exact build.  ``parts`` (int64, one more than the threads, or None) say which
    particles thread k handles: the generated module's thread parts, so that each row is
    cut, and each record gathered, by the thread that wrote those particles and walks those
    rows.  Two parallel regions in all (the records, then every list), one Python call.

    ``motions`` (optional): ``(coords, refs, h, h_ref, parts)`` per array of the search,
    its coordinates and ``h`` now and at the build of the skin lists; each thread then also
    measures, in the first region, how far its particles moved, and the lists are cut only
    if no pair can have come within reach since the build (twice the largest displacement
    plus ``radius_scale`` times the largest change of h at most ``skin_distance``;
    ``lengths[a] > 0``: axis ``a`` periodic, minimum image).  Returns None, having cut
    nothing, if some pair can have (or a value is not finite): the lists must be rebuilt.
    The skin check of an update and its cut are then one call (the skin check alone was
    a Python loop and a parallel region per array)."""
    return CutPlan(grid, jobs, gathers, radius_scale, motions, lengths).run(skin_distance)


cdef class CutPlan:
    """The arguments of :func:`cut_rows` read once, :meth:`run` as often as wanted: an update
    of the skin lists cuts the same lists of the same arrays until the next rebuild, and
    reading some fifty arrays' memory anew at each call cost more than the small loops
    they feed (the records, the skin check, the wall lists).  It keeps the arrays alive;
    the caller must drop it when an array is replaced or resized (NeighbourSearch does)."""
    cdef GridSpec grid
    cdef CutJob* cj
    cdef GatherJob* gj
    cdef MotionJob* mj
    cdef Py_ssize_t nj, ng, nm
    cdef double radius_scale
    cdef double L[3]
    cdef list keep             # the argument tuples: the arrays behind the pointers

    def __cinit__(self, GridSpec grid, list jobs, list gathers, double radius_scale, list motions=None,
                  lengths=None):
        cdef const Grid* g = &grid.c
        cdef Py_ssize_t j
        cdef int a
        cdef int[::1] off, nbrs, out, ends
        cdef double[::1] h, h_ref
        cdef double[:, ::1] pts
        self.grid = grid
        self.radius_scale = radius_scale
        self.nj, self.ng = len(jobs), len(gathers)
        self.nm = 0 if motions is None else len(motions)
        self.keep = []
        self.cj = <CutJob*>malloc((self.nj + 1) * sizeof(CutJob))
        self.gj = <GatherJob*>malloc((self.ng + 1) * sizeof(GatherJob))
        self.mj = <MotionJob*>malloc((self.nm + 1) * sizeof(MotionJob))
        if self.cj == NULL or self.gj == NULL or self.mj == NULL:
            raise MemoryError("cut_rows")
        for a in range(3):
            self.L[a] = float(lengths[a]) if lengths is not None and a < len(lengths) else 0.0
        for j in range(self.nm):
            coords, refs, h, h_ref, parts = motions[j]
            self.mj[j].n = h.shape[0]
            if h_ref.shape[0] != self.mj[j].n or len(coords) < g.dim or len(refs) < g.dim:
                raise ValueError("cut_rows: a motion's arrays do not match")
            for a in range(3):
                self.mj[j].x[a] = _coord_ptr(coords[a], self.mj[j].n) if a < g.dim else NULL
                self.mj[j].r[a] = _coord_ptr(refs[a], self.mj[j].n) if a < g.dim else NULL
            self.mj[j].h = &h[0] if self.mj[j].n else NULL
            self.mj[j].h_ref = &h_ref[0] if self.mj[j].n else NULL
            self.mj[j].given = _given_parts(parts, &self.mj[j].ngiven)
            self.keep.append(motions[j])
        for j in range(self.ng):
            coords, h, pts, parts = gathers[j]
            if pts.shape[0] < h.shape[0] or pts.shape[1] != 4:
                raise ValueError("cut_rows: a source's records need (n, 4) entries")
            self.gj[j].n = h.shape[0]
            for a in range(3):
                self.gj[j].x[a] = _coord_ptr(coords[a], self.gj[j].n) if a < len(coords) else NULL
            self.gj[j].h = &h[0] if self.gj[j].n else NULL
            self.gj[j].out = &pts[0, 0] if pts.shape[0] else NULL
            self.gj[j].given = _given_parts(parts, &self.gj[j].ngiven)
            self.keep.append(gathers[j])
        for j in range(self.nj):
            off, nbrs, coords, h, pts, out, ends, parts = jobs[j]
            self.cj[j].nd = h.shape[0]
            if (off.shape[0] != self.cj[j].nd + 1 or out.shape[0] < nbrs.shape[0]
                    or ends.shape[0] < self.cj[j].nd or pts.shape[1] != 4):
                raise ValueError("cut_rows: the list does not fit the arrays")
            self.cj[j].off = _iptr(off)
            self.cj[j].nbrs = _iptr(nbrs)
            for a in range(3):
                self.cj[j].xd[a] = _coord_ptr(coords[a], self.cj[j].nd) if a < g.dim else NULL
            self.cj[j].h = &h[0] if self.cj[j].nd else NULL
            self.cj[j].pts = &pts[0, 0] if pts.shape[0] else NULL
            self.cj[j].out = _iptr(out)
            self.cj[j].ends = _iptr(ends)
            self.cj[j].given = _given_parts(parts, &self.cj[j].ngiven)
            self.keep.append(jobs[j])

    def __dealloc__(self):
        free(self.cj)
        free(self.gj)
        free(self.mj)

    def run(self, double skin_distance=0.0):
        """Cut the lists (with the motions: only if the skin still covers them, else None);
        the number of pairs of each list.  See :func:`cut_rows`."""
        cdef const Grid* g = &self.grid.c
        cdef int nt = max(1, min(sphgen_max_threads(), 64))
        cdef Py_ssize_t nj = self.nj, ng = self.ng, nm = self.nm, j, i, lo, hi, cnt
        cdef CutJob* cj = self.cj
        cdef GatherJob* gj = self.gj
        cdef MotionJob* mj = self.mj
        cdef double radius_scale = self.radius_scale
        cdef double* L = self.L
        cdef int k, o, owner
        cdef double m2 = 0.0, mh = 0.0
        cdef bint open_box = g.dim >= 2 and not (g.periodic[0] or g.periodic[1] or g.periodic[2])
        cdef Py_ssize_t* found = <Py_ssize_t*>malloc((nj * nt + 1) * sizeof(Py_ssize_t))
        # where the unclaimed rows of part k of list j start (one cache line each)
        cdef long* claims = <long*>malloc((8 * nj * nt + 1) * sizeof(long))
        # per thread: largest |dx|^2 and |dh| of its parts (8 doubles apart: no shared line)
        cdef double* moved = <double*>malloc((8 * nt + 2) * sizeof(double))
        try:
            if found == NULL or moved == NULL or claims == NULL:
                raise MemoryError("cut_rows")
            for j in range(nm):
                mj[j].parts = _parts_for(mj[j].given, mj[j].ngiven, mj[j].n, nt)
            for j in range(ng):
                gj[j].parts = _parts_for(gj[j].given, gj[j].ngiven, gj[j].n, nt)
            for j in range(nj):
                cj[j].parts = _parts_for(cj[j].given, cj[j].ngiven, cj[j].nd, nt)
            if ng or nm:
                for k in prange(nt, nogil=True, schedule="static", num_threads=nt):
                    moved[8 * k] = 0.0        # largest |dx|^2
                    moved[8 * k + 1] = 0.0    # largest |dh|
                    moved[8 * k + 2] = 0.0    # count of non-finite results
                    for j in range(nm):
                        lo = _cut(mj[j].parts, mj[j].n, k, nt)
                        hi = _cut(mj[j].parts, mj[j].n, k + 1, nt)
                        if hi > lo:
                            _motion_chunk(g.dim, mj[j].x, mj[j].r, L, mj[j].h, mj[j].h_ref, lo, hi,
                                          &moved[8 * k + 3])
                            moved[8 * k + 2] += (not isfinite(moved[8 * k + 3])) + (not isfinite(moved[8 * k + 4]))
                            moved[8 * k] = max(moved[8 * k], moved[8 * k + 3])
                            moved[8 * k + 1] = max(moved[8 * k + 1], moved[8 * k + 4])
                    for j in range(ng):
                        lo = _cut(gj[j].parts, gj[j].n, k, nt)
                        hi = _cut(gj[j].parts, gj[j].n, k + 1, nt)
                        for i in range(lo, hi):
                            _record(gj[j].out, gj[j].x, gj[j].h, i, radius_scale)
            if nm:
                for k in range(nt):
                    if moved[8 * k + 2] != 0.0:
                        return None
                    m2 = max(m2, moved[8 * k])
                    mh = max(mh, moved[8 * k + 1])
                if not (2.0 * sqrt(m2) + radius_scale * mh <= skin_distance):
                    return None
            # thread k cuts its own part of each list first, CUT_CLAIM rows at a time, then
            # what is left of the others' parts of that list (a slowed core hands over its rest)
            for j in range(nj):
                for k in range(nt):
                    claims[8 * (j * nt + k)] = _cut(cj[j].parts, cj[j].nd, k, nt)
            for k in prange(nt, nogil=True, schedule="static", num_threads=nt):
                for j in range(nj):
                    cnt = 0
                    for o in range(nt):
                        owner = (k + o) % nt
                        hi = _cut(cj[j].parts, cj[j].nd, owner + 1, nt)
                        lo = sphgen_claim(&claims[8 * (j * nt + owner)], CUT_CLAIM)
                        while lo < hi:
                            cnt = cnt + _cut_part(g, open_box, &cj[j], lo, min(lo + CUT_CLAIM, hi),
                                                  radius_scale)
                            lo = sphgen_claim(&claims[8 * (j * nt + owner)], CUT_CLAIM)
                    found[j * nt + k] = cnt
            return [sum(found[j * nt + k] for k in range(nt)) for j in range(nj)]
        finally:
            free(found)
            free(moved)
            free(claims)


def refine_csr(GridSpec grid, int[::1] offsets, int[::1] nbrs, list dest_coords,
               double[::1] dest_h, double[:, ::1] src_points, double radius_scale,
               int[::1] scratch):
    """The exact lists as compact CSR ``(offsets, nbrs)``: :func:`cut_rows` into
    ``scratch`` (``len(nbrs)`` entries), then the rows packed."""
    cdef Py_ssize_t nd = dest_h.shape[0], i
    cdef int[::1] counts = np.empty(nd, dtype=np.int32)
    cut_rows(grid, [(offsets, nbrs, dest_coords, dest_h, src_points, scratch, counts, None)], [], radius_scale)
    for i in range(nd):
        counts[i] -= offsets[i]
    return _compact(offsets, counts, _iptr(scratch), nd)


cdef tuple _compact(int[::1] offsets, int[::1] counts, int* tmp, Py_ssize_t nd):
    """CSR lists of the first counts[i] entries of each row of tmp (rows at offsets)."""
    cdef Py_ssize_t i
    new_off_arr = np.empty(nd + 1, dtype=np.int32)
    cdef int[::1] new_off = new_off_arr
    _prefix_sum(_iptr(counts), nd, new_off)
    new_nbrs_arr = np.empty(new_off[nd], dtype=np.int32)
    cdef int[::1] new_nbrs = new_nbrs_arr
    cdef int* pn = _iptr(new_nbrs)
    for i in prange(nd, nogil=True, schedule="static"):
        if counts[i] > 0:
            memcpy(pn + new_off[i], tmp + offsets[i], counts[i] * sizeof(int))
    return new_off_arr, new_nbrs_arr
