/* Loops of the neighbour search four doubles at a time (AVX2): the reach test, and the
 * look for positions outside a periodic box.
 *
 * A candidate j of destination i is kept if |x_i - x_j|^2 < max((k h_i)^2, (k h_j)^2).
 * Two loops make that test on every candidate: the build's scan of a cell
 * (_scan_cell, the sources of one cell, contiguous) and the cut of a skin-list row
 * (_cut_open and, near a periodic edge, the minimum-image loop of _refine_row; the
 * candidates of a row, scattered).  Written plainly, gcc does not
 * vectorise them: the kept indices are packed to the front of the output, so each
 * store depends on the count so far.  Here four records are loaded and transposed,
 * the four distances computed with the same operations in the same order as the
 * scalar loops (no fused multiply-add: setup.py builds with -ffp-contract=off), and the
 * kept indices packed with one byte shuffle from a table of sixteen.  The rows are
 * the same, bit for bit; tests compare both paths.
 *
 * wrap_periodic looks at every coordinate on a periodic axis at every update, and at
 * most updates none is outside the box: sphgen_outside_avx2 says whether one is (or is
 * not finite) with two compares per four values and no branch, before the scalar loop
 * that wraps them runs at all.
 *
 * The functions are compiled for AVX2 whatever the build's flags and chosen at run
 * time (sphgen_simd_available()); other machines and compilers use the scalar loops. */
#ifndef SPHGEN_SIMD_H
#define SPHGEN_SIMD_H

#if defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__))
#define SPHGEN_SIMD_AVX2 1
#include <immintrin.h>

static int sphgen_simd_available(void) {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") ? 1 : 0;
}

/* byte shuffles that pack the int32 lanes whose mask bit is set to the front */
static const unsigned char sphgen_pack_table[16][16] __attribute__((aligned(16))) = {
#define L(a) (4 * (a)), (4 * (a) + 1), (4 * (a) + 2), (4 * (a) + 3)
#define Z 0x80, 0x80, 0x80, 0x80
    {Z, Z, Z, Z}, {L(0), Z, Z, Z}, {L(1), Z, Z, Z}, {L(0), L(1), Z, Z},
    {L(2), Z, Z, Z}, {L(0), L(2), Z, Z}, {L(1), L(2), Z, Z}, {L(0), L(1), L(2), Z},
    {L(3), Z, Z, Z}, {L(0), L(3), Z, Z}, {L(1), L(3), Z, Z}, {L(0), L(1), L(3), Z},
    {L(2), L(3), Z, Z}, {L(0), L(2), L(3), Z}, {L(1), L(2), L(3), Z}, {L(0), L(1), L(2), L(3)},
#undef L
#undef Z
};

/* x, y, z and (k h)^2 of four records, each lane one record */
#define SPHGEN_TRANSPOSE(r0, r1, r2, r3, X, Y, Z, R) do {             \
        __m256d t0_ = _mm256_unpacklo_pd(r0, r1);                     \
        __m256d t1_ = _mm256_unpackhi_pd(r0, r1);                     \
        __m256d t2_ = _mm256_unpacklo_pd(r2, r3);                     \
        __m256d t3_ = _mm256_unpackhi_pd(r2, r3);                     \
        X = _mm256_permute2f128_pd(t0_, t2_, 0x20);                   \
        Y = _mm256_permute2f128_pd(t1_, t3_, 0x20);                   \
        Z = _mm256_permute2f128_pd(t0_, t2_, 0x31);                   \
        R = _mm256_permute2f128_pd(t1_, t3_, 0x31);                   \
    } while (0)

/* the records of the four sources j[0..3], transposed as above */
#define SPHGEN_GATHER4(pts, j, X, Y, Z, R)                                            \
    SPHGEN_TRANSPOSE(_mm256_loadu_pd((pts) + 4 * (long)(j)[0]),                       \
                     _mm256_loadu_pd((pts) + 4 * (long)(j)[1]),                       \
                     _mm256_loadu_pd((pts) + 4 * (long)(j)[2]),                       \
                     _mm256_loadu_pd((pts) + 4 * (long)(j)[3]), X, Y, Z, R)

/* dx^2 + dy^2 (+ dz^2 in 3D), summed in that order as the scalar loops do */
__attribute__((target("avx2")))
static inline __m256d sphgen_r2_4(__m256d dx, __m256d dy, __m256d dz, int three_d) {
    __m256d r2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
    return three_d ? _mm256_add_pd(r2, _mm256_mul_pd(dz, dz)) : r2;
}

/* one candidate of a loop's tail: index j kept if dx^2 + dy^2 (+ dz^2) < max(ri2, rj2) */
__attribute__((target("avx2")))
static inline long sphgen_keep1(double dx, double dy, double dz, int three_d, double ri2,
                                double rj2, int j, int* out, long cnt) {
    double r2 = dx * dx + dy * dy;
    if (three_d)
        r2 = r2 + dz * dz;
    out[cnt] = j;
    return cnt + (r2 < (ri2 > rj2 ? ri2 : rj2));
}

/* keep the lanes of idx where r2 < max(ri2, rj2); returns the new count */
__attribute__((target("avx2")))
static inline long sphgen_keep4(__m256d r2, __m256d ri2, __m256d rj2, __m128i idx,
                                int* out, long cnt) {
    __m256d rc2 = _mm256_max_pd(ri2, rj2);     /* ri2 > rj2 ? ri2 : rj2, NaN as the scalar */
    int mask = _mm256_movemask_pd(_mm256_cmp_pd(r2, rc2, _CMP_LT_OQ));
    __m128i shuf = _mm_load_si128((const __m128i*)sphgen_pack_table[mask]);
    _mm_storeu_si128((__m128i*)(out + cnt), _mm_shuffle_epi8(idx, shuf));
    return cnt + __builtin_popcount(mask);
}

/* _cut_open: the candidates nbrs[k0:k1] in reach of (xi, yi, zi); 2D if !three_d (the
 * z terms are 0 - 0 there and adding 0.0 changes no sum).  out may be nbrs + k0. */
__attribute__((target("avx2")))
static long sphgen_cut_open_avx2(const int* nbrs, long k0, long k1, double xi, double yi,
                                 double zi, double ri2, const double* pts, int* out,
                                 int three_d) {
    long k = k0, cnt = 0;
    const __m256d vx = _mm256_set1_pd(xi), vy = _mm256_set1_pd(yi), vz = _mm256_set1_pd(zi);
    const __m256d vr = _mm256_set1_pd(ri2);
    for (; k + 4 <= k1; k += 4) {
        const __m128i idx = _mm_loadu_si128((const __m128i*)(nbrs + k));
        __m256d X, Y, Z, R, r2;
        SPHGEN_GATHER4(pts, nbrs + k, X, Y, Z, R);
        r2 = sphgen_r2_4(_mm256_sub_pd(vx, X), _mm256_sub_pd(vy, Y), _mm256_sub_pd(vz, Z), three_d);
        cnt = sphgen_keep4(r2, vr, R, idx, out, cnt);
    }
    for (; k < k1; k++) {
        const double* q = pts + 4 * (long)nbrs[k];
        cnt = sphgen_keep1(xi - q[0], yi - q[1], zi - q[2], three_d, ri2, q[3], nbrs[k], out, cnt);
    }
    return cnt;
}

/* the minimum image of d on an axis of half length hl (inf: not periodic), length l:
 * d - l above hl, d + l below -hl, as the scalar loop's two branches */
__attribute__((target("avx2")))
static inline __m256d sphgen_image4(__m256d d, __m256d hl, __m256d l) {
    __m256d above = _mm256_cmp_pd(d, hl, _CMP_GT_OQ);
    __m256d below = _mm256_cmp_pd(d, _mm256_sub_pd(_mm256_setzero_pd(), hl), _CMP_LT_OQ);
    __m256d out = _mm256_blendv_pd(d, _mm256_sub_pd(d, l), above);
    return _mm256_blendv_pd(out, _mm256_add_pd(d, l), below);
}

/* the periodic loop of _refine_row: _cut_open with the minimum image on every axis whose
 * half length half[a] is finite (the others: inf) */
__attribute__((target("avx2")))
static long sphgen_cut_image_avx2(const int* nbrs, long k0, long k1, double xi, double yi,
                                  double zi, double ri2, const double* pts, int* out,
                                  int three_d, const double* half, const double* length) {
    long k = k0, cnt = 0;
    const __m256d vx = _mm256_set1_pd(xi), vy = _mm256_set1_pd(yi), vz = _mm256_set1_pd(zi);
    const __m256d vr = _mm256_set1_pd(ri2);
    const __m256d hx = _mm256_set1_pd(half[0]), hy = _mm256_set1_pd(half[1]), hz = _mm256_set1_pd(half[2]);
    const __m256d lx = _mm256_set1_pd(length[0]), ly = _mm256_set1_pd(length[1]), lz = _mm256_set1_pd(length[2]);
    for (; k + 4 <= k1; k += 4) {
        const __m128i idx = _mm_loadu_si128((const __m128i*)(nbrs + k));
        __m256d X, Y, Z, R, r2;
        SPHGEN_GATHER4(pts, nbrs + k, X, Y, Z, R);
        r2 = sphgen_r2_4(sphgen_image4(_mm256_sub_pd(vx, X), hx, lx),
                         sphgen_image4(_mm256_sub_pd(vy, Y), hy, ly),
                         sphgen_image4(_mm256_sub_pd(vz, Z), hz, lz), three_d);
        cnt = sphgen_keep4(r2, vr, R, idx, out, cnt);
    }
    for (; k < k1; k++) {
        const double* q = pts + 4 * (long)nbrs[k];
        double d[3] = {xi - q[0], yi - q[1], zi - q[2]};
        int a;
        for (a = 0; a < 3; a++) {
            if (d[a] > half[a])
                d[a] = d[a] - length[a];
            else if (d[a] < -half[a])
                d[a] = d[a] + length[a];
        }
        cnt = sphgen_keep1(d[0], d[1], d[2], three_d, ri2, q[3], nbrs[k], out, cnt);
    }
    return cnt;
}

/* _scan_cell: the sources pts[p0:p1] (contiguous records, indices index[p0:p1]) in reach
 * of xi (a record) seen through the image shift; 2D or 1D if !three_d (y is 0 in 1D). */
__attribute__((target("avx2")))
static long sphgen_scan_cell_avx2(const double* xi, const double* pts, const int* index,
                                  long p0, long p1, const double* shift, int* out,
                                  int three_d) {
    long p = p0, cnt = 0;
    const double x0 = xi[0], y0 = xi[1], z0 = xi[2], ri2 = xi[3];
    const double sx = shift[0], sy = shift[1], sz = shift[2];
    const __m256d vx = _mm256_set1_pd(x0), vy = _mm256_set1_pd(y0), vz = _mm256_set1_pd(z0);
    const __m256d vsx = _mm256_set1_pd(sx), vsy = _mm256_set1_pd(sy), vsz = _mm256_set1_pd(sz);
    const __m256d vr = _mm256_set1_pd(ri2);
    for (; p + 4 <= p1; p += 4) {
        const double* q = pts + 4 * p;
        __m128i idx = _mm_loadu_si128((const __m128i*)(index + p));
        __m256d X, Y, Z, R, r2;
        SPHGEN_TRANSPOSE(_mm256_loadu_pd(q), _mm256_loadu_pd(q + 4), _mm256_loadu_pd(q + 8),
                         _mm256_loadu_pd(q + 12), X, Y, Z, R);
        r2 = sphgen_r2_4(_mm256_add_pd(_mm256_sub_pd(vx, X), vsx), _mm256_add_pd(_mm256_sub_pd(vy, Y), vsy),
                         _mm256_add_pd(_mm256_sub_pd(vz, Z), vsz), three_d);
        cnt = sphgen_keep4(r2, vr, R, idx, out, cnt);
    }
    for (; p < p1; p++) {
        const double* q = pts + 4 * p;
        cnt = sphgen_keep1((x0 - q[0]) + sx, (y0 - q[1]) + sy, (z0 - q[2]) + sz, three_d, ri2, q[3],
                           index[p], out, cnt);
    }
    return cnt;
}

/* whether some x[i] is not in [lo, hi) (NaN and inf included) */
__attribute__((target("avx2")))
static int sphgen_outside_avx2(const double* x, long n, double lo, double hi) {
    long i = 0;
    const __m256d vlo = _mm256_set1_pd(lo), vhi = _mm256_set1_pd(hi);
    __m256d acc = _mm256_setzero_pd();
    for (; i + 4 <= n; i += 4) {
        __m256d v = _mm256_loadu_pd(x + i);
        acc = _mm256_or_pd(acc, _mm256_or_pd(_mm256_cmp_pd(v, vlo, _CMP_NGE_UQ),
                                             _mm256_cmp_pd(v, vhi, _CMP_NLT_UQ)));
    }
    for (; i < n; i++)
        if (!(x[i] >= lo && x[i] < hi))
            return 1;
    return _mm256_movemask_pd(acc) != 0;
}

#else  /* no AVX2 path: the scalar loops of _cell_list.pyx */
#define SPHGEN_SIMD_AVX2 0
static int sphgen_simd_available(void) { return 0; }
static long sphgen_cut_open_avx2(const int* nbrs, long k0, long k1, double xi, double yi,
                                 double zi, double ri2, const double* pts, int* out,
                                 int three_d) { return 0; }
static long sphgen_scan_cell_avx2(const double* xi, const double* pts, const int* index,
                                  long p0, long p1, const double* shift, int* out,
                                  int three_d) { return 0; }
static long sphgen_cut_image_avx2(const int* nbrs, long k0, long k1, double xi, double yi,
                                  double zi, double ri2, const double* pts, int* out,
                                  int three_d, const double* half, const double* length) { return 0; }
static int sphgen_outside_avx2(const double* x, long n, double lo, double hi) { return 1; }
#endif

#endif
