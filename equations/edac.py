"""Entropically damped artificial compressibility (EDAC) pressure evolution."""
from sphgen.equation import Equation


class EDACPressureRate(Equation):
    """dp/dt = -rho c^2 div(u) + nu_edac lap(p) (Adepu & Ramachandran (2024), eq. 22, as eq. 26
    without the CTVF corrections; damping in the consistent form: eq. 26 has an extra 1/rho).

    div(u)_a = -sum_b V_b u_ab . grad W_ab; the Laplacian is
    sum_b V_b 4 rho_a (p_a - p_b) r_ab . grad W_ab / ((rho_a + rho_b)(r^2 + 0.01 h^2)).
    """

    positive = ("c0",)
    nonnegative = ("nu_edac",)

    def initialize(self, d_idx, d_ap):
        d_ap[d_idx] = 0.0

    def loop(self, d_idx, d_ap, d_rho, d_p, s_idx, s_m, s_rho, s_p, VIJ, XIJ, DWIJ, R2IJ, EPS):
        vb = s_m[s_idx] / s_rho[s_idx]
        udotdw = VIJ[0] * DWIJ[0] + VIJ[1] * DWIJ[1] + VIJ[2] * DWIJ[2]
        xdotdw = XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1] + XIJ[2] * DWIJ[2]
        rhoa = d_rho[d_idx]
        damp = 4.0 * self.nu_edac * rhoa * (d_p[d_idx] - s_p[s_idx]) / ((rhoa + s_rho[s_idx]) * (R2IJ + EPS))
        d_ap[d_idx] += vb * (rhoa * self.c0 * self.c0 * udotdw + damp * xdotdw)
