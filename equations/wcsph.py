"""Classical weakly compressible SPH (Monaghan 1992, 1994, 2005): continuity density,
Tait equation of state, artificial viscosity, body force, delta-SPH density diffusion.

The pressure-gradient term is :class:`sphgen.equations.momentum.PressureGradient`
(Monaghan's symmetric form) and the physical viscosity
:class:`~sphgen.equations.momentum.LaminarViscosity`; walls are the Adami equations of
:mod:`sphgen.equations.walls`.
"""
from math import fabs, pow, sin  # noqa: F401  (the Python evaluator needs the names)

from sphgen.equation import Equation, declare, helper
from sphgen.linalg import inv3


class TaitEOS(Equation):
    """p = B ((rho/rho0)^gamma - 1), B = rho0 c0^2 / gamma (Batchelor 1967; Monaghan 1994
    eq. 3.3 with gamma = 7).  No sources."""

    positive = ("rho0", "c0", "gamma")
    def initialize(self, d_idx, d_rho, d_p):
        b = self.rho0 * self.c0 * self.c0 / self.gamma
        x = d_rho[d_idx] / self.rho0
        if self.gamma == 7.0:      # the usual case: four products instead of pow
            x2 = x * x
            xg = x2 * x2 * x2 * x
        else:
            xg = pow(x, self.gamma)
        d_p[d_idx] = b * (xg - 1.0)


class ContinuityEquation(Equation):
    """drho_a/dt = sum_b m_b (u_a - u_b) . grad_a W_ab (Monaghan 1992 eq. 2.10 form;
    Monaghan 2005 eq. 4.4).  Initialises ``arho``: it comes first among the density rates.
    Sources: fluids only (walls have :class:`~sphgen.equations.walls.WallContinuity`)."""

    def initialize(self, d_idx, d_arho):
        d_arho[d_idx] = 0.0

    def loop(self, d_idx, d_arho, s_idx, s_m, VIJ, DWIJ):
        d_arho[d_idx] += s_m[s_idx] * (VIJ[0] * DWIJ[0] + VIJ[1] * DWIJ[1] + VIJ[2] * DWIJ[2])


class RenormalisedDensityGradient(Equation):
    """<grad rho>^L_a = L_a sum_b (rho_b - rho_a) grad_a W_ab V_b with the renormalisation
    L_a = [sum_b (x_b - x_a) (x) grad_a W_ab V_b]^-1 (Antuono et al. 2010, eq. 2.4), used by
    the corrected delta-SPH term.  Writes ``gradrho`` (stride 3) and ``lmat`` (stride 9,
    the matrix before inversion).  In 2D (``dim``) the z row and column are the identity.
    A particle with a singular matrix (e.g. isolated) falls back to the plain gradient."""

    switches = ("dim",)

    def __init__(self, dest, sources, dim=2):
        super().__init__(dest, sources, dim=int(dim))

    def initialize(self, d_idx, d_gradrho, d_lmat):
        for i in range(3):
            d_gradrho[3 * d_idx + i] = 0.0
        for i in range(9):
            d_lmat[9 * d_idx + i] = 0.0

    def loop(self, d_idx, d_gradrho, d_lmat, d_rho, s_idx, s_m, s_rho, XIJ, DWIJ):
        vb = s_m[s_idx] / s_rho[s_idx]
        drho = (s_rho[s_idx] - d_rho[d_idx]) * vb
        for i in range(3):
            d_gradrho[3 * d_idx + i] += drho * DWIJ[i]
            for j in range(3):
                d_lmat[9 * d_idx + 3 * i + j] -= XIJ[i] * DWIJ[j] * vb

    def post_loop(self, d_idx, d_gradrho, d_lmat):
        a = declare("matrix(9)")
        ai = declare("matrix(9)")
        g = declare("matrix(3)")
        for i in range(9):
            a[i] = d_lmat[9 * d_idx + i]
        if self.dim < 3:
            a[2] = 0.0
            a[5] = 0.0
            a[6] = 0.0
            a[7] = 0.0
            a[8] = 1.0
        if self.dim < 2:
            a[1] = 0.0
            a[3] = 0.0
            a[4] = 1.0
        det = a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6]) \
            + a[2] * (a[3] * a[7] - a[4] * a[6])
        if fabs(det) > 1e-6:
            inv3(a, ai)
            for i in range(3):
                g[i] = d_gradrho[3 * d_idx + i]
            # with A = sum_b (x_b - x_a) (x) grad W V_b, a linear rho = b . x gives
            # sum_b (rho_b - rho_a) grad W V_b = A^T b: the gradient is A^-T times the sum
            for i in range(3):
                d_gradrho[3 * d_idx + i] = ai[i] * g[0] + ai[3 + i] * g[1] + ai[6 + i] * g[2]


class DensityDiffusion(Equation):
    """delta-SPH: drho_a/dt += delta h c0 sum_b psi_ab . grad_a W_ab V_b,
    psi_ab = 2 (rho_b - rho_a) (x_b - x_a)/r^2 - (<grad rho>^L_a + <grad rho>^L_b)
    (Antuono, Colagrossi, Marrone & Molteni 2010, eq. 2.3; with ``correction=False`` the
    bracket is dropped: Molteni & Colagrossi 2009, eq. 7).  ``delta`` = 0 removes it from
    the generated code.  The corrected form needs :class:`RenormalisedDensityGradient` in
    an earlier group.  Sources: fluids only (the walls do not diffuse density)."""

    switches = ("delta", "correction")
    nonnegative = ("delta", "c0")

    def __init__(self, dest, sources, delta=0.1, c0=1.0, correction=True):
        super().__init__(dest, sources, delta=delta, c0=c0, correction=bool(correction))

    def loop(self, d_idx, d_arho, d_rho, d_gradrho, s_idx, s_m, s_rho, s_gradrho,
             XIJ, DWIJ, R2IJ, HIJ):
        if self.delta != 0.0:
            vb = s_m[s_idx] / s_rho[s_idx]
            xdotdw = XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1] + XIJ[2] * DWIJ[2]
            # (x_b - x_a) . grad W = -XIJ . DWIJ; 1/r^2 unregularised as in the papers (the
            # pair term is bounded: xdotdw ~ r W'), so a linear rho gives exactly zero.  r^2 is
            # floored at 1e-12 h^2 instead of skipping the pair: at r = 0 (a particle and
            # itself) XIJ = DWIJ = 0 and the term is 0 either way, and the loop has no branch.
            r2 = R2IJ if R2IJ > 1e-12 * HIJ * HIJ else 1e-12 * HIJ * HIJ
            psidw = -2.0 * (s_rho[s_idx] - d_rho[d_idx]) * xdotdw / r2
            if self.correction:
                for i in range(3):
                    psidw -= (d_gradrho[3 * d_idx + i] + s_gradrho[3 * s_idx + i]) * DWIJ[i]
            d_arho[d_idx] += self.delta * HIJ * self.c0 * psidw * vb


@helper
def monaghan_pi(vr=0.0, hij=1.0, r2eps=1.0, rho_sum=2.0, alpha=0.0, beta=0.0, c0=1.0):
    """Pi_ab = (-alpha c0 mu + beta mu^2) / rho_ab for approaching pairs (vr = u_ab.r_ab < 0),
    0 otherwise; mu = h vr / (r^2 + 0.01 h^2), rho_ab = rho_sum / 2 (Monaghan 1992 eq. 4.1).
    One division and no branch per pair: min(vr, 0) is 0.5 (vr - |vr|), exactly."""
    mu = hij * 0.5 * (vr - fabs(vr))
    inv = 1.0 / (r2eps * rho_sum)
    pi = -2.0 * alpha * c0 * mu * inv
    if beta != 0.0:
        pi += 2.0 * beta * mu * mu * inv / r2eps
    return pi


class MonaghanArtificialViscosity(Equation):
    """du_a/dt -= sum_b m_b Pi_ab grad_a W_ab, Pi_ab = (-alpha c0 mu_ab + beta mu_ab^2)/rho_ab
    for u_ab . r_ab < 0, mu_ab = h u_ab . r_ab / (r^2 + 0.01 h^2), rho_ab the mean density
    (Monaghan 1992 eq. 4.1, with the constant c0 for c_ab).  alpha = beta = 0 removes it.
    Sources: fluids (walls: :class:`~sphgen.equations.walls.WallArtificialViscosity`)."""

    switches = ("alpha", "beta")
    nonnegative = ("alpha", "beta", "c0")

    def loop(self, d_idx, d_au, d_av, d_aw, d_rho, s_idx, s_m, s_rho, XIJ, VIJ, DWIJ, R2IJ, HIJ, EPS):
        if self.alpha != 0.0 or self.beta != 0.0:
            vr = VIJ[0] * XIJ[0] + VIJ[1] * XIJ[1] + VIJ[2] * XIJ[2]
            pi = monaghan_pi(vr, HIJ, R2IJ + EPS, d_rho[d_idx] + s_rho[s_idx], self.alpha, self.beta,
                             self.c0)
            f = -s_m[s_idx] * pi
            d_au[d_idx] += f * DWIJ[0]
            d_av[d_idx] += f * DWIJ[1]
            d_aw[d_idx] += f * DWIJ[2]


class BodyForce(Equation):
    """du/dt += g (gravity or a driving body force), optionally ramped in over ``tdamp``
    with 0.5 (sin((t/tdamp - 1/2) pi) + 1) (Adami, Hu & Adams 2012, eq. 13).
    No sources; place it after the equation that initialises ``au, av, aw``."""

    switches = ("tdamp",)
    nonnegative = ("tdamp",)

    def __init__(self, dest, sources=None, gx=0.0, gy=0.0, gz=0.0, tdamp=0.0):
        super().__init__(dest, None, gx=gx, gy=gy, gz=gz, tdamp=tdamp)

    def post_loop(self, d_idx, d_au, d_av, d_aw, t):
        f = 1.0
        if self.tdamp != 0.0:
            if t < self.tdamp:
                f = 0.5 * (sin((t / self.tdamp - 0.5) * 3.141592653589793) + 1.0)
        d_au[d_idx] += f * self.gx
        d_av[d_idx] += f * self.gy
        d_aw[d_idx] += f * self.gz
