"""Free-surface particles and their normals (Adepu & Ramachandran 2021, section 3.4).

Three groups, in this order, for each medium (a fluid or a solid body):

1. :class:`SurfaceNormal`: n*_a = -sum_b V_b grad W_ab over the medium and its walls
   (eq. 42), zeroed where |n*| < 1/(4 h_a), else normalised; walls among the sources stop a
   particle resting on a wall from getting a normal towards it;
2. :class:`SmoothedSurfaceNormal`: n_a = sum_b V_b n*_b W_ab over the medium (eq. 43),
   normalised (zero where |n| <= 1e-3); with h = dx three layers carry a normal;
3. :class:`FreeSurfaceParticles`: a particle with a normal is a free-surface particle
   unless a neighbour (medium or wall) lies within 60 degrees of its normal (the cone
   test of section 3.4); a particle whose summation density (medium and walls) is below
   half the reference density is isolated and a free-surface particle too.

Properties of the medium: ``normal_tmp`` and ``normal`` (stride 3), ``free_surface``
(1.0 or 0.0), ``rho_s`` (the summation density of the isolation test) and
``fs_blocked`` (neighbours inside the cone).  :func:`free_surface_groups` builds the
three groups.

Near the surface (section 3.5): :class:`NearSurfaceSmoothingLength` sets h_b
(Algorithm 1), :class:`SurfaceShiftingFilter` removes the normal part of the shifting
acceleration where h_b < h and all of it on the surface (eq. 44), and
:class:`SurfacePressure` holds p = 0 on free-surface particles (not in the paper: the
first author's later code does it; an option of the scheme).
"""
from math import sqrt  # noqa: F401  (the Python evaluator needs the name)

from sphgen.equation import Equation, Group

PROPERTIES = ("rho_s", "free_surface", "fs_blocked", "h_b", "fs_dist")
VECTORS = ("normal", "normal_tmp")


class SurfaceNormal(Equation):
    """n*_a = -sum_b m_b/rho_b grad W_ab, zero if |n*_a| < 1/(4 h_a), else n*_a/|n*_a|
    (Adepu & Ramachandran 2021, eq. 42 and the threshold after it).  Writes ``normal_tmp``."""

    def initialize(self, d_idx, d_normal_tmp):
        d_normal_tmp[3 * d_idx] = 0.0
        d_normal_tmp[3 * d_idx + 1] = 0.0
        d_normal_tmp[3 * d_idx + 2] = 0.0

    def loop(self, d_idx, d_normal_tmp, s_idx, s_m, s_rho, DWIJ):
        vb = s_m[s_idx] / s_rho[s_idx]
        d_normal_tmp[3 * d_idx] -= vb * DWIJ[0]
        d_normal_tmp[3 * d_idx + 1] -= vb * DWIJ[1]
        d_normal_tmp[3 * d_idx + 2] -= vb * DWIJ[2]

    def post_loop(self, d_idx, d_normal_tmp, d_h):
        nx = d_normal_tmp[3 * d_idx]
        ny = d_normal_tmp[3 * d_idx + 1]
        nz = d_normal_tmp[3 * d_idx + 2]
        mag = sqrt(nx * nx + ny * ny + nz * nz)
        s = 0.0
        if mag >= 0.25 / d_h[d_idx]:
            s = 1.0 / mag
        d_normal_tmp[3 * d_idx] = nx * s
        d_normal_tmp[3 * d_idx + 1] = ny * s
        d_normal_tmp[3 * d_idx + 2] = nz * s


class SmoothedSurfaceNormal(Equation):
    """n_a = sum_b m_b/rho_b n*_b W_ab, normalised, zero where |n_a| <= ``tolerance``
    (Adepu & Ramachandran 2021, eq. 43; sources: the medium only).  Writes ``normal``."""

    nonnegative = ("tolerance",)

    def __init__(self, dest, sources, tolerance=1e-3):
        super().__init__(dest, sources, tolerance=tolerance)

    def initialize(self, d_idx, d_normal):
        d_normal[3 * d_idx] = 0.0
        d_normal[3 * d_idx + 1] = 0.0
        d_normal[3 * d_idx + 2] = 0.0

    def loop(self, d_idx, d_normal, s_idx, s_m, s_rho, s_normal_tmp, WIJ):
        f = s_m[s_idx] / s_rho[s_idx] * WIJ
        d_normal[3 * d_idx] += f * s_normal_tmp[3 * s_idx]
        d_normal[3 * d_idx + 1] += f * s_normal_tmp[3 * s_idx + 1]
        d_normal[3 * d_idx + 2] += f * s_normal_tmp[3 * s_idx + 2]

    def post_loop(self, d_idx, d_normal):
        nx = d_normal[3 * d_idx]
        ny = d_normal[3 * d_idx + 1]
        nz = d_normal[3 * d_idx + 2]
        mag = sqrt(nx * nx + ny * ny + nz * nz)
        s = 0.0
        if mag > self.tolerance:
            s = 1.0 / mag
        d_normal[3 * d_idx] = nx * s
        d_normal[3 * d_idx + 1] = ny * s
        d_normal[3 * d_idx + 2] = nz * s


class FreeSurfaceParticles(Equation):
    """free_surface_a = 1 if (n_a != 0 and no neighbour b within ``radius`` h_a lies within
    60 degrees of n_a, i.e. n_a . (r_b - r_a)/|r_b - r_a| > 1/2 for none) or if
    sum_b m_b W_ab < ``isolated`` rho0 (Adepu & Ramachandran 2021, section 3.4: the cone
    test and the isolated particles, threshold one half).  Sources: the medium and its
    walls.  ``radius`` = 2 (not the kernel's 3): see docs/ctvf.md."""

    positive = ("rho0", "radius")
    nonnegative = ("isolated",)

    def __init__(self, dest, sources, rho0=1.0, radius=2.0, isolated=0.5):
        super().__init__(dest, sources, rho0=rho0, radius=radius, isolated=isolated)

    def initialize(self, d_idx, d_rho_s, d_fs_blocked):
        d_rho_s[d_idx] = 0.0
        d_fs_blocked[d_idx] = 0.0

    def loop(self, d_idx, d_rho_s, d_fs_blocked, d_normal, d_h, s_idx, s_m, WIJ, XIJ, RIJ):
        d_rho_s[d_idx] += s_m[s_idx] * WIJ
        # the cosine of the angle between n_a and r_b - r_a = -XIJ, computed before the
        # test: a test on plain values is one the pair loop vectorises with
        c = -(d_normal[3 * d_idx] * XIJ[0] + d_normal[3 * d_idx + 1] * XIJ[1]
              + d_normal[3 * d_idx + 2] * XIJ[2]) / max(RIJ, 1e-12)
        reach = self.radius * d_h[d_idx]
        if RIJ > 1e-12 and RIJ < reach and c > 0.5:
            d_fs_blocked[d_idx] += 1.0

    def post_loop(self, d_idx, d_rho_s, d_fs_blocked, d_normal, d_free_surface):
        nx = d_normal[3 * d_idx]
        ny = d_normal[3 * d_idx + 1]
        nz = d_normal[3 * d_idx + 2]
        d_free_surface[d_idx] = 0.0
        if nx * nx + ny * ny + nz * nz > 1e-6 and d_fs_blocked[d_idx] == 0.0:
            d_free_surface[d_idx] = 1.0
        if d_rho_s[d_idx] < self.isolated * self.rho0:
            d_free_surface[d_idx] = 1.0


def setup_free_surface_properties(pa):
    """Declare the properties the three groups write on a medium ``pa``."""
    for p in PROPERTIES:
        if not pa.has(p):
            pa.add_property(p)
    for p in VECTORS:
        if not pa.has(p):
            pa.add_property(p, stride=3)


def free_surface_groups(media, walls=(), rho0=1.0, radius=2.0, h_b_factor=None):
    """The three groups of section 3.4 for the arrays ``media`` (each its own medium), with
    the wall arrays ``walls`` among the sources of eq. 42 and of the cone test; with
    ``h_b_factor`` a fourth group sets h_b (section 3.5)."""
    walls = list(walls)
    groups = [Group([SurfaceNormal(d, [d] + walls) for d in media]),
              Group([SmoothedSurfaceNormal(d, [d]) for d in media]),
              Group([FreeSurfaceParticles(d, [d] + walls, rho0=rho0, radius=radius) for d in media])]
    if h_b_factor is not None:
        groups.append(Group([NearSurfaceSmoothingLength(d, [d], factor=h_b_factor) for d in media]))
    return groups


class NearSurfaceSmoothingLength(Equation):
    """h_b = 0 on a free-surface particle; x_dist / ``factor`` where the nearest free-surface
    particle within the support is x_dist away; h otherwise (Adepu & Ramachandran 2021,
    section 3.5, Algorithm 1; ``factor`` = 3 is the quintic spline's support radius in
    units of h: use the kernel's ``radius_scale``, e.g. 2 for the Wendland kernels and
    the cubic spline).  Sources: the medium (after :class:`FreeSurfaceParticles`)."""

    positive = ("factor",)

    def __init__(self, dest, sources, factor=3.0):
        super().__init__(dest, sources, factor=factor)

    def initialize(self, d_idx, d_fs_dist):
        d_fs_dist[d_idx] = 1e300

    def loop(self, d_idx, d_fs_dist, s_idx, s_free_surface, RIJ):
        if s_free_surface[s_idx] > 0.5 and RIJ > 1e-12:
            if RIJ < d_fs_dist[d_idx]:
                d_fs_dist[d_idx] = RIJ

    def post_loop(self, d_idx, d_fs_dist, d_h_b, d_h, d_free_surface):
        d_h_b[d_idx] = d_h[d_idx]
        if d_free_surface[d_idx] > 0.5:
            d_h_b[d_idx] = 0.0
        elif d_fs_dist[d_idx] < 1e299:
            d_h_b[d_idx] = d_fs_dist[d_idx] / self.factor


class SurfaceShiftingFilter(Equation):
    """(du/dt)_c = 0 on a free-surface particle, (du/dt)_c - ((du/dt)_c . n) n where
    h_b < h, unchanged elsewhere (Adepu & Ramachandran 2021, eq. 44).  No sources: put it
    in a group after the one that computes the shifting acceleration."""

    def __init__(self, dest, sources=None):
        super().__init__(dest, None)

    def initialize(self, d_idx, d_auhat, d_avhat, d_awhat, d_free_surface, d_h_b, d_h, d_normal):
        if d_free_surface[d_idx] > 0.5:
            d_auhat[d_idx] = 0.0
            d_avhat[d_idx] = 0.0
            d_awhat[d_idx] = 0.0
        elif d_h_b[d_idx] < d_h[d_idx]:
            nx = d_normal[3 * d_idx]
            ny = d_normal[3 * d_idx + 1]
            nz = d_normal[3 * d_idx + 2]
            an = d_auhat[d_idx] * nx + d_avhat[d_idx] * ny + d_awhat[d_idx] * nz
            d_auhat[d_idx] -= an * nx
            d_avhat[d_idx] -= an * ny
            d_awhat[d_idx] -= an * nz


class SurfacePressure(Equation):
    """p = 0 and dp/dt = 0 on free-surface particles (the dynamic free-surface condition,
    imposed; not in Adepu & Ramachandran 2021).  No sources: after the pressure rate."""

    def __init__(self, dest, sources=None):
        super().__init__(dest, None)

    def initialize(self, d_idx, d_p, d_ap, d_free_surface):
        if d_free_surface[d_idx] > 0.5:
            d_p[d_idx] = 0.0
            d_ap[d_idx] = 0.0
