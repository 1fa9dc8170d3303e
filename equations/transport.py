"""Transport velocity: particle shifting written as an acceleration, and the TVF stress."""
from sphgen.equation import Equation


class SunShiftingAcceleration(Equation):
    """(du/dt)_c = -Ma (2h) c0 / dt sum_b [1 + R (W_ab / W(dx))^n] grad W_ab V_b
    (SPST; Adepu & Ramachandran (2024), eq. 36; R = 0.2, n = 4)."""

    positive = ("mach", "c0", "wdx")

    def initialize(self, d_idx, d_auhat, d_avhat, d_awhat):
        d_auhat[d_idx] = 0.0
        d_avhat[d_idx] = 0.0
        d_awhat[d_idx] = 0.0

    def loop(self, d_idx, d_auhat, d_avhat, d_awhat, d_h, s_idx, s_m, s_rho, WIJ, DWIJ, dt):
        ratio = WIJ / self.wdx
        ratio2 = ratio * ratio
        fac = -self.mach * 2.0 * d_h[d_idx] * self.c0 / dt * (1.0 + 0.2 * ratio2 * ratio2)
        vb = s_m[s_idx] / s_rho[s_idx]
        d_auhat[d_idx] += fac * vb * DWIJ[0]
        d_avhat[d_idx] += fac * vb * DWIJ[1]
        d_awhat[d_idx] += fac * vb * DWIJ[2]


class TransportStress(Equation):
    """du_a/dt += sum_b m_b (u_a (x) delta_a / rho_a + u_b (x) delta_b / rho_b) . grad W_ab,
    delta = u~ - u (the TVF 'A' term of the uncorrected baseline; Adepu & Ramachandran (2024), eq. 27)."""

    def loop(self, d_idx, d_au, d_av, d_aw, d_u, d_v, d_w, d_uhat, d_vhat, d_what, d_rho,
             s_idx, s_m, s_u, s_v, s_w, s_uhat, s_vhat, s_what, s_rho, DWIJ):
        dxa = d_uhat[d_idx] - d_u[d_idx]
        dya = d_vhat[d_idx] - d_v[d_idx]
        dza = d_what[d_idx] - d_w[d_idx]
        dxb = s_uhat[s_idx] - s_u[s_idx]
        dyb = s_vhat[s_idx] - s_v[s_idx]
        dzb = s_what[s_idx] - s_w[s_idx]
        ra = 1.0 / d_rho[d_idx]
        rb = 1.0 / s_rho[s_idx]
        dda = (dxa * DWIJ[0] + dya * DWIJ[1] + dza * DWIJ[2]) * ra
        ddb = (dxb * DWIJ[0] + dyb * DWIJ[1] + dzb * DWIJ[2]) * rb
        mb = s_m[s_idx]
        d_au[d_idx] += mb * (d_u[d_idx] * dda + s_u[s_idx] * ddb)
        d_av[d_idx] += mb * (d_v[d_idx] * dda + s_v[s_idx] * ddb)
        d_aw[d_idx] += mb * (d_w[d_idx] * dda + s_w[s_idx] * ddb)


class BackgroundPressureAcceleration(Equation):
    """(du/dt)_c = -p_b sum_b m_b (1/rho_a^2 + 1/rho_b^2) grad W_ab: the TVF homogenisation
    of Adepu & Ramachandran (2024), eq. 20, in the symmetric form of Adami et al. 2013 (eq. 13)."""

    positive = ("pb",)

    def initialize(self, d_idx, d_auhat, d_avhat, d_awhat):
        d_auhat[d_idx] = 0.0
        d_avhat[d_idx] = 0.0
        d_awhat[d_idx] = 0.0

    def loop(self, d_idx, d_auhat, d_avhat, d_awhat, d_rho, s_idx, s_m, s_rho, DWIJ):
        ra = 1.0 / d_rho[d_idx]
        rb = 1.0 / s_rho[s_idx]
        f = -self.pb * s_m[s_idx] * (ra * ra + rb * rb)
        d_auhat[d_idx] += f * DWIJ[0]
        d_avhat[d_idx] += f * DWIJ[1]
        d_awhat[d_idx] += f * DWIJ[2]
