"""Momentum equation pieces: pressure gradient, viscosity, artificial viscosity."""
from sphgen.equation import Equation


class AveragePressure(Equation):
    """p_avg,a = sum_b p_b / N_a, the local mean pressure (Basa, Quinlan & Lastiwka 2009)."""

    def initialize(self, d_idx, d_pavg, d_nnbr):
        d_pavg[d_idx] = 0.0
        d_nnbr[d_idx] = 0.0

    def loop(self, d_idx, d_pavg, d_nnbr, s_idx, s_p):
        d_pavg[d_idx] += s_p[s_idx]
        d_nnbr[d_idx] += 1.0

    def post_loop(self, d_idx, d_pavg, d_nnbr):
        if d_nnbr[d_idx] > 0.0:
            d_pavg[d_idx] /= d_nnbr[d_idx]


class PressureGradient(Equation):
    """du_a/dt = -sum_b m_b (p_a/rho_a^2 + p_b/rho_b^2) grad W_ab (Adepu & Ramachandran (2024), eq. 27).

    With ``bql`` the destination's local mean pressure p_avg,a is subtracted from p_a
    and p_b (Basa, Quinlan & Lastiwka 2009), which removes the tensile instability of
    negative absolute pressures; the pair force is then not exactly antisymmetric, so
    linear momentum is conserved to round-off only with ``bql`` off (docs/schemes.rst).
    Initialises the acceleration, so it comes first.
    """

    switches = ("bql",)

    def initialize(self, d_idx, d_au, d_av, d_aw):
        d_au[d_idx] = 0.0
        d_av[d_idx] = 0.0
        d_aw[d_idx] = 0.0

    def loop(self, d_idx, d_au, d_av, d_aw, d_p, d_pavg, d_rho, s_idx, s_m, s_p, s_rho, DWIJ):
        pref = 0.0
        if self.bql:
            pref = d_pavg[d_idx]
        pa = (d_p[d_idx] - pref) / (d_rho[d_idx] * d_rho[d_idx])
        pb = (s_p[s_idx] - pref) / (s_rho[s_idx] * s_rho[s_idx])
        f = -s_m[s_idx] * (pa + pb)
        d_au[d_idx] += f * DWIJ[0]
        d_av[d_idx] += f * DWIJ[1]
        d_aw[d_idx] += f * DWIJ[2]


class LaminarViscosity(Equation):
    """du_a/dt += sum_b m_b 4 nu (r_ab . grad W_ab) u_ab / ((rho_a + rho_b)(r^2 + 0.01 h^2))
    (Morris et al. 1997; Adepu & Ramachandran (2024), eq. 27, third term)."""

    nonnegative = ("nu",)
    switches = ("nu",)

    def loop(self, d_idx, d_au, d_av, d_aw, d_rho, s_idx, s_m, s_rho, XIJ, VIJ, DWIJ, R2IJ, EPS):
        if self.nu != 0.0:
            xdotdw = XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1] + XIJ[2] * DWIJ[2]
            f = s_m[s_idx] * 4.0 * self.nu * xdotdw / ((d_rho[d_idx] + s_rho[s_idx]) * (R2IJ + EPS))
            d_au[d_idx] += f * VIJ[0]
            d_av[d_idx] += f * VIJ[1]
            d_aw[d_idx] += f * VIJ[2]


class ArtificialViscosity(Equation):
    """du_a/dt -= sum_b m_b Pi_ab grad W_ab, Pi_ab = -alpha h c phi_ab / rho_ab for
    u_ab . r_ab < 0 (Monaghan; Adepu & Ramachandran (2024), eqs. 28-29).  ``alpha`` is a
    switch: with alpha = 0 the equation vanishes from the generated code."""

    switches = ("alpha",)
    nonnegative = ("alpha", "c0")

    def loop(self, d_idx, d_au, d_av, d_aw, d_rho, s_idx, s_m, s_rho, XIJ, VIJ, DWIJ, R2IJ, HIJ, EPS):
        if self.alpha != 0.0:
            vr = VIJ[0] * XIJ[0] + VIJ[1] * XIJ[1] + VIJ[2] * XIJ[2]
            if vr < 0.0:
                phi = HIJ * vr / (R2IJ + EPS)
                pi = -self.alpha * self.c0 * phi / (0.5 * (d_rho[d_idx] + s_rho[s_idx]))
                f = -s_m[s_idx] * pi
                d_au[d_idx] += f * DWIJ[0]
                d_av[d_idx] += f * DWIJ[1]
                d_aw[d_idx] += f * DWIJ[2]
