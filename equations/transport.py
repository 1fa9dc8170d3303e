"""Transport-velocity pieces: the TVF stress term and the continuity equation with u~.

Particles move with the transport velocity u~ = u + delta (``uhat, vhat, what``); the
homogenisation accelerations that make delta live in :mod:`sphgen.equations.shifting`
(re-exported here for the schemes that imported them from this module).
"""
from sphgen.equation import Equation

from .shifting import BackgroundPressureAcceleration, SunShiftingAcceleration  # noqa: F401


class TransportStress(Equation):
    """du_a/dt += sum_b m_b (u_a (x) delta_a / rho_a + u_b (x) delta_b / rho_b) . grad W_ab,
    delta = u~ - u: the divergence of u (x) (u~ - u), the TVF 'A' term (Adami, Hu & Adams
    2013, eq. 9; Adepu & Ramachandran 2021, eq. 27).  ``enabled`` is a switch: False
    removes it from the generated code (the CTVF runs without corrections).
    ``difference``: sum_b V_b (u_b (x) delta_b - u_a (x) delta_a) . grad W_ab instead, the
    divergence without the zeroth-order error 2 u_a (delta_a . sum_b V_b grad W_ab) of the
    symmetric form (not the paper's printed form; see docs/ctvf.md)."""

    switches = ("enabled", "difference")

    def __init__(self, dest, sources, enabled=True, difference=False):
        super().__init__(dest, sources, enabled=bool(enabled), difference=int(bool(difference)))

    def loop(self, d_idx, d_au, d_av, d_aw, d_u, d_v, d_w, d_uhat, d_vhat, d_what, d_rho,
             s_idx, s_m, s_u, s_v, s_w, s_uhat, s_vhat, s_what, s_rho, DWIJ):
        if self.enabled:
            dxa = d_uhat[d_idx] - d_u[d_idx]
            dya = d_vhat[d_idx] - d_v[d_idx]
            dza = d_what[d_idx] - d_w[d_idx]
            dxb = s_uhat[s_idx] - s_u[s_idx]
            dyb = s_vhat[s_idx] - s_v[s_idx]
            dzb = s_what[s_idx] - s_w[s_idx]
            ra = 1.0 / d_rho[d_idx]
            rb = 1.0 / s_rho[s_idx]
            if self.difference:
                ra = -rb
            dda = (dxa * DWIJ[0] + dya * DWIJ[1] + dza * DWIJ[2]) * ra
            ddb = (dxb * DWIJ[0] + dyb * DWIJ[1] + dzb * DWIJ[2]) * rb
            mb = s_m[s_idx]
            d_au[d_idx] += mb * (d_u[d_idx] * dda + s_u[s_idx] * ddb)
            d_av[d_idx] += mb * (d_v[d_idx] * dda + s_v[s_idx] * ddb)
            d_aw[d_idx] += mb * (d_w[d_idx] * dda + s_w[s_idx] * ddb)


class TransportContinuity(Equation):
    """d~rho_a/dt = rho_a sum_b V_b (u~_a - u~_b) . grad W_ab: the density follows the
    particles, which move with u~ (Zhang, Hu & Adams 2017, eq. 12; the first part of
    Adepu & Ramachandran 2021, eq. 25).  Initialises ``arho``, so it comes first."""

    def initialize(self, d_idx, d_arho):
        d_arho[d_idx] = 0.0

    def loop(self, d_idx, d_arho, d_rho, d_uhat, d_vhat, d_what, s_idx, s_m, s_rho,
             s_uhat, s_vhat, s_what, DWIJ):
        du = d_uhat[d_idx] - s_uhat[s_idx]
        dv = d_vhat[d_idx] - s_vhat[s_idx]
        dw = d_what[d_idx] - s_what[s_idx]
        vb = s_m[s_idx] / s_rho[s_idx]
        d_arho[d_idx] += d_rho[d_idx] * vb * (du * DWIJ[0] + dv * DWIJ[1] + dw * DWIJ[2])
