"""The correction terms of the corrected transport-velocity formulation (CTVF).

Adepu & Ramachandran (2021) rewrite continuity, momentum and the EDAC pressure equation
for particles that move with the transport velocity u~ = u + delta and keep the terms
earlier transport-velocity schemes drop.  Each term is one equation with an ``enabled``
switch: off, it is pruned ("switched off") and absent from the generated code, so the
paper's with/without-correction comparisons are the same scene with a switch flipped.

* :class:`EDACTransportCorrection`: the terms of eq. 26 beyond the plain EDAC eq. 22;
* :class:`MomentumTransportDivergence`: -u div(u~ - u) of eqs. 19/27;
* :class:`ContinuityTransportCorrection`: +div(rho (u~ - u)) of eqs. 12/25.

The momentum equation's other transport term, div(u (x) (u~ - u)), is
:class:`sphgen.equations.transport.TransportStress` (it predates the CTVF: TVF keeps it).
All three need ``u, v, w`` and ``uhat, vhat, what`` of the sources.
"""
from sphgen.equation import Equation


class EDACTransportCorrection(Equation):
    """dp_a/dt += sum_b V_b [p_a u~_ab - p_a u_ab - (p delta)_ab] . grad W_ab
    = sum_b V_b (p_b - p_a) delta_b . grad W_ab, delta = u~ - u, a discrete delta . grad p
    (Adepu & Ramachandran 2021, eq. 26 minus eq. 22; eq. 23).

    Adds to ``ap``: put it after :class:`~sphgen.equations.edac.EDACPressureRate`, which
    initialises ``ap`` and holds -rho c^2 div(u) and the damping.  The first term of the
    printed eq. 26 has (p_a - rho_a c^2) where eq. 23 needs (rho_a c^2 - p_a); with that
    sign the three printed terms reduce exactly to the sum above.
    """

    switches = ("enabled",)

    def __init__(self, dest, sources, enabled=True):
        super().__init__(dest, sources, enabled=bool(enabled))

    def loop(self, d_idx, d_ap, d_p, s_idx, s_m, s_rho, s_p, s_u, s_v, s_w, s_uhat, s_vhat,
             s_what, DWIJ):
        if self.enabled:
            ddw = ((s_uhat[s_idx] - s_u[s_idx]) * DWIJ[0] + (s_vhat[s_idx] - s_v[s_idx]) * DWIJ[1]
                   + (s_what[s_idx] - s_w[s_idx]) * DWIJ[2])
            d_ap[d_idx] += s_m[s_idx] / s_rho[s_idx] * (s_p[s_idx] - d_p[d_idx]) * ddw


class MomentumTransportDivergence(Equation):
    """du_a/dt += u_a sum_b V_b (delta_a - delta_b) . grad W_ab, a discrete -u div(u~ - u)
    (Adepu & Ramachandran 2021, eq. 19, second term).  Eq. 27 prints u~_ab where eq. 19
    needs delta_ab = u~_ab - u_ab; this uses delta_ab unless ``printed`` (then u~_ab, a
    discrete -u div(u~)).  Not antisymmetric: it does not conserve linear momentum pair
    by pair."""

    switches = ("enabled", "printed")

    def __init__(self, dest, sources, enabled=True, printed=False):
        super().__init__(dest, sources, enabled=bool(enabled), printed=int(bool(printed)))

    def loop(self, d_idx, d_au, d_av, d_aw, d_u, d_v, d_w, d_uhat, d_vhat, d_what,
             s_idx, s_m, s_rho, s_u, s_v, s_w, s_uhat, s_vhat, s_what, DWIJ):
        if self.enabled:
            f = ((d_uhat[d_idx] - s_uhat[s_idx]) * DWIJ[0] + (d_vhat[d_idx] - s_vhat[s_idx]) * DWIJ[1]
                 + (d_what[d_idx] - s_what[s_idx]) * DWIJ[2])
            if not self.printed:
                f = f - ((d_u[d_idx] - s_u[s_idx]) * DWIJ[0] + (d_v[d_idx] - s_v[s_idx]) * DWIJ[1]
                         + (d_w[d_idx] - s_w[s_idx]) * DWIJ[2])
            f = f * s_m[s_idx] / s_rho[s_idx]
            d_au[d_idx] += f * d_u[d_idx]
            d_av[d_idx] += f * d_v[d_idx]
            d_aw[d_idx] += f * d_w[d_idx]


class ContinuityTransportCorrection(Equation):
    """d~rho_a/dt += sum_b V_b (rho_b delta_b - rho_a delta_a) . grad W_ab, a discrete
    div(rho (u~ - u)) (Adepu & Ramachandran 2021, eq. 25 second term, with the sign eq. 12
    requires: the printed + (rho delta)_ab gives -div(rho delta)).  Adds to ``arho``: put
    it after :class:`~sphgen.equations.transport.TransportContinuity`."""

    switches = ("enabled",)

    def __init__(self, dest, sources, enabled=True):
        super().__init__(dest, sources, enabled=bool(enabled))

    def loop(self, d_idx, d_arho, d_rho, d_u, d_v, d_w, d_uhat, d_vhat, d_what, s_idx, s_m,
             s_rho, s_u, s_v, s_w, s_uhat, s_vhat, s_what, DWIJ):
        if self.enabled:
            ra = d_rho[d_idx]
            rb = s_rho[s_idx]
            fx = rb * (s_uhat[s_idx] - s_u[s_idx]) - ra * (d_uhat[d_idx] - d_u[d_idx])
            fy = rb * (s_vhat[s_idx] - s_v[s_idx]) - ra * (d_vhat[d_idx] - d_v[d_idx])
            fz = rb * (s_what[s_idx] - s_w[s_idx]) - ra * (d_what[d_idx] - d_w[d_idx])
            d_arho[d_idx] += s_m[s_idx] / rb * (fx * DWIJ[0] + fy * DWIJ[1] + fz * DWIJ[2])
