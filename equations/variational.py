"""Forces of the variational SPH scheme of da Silva & Giraldi (2024).

What the paper needs beyond :mod:`equations.wcsph` (Tait, reused) and
:mod:`equations.walls` (the Lennard-Jones wall force of eq. 58, reused):

* a Gaussian kernel gradient (eqs. 10, 24, 69) computed from ``XIJ`` and ``RIJ`` inside
  each equation (the scene's kernel only sets the neighbour radius: give the particles
  ``h = rc / 3`` with the quintic spline, whose support is 3h), in the family
  ``grad W = -(2 ell / lam^2) (exp(-(r/lam)^2) - shift) x_ij`` for ``r <= rc``:

  - ``K1`` "as printed" (eq. 69): ell = 9.47, lam = 1 (R in metres), rc = h = 0.072,
    plain cut (shift = 0).  Unnormalised and almost flat on its support: pressure
    forces ~2500 times too weak (digest A1).  Kept for the record.
  - ``K2`` the paper's cut-off rc = 0.072 with a normalised Gaussian, lam = rc/3.
  - ``K3`` (default of the application) a standard normalised Gaussian, lam = 1.3 dx,
    rc = 3 lam, ~28 neighbours instead of ~650 for K2.

  K2 and K3 use the shifted (force-continuous) cut, shift = exp(-(rc/lam)^2), so that the
  fixed-point map has no jump at r = rc (digest A20h/A41), and
  ell = 1/(pi lam^2 I), I = 1 - e^{-k^2}(1 + k^2 + k^4/2), k = rc/lam: the 2-D integral
  of the W whose gradient this is.  See :func:`kernel_parameters`.
* the continuity density of eq. 67 with its sign fixed (digest A11), and the summation
  density of eq. 20 at the interpolated configuration (the "pure" variational scheme),
* the symmetric pressure gradient of eqs. 37/64 with that gradient,
* the artificial viscosity of eq. 55 with the dissipative (Monaghan) sign (digest A4).

Every pair term is a radial function of RIJ times XIJ with coefficients symmetric in
i <-> j, so the (j, i) term is the exact negative of the (i, j) term (momentum to round-off).
"""
from math import exp, pi  # noqa: F401  (the Python evaluator needs the names)

from sphgen.equation import Equation, helper


def kernel_parameters(kernel, dx=0.005, h_cut=0.072):
    """(ell, lam, rc, shift) of the kernel variants K1 (eq. 69 as printed), K2, K3 (module doc)."""
    if kernel == "K1":
        return 9.47, 1.0, h_cut, 0.0
    if kernel == "K2":
        lam, rc = h_cut / 3.0, h_cut
    elif kernel == "K3":
        lam = 1.3 * dx
        rc = 3.0 * lam
    else:
        raise ValueError(f"unknown kernel {kernel!r}: K1, K2 or K3")
    k2 = (rc / lam) ** 2
    shift = exp(-k2)
    integral = 1.0 - shift * (1.0 + k2 + 0.5 * k2 * k2)
    return 1.0 / (pi * lam * lam * integral), lam, rc, shift


@helper
def gauss_grad_factor(r=0.0, ell=1.0, lam=1.0, rc=1.0, shift=0.0):
    """F with grad_i W = F x_ij: -(2 ell/lam^2)(exp(-(r/lam)^2) - shift), 0 beyond rc
    (da Silva & Giraldi 2024, eqs. 24 and 69; shift = 0 is the printed plain cut)."""
    if r > rc:
        return 0.0
    q = r / lam
    return -2.0 * ell / (lam * lam) * (exp(-q * q) - shift)


@helper
def gauss_w(r=0.0, ell=1.0, lam=1.0, rc=1.0, shift=0.0):
    """W(r) whose gradient is :func:`gauss_grad_factor` times x_ij:
    ell (exp(-(r/lam)^2) - shift (1 + (rc^2 - r^2)/lam^2)), 0 beyond rc (da Silva & Giraldi
    2024, eqs. 10 and 69; shift = 0 is the printed plain cut)."""
    if r > rc:
        return 0.0
    q = r / lam
    return ell * (exp(-q * q) - shift * (1.0 + (rc * rc - r * r) / (lam * lam)))


class GaussianSummationDensity(Equation):
    """rho_i = sum_j m_j W(beta_ij) at the current (interpolated) configuration (da Silva &
    Giraldi 2024, eqs. 8 and 20); writes ``rho``.  Sources: the fluids (self included)."""

    positive = ("lam", "rc")

    def initialize(self, d_idx, d_rho):
        d_rho[d_idx] = 0.0

    def loop(self, d_idx, d_rho, s_idx, s_m, RIJ):
        d_rho[d_idx] += s_m[s_idx] * gauss_w(RIJ, self.ell, self.lam, self.rc, self.shift)


class GaussianContinuityDensity(Equation):
    """rho_{k,k+1} = rho_{k-1,k} + dt sum_j m_j v_ij . grad_i W (da Silva & Giraldi 2024,
    eq. 67 with the sign fixed); ``rhok`` holds rho_{k-1,k}; writes ``arho`` and ``rho``.
    ``weight`` w gives rho = rhok + w dt Cont (the centred variant: w = alpha, -(1 - alpha))."""

    positive = ("lam", "rc")

    def __init__(self, dest, sources=None, weight=1.0, **params):
        self.weight = float(weight)
        super().__init__(dest, sources, **params)

    def initialize(self, d_idx, d_arho):
        d_arho[d_idx] = 0.0

    def loop(self, d_idx, d_arho, s_idx, s_m, XIJ, VIJ, RIJ):
        f = gauss_grad_factor(RIJ, self.ell, self.lam, self.rc, self.shift)
        d_arho[d_idx] += s_m[s_idx] * f * (VIJ[0] * XIJ[0] + VIJ[1] * XIJ[1] + VIJ[2] * XIJ[2])

    def post_loop(self, d_idx, d_arho, d_rho, d_rhok, dt):
        d_rho[d_idx] = d_rhok[d_idx] + self.weight * dt * d_arho[d_idx]


class GaussianPressureGradient(Equation):
    """a_i = -sum_j m_j (p_i/rho_i^2 + p_j/rho_j^2) grad_i W (da Silva & Giraldi 2024,
    eq. 37 / 64 with the rho_j typo of eq. 28 fixed).  Initialises ``au, av, aw``."""

    positive = ("lam", "rc")

    def initialize(self, d_idx, d_au, d_av, d_aw):
        d_au[d_idx] = 0.0
        d_av[d_idx] = 0.0
        d_aw[d_idx] = 0.0

    def loop(self, d_idx, d_au, d_av, d_aw, d_p, d_rho, s_idx, s_m, s_p, s_rho, XIJ, RIJ):
        f = gauss_grad_factor(RIJ, self.ell, self.lam, self.rc, self.shift)
        c = -s_m[s_idx] * (d_p[d_idx] / (d_rho[d_idx] * d_rho[d_idx])
                           + s_p[s_idx] / (s_rho[s_idx] * s_rho[s_idx])) * f
        d_au[d_idx] += c * XIJ[0]
        d_av[d_idx] += c * XIJ[1]
        d_aw[d_idx] += c * XIJ[2]


class PaperArtificialViscosity(Equation):
    """a_i -= sum_j m_j Pi_ij grad_i W, Pi_ij = 2(-a c phi + b phi^2)/(rho_i + rho_j) for
    v_ij . x_ij < 0, phi = h v.x/(r^2 + 0.01 h^2) (da Silva & Giraldi 2024, eq. 55 with the
    dissipative sign and the m_j of eq. 64).  a = b = 0 removes it."""

    switches = ("a", "b")
    nonnegative = ("a", "b", "c", "hphi")

    def loop(self, d_idx, d_au, d_av, d_aw, d_rho, s_idx, s_m, s_rho, XIJ, VIJ, RIJ, R2IJ):
        if self.a != 0.0 or self.b != 0.0:
            vx = VIJ[0] * XIJ[0] + VIJ[1] * XIJ[1] + VIJ[2] * XIJ[2]
            if vx < 0.0:
                phi = self.hphi * vx / (R2IJ + 0.01 * self.hphi * self.hphi)
                pij = 2.0 * (-self.a * self.c * phi + self.b * phi * phi) / (d_rho[d_idx] + s_rho[s_idx])
                f = gauss_grad_factor(RIJ, self.ell, self.lam, self.rc, self.shift)
                c = -s_m[s_idx] * pij * f
                d_au[d_idx] += c * XIJ[0]
                d_av[d_idx] += c * XIJ[1]
                d_aw[d_idx] += c * XIJ[2]


class ZeroAcceleration(Equation):
    """au = av = aw = 0: starts the wall-force evaluation (the Lennard-Jones force of
    da Silva & Giraldi 2024, eq. 58, adds to them).  No sources."""

    def __init__(self, dest, sources=None):
        super().__init__(dest, None)

    def initialize(self, d_idx, d_au, d_av, d_aw):
        d_au[d_idx] = 0.0
        d_av[d_idx] = 0.0
        d_aw[d_idx] = 0.0
