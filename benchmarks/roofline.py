"""The machine's limits, for the benchmarks' roofline line: peak FMA rate and a triad.

Peak: 10 independent chains of fused multiply-adds, one core, compiled with the flags of
the generated modules (``sphgen.codegen.build``: ``-O3 -march=native``): scalar doubles,
and arrays of 4 doubles per chain that gcc turns into one AVX2 register each.  Triad:
``a = b + s c`` with numpy on arrays far larger than the caches (two passes: numpy
makes ``s c`` first), in GB/s of the three streams.  ``roofline_line`` turns a run's
``info.json`` (estimated pair flops per step, steps, wall time, threads) into the
distance to the peak.

    python benchmarks/roofline.py            # prints the machine's numbers
"""
import time

import numpy as np

_SOURCE = '''
# cython: boundscheck=False, wraparound=False, cdivision=True
def fma_scalar(long n):
    """2 flops x 10 chains per iteration, scalar doubles."""
    cdef double a0 = 1.0, a1 = 1.1, a2 = 1.2, a3 = 1.3, a4 = 1.4
    cdef double a5 = 1.5, a6 = 1.6, a7 = 1.7, a8 = 1.8, a9 = 1.9
    cdef double m = 0.999999, c = 1e-7
    cdef long i
    for i in range(n):
        a0 = a0 * m + c
        a1 = a1 * m + c
        a2 = a2 * m + c
        a3 = a3 * m + c
        a4 = a4 * m + c
        a5 = a5 * m + c
        a6 = a6 * m + c
        a7 = a7 * m + c
        a8 = a8 * m + c
        a9 = a9 * m + c
    return a0 + a1 + a2 + a3 + a4 + a5 + a6 + a7 + a8 + a9


cdef double _lanes(long n) noexcept nogil:
    """fma_vector's loop, callable from a parallel region."""
    cdef double a[40]
    cdef double m = 0.999999, c = 1e-7, s = 0.0
    cdef long i
    cdef int k
    for k in range(40):
        a[k] = 1.0 + 0.01 * k
    for i in range(n):
        for k in range(40):
            a[k] = a[k] * m + c
    for k in range(40):
        s += a[k]
    return s


def fma_vector(long n):
    """2 flops x 40 lanes (10 chains of 4 doubles) per iteration."""
    return _lanes(n)


from cython.parallel cimport prange
cimport openmp


def fma_cores(long n, int threads):
    """fma_vector's n iterations on each of ``threads`` threads at once (one region)."""
    cdef int k
    cdef double s = 0.0
    for k in prange(threads, nogil=True, num_threads=threads, schedule='static'):
        s += _lanes(n)
    return s


def regions(long n, double[::1] data, bint hand_over):
    """n parallel regions of 2 threads.  Each thread adds 1 to its half of ``data``;
    with ``hand_over`` the halves swap from one region to the next, so every line a
    thread writes was last written by the other core (what a stage meets after a pass
    whose particles moved between cores)."""
    cdef long r, i, lo, hi, m = data.shape[0]
    cdef int k, who
    for r in range(n):
        for k in prange(2, nogil=True, num_threads=2, schedule='static'):
            who = (k + r) % 2 if hand_over else k
            lo = who * (m // 2)
            hi = lo + m // 2
            for i in range(lo, hi):
                data[i] = data[i] + 1.0
    return data[0]


cdef long _keep_near(const int* nbrs, long m, const double* rec, int* out) noexcept nogil:
    """The cut's kind of loop: read an index, gather its record, keep the index if the
    record lies within a radius (branch-free store); the count kept."""
    cdef long i, c = 0
    cdef int j
    cdef double dx, dy
    for i in range(m):
        j = nbrs[i]
        dx = rec[4 * j] - 0.5
        dy = rec[4 * j + 1] - 0.5
        out[c] = j
        c += dx * dx + dy * dy < 0.232
    return c


def keep_near_cores(long reps, int threads, int[:, ::1] nbrs, double[:, ::1] rec, int[:, ::1] out):
    """_keep_near ``reps`` times on each of ``threads`` threads at once, thread k on row k
    of every argument (its own data, nothing shared)."""
    cdef int k
    cdef long r, s = 0
    cdef long m = nbrs.shape[1]
    for k in prange(threads, nogil=True, num_threads=threads, schedule='static'):
        for r in range(reps):
            s += _keep_near(&nbrs[k, 0], m, &rec[k, 0], &out[k, 0])
    return s
'''


def _module():
    from sphgen.codegen.build import load_or_build
    return load_or_build(_SOURCE)[0]


def peak_gflops(repeat=5, n=20_000_000):
    """{'scalar': GFLOP/s, 'avx': GFLOP/s} of one core: the best of ``repeat`` runs."""
    mod = _module()
    out = {}
    for name, fn, flops in (("scalar", mod.fma_scalar, 20), ("avx", mod.fma_vector, 80)):
        m = n if name == "scalar" else n // 4
        best = min(_timed(fn, m) for _ in range(repeat))
        out[name] = flops * m / best / 1e9
    return out


def _timed(fn, n):
    t0 = time.perf_counter()
    fn(n)
    return time.perf_counter() - t0


def triad_gbs(n=20_000_000, repeat=5):
    """numpy a = b + s c: GB/s counting the three arrays once (best of ``repeat``)."""
    b, c = np.random.rand(n), np.random.rand(n)
    a = np.empty(n)
    best = np.inf
    for _ in range(repeat):
        t0 = time.perf_counter()
        np.multiply(c, 3.0, out=a)
        np.add(a, b, out=a)
        best = min(best, time.perf_counter() - t0)
    return 3 * 8 * n / best / 1e9


def cross_core_us(n=20_000, nbytes=16_384, repeat=5):
    """The host's cost of two-thread work, in µs a parallel region (medians of
    ``repeat``): 'region', each thread touching its own 8 kB; 'hand_over', the halves
    swapped at every region, so each line comes from the other core.  On this kind of VM
    both jump by 2-3x for minutes at a time, with the load average at 0: the two vCPUs
    are then farther apart on the host (docs/performance.md)."""
    mod = _module()
    data = np.zeros(nbytes // 8)
    out = {}
    for name, hand in (("region", False), ("hand_over", True)):
        mod.regions(n // 10, data, hand)
        out[name] = 1e6 * float(np.median([_timed(lambda m: mod.regions(m, data, hand), n) for _ in range(repeat)])) / n
    return out


def two_core_fma(n=25_000_000, repeat=5):
    """How many times one core's FMA rate the host's two cores give together: the AVX2
    chains of ``fma_vector`` on one thread, then the same on each of two threads at once,
    alternated ``repeat`` times (medians).  No memory, no synchronisation inside: the most
    any program can gain from a second core of this VM at that moment (1.8-2.0 on
    2026-11-28, docs/performance.md)."""
    mod = _module()
    times = {1: [], 2: []}
    for _ in range(repeat):
        for k in (1, 2):
            times[k].append(_timed(lambda m: mod.fma_cores(m, k), n))
    return 2.0 * float(np.median(times[1])) / float(np.median(times[2]))


def two_core_gathers(reps=2_000, repeat=5, m=37_500, records=4_096):
    """As :func:`two_core_fma` for the neighbour search's kind of work: each thread keeps
    the indices of its own 150 kB of indices whose records (its own 128 kB) lie within a
    radius, as the cut of the skin rows does; everything stays in the thread's own L2, and
    nothing is shared.  The most a second core of this VM gives such a loop at that moment."""
    mod = _module()
    rng = np.random.default_rng(0)
    nbrs = rng.integers(0, records, size=(2, m)).astype(np.int32)
    rec = rng.random((2, 4 * records))
    out = np.empty((2, m), dtype=np.int32)
    mod.keep_near_cores(reps // 10, 2, nbrs, rec, out)
    times = {1: [], 2: []}
    for _ in range(repeat):
        for k in (1, 2):
            times[k].append(_timed(lambda r: mod.keep_near_cores(r, k, nbrs, rec, out), reps))
    return 2.0 * float(np.median(times[1])) / float(np.median(times[2]))


def host_line():
    """One line for a benchmark's output: the load, the two cores' ceilings (FMA chains,
    and the cut's kind of gathers) and the host's cross-core costs."""
    import os
    c = cross_core_us()
    return (f"host: load average {os.getloadavg()[0]:.2f}; two cores give {two_core_fma():.2f}x one "
            f"core's FMA rate, {two_core_gathers():.2f}x its rate of cache-bound gathers; "
            f"a two-thread region {c['region']:.2f} us, "
            f"with its 16 kB handed between the cores {c['hand_over']:.2f} us")


def roofline_line(info, peak, label=""):
    """One line: pairs per second per core, estimated GFLOP/s per core, % of the peaks."""
    flops, pairs = info.get("estimated_pair_flops_per_step"), info.get("neighbour_pairs_per_step")
    if not flops or not pairs:
        return f"roofline {label}: no flop estimate in info.json"
    threads = max(1, int(info.get("threads") or 1))
    seconds = info["wall_time"] * threads
    pps = pairs * info["steps"] / seconds
    gf = flops * info["steps"] / seconds / 1e9
    return (f"roofline {label}: {pps:.3g} pairs/s per core, ~{flops / pairs:.0f} flops per pair "
            f"(generator's estimate), {gf:.2f} GFLOP/s per core = {100 * gf / peak['scalar']:.0f} % of "
            f"the scalar FMA peak ({peak['scalar']:.1f}), {100 * gf / peak['avx']:.0f} % of the AVX2 "
            f"peak ({peak['avx']:.1f}); pair passes and everything around them included")


def median_run_line(rows, peak, label=""):
    """``roofline_line`` of the run with the median wall time (rows: dicts with "wall", "info")."""
    rows = sorted(rows, key=lambda x: x["wall"])
    return roofline_line(rows[len(rows) // 2]["info"], peak, label)


if __name__ == "__main__":
    p = peak_gflops()
    print(f"peak, one core: scalar FMA {p['scalar']:.1f} GFLOP/s, AVX2 FMA {p['avx']:.1f} GFLOP/s; "
          f"numpy triad {triad_gbs():.1f} GB/s")
    print(host_line())
