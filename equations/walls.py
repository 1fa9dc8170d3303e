"""Solid walls for any scheme.

Generalised wall boundary of Adami, Hu & Adams (2012, J. Comput. Phys. 231, 7057; "AHA"
below) and two repulsive-force walls (Monaghan & Kajtar 2009; the Lennard-Jones-type
force of da Silva & Giraldi (2024), eq. 58).

Wall arrays are fixed layers of particles with ``m`` (= rho0 dx^dim), ``h``, and the
properties these equations compute: ``p``, ``rho``, ``wij`` (the Shepard sum) and, for
viscous walls, the ghost velocity ``ug, vg, wg``.  A wall may carry

* ``uw, vw, ww``: its prescribed velocity (only with ``moving=True``),
* ``auw, avw, aww``: its prescribed acceleration (only with ``accelerating=True``),
* ``normal`` (stride 3): unit normals pointing into the fluid (only for free slip).

``moving`` and ``accelerating`` are switches: a wall at rest is compiled with no
velocity or acceleration arrays at all.  The wall's own ``u, v, w`` are never read:
the fluid-side equations below take the wall velocity from ``uw, vw, ww`` (or zero)
and from the ghost velocity, so the generic fluid equations that use ``VIJ`` must not
list walls as sources.

Usage in a scheme, per evaluation::

    Group([EOS(fluid)]),                                          # fluid p from rho
    Group([WallPressure(wall, fluids, gx=.., gy=..),              # AHA eq. 27
           WallDensity(wall, eos="tait", rho0=.., c0=..),         # p_w -> rho_w
           WallGhostVelocity(wall, fluids)]),                     # AHA eqs. 22-23
    Group([... fluid equations with fluids + walls as sources ...,
           WallContinuity(fluid, walls), WallViscosity(fluid, walls, nu=..)])
"""
from math import pow  # noqa: F401  (the Python evaluator needs the name)

from sphgen.equation import Equation, helper

from .wcsph import monaghan_pi

TAIT, LINEAR = 0, 1
EOS_NAMES = {"tait": TAIT, "linear": LINEAR}


@helper
def tait_density(p=0.0, rho0=1.0, b=1.0, gamma=7.0):
    """Inverse of the Tait equation p = B((rho/rho0)^gamma - 1).  A tension p <= -B has
    no density; it gives rho = rho0 (1e-21)^(1/gamma) (1e-3 rho0 for gamma = 7) instead
    of a NaN, and the density guard of the scheme then reports it."""
    ratio = 1.0 + p / b
    if ratio < 1e-21:
        ratio = 1e-21
    return rho0 * pow(ratio, 1.0 / gamma)


class WallPressure(Equation):
    """p_w = (sum_f p_f W_wf + (g - a_w) . sum_f rho_f r_wf W_wf) / sum_f W_wf
    (AHA eq. 27), r_wf = x_w - x_f; dest: a wall, sources: the fluids.

    ``accelerating``: the wall has a prescribed acceleration ``auw, avw, aww`` (switch;
    off, the wall is inertial and no acceleration arrays exist).  ``clamp``: limit p_w
    to >= 0 (free-surface flows where a tension at the wall would glue particles; off
    by default, as in AHA).  A wall particle with no fluid neighbour gets p_w = 0.
    Writes ``p`` and the Shepard sum ``wij`` (which :class:`WallGhostVelocity` reuses).
    """

    switches = ("accelerating", "clamp", "dim")

    def __init__(self, dest, sources, gx=0.0, gy=0.0, gz=0.0, accelerating=False, clamp=False, dim=3):
        super().__init__(dest, sources, gx=gx, gy=gy, gz=gz, accelerating=bool(accelerating),
                         clamp=bool(clamp), dim=int(dim))

    def initialize(self, d_idx, d_p, d_wij):
        d_p[d_idx] = 0.0
        d_wij[d_idx] = 0.0

    def loop(self, d_idx, d_p, d_wij, d_auw, d_avw, d_aww, s_idx, s_p, s_rho, XIJ, WIJ):
        gx = self.gx
        gy = 0.0
        gz = 0.0
        if self.dim > 1:
            gy = self.gy
        if self.dim > 2:
            gz = self.gz
        if self.accelerating:
            gx = gx - d_auw[d_idx]
            if self.dim > 1:
                gy = gy - d_avw[d_idx]
            if self.dim > 2:
                gz = gz - d_aww[d_idx]
        gdotr = gx * XIJ[0] + gy * XIJ[1] + gz * XIJ[2]
        d_p[d_idx] += (s_p[s_idx] + s_rho[s_idx] * gdotr) * WIJ
        d_wij[d_idx] += WIJ

    def post_loop(self, d_idx, d_p, d_wij):
        if d_wij[d_idx] > 1e-12:
            d_p[d_idx] /= d_wij[d_idx]
        else:
            d_p[d_idx] = 0.0
        if self.clamp:
            if d_p[d_idx] < 0.0:
                d_p[d_idx] = 0.0


class WallDensity(Equation):
    """rho_w from p_w through the scheme's equation of state (AHA section 2.3):
    Tait rho0 (1 + p/B)^(1/gamma), B = rho0 c0^2/gamma, or linear rho0 + p/c0^2.

    ``eos`` is 'tait' or 'linear' (folded into the code).  No sources: put it after
    :class:`WallPressure` in the same group (its ``post_loop`` then sees the final p_w).
    """

    switches = ("eos",)
    positive = ("rho0", "c0", "gamma")

    def __init__(self, dest, sources=None, eos="tait", rho0=1.0, c0=1.0, gamma=7.0):
        if eos not in EOS_NAMES:
            raise ValueError(f"WallDensity: eos must be one of {', '.join(EOS_NAMES)}; got {eos!r}")
        super().__init__(dest, None, eos=EOS_NAMES[eos], rho0=rho0, c0=c0, gamma=gamma)

    def post_loop(self, d_idx, d_p, d_rho):
        if self.eos == 0:
            b = self.rho0 * self.c0 * self.c0 / self.gamma
            d_rho[d_idx] = tait_density(d_p[d_idx], self.rho0, b, self.gamma)
        else:
            d_rho[d_idx] = self.rho0 + d_p[d_idx] / (self.c0 * self.c0)


class WallGhostVelocity(Equation):
    """Ghost velocity of a wall particle for the viscous term (AHA eqs. 22-23).

    u~_w = sum_f u_f W_wf / sum_f W_wf (eq. 22); no slip: u_g = 2 u_w - u~_w (eq. 23);
    free slip (``slip=True``): the tangential part of u~_w is kept and only the normal
    part is mirrored, u_g = u~_w + 2 ((u_w - u~_w) . n) n, which needs ``normal``.
    ``moving``: the wall has a prescribed velocity ``uw, vw, ww`` (switch; off, u_w = 0
    and no velocity arrays exist).  Uses ``wij`` of :class:`WallPressure`, which must
    come before it in the same group.
    """

    switches = ("slip", "moving", "dim")

    def __init__(self, dest, sources, slip=False, moving=False, dim=3):
        super().__init__(dest, sources, slip=bool(slip), moving=bool(moving), dim=int(dim))

    def initialize(self, d_idx, d_ug, d_vg, d_wg):
        d_ug[d_idx] = 0.0
        d_vg[d_idx] = 0.0
        if self.dim > 2:
            d_wg[d_idx] = 0.0

    def loop(self, d_idx, d_ug, d_vg, d_wg, s_idx, s_u, s_v, s_w, WIJ):
        d_ug[d_idx] += s_u[s_idx] * WIJ
        if self.dim > 1:
            d_vg[d_idx] += s_v[s_idx] * WIJ
        if self.dim > 2:
            d_wg[d_idx] += s_w[s_idx] * WIJ

    def post_loop(self, d_idx, d_ug, d_vg, d_wg, d_wij, d_uw, d_vw, d_ww, d_normal):
        ut = 0.0
        vt = 0.0
        wt = 0.0
        if d_wij[d_idx] > 1e-12:
            ut = d_ug[d_idx] / d_wij[d_idx]
            vt = d_vg[d_idx] / d_wij[d_idx]
            if self.dim > 2:
                wt = d_wg[d_idx] / d_wij[d_idx]
        uw = 0.0
        vw = 0.0
        ww = 0.0
        if self.moving:
            uw = d_uw[d_idx]
            if self.dim > 1:
                vw = d_vw[d_idx]
            if self.dim > 2:
                ww = d_ww[d_idx]
        if self.slip:
            nx = d_normal[3 * d_idx]
            ny = d_normal[3 * d_idx + 1]
            nz = d_normal[3 * d_idx + 2]
            dn = 2.0 * ((uw - ut) * nx + (vw - vt) * ny + (ww - wt) * nz)
            d_ug[d_idx] = ut + dn * nx
            d_vg[d_idx] = vt + dn * ny
            if self.dim > 2:
                d_wg[d_idx] = wt + dn * nz
        else:
            d_ug[d_idx] = 2.0 * uw - ut
            d_vg[d_idx] = 2.0 * vw - vt
            if self.dim > 2:
                d_wg[d_idx] = 2.0 * ww - wt


# ---------------------------------------------------------------- fluid <- wall
class WallContinuity(Equation):
    """drho_a/dt += rho_a sum_w V_w (u_a - u_w) . grad W_aw, V_w = m_w/rho_w (AHA eq. 6 with
    the wall's prescribed velocity: the wall moves the fluid only through it).

    dest: a fluid, sources: walls.  Accumulates into ``arho`` (a fluid continuity
    equation earlier in the group initialises it).  ``moving`` as in
    :class:`WallGhostVelocity`.
    """

    switches = ("moving", "dim")

    def __init__(self, dest, sources, moving=False, dim=3):
        super().__init__(dest, sources, moving=bool(moving), dim=int(dim))

    def loop(self, d_idx, d_arho, d_rho, d_u, d_v, d_w, s_idx, s_m, s_rho, s_uw, s_vw, s_ww, DWIJ):
        du = d_u[d_idx]
        dv = 0.0
        dw = 0.0
        if self.dim > 1:
            dv = d_v[d_idx]
        if self.dim > 2:
            dw = d_w[d_idx]
        if self.moving:
            du = du - s_uw[s_idx]
            if self.dim > 1:
                dv = dv - s_vw[s_idx]
            if self.dim > 2:
                dw = dw - s_ww[s_idx]
        udotdw = du * DWIJ[0] + dv * DWIJ[1] + dw * DWIJ[2]
        d_arho[d_idx] += d_rho[d_idx] * s_m[s_idx] / s_rho[s_idx] * udotdw


class WallViscosity(Equation):
    """du_a/dt += sum_w m_w 4 nu (r_aw . grad W_aw) (u_a - u_g,w) / ((rho_a + rho_w)(r^2 + 0.01 h^2))
    (Morris et al. 1997 form with the AHA ghost velocity u_g of eq. 23; dest: a fluid,
    sources: walls with :class:`WallGhostVelocity`).  ``nu`` = 0 removes it."""

    switches = ("nu", "dim")
    nonnegative = ("nu",)

    def __init__(self, dest, sources, nu=0.0, dim=3):
        super().__init__(dest, sources, nu=nu, dim=int(dim))

    def loop(self, d_idx, d_au, d_av, d_aw, d_u, d_v, d_w, d_rho, s_idx, s_m, s_rho,
             s_ug, s_vg, s_wg, XIJ, DWIJ, R2IJ, EPS):
        if self.nu != 0.0:
            xdotdw = XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1] + XIJ[2] * DWIJ[2]
            f = s_m[s_idx] * 4.0 * self.nu * xdotdw / ((d_rho[d_idx] + s_rho[s_idx]) * (R2IJ + EPS))
            d_au[d_idx] += f * (d_u[d_idx] - s_ug[s_idx])
            if self.dim > 1:
                d_av[d_idx] += f * (d_v[d_idx] - s_vg[s_idx])
            if self.dim > 2:
                d_aw[d_idx] += f * (d_w[d_idx] - s_wg[s_idx])


class WallArtificialViscosity(Equation):
    """Monaghan's artificial viscosity between a fluid particle and a wall particle,
    with the wall's prescribed velocity: du_a/dt -= sum_w m_w Pi_aw grad W_aw,
    Pi = (-alpha c0 mu + beta mu^2) / rho_bar, mu = h u_aw . r_aw / (r^2 + 0.01 h^2)
    for u_aw . r_aw < 0 (Monaghan 1992).  ``alpha`` = ``beta`` = 0 removes it."""

    switches = ("alpha", "beta", "moving", "dim")
    nonnegative = ("alpha", "beta", "c0")

    def __init__(self, dest, sources, alpha=0.1, beta=0.0, c0=1.0, moving=False, dim=3):
        super().__init__(dest, sources, alpha=alpha, beta=beta, c0=c0, moving=bool(moving), dim=int(dim))

    def loop(self, d_idx, d_au, d_av, d_aw, d_u, d_v, d_w, d_rho, s_idx, s_m, s_rho,
             s_uw, s_vw, s_ww, XIJ, DWIJ, R2IJ, HIJ, EPS):
        if self.alpha != 0.0 or self.beta != 0.0:
            du = d_u[d_idx]
            dv = 0.0
            dw = 0.0
            if self.dim > 1:
                dv = d_v[d_idx]
            if self.dim > 2:
                dw = d_w[d_idx]
            if self.moving:
                du = du - s_uw[s_idx]
                if self.dim > 1:
                    dv = dv - s_vw[s_idx]
                if self.dim > 2:
                    dw = dw - s_ww[s_idx]
            vr = du * XIJ[0] + dv * XIJ[1] + dw * XIJ[2]
            pi = monaghan_pi(vr, HIJ, R2IJ + EPS, d_rho[d_idx] + s_rho[s_idx], self.alpha, self.beta, self.c0)
            f = -s_m[s_idx] * pi
            d_au[d_idx] += f * DWIJ[0]
            d_av[d_idx] += f * DWIJ[1]
            d_aw[d_idx] += f * DWIJ[2]


class WallEDACPressureRate(Equation):
    """Wall part of the EDAC pressure equation (Adepu & Ramachandran (2024), eq. 22/26, AHA walls):
    dp_a/dt += sum_w V_w [rho_a c0^2 (u_a - u_w) . grad W_aw
    + 4 nu_edac rho_a (p_a - p_w) r_aw . grad W_aw / ((rho_a + rho_w)(r^2 + 0.01 h^2))],
    V_w = m_w/rho_w, u_w the prescribed wall velocity (dest: a fluid, sources: walls)."""

    switches = ("moving", "dim")
    positive = ("c0",)
    nonnegative = ("nu_edac",)

    def __init__(self, dest, sources, c0=1.0, nu_edac=0.0, moving=False, dim=3):
        super().__init__(dest, sources, c0=c0, nu_edac=nu_edac, moving=bool(moving), dim=int(dim))

    def loop(self, d_idx, d_ap, d_rho, d_p, d_u, d_v, d_w, s_idx, s_m, s_rho, s_p,
             s_uw, s_vw, s_ww, XIJ, DWIJ, R2IJ, EPS):
        du = d_u[d_idx]
        dv = 0.0
        dw = 0.0
        if self.dim > 1:
            dv = d_v[d_idx]
        if self.dim > 2:
            dw = d_w[d_idx]
        if self.moving:
            du = du - s_uw[s_idx]
            if self.dim > 1:
                dv = dv - s_vw[s_idx]
            if self.dim > 2:
                dw = dw - s_ww[s_idx]
        vb = s_m[s_idx] / s_rho[s_idx]
        udotdw = du * DWIJ[0] + dv * DWIJ[1] + dw * DWIJ[2]
        xdotdw = XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1] + XIJ[2] * DWIJ[2]
        rhoa = d_rho[d_idx]
        damp = 4.0 * self.nu_edac * rhoa * (d_p[d_idx] - s_p[s_idx]) / ((rhoa + s_rho[s_idx]) * (R2IJ + EPS))
        d_ap[d_idx] += vb * (rhoa * self.c0 * self.c0 * udotdw + damp * xdotdw)


# ---------------------------------------------------------------- repulsive walls
class MonaghanKajtarForce(Equation):
    """Repulsive boundary force of Monaghan & Kajtar (2009, Comput. Phys. Commun. 180,
    1811, eq. 3.1): a_a += sum_k (K/beta) x_ak / r_ak^2 Phi(r_ak/h) 2 m_k/(m_a + m_k), with
    Phi(q) = (1.77/32)(1 + 5q/2 + 2q^2)(2 - q)^5 for q < 2 (their section 4: a
    dimensionless Wendland shape, 1.77 at q = 0), h the fluid's, beta = fluid spacing /
    boundary spacing, K of order g H or the square of the largest speed.  The wall particles
    need ``m``; they take part in no SPH sum.  dest: a fluid, sources: boundary arrays."""

    positive = ("K", "beta")

    def loop(self, d_idx, d_au, d_av, d_aw, d_m, d_h, s_idx, s_m, XIJ, R2IJ, RIJ):
        q = RIJ / d_h[d_idx]
        if q < 2.0 and R2IJ > 1e-24:
            t = 2.0 - q
            phi = 1.77 / 32.0 * (1.0 + 2.5 * q + 2.0 * q * q) * t * t * t * t * t
            f = self.K / self.beta * phi / R2IJ * 2.0 * s_m[s_idx] / (d_m[d_idx] + s_m[s_idx])
            d_au[d_idx] += f * XIJ[0]
            d_av[d_idx] += f * XIJ[1]
            d_aw[d_idx] += f * XIJ[2]


class LennardJonesWallForce(Equation):
    """Wall force of da Silva & Giraldi (2024), eq. 58, a Lennard-Jones-type repulsion:
    a_a += sum_g D [(r0/r)^n1 - (r0/r)^n2] x_ag / r^power for r < r0, n1 = 12, n2 = 4;
    ``power`` = 1 (unit vector, as printed) or 2 (Monaghan 1994 / Liu & Liu).
    dest: a fluid, sources: boundary particles (no other property needed)."""

    switches = ("power",)
    positive = ("D", "r0")

    def __init__(self, dest, sources, D=1.0, r0=1.0, power=1):
        if power not in (1, 2):
            raise ValueError(f"LennardJonesWallForce: power must be 1 or 2, got {power!r}")
        super().__init__(dest, sources, D=D, r0=r0, power=int(power))

    def loop(self, d_idx, d_au, d_av, d_aw, s_idx, XIJ, RIJ):
        if RIJ < self.r0 and RIJ > 1e-12:
            s = self.r0 / RIJ
            s2 = s * s
            s4 = s2 * s2
            s12 = s4 * s4 * s4
            f = self.D * (s12 - s4) / RIJ
            if self.power == 2:
                f = f / RIJ
            d_au[d_idx] += f * XIJ[0]
            d_av[d_idx] += f * XIJ[1]
            d_aw[d_idx] += f * XIJ[2]
