"""Kernel identities: normalisation, derivatives, and the compiled kernel == Python."""
import numpy as np
import pytest

from sphgen.equation import Equation
from sphgen.kernels import QuarticSpline, QuinticSpline, TruncatedGaussian, WendlandQuinticC2, get_kernel
from sphgen.scene import Scene

from conftest import lattice_cloud


KINDS = [(cls, dim) for cls in (QuinticSpline, WendlandQuinticC2, TruncatedGaussian, QuarticSpline)
         for dim in (1, 2, 3)]


@pytest.mark.parametrize("cls,dim", KINDS)
def test_normalisation(cls, dim):
    k = cls(dim)
    r = np.linspace(0.0, k.radius_scale, 30001)
    w = np.array([k.w(x, 1.0) for x in r])
    surface = {1: 2.0, 2: 2 * np.pi * r, 3: 4 * np.pi * r ** 2}[dim]
    assert abs(np.trapezoid(w * surface, r) - 1.0) < 1e-6


@pytest.mark.parametrize("cls,dim", KINDS)
def test_derivatives_match_finite_differences(cls, dim):
    k = cls(dim)
    h, e, rs = 0.7, 1e-6, k.radius_scale
    for r in np.linspace(0.05, rs - 0.05, 40):
        fd = (k.w(r + e, h) - k.w(r - e, h)) / (2 * e)
        assert abs(k.dwdr(r, h) - fd) < 1e-6 * max(1.0, abs(fd)) / h ** (dim + 1)
        fdh = h * (k.w(r, h + e) - k.w(r, h - e)) / (2 * e)
        assert abs(k.gradh(r, h) - fdh) < 1e-5 / h ** dim
    assert k.w(rs * h * (1 + 1e-12), h) == 0.0 and k.dwdr(rs * h * (1 + 1e-12), h) == 0.0


@pytest.mark.parametrize("cls,dim", KINDS)
def test_dwdr_over_r_times_r_is_dwdr(cls, dim):
    """grad W = dwdr_over_r x_ij: the closed forms (Wendland: no division by r) agree with
    dW/dr / r to round-off, vanish outside the support and give a zero gradient at r = 0."""
    k = cls(dim)
    h = 0.7
    for r in np.linspace(1e-3, k.radius_scale * h * 1.01, 57):
        assert abs(k.dwdr_over_r(r, h) * r - k.dwdr(r, h)) <= 1e-13 * abs(k.dwdr(0.5 * h, h))
    assert np.isfinite(k.dwdr_over_r(0.0, h)) and 0.0 * k.dwdr_over_r(0.0, h) == 0.0


def test_unknown_kernel_is_a_clear_error():
    with pytest.raises(ValueError, match="unknown kernel 'cubic'; known: quintic, wendland, gaussian, quartic"):
        get_kernel("cubic", 2)


@pytest.mark.parametrize("dim", [1, 2, 3])
def test_wendland_values_at_the_origin(dim):
    """w(0) = a_d and h dW/dh(0) = -d a_d (Kincl et al. 2025, sec. 2)."""
    k = WendlandQuinticC2(dim)
    assert k.w(0.0, 1.0) == pytest.approx(k.fac, rel=1e-15)
    assert k.gradh(0.0, 1.0) == pytest.approx(-dim * k.fac, rel=1e-15)


class _KernelSums(Equation):
    def initialize(self, d_idx, d_q, d_gx):
        d_q[d_idx] = 0.0
        d_gx[d_idx] = 0.0

    def loop(self, d_idx, d_q, d_gx, s_idx, s_m, WIJ, DWIJ):
        d_q[d_idx] += s_m[s_idx] * WIJ
        d_gx[d_idx] += s_m[s_idx] * DWIJ[0]


@pytest.mark.parametrize("cls,backend", [(WendlandQuinticC2, "cython"), (WendlandQuinticC2, "python"),
                                         (TruncatedGaussian, "cython"), (QuarticSpline, "cython")])
def test_kernel_in_generated_code_matches_brute_force(cls, backend):
    pa = lattice_cloud(nx=6, jitter=0.3, seed=2)
    pa.add_property("q")
    pa.add_property("gx")
    kernel = cls(2)
    sc = Scene([pa], [_KernelSums("fluid", ["fluid"])], dim=2, kernel=kernel,
               outputs={"fluid": ["q", "gx"]}, backend=backend)
    sc.compute(0, 0.0, 0.1)
    q, gx = np.zeros(pa.n), np.zeros(pa.n)
    for i in range(pa.n):
        for j in range(pa.n):
            dx, dy = pa.x[i] - pa.x[j], pa.y[i] - pa.y[j]
            r, h = np.hypot(dx, dy), 0.5 * (pa.h[i] + pa.h[j])
            if r < kernel.radius_scale * h:
                q[i] += pa.m[j] * kernel.w(r, h)
                if r > 0:
                    gx[i] += pa.m[j] * kernel.dwdr(r, h) * dx / r
    assert np.abs(q).max() > 0 and np.abs(gx).max() > 0
    assert np.allclose(pa.q, q, rtol=1e-12, atol=1e-13)
    assert np.allclose(pa.gx, gx, rtol=1e-12, atol=1e-12)


@pytest.mark.parametrize("name", ["wendland", "quintic", "gaussian", "quartic"])
@pytest.mark.parametrize("dim", [1, 2, 3])
def test_mixed_derivative_matches_finite_differences_of_gradh(name, dim):
    """(h/r) d2W/(dr dh) = (1/r) d/dr (h dW/dh): the penalty force of Kincl et al. (2023) eq. 21."""
    k = get_kernel(name, dim)
    h, e = 0.7, 1e-6
    R = k.radius_scale * h
    for r in np.linspace(0.03, 0.98, 40) * R:
        fd = (k.gradh(r + e, h) - k.gradh(r - e, h)) / (2 * e) / r
        assert abs(k.mixed(r, h) - fd) < 1e-6 * max(1.0, abs(fd)) / h ** (dim + 2)
    # continuous at r = 0 and zero outside the support
    assert k.mixed(0.0, h) == pytest.approx(k.mixed(1e-7 * h, h), rel=1e-6)
    assert k.mixed(R * (1 + 1e-12), h) == 0.0


def test_wendland_mixed_derivative_values_of_the_paper():
    """2D: -35/(8 pi h^4)(1-q/2)^2 (7q-8) (the paper prints 35/(4 pi), twice too large);
    3D: -105/(16 pi h^5)(1-q/2)^2 (4q-5) as printed; zeros at q = 8/7 and 5/4."""
    h = 1.3
    for q in np.linspace(0.0, 1.99, 25):
        t = 1 - q / 2
        assert WendlandQuinticC2(2).mixed(q * h, h) == pytest.approx(
            -35 / (8 * np.pi * h ** 4) * t * t * (7 * q - 8), rel=1e-12, abs=1e-15)
        assert WendlandQuinticC2(3).mixed(q * h, h) == pytest.approx(
            -105 / (16 * np.pi * h ** 5) * t * t * (4 * q - 5), rel=1e-12, abs=1e-15)
    assert WendlandQuinticC2(2).mixed(8 / 7 * h, h) == pytest.approx(0.0, abs=1e-14)
    assert WendlandQuinticC2(3).mixed(1.25 * h, h) == pytest.approx(0.0, abs=1e-14)
    assert WendlandQuinticC2(2).mixed(0.0, 1.0) == pytest.approx(35 / np.pi, rel=1e-14)
    assert WendlandQuinticC2(3).mixed(0.0, 1.0) == pytest.approx(525 / (16 * np.pi), rel=1e-14)


@pytest.mark.parametrize("cls,dim", KINDS)
def test_lattice_sum_is_one(cls, dim):
    """sum_b dx^d W(|x_b|) over a cubic lattice of spacing h/8 (offset by a random shift):
    the quadrature of the unit integral (Kincl 2023, sec. 1.1: every kernel has unit integral)."""
    k = cls(dim)
    dx, n = 1.0 / 8.0, int(np.ceil(8 * k.radius_scale)) + 1
    shift = np.random.default_rng(dim).uniform(0, dx, dim)
    axes = [np.arange(-n, n + 1) * dx + s for s in shift]
    r = np.sqrt(sum(g ** 2 for g in np.meshgrid(*axes, indexing="ij"))).ravel()
    r = r[r < k.radius_scale]
    w = np.vectorize(k.w, otypes=[float])(r, 1.0)
    # the sum's quadrature error at dx = h/8: at most 6.7e-6 (Wendland, 1D); 5.4e-7 for the
    # Gaussian, whose kink at 3h (W' jumps by 6 exp(-9) a_d) makes it decay only as dx^2
    assert abs(w.sum() * dx ** dim - 1.0) < 1e-5


def test_gaussian_and_quartic_of_the_thesis():
    """Kincl (2023): the Gaussian (eq. 1.5, its sign and normalisation corrected, truncated at 3h
    and shifted by exp(-9)) and the M5 quartic (eqs. 1.8-1.9, as printed): values at q = 0 and on
    the pieces' joins, support, dW/dr <= 0."""
    for dim in (1, 2, 3):
        g = TruncatedGaussian(dim)
        assert g.w(0.0, 1.0) == pytest.approx(g.fac * (1.0 - np.exp(-9.0)), rel=1e-15)
        assert g.w(1.0, 1.0) == pytest.approx(g.fac * (np.exp(-1.0) - np.exp(-9.0)), rel=1e-14)
        assert abs(g.w(3.0 * (1 - 1e-12), 1.0)) < 1e-14 and g.w(3.0, 1.0) == 0.0
        q4 = QuarticSpline(dim)
        assert q4.w(0.0, 1.0) == pytest.approx(q4.fac * (2.5 ** 4 - 5 * 1.5 ** 4 + 10 * 0.5 ** 4), rel=1e-15)
        assert q4.w(1.0, 1.0) == pytest.approx(q4.fac * (1.5 ** 4 - 5 * 0.5 ** 4), rel=1e-15)
        assert q4.w(2.0, 1.0) == pytest.approx(q4.fac * 0.5 ** 4, rel=1e-15)
        for k in (g, q4):
            r = np.linspace(0.0, k.radius_scale * 1.01, 301)
            assert all(k.dwdr(x, 1.0) <= 0.0 for x in r)
    assert TruncatedGaussian(2).fac == pytest.approx(1.0 / np.pi, rel=2e-3)   # (pi h^2)^-1 untruncated
    assert 1.2340980408667956e-4 == np.exp(-9.0)
