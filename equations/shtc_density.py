"""Density by kernel summation with a time-independent constant, and the particle masses
(Kincl, Peshkov, Pavelka & Klika (2023), sec. 3.1)."""
from sphgen.equation import Equation

from .basic import SummationDensityWithConstant  # noqa: F401  (eq. 4; re-exported)


class KernelVolumeMass(Equation):
    """m_a = rho0 V_a with V_a = (sum_b w_ab)^-1 at t = 0 (Kincl et al. (2023), sec. 3.1)."""

    positive = ("rho0",)

    def initialize(self, d_idx, d_m):
        d_m[d_idx] = 0.0

    def loop(self, d_idx, d_m, WIJ):
        d_m[d_idx] += WIJ

    def post_loop(self, d_idx, d_m):
        d_m[d_idx] = self.rho0 / d_m[d_idx]


class DensityConstant(Equation):
    """C_rho,a = rho0 - sum_b m_b w_ab at t = 0, so that rho_a(0) = rho0 (Kincl et al. (2023), eq. 4)."""

    positive = ("rho0",)

    def initialize(self, d_idx, d_crho):
        d_crho[d_idx] = self.rho0

    def loop(self, d_idx, d_crho, s_idx, s_m, WIJ):
        d_crho[d_idx] -= s_m[s_idx] * WIJ
