"""Walls for the transport-velocity schemes: the free-slip ghost velocities of the divergence terms.

Adepu & Ramachandran (2021, section 3.6) use Adami et al. (2012) ghost particles with two
velocities per wall particle: a no-slip ghost velocity for the viscous term (eq. 50,
:class:`sphgen.equations.walls.WallGhostVelocity`, into ``ug, vg, wg``) and a free-slip
(no-penetration) ghost velocity, of both the momentum and the transport velocity, for
every divergence of a velocity field on the fluid (eqs. 46-49, :class:`WallSlipVelocity`
here).  The latter is written into the wall's own ``u, v, w`` and ``uhat, vhat, what``,
so the fluid equations of the schemes (EDAC pressure rate, continuity, the CTVF
corrections, the transport stress) take walls as ordinary sources; the prescribed wall
velocity lives in ``uw, vw, ww`` (``moving`` walls) as in :mod:`sphgen.equations.walls`.
"""
from sphgen.equation import Equation


class WallSlipVelocity(Equation):
    """Free-slip ghost velocities u_G = u^ + 2((u_p - u^) . n) n and u~_G = u~^ + 2((u_p - u~^) . n) n,
    u^ = sum_f u_f W_wf / sum_f W_wf and u~^ the same of u~ (Adepu & Ramachandran 2021,
    eqs. 46-49); dest: a wall with ``normal`` (stride 3, into the fluid), sources: the fluids.

    Writes the wall's ``u, v, w`` and ``uhat, vhat, what``.  Uses the Shepard sum ``wij`` of
    :class:`~sphgen.equations.walls.WallPressure`, which must come before it in the same
    group; a wall particle with no fluid neighbour gets u_G = u~_G = the normal part of u_p.
    ``moving``: the wall has a prescribed velocity ``uw, vw, ww`` (switch; off, u_p = 0).
    """

    switches = ("moving", "dim")

    def __init__(self, dest, sources, moving=False, dim=3):
        super().__init__(dest, sources, moving=bool(moving), dim=int(dim))

    def initialize(self, d_idx, d_u, d_v, d_w, d_uhat, d_vhat, d_what):
        d_u[d_idx] = 0.0
        d_uhat[d_idx] = 0.0
        if self.dim > 1:
            d_v[d_idx] = 0.0
            d_vhat[d_idx] = 0.0
        if self.dim > 2:
            d_w[d_idx] = 0.0
            d_what[d_idx] = 0.0

    def loop(self, d_idx, d_u, d_v, d_w, d_uhat, d_vhat, d_what, s_idx, s_u, s_v, s_w,
             s_uhat, s_vhat, s_what, WIJ):
        d_u[d_idx] += s_u[s_idx] * WIJ
        d_uhat[d_idx] += s_uhat[s_idx] * WIJ
        if self.dim > 1:
            d_v[d_idx] += s_v[s_idx] * WIJ
            d_vhat[d_idx] += s_vhat[s_idx] * WIJ
        if self.dim > 2:
            d_w[d_idx] += s_w[s_idx] * WIJ
            d_what[d_idx] += s_what[s_idx] * WIJ

    def post_loop(self, d_idx, d_u, d_v, d_w, d_uhat, d_vhat, d_what, d_wij, d_uw, d_vw, d_ww,
                  d_normal):
        s = 0.0
        if d_wij[d_idx] > 1e-12:
            s = 1.0 / d_wij[d_idx]
        u = d_u[d_idx] * s
        uh = d_uhat[d_idx] * s
        v = 0.0
        vh = 0.0
        w = 0.0
        wh = 0.0
        if self.dim > 1:
            v = d_v[d_idx] * s
            vh = d_vhat[d_idx] * s
        if self.dim > 2:
            w = d_w[d_idx] * s
            wh = d_what[d_idx] * s
        up = 0.0
        vp = 0.0
        wp = 0.0
        if self.moving:
            up = d_uw[d_idx]
            if self.dim > 1:
                vp = d_vw[d_idx]
            if self.dim > 2:
                wp = d_ww[d_idx]
        nx = d_normal[3 * d_idx]
        ny = d_normal[3 * d_idx + 1]
        nz = d_normal[3 * d_idx + 2]
        dn = 2.0 * ((up - u) * nx + (vp - v) * ny + (wp - w) * nz)
        dnh = 2.0 * ((up - uh) * nx + (vp - vh) * ny + (wp - wh) * nz)
        d_u[d_idx] = u + dn * nx
        d_uhat[d_idx] = uh + dnh * nx
        if self.dim > 1:
            d_v[d_idx] = v + dn * ny
            d_vhat[d_idx] = vh + dnh * ny
        if self.dim > 2:
            d_w[d_idx] = w + dn * nz
            d_what[d_idx] = wh + dnh * nz
