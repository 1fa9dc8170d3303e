"""The tensile penalty of SHTC-SPH (Kincl, Peshkov, Pavelka & Klika (2023), sec. 3.5).

P_h = 1/2 sum_a m_a cp^2 (lambda_a/rho0)^2 (eq. 19) with lambda_a = sum_b m_b h dw_ab/dh +
C_lambda,a (eq. 20), C_lambda such that lambda = 0 at t = 0.  Its force is (eq. 21)
-sum_b m_b cp^2 (lambda_a + lambda_b)/rho0^2 (h/r d2w/(dr dh))_ab x_ab, with the mixed kernel
derivative ``MIXEDIJ`` (the paper's 2D formula is a factor 2 too large; see
:meth:`sphgen.kernels.WendlandQuinticC2.mixed`).  ``cp`` = 0 removes all three equations
from the generated code.
"""
from sphgen.equation import Equation


class PenaltyLambdaConstant(Equation):
    """C_lambda,a = -sum_b m_b h dw_ab/dh at t = 0 (Kincl et al. (2023), eq. 20)."""

    switches = ("cp",)
    nonnegative = ("cp",)

    def initialize(self, d_idx, d_clam):
        if self.cp != 0.0:
            d_clam[d_idx] = 0.0

    def loop(self, d_idx, d_clam, s_idx, s_m, GHIJ):
        if self.cp != 0.0:
            d_clam[d_idx] -= s_m[s_idx] * GHIJ


class PenaltyLambda(Equation):
    """lambda_a = sum_b m_b h dw_ab/dh + C_lambda,a (Kincl, Peshkov, Pavelka & Klika (2023), eq. 20)."""

    switches = ("cp",)
    nonnegative = ("cp",)

    def initialize(self, d_idx, d_lam, d_clam):
        if self.cp != 0.0:
            d_lam[d_idx] = d_clam[d_idx]

    def loop(self, d_idx, d_lam, s_idx, s_m, GHIJ):
        if self.cp != 0.0:
            d_lam[d_idx] += s_m[s_idx] * GHIJ


class TensilePenaltyForce(Equation):
    """dv_a/dt -= sum_b m_b cp^2 (lambda_a + lambda_b)/rho0^2 (h/r d2w/(dr dh))_ab x_ab
    (Kincl, Peshkov, Pavelka & Klika (2023), eq. 21)."""

    switches = ("cp",)
    nonnegative = ("cp",)
    positive = ("rho0",)

    def loop(self, d_idx, d_au, d_av, d_aw, d_lam, s_idx, s_m, s_lam, XIJ, MIXEDIJ):
        if self.cp != 0.0:
            f = s_m[s_idx] * self.cp * self.cp * (d_lam[d_idx] + s_lam[s_idx]) * MIXEDIJ / (self.rho0 * self.rho0)
            d_au[d_idx] -= f * XIJ[0]
            d_av[d_idx] -= f * XIJ[1]
            d_aw[d_idx] -= f * XIJ[2]
