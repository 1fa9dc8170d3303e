"""Density and simple per-particle equations shared by every scheme."""
from sphgen.equation import Equation


class SummationDensity(Equation):
    """rho_a = sum_b m_b W_ab (Adepu & Ramachandran (2024), sec. 2.3, option 1)."""

    def initialize(self, d_idx, d_rho):
        d_rho[d_idx] = 0.0

    def loop(self, d_idx, d_rho, s_idx, s_m, WIJ):
        d_rho[d_idx] += s_m[s_idx] * WIJ


class Vorticity2D(Equation):
    """omega_a = -sum_b V_b (u_ab x grad W_ab)_z, a diagnostic for output only."""

    def initialize(self, d_idx, d_omega):
        d_omega[d_idx] = 0.0

    def loop(self, d_idx, d_omega, s_idx, s_m, s_rho, VIJ, DWIJ):
        vb = s_m[s_idx] / s_rho[s_idx]
        d_omega[d_idx] += -vb * (VIJ[0] * DWIJ[1] - VIJ[1] * DWIJ[0])


class SummationDensityWithConstant(Equation):
    """rho_a = C_a + sum_b m_b W_ab with a time-independent C_a (``crho``) fixed at t = 0 (Kincl 2023,
    eq. 1.14; Kincl, Peshkov, Pavelka & Klika (2023), eq. 4)."""

    def initialize(self, d_idx, d_rho, d_crho):
        d_rho[d_idx] = d_crho[d_idx]

    def loop(self, d_idx, d_rho, s_idx, s_m, WIJ):
        d_rho[d_idx] += s_m[s_idx] * WIJ
