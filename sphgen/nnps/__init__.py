"""Neighbour search: cell-linked lists and CSR neighbour lists (compiled, OpenMP).

``NeighbourSearch(arrays, dim, radius_scale, domain)`` bins all particles of all
arrays into one grid of cells of edge ``radius_scale * max(h)`` and gives, for a
(dest, src) pair of arrays, the CSR lists ``(offsets, nbrs)`` (int32) of the source
particles ``j`` with ``|x_i - x_j| < radius_scale * max(h_i, h_j)``.  Periodic axes
use the minimum-image convention; no ghost particles are ever created.

Typical use in a time loop::

    nnps = NeighbourSearch([fluid, solid], dim=2, radius_scale=3.0, domain=domain)
    for step in ...:
        nnps.update()                      # after the positions moved
        offsets, nbrs = nnps.neighbours("fluid", "solid")

The heavy work is in ``_cell_list.pyx``; this module chooses the grid, validates the
input and caches the lists.
"""
import math

import numpy as np

from ._cell_list import (CutPlan, GridSpec, RowBuffers, bin_particles, build_csr, cut_rows, gather_points,
                          largest_motion, refine_csr, remap_csr, scan, wrap_periodic)

__all__ = ["Domain", "NeighbourSearch", "NotFrozenError"]

_AXES = ("x", "y", "z")
# Cells are a little larger than the cut-off so that floating-point rounding in the
# cell coordinates can never put two neighbours two cells apart.
_CELL_MARGIN = 1.0 + 1e-9


class NotFrozenError(KeyError):
    """``reference_neighbours`` was asked for a pair that was never frozen."""

    def __str__(self):  # KeyError would print the repr of the message
        return str(self.args[0]) if self.args else ""


class Domain:
    """Box [xmin,xmax]x[ymin,ymax]x[zmin,zmax] with per-axis periodicity.

    Only periodic axes use the box: positions are wrapped into ``[lo, hi)`` and
    separations follow the minimum-image convention.  Non-periodic axes are open
    (the cell grid covers the particles, wherever they are).
    """

    def __init__(self, xmin=0., xmax=0., ymin=0., ymax=0., zmin=0., zmax=0.,
                 periodic_in_x=False, periodic_in_y=False, periodic_in_z=False):
        lo = (xmin, ymin, zmin)
        hi = (xmax, ymax, zmax)
        periodic = (bool(periodic_in_x), bool(periodic_in_y), bool(periodic_in_z))
        for a, name in enumerate(_AXES):
            try:
                lo_a, hi_a = float(lo[a]), float(hi[a])
            except (TypeError, ValueError):
                raise ValueError(f"Domain: {name}min/{name}max must be numbers, got "
                                 f"{lo[a]!r}, {hi[a]!r}") from None
            if not (math.isfinite(lo_a) and math.isfinite(hi_a)):
                raise ValueError(f"Domain: {name}min={lo[a]!r}, {name}max={hi[a]!r} must be finite")
            if hi_a < lo_a:
                raise ValueError(f"Domain: {name}max={hi_a} is below {name}min={lo_a}")
            if periodic[a] and not hi_a > lo_a:
                raise ValueError(f"Domain: periodic in {name} needs {name}max > {name}min, got "
                                 f"{name}min={lo_a}, {name}max={hi_a}")
        self.lo = tuple(float(v) for v in lo)
        self.hi = tuple(float(v) for v in hi)
        self.length = tuple(h - l for l, h in zip(self.lo, self.hi))
        self.periodic = periodic

    @property
    def is_periodic(self):
        return any(self.periodic)

    def __repr__(self):
        box = ", ".join(f"{n}=[{l}, {h}]" + (" periodic" if p else "")
                        for n, l, h, p in zip(_AXES, self.lo, self.hi, self.periodic))
        return f"Domain({box})"


def _same_parts(a, b):
    """Whether two {array: thread parts} maps hold the very same arrays."""
    return a.keys() == b.keys() and all(a[k] is b[k] for k in a)


def _morton_rank(n, dim):
    """int32 array: storage rank of each linear cell ``ix + nx*(iy + ny*iz)``, so
    that cells sorted by rank follow the Morton (Z-order) curve."""
    nx, ny, nz = n
    ncells = nx * ny * nz
    lin = np.arange(ncells, dtype=np.int64)
    coords = (lin % nx, (lin // nx) % ny, lin // (nx * ny))
    bits = max(1, int(max(n) - 1).bit_length())
    key = np.zeros(ncells, dtype=np.uint64)
    for b in range(bits):
        for a in range(dim):
            bit = (coords[a] >> b) & 1
            key |= bit.astype(np.uint64) << np.uint64(dim * b + a)
    order = np.argsort(key, kind="stable")
    rank = np.empty(ncells, dtype=np.int32)
    rank[order] = np.arange(ncells, dtype=np.int32)
    return rank


class NeighbourSearch:
    """Cell-linked-list neighbour search over several particle arrays.

    Parameters
    ----------
    arrays : list of ParticleArray
        Distinct names; each needs ``x`` (``y``, ``z`` up to ``dim``) and ``h``.
    dim : int
        1, 2 or 3; only the first ``dim`` coordinates count in distances.
    radius_scale : float
        The kernel support factor k: neighbours have ``|r_ij| < k * max(h_i, h_j)``.
    domain : Domain or None
        Periodic axes, or None (open in every axis).
    sort : bool
        If True, spatially sort the arrays once at construction (:meth:`sort`
        permutes them in place).
    skin : float
        Verlet skin as a fraction of the largest support ``k max(h)`` (0: none).  With
        a skin, the cells and a list of the pairs closer than ``k max(h_i, h_j) + s``
        (``s = skin k max(h)`` at the last rebuild) are kept by :meth:`update` while
        they still hold every pair that can be in reach (twice the largest
        displacement since the rebuild plus ``k`` times the largest change of ``h``
        at most ``s``), and the exact lists are cut from them at each update (one
        scan of the candidates, :func:`refine_csr`).  The lists returned are the same
        either way.

    Notes
    -----
    The cells are built at construction and by :meth:`update`, which takes a copy of
    the positions and ``h``: the lists describe the particles as they were at the
    last update, so call it whenever positions or ``h`` changed.

    Attributes: ``n_updates``, ``n_builds`` (updates that rebuilt the cells),
    ``grid`` (the cell grid), ``cell_size`` and ``n_cells`` (per axis), ``arrays``,
    ``dim``, ``radius_scale``, ``domain``, ``skin``, ``skin_distance`` (``s``),
    ``row_version`` (changes whenever :meth:`rows_of` may hand out other arrays; see
    :meth:`rows_unchanged`).
    """

    def __init__(self, arrays, dim, radius_scale, domain=None, sort=True, skin=0.0):
        arrays = list(arrays)
        if not arrays:
            raise ValueError("NeighbourSearch needs at least one particle array")
        names = [getattr(pa, "name", None) for pa in arrays]
        for pa, name in zip(arrays, names):
            if name is None or not hasattr(pa, "get") or not hasattr(pa, "permute"):
                raise TypeError(f"NeighbourSearch: {pa!r} is not a ParticleArray")
        if len(set(names)) != len(names):
            raise ValueError(f"NeighbourSearch: array names must be distinct, got {names}")
        if dim not in (1, 2, 3):
            raise ValueError(f"NeighbourSearch: dim must be 1, 2 or 3, got {dim!r}")
        radius_scale = float(radius_scale)
        if not (math.isfinite(radius_scale) and radius_scale > 0):
            raise ValueError(f"NeighbourSearch: radius_scale must be positive, got {radius_scale}")
        domain = Domain() if domain is None else domain
        if not isinstance(domain, Domain):
            raise TypeError(f"NeighbourSearch: domain must be a Domain or None, got {domain!r}")
        for a in range(dim, 3):
            if domain.periodic[a]:
                raise ValueError(f"NeighbourSearch: the domain is periodic in {_AXES[a]} but "
                                 f"dim={dim} (only the first {dim} coordinates count)")
        self.arrays = arrays
        self.dim = int(dim)
        self.radius_scale = radius_scale
        self.domain = domain
        skin = float(skin)
        if not (math.isfinite(skin) and skin >= 0):
            raise ValueError(f"NeighbourSearch: skin must be >= 0, got {skin}")
        self.skin = skin
        self.sort_skin = skin    # the skin of the cells that :meth:`sort` orders by
        self.skin_distance = 0.0
        self._periodic_lengths = [domain.length[a] if domain.periodic[a] else 0.0 for a in range(self.dim)]
        self.n_updates = 0
        self.n_builds = 0
        self._built_at = None    # positions and h at the last rebuild (with a skin)
        self._skin_lists = {}    # (dest, src) -> lists with the skin, since the rebuild
        self._scratch = {}       # (dest, src) -> int32 scratch of refine_csr
        self._points = {}        # src -> its gather_points records, since the last update
        self._point_buffers = {}  # src -> the float64 (n, 4) buffer they live in
        self._by_name = dict(zip(names, arrays))
        self._cache = {}
        self._row_cache = {}     # (dest, src) -> (starts, ends, nbrs, pairs) since the update
        self.row_version = 0     # changes whenever rows_of may hand out other arrays
        self._row_buffers = {}   # (dest, src) -> buffers of the cut rows, kept across updates
        self._plan = None        # the cut of every update while the skin lists stand
        self._frozen = {}
        self._rows = {}          # (dest, src) -> RowBuffers kept across updates
        self._bins = {}
        self._sizes = {}
        self._rank_key = None
        self._rank = None
        self.grid = None
        self.cell_size = None    # (3,) cell edge per axis of the current grid
        self.n_cells = None      # (3,) cells per axis of the current grid
        self._build()
        if sort:
            self.sort()

    # ------------------------------------------------------------ lookup
    def _array(self, key):
        """The ParticleArray named ``key`` (or ``key`` itself if it is one of ours)."""
        if isinstance(key, str):
            try:
                return self._by_name[key]
            except KeyError:
                raise KeyError(f"NeighbourSearch has no array '{key}' "
                               f"(arrays: {', '.join(self._by_name)})") from None
        for pa in self.arrays:
            if pa is key:
                return pa
        raise KeyError(f"NeighbourSearch: {key!r} is not one of its arrays "
                       f"({', '.join(self._by_name)})")

    def _coords(self, pa):
        """The ``dim`` coordinate arrays of ``pa``."""
        return [pa.get(_AXES[a]) for a in range(self.dim)]

    # ------------------------------------------------------------ building
    def update(self):
        """Wrap positions into the periodic box (in place, periodic axes only),
        rebuild the cell lists (unless a skin still covers the motion since the last
        rebuild) and drop the cached neighbour lists; with a skin, the rows the last update
        cut are cut anew here, in the same call as the skin check (:meth:`_refresh`)."""
        self.n_updates += 1
        if self._built_at is not None:
            kept = self._refresh()
            if kept is None:          # no refresh planned: the skin check alone
                kept = self._within_skin()
                if kept:
                    self._row_cache = {}
                    self.row_version += 1
                    self._points = {}
            if kept:
                self._cache = {}
                return
        self._build()

    def _refresh(self):
        """The update of the rows cut at the previous update (:meth:`_plan_refresh`), skin
        check included, in one compiled call: True if they are cut anew, False if the
        lists must be rebuilt, None if there is no such plan (or an array's memory or size
        changed since it was made)."""
        plan = self._plan
        if plan is None:
            return None
        for pa, n, arrays in plan["arrays"]:
            if pa.n != n or any(pa.get(p) is not v for p, v in arrays):
                self._plan = None
                return None
        if not self._wrap():
            return False
        pairs = plan["cutter"].run(self.skin_distance)
        if pairs is None:
            return False
        self._points = dict(plan["records"])
        self._row_cache = {key: (kept[1], kept[3], kept[4], int(n)) for (key, kept), n in zip(plan["kept"], pairs)}
        return True

    def _wrap(self):
        """Wrap positions into the periodic box (periodic axes only); False if one is not
        finite (the rebuild names it)."""
        dom = self.domain
        for pa in self.arrays:
            for a in range(self.dim):
                if dom.periodic[a] and pa.n and wrap_periodic(pa.get(_AXES[a]), dom.lo[a], dom.length[a]) >= 0:
                    return False
        return True

    def _within_skin(self):
        """Wrap positions; True if no pair can have come within reach since the rebuild."""
        if any(pa.n != self._sizes[pa.name] for pa in self.arrays) or not self._wrap():
            return False                      # non-finite: the rebuild names it
        moved2, dh = 0.0, 0.0
        for pa in self.arrays:
            if not pa.n:
                continue
            ref = self._built_at[pa.name]
            try:
                m2, mh = largest_motion(self._coords(pa), ref[:-1], pa.get("h"), ref[-1], self._periodic_lengths)
            except (TypeError, ValueError):   # replaced by a wrong array: the rebuild names it
                return False
            if not (math.isfinite(m2) and math.isfinite(mh)):
                return False
            moved2, dh = max(moved2, m2), max(dh, mh)
        return 2.0 * math.sqrt(moved2) + self.radius_scale * dh <= self.skin_distance

    def _build(self):
        dom, dim = self.domain, self.dim
        lo = [math.inf] * 3
        hi = [-math.inf] * 3
        hmax, ntotal = 0.0, 0
        for pa in self.arrays:
            ntotal += pa.n
            for a in range(dim):
                x = self._checked(pa, _AXES[a])
                if dom.periodic[a]:
                    bad = wrap_periodic(x, dom.lo[a], dom.length[a])
                    if bad >= 0:
                        self._non_finite(pa, _AXES[a], bad)
                else:
                    mn, mx, bad = scan(x)
                    if bad >= 0:
                        self._non_finite(pa, _AXES[a], bad)
                    lo[a], hi[a] = min(lo[a], mn), max(hi[a], mx)
            h = self._checked(pa, "h")
            hmn, hmx, bad = scan(h)
            if bad >= 0:
                self._non_finite(pa, "h", bad)
            if pa.n and hmn <= 0.0:
                i = int(np.flatnonzero(h <= 0.0)[0])
                raise ValueError(f"array '{pa.name}': particle {i} has h = {h[i]}; "
                                 "the neighbour search needs h > 0")
            hmax = max(hmax, hmx)
        if ntotal == 0:
            hmax = 1.0
        cutoff = self.radius_scale * hmax
        for a in range(dim):
            if dom.periodic[a] and dom.length[a] < 2.0 * cutoff:
                raise ValueError(
                    f"periodic {_AXES[a]}-length {dom.length[a]} is less than twice the "
                    f"largest cut-off radius_scale*max(h) = {cutoff}: the minimum image is "
                    "not unique (enlarge the box or reduce h)")
        skin = self.skin * cutoff
        for a in range(dim):     # the minimum image must stay unique for the skin too
            if dom.periodic[a]:
                skin = min(skin, max(0.0, 0.5 * dom.length[a] / _CELL_MARGIN - cutoff))
        self.skin_distance = skin
        self._make_grid(lo, hi, (cutoff + skin) * _CELL_MARGIN, ntotal)
        self._bins = {}
        self._sizes = {}
        for pa in self.arrays:
            self._bins[pa.name] = bin_particles(self.grid, self._coords(pa), pa.get("h"),
                                                 self.radius_scale, skin)
            self._sizes[pa.name] = pa.n
        self._cache = {}
        self._row_cache = {}
        self.row_version += 1
        self._points = {}
        self._skin_lists = {}
        self._plan = None
        self.n_builds += 1
        if skin > 0:
            self._built_at = {pa.name: [self._checked(pa, _AXES[a]).copy() for a in range(dim)]
                              + [self._checked(pa, "h").copy()] for pa in self.arrays}
        else:
            self._built_at = None

    def _checked(self, pa, prop):
        """The float64 contiguous array of ``prop`` with ``pa.n`` entries."""
        arr = pa.get(prop)
        if (not isinstance(arr, np.ndarray) or arr.dtype != np.float64 or arr.ndim != 1
                or not arr.flags.c_contiguous or arr.size != pa.n):
            raise ValueError(f"array '{pa.name}': property '{prop}' must be a contiguous "
                             f"float64 array of {pa.n} values for the neighbour search")
        return arr

    @staticmethod
    def _non_finite(pa, prop, i):
        raise ValueError(f"array '{pa.name}': particle {i} has a non-finite {prop} "
                         f"({pa.get(prop)[i]}); the neighbour search needs finite values")

    def _make_grid(self, lo, hi, cell, ntotal):
        """Choose the grid: cells of edge ``>= cell`` (periodic axes: L/n exactly),
        anchored at multiples of the edge on open axes; coarsened if the cells would
        far outnumber the particles (a few particles far away)."""
        dom, dim = self.domain, self.dim
        limit = max(8 * ntotal, 4096)
        while True:
            g_lo, g_cs, g_len, g_n = [0.0] * 3, [1.0] * 3, [0.0] * 3, [1] * 3
            for a in range(dim):
                if dom.periodic[a]:
                    n = max(1, int(dom.length[a] / cell))
                    g_lo[a], g_cs[a], g_len[a], g_n[a] = dom.lo[a], dom.length[a] / n, dom.length[a], n
                elif lo[a] <= hi[a]:
                    start = math.floor(lo[a] / cell) * cell
                    g_lo[a], g_cs[a] = start, cell
                    g_n[a] = int((hi[a] - start) / cell) + 1
            if g_n[0] * g_n[1] * g_n[2] <= limit:
                break
            cell *= 2.0
        key = (tuple(g_n), dim)
        if key != self._rank_key:
            self._rank = _morton_rank(g_n, dim)
            self._rank_key = key
        self.grid = GridSpec(dim, g_lo, g_cs, g_len, g_n,
                             [int(p) for p in dom.periodic], self._rank)
        self.cell_size = tuple(g_cs)
        self.n_cells = tuple(g_n)

    # ------------------------------------------------------------ queries
    def pair_totals(self):
        """{(dest, src): total pairs} of the lists built since the last update (cheap: one
        read per list; the blow-up guard's per-step look)."""
        totals = {key: int(off[-1]) for key, (off, _) in self._cache.items() if len(off) > 1}
        totals.update((key, rows[3]) for key, rows in self._row_cache.items() if len(rows[0]))
        return totals

    def busiest(self):
        """(dest, src, total pairs, particle with most neighbours, its count) over the lists
        built since the last update, one tuple per (dest, src); for the blow-up guard."""
        out = []
        counts = {key: np.diff(off) for key, (off, _) in self._cache.items() if len(off) > 1}
        counts.update((key, rows[1] - rows[0]) for key, rows in self._row_cache.items()
                      if key not in counts and len(rows[0]))
        for (d, s), c in counts.items():
            i = int(np.argmax(c))
            out.append((d, s, int(c.sum()), i, int(c[i])))
        return out

    def neighbours(self, dest, src):
        """``(offsets, nbrs)``: int32 CSR lists; ``nbrs[offsets[i]:offsets[i+1]]`` are
        the indices j of ``src`` (ascending) with ``|r_ij| < k*max(h_i, h_j)``.

        ``dest`` and ``src`` are array names or the arrays.  Computed on first use
        after an update (positions and h as they were at that update) and cached
        until the next one: do not modify the returned arrays."""
        d, s = self._array(dest), self._array(src)
        key = (d.name, s.name)
        lists = self._cache.get(key)
        if lists is None:
            lists = self._built_lists(d, s)
            if self.skin_distance > 0:
                lists = self._refine(d, s, lists)
            self._cache[key] = lists
        return lists

    def _check_sizes(self, *arrays):
        for pa in arrays:
            if pa.n != self._sizes[pa.name]:
                raise RuntimeError(f"array '{pa.name}' has {pa.n} particles but had "
                                   f"{self._sizes[pa.name]} at the last update(): call update()")

    def _built_lists(self, d, s):
        """The lists of the cells as built (with the skin, if any; kept until the rebuild)."""
        key = (d.name, s.name)
        self._check_sizes(d, s)
        lists = self._skin_lists.get(key)
        if lists is None:
            lists = build_csr(self.grid, self._bins[d.name], self._bins[s.name],
                              buffers=self._rows.setdefault(key, RowBuffers()))
            if self.skin_distance > 0:
                self._skin_lists[key] = lists
        return lists

    def neighbour_counts(self, dest, src):
        """The number of neighbours of each particle of ``dest`` among ``src`` (int32), as
        ``np.diff`` of the offsets of :meth:`neighbours` but without building the lists."""
        d, s = self._array(dest), self._array(src)
        if (d.name, s.name) in self._cache or self.skin_distance > 0:
            return np.diff(self.neighbours(d, s)[0])
        self._check_sizes(d, s)
        return build_csr(self.grid, self._bins[d.name], self._bins[s.name], counts_only=True)

    def rows(self, dest, src):
        """``(starts, ends, nbrs, pairs)``: the lists of :meth:`neighbours` as rows
        ``nbrs[starts[i]:ends[i]]`` (int32; ``pairs`` in all), for loops that take a row's
        bounds from two arrays, as the generated passes do.  Without a skin these are views
        of the CSR lists.  With one, the rows are cut in place from the skin lists
        (:func:`cut_rows`): the rows hold the same neighbours in the same order, with
        gaps between them, and cost one parallel scan instead of a scan and a compaction.
        Cached until the next update: do not modify the returned arrays."""
        return self.rows_of([(dest, src)])[0]

    def rows_of(self, pairs, parts=None):
        """:meth:`rows` of every ``(dest, src)`` of ``pairs``; with a skin, those not cut
        since the update are cut together, in one call.  ``parts`` ({array name: int64
        thread parts}, optional) says which particles each thread handles (the generated
        module's parts): each row is then cut by the thread whose pass walks it."""
        keys = [(self._array(d), self._array(s)) for d, s in pairs]
        todo = [(d, s) for d, s in keys if (d.name, s.name) not in self._row_cache]
        if todo:
            self.row_version += 1
            if self.skin_distance <= 0:
                for d, s in todo:
                    off, nbrs = self.neighbours(d, s)
                    self._row_cache[(d.name, s.name)] = (off[:-1], off[1:], nbrs, int(off[-1]))
            else:
                cached = [(d, s) for d, s in todo if (d.name, s.name) in self._cache]
                for d, s in cached:
                    off, nbrs = self._cache[(d.name, s.name)]
                    self._row_cache[(d.name, s.name)] = (off[:-1], off[1:], nbrs, int(off[-1]))
                cut = [(d, s, self._built_lists(d, s)) for d, s in todo if (d.name, s.name) not in self._cache]
                if cut:
                    first = not self._row_cache and not cached
                    self._row_cache.update(self._cut_rows(cut, parts or {}))
                    if first:         # the lists an update needs: cut them at the next ones
                        self._plan_refresh(cut, parts or {})
        elif self._plan is not None and parts is not None and not _same_parts(parts, self._plan["parts"]):
            self._plan_refresh(self._plan["cut"], parts)   # the module cut its parts anew
        return [self._row_cache[(d.name, s.name)] for d, s in keys]

    def rows_unchanged(self, version, parts):
        """True if every row :meth:`rows_of` handed out when :attr:`row_version` was
        ``version`` (and the frozen lists) are still the arrays it would hand out now, cut
        anew in place by the update, along the thread ``parts`` given then: a backend that
        holds those arrays need not look at them again."""
        plan = self._plan
        return version == self.row_version and plan is not None and plan["parts"] is parts

    def _plan_refresh(self, cut, parts):
        """Keep what :func:`cut_rows` needs to check the skin and cut the rows of ``cut``
        ((d, s, lists) triples: the lists of a whole update) at each following update
        until the rebuild: the calls of one update become one."""
        self._plan = None
        if self._built_at is None:
            return
        gathers, records = [], {}
        if any(s.name not in self._points for _, s, _ in cut):
            return                    # records not gathered this update: planned at the next cut
        for d, s, lists in cut:
            if s.name not in records:
                records[s.name] = self._points[s.name]
                gathers.append((self._coords(s), s.get("h"), records[s.name], parts.get(s.name)))
        kept = [((d.name, s.name), self._row_buffers[(d.name, s.name)]) for d, s, _ in cut]
        jobs = [(lists[0], lists[1], self._coords(d), d.get("h"), records[s.name], buf[4], buf[2],
                 parts.get(d.name)) for (d, s, lists), (_, buf) in zip(cut, kept)]
        motions = [(self._coords(pa), ref[:-1], pa.get("h"), ref[-1], parts.get(pa.name))
                   for pa in self.arrays for ref in [self._built_at[pa.name]] if pa.n]
        arrays = [(pa, pa.n, [(p, pa.get(p)) for p in _AXES[:self.dim] + ("h",)]) for pa in self.arrays]
        # the arrays' memory read once for every update until the rebuild
        cutter = CutPlan(self.grid, jobs, gathers, self.radius_scale, motions, self._periodic_lengths)
        self._plan = {"cutter": cutter, "records": records, "kept": kept, "arrays": arrays, "parts": parts,
                      "cut": cut}

    def _cut_rows(self, todo, parts):
        """{(dest, src): rows} cut in place from the skin lists of ``todo`` ((d, s, lists)
        triples) into buffers kept across updates (the same arrays from step to step while
        the skin lists stand, so a backend need not take them again); the sources' records
        not gathered since the update are gathered in the same call."""
        gathers, jobs, kept_of, records = [], [], [], dict(self._points)
        for d, s, lists in todo:
            if s.name not in records:
                buf = self._point_buffers.get(s.name)
                if buf is None or buf.shape[0] < s.n:
                    buf = self._point_buffers[s.name] = np.empty((max(s.n, 1), 4), dtype=np.float64)
                records[s.name] = buf
                gathers.append((self._coords(s), s.get("h"), buf, parts.get(s.name)))
            key = (d.name, s.name)
            kept = self._row_buffers.get(key)
            if kept is None or kept[0] is not lists[0] or kept[2].size < d.n or kept[4].size < lists[1].size:
                ends = kept[2] if kept is not None and kept[2].size >= d.n else np.empty(max(d.n, 1), np.int32)
                out = (kept[4] if kept is not None and kept[4].size >= lists[1].size
                       else np.empty(int(1.25 * lists[1].size) + 16, dtype=np.int32))
                kept = self._row_buffers[key] = (lists[0], lists[0][:-1], ends, ends[:d.n], out)
            jobs.append((lists[0], lists[1], self._coords(d), d.get("h"), records[s.name], kept[4],
                         kept[2], parts.get(d.name)))
            kept_of.append((key, kept))
        pairs = cut_rows(self.grid, jobs, gathers, self.radius_scale)
        self._points = records
        return {key: (kept[1], kept[3], kept[4], int(n)) for (key, kept), n in zip(kept_of, pairs)}

    def _source_points(self, s):
        """The :func:`gather_points` records of source ``s``, gathered once per update."""
        points = self._points.get(s.name)
        if points is None:
            buf = self._point_buffers.get(s.name)
            if buf is None or buf.shape[0] < s.n:
                buf = self._point_buffers[s.name] = np.empty((max(s.n, 1), 4), dtype=np.float64)
            points = self._points[s.name] = gather_points(self._coords(s), s.get("h"), self.radius_scale, buf)
        return points

    def _refine(self, d, s, lists):
        """The exact lists of (d, s) now, cut from ``lists`` (built with the skin)."""
        key = (d.name, s.name)
        scratch = self._scratch.get(key)
        if scratch is None or scratch.size < lists[1].size:
            scratch = self._scratch[key] = np.empty(int(1.25 * lists[1].size) + 16, dtype=np.int32)
        return refine_csr(self.grid, lists[0], lists[1], self._coords(d), d.get("h"),
                          self._source_points(s), self.radius_scale, scratch)

    def freeze(self, dest, src):
        """Keep the current lists of (dest, src) as the fixed reference list (Total
        Lagrangian SPH); they survive update() and are remapped by sort()."""
        d, s = self._array(dest), self._array(src)
        offsets, nbrs = self.neighbours(d, s)
        self._frozen[(d.name, s.name)] = (offsets.copy(), nbrs.copy())
        self.row_version += 1

    def reference_neighbours(self, dest, src):
        """``(offsets, nbrs)`` of the list frozen by :meth:`freeze`."""
        d, s = self._array(dest), self._array(src)
        try:
            return self._frozen[(d.name, s.name)]
        except KeyError:
            frozen = ", ".join(f"{a}<-{b}" for a, b in self._frozen) or "none"
            raise NotFrozenError(
                f"no reference neighbour list for dest '{d.name}', src '{s.name}': call "
                f"freeze('{d.name}', '{s.name}') first (frozen: {frozen})") from None

    def is_frozen(self, dest, src):
        d, s = self._array(dest), self._array(src)
        return (d.name, s.name) in self._frozen

    # ------------------------------------------------------------ sorting
    def sort(self):
        """Spatially sort every array (particles of one cell contiguous, cells in
        Morton order) with ``pa.permute(perm)``, remap the frozen reference lists
        and rebuild.  Returns ``{name: perm}`` with ``new[k] = old[perm[k]]``.  The cells of
        the order are those of the skin given at construction, whatever ``skin`` is now
        (a :class:`~sphgen.nnps.skin_tuner.SkinTuner` changes it): the order, and so the
        sums of the passes, do not depend on the skin, and neither do the results."""
        skin, self.skin = self.skin, self.sort_skin
        try:
            self._build()
        finally:
            self.skin = skin
        perms, inverse = {}, {}
        for pa in self.arrays:
            perm = self._bins[pa.name][1].copy()
            inv = np.empty_like(perm)
            inv[perm] = np.arange(perm.size, dtype=perm.dtype)
            pa.permute(perm)
            perms[pa.name], inverse[pa.name] = perm, inv
        for (d, s), (offsets, nbrs) in list(self._frozen.items()):
            n_d, n_s = perms[d].size, perms[s].size
            if offsets.size != n_d + 1 or (nbrs.size and int(nbrs.max()) >= n_s):
                raise ValueError(f"the reference list frozen for dest '{d}', src '{s}' does "
                                 f"not fit arrays of {n_d} and {n_s} particles (did the "
                                 "particle count change since freeze()?)")
            self._frozen[(d, s)] = remap_csr(offsets, nbrs, perms[d], inverse[s])
        self._build()
        return perms
