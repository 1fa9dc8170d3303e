"""The kernel moment H and the renormalised velocity gradient L of SHTC-SPH.

H_a = sum_b m_b x_ab (x) grad w_ab (Kincl, Peshkov, Pavelka & Klika (2023), eq. 10) and
L_a = (sum_b m_b v_ab (x) grad w_ab) H_a^-1 (eq. 7), both flat 3x3 (stride 9) even in 2D.
In 2D the third row and column of H are zero; its inverse is the inverse of the 2x2 block
with zeros elsewhere (plane strain: nothing varies along z).

H is negative definite when a particle has ``dim`` linearly independent neighbours
(Statement 2 of the paper).  A particle on a chain or alone has a singular H; then
:func:`moment_inverse` regularises it and flags the particle (``hflag`` = 1), so a run that
tears reports the event instead of producing infinities.
"""
from sphgen.equation import Equation, declare, helper
from sphgen.linalg import det3, inv3

SINGULAR_RATIO = 1e-6
"""H counts as singular when det H / (tr H / d)^d < this (1 for an isotropic H, 0 singular)."""

REGULARISATION = 1e-3
"""A singular H is replaced by H + REGULARISATION (tr H / d) I before inverting."""


@helper
def moment_inverse(h=[0.0], out=[0.0], dim=2):
    """out = H^-1 on the first ``dim`` rows/columns (zeros elsewhere); returns 1.0 if H was
    singular (det H / (tr H/d)^d < 1e-6) and H + 1e-3 (tr H/d) I was inverted instead, else 0."""
    for i in range(9):
        out[i] = 0.0
    flag = 0.0
    if dim == 1:
        if h[0] != 0.0:
            out[0] = 1.0 / h[0]
        else:
            flag = 1.0
        return flag
    if dim == 2:
        a = h[0]
        b = h[1]
        c = h[3]
        d = h[4]
        m = 0.5 * (a + d)
        det = a * d - b * c
        if m == 0.0:
            return 1.0
        if det < 1e-6 * m * m:
            a = a + 1e-3 * m
            d = d + 1e-3 * m
            det = a * d - b * c
            flag = 1.0
        out[0] = d / det
        out[1] = -b / det
        out[3] = -c / det
        out[4] = a / det
        return flag
    g = declare("matrix(9)")
    for i in range(9):
        g[i] = h[i]
    m = (g[0] + g[4] + g[8]) / 3.0
    if m == 0.0:
        return 1.0
    # H is negative definite: det < 0 and m < 0, det / m^3 in (0, 1]
    if det3(g) / (m * m * m) < 1e-6:
        g[0] += 1e-3 * m
        g[4] += 1e-3 * m
        g[8] += 1e-3 * m
        flag = 1.0
    inv3(g, out)
    return flag


class KernelMoment(Equation):
    """H_a = sum_b m_b x_ab (x) grad w_ab (Kincl, Peshkov, Pavelka & Klika (2023), eq. 10)."""

    def initialize(self, d_idx, d_H):
        for i in range(9):
            d_H[9 * d_idx + i] = 0.0

    def loop(self, d_idx, d_H, s_idx, s_m, XIJ, DWIJ):
        mb = s_m[s_idx]
        for i in range(3):
            for j in range(3):
                d_H[9 * d_idx + 3 * i + j] += mb * XIJ[i] * DWIJ[j]


class RenormalisedVelocityGradient(Equation):
    """L_a = (sum_b m_b v_ab (x) grad w_ab) H_a^-1 (Kincl, Peshkov, Pavelka & Klika (2023), eq. 7).

    Writes H too (it is the same neighbour sum); ``hflag`` = 1 where H was singular.
    """

    switches = ("dim",)

    def initialize(self, d_idx, d_H, d_L):
        for i in range(9):
            d_H[9 * d_idx + i] = 0.0
            d_L[9 * d_idx + i] = 0.0

    def loop(self, d_idx, d_H, d_L, s_idx, s_m, XIJ, VIJ, DWIJ):
        mb = s_m[s_idx]
        for i in range(3):
            for j in range(3):
                d_H[9 * d_idx + 3 * i + j] += mb * XIJ[i] * DWIJ[j]
                d_L[9 * d_idx + 3 * i + j] += mb * VIJ[i] * DWIJ[j]

    def post_loop(self, d_idx, d_H, d_L, d_hflag):
        h = declare("matrix(9)")
        hi = declare("matrix(9)")
        g = declare("matrix(9)")
        for i in range(9):
            h[i] = d_H[9 * d_idx + i]
            g[i] = d_L[9 * d_idx + i]
        d_hflag[d_idx] = moment_inverse(h, hi, self.dim)
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += g[3 * i + k] * hi[3 * k + j]
                d_L[9 * d_idx + 3 * i + j] = s



class BodyGradientVelocity(Equation):
    """v_g = v for a body particle: the velocity that :class:`GhostVelocityGradient` reads."""

    def initialize(self, d_idx, d_u, d_v, d_w, d_ug, d_vg, d_wg):
        d_ug[d_idx] = d_u[d_idx]
        d_vg[d_idx] = d_v[d_idx]
        d_wg[d_idx] = d_w[d_idx]


class WallGradientVelocity(Equation):
    """v_g = 2 v_w - sum_f v_f w_wf / sum_f w_wf of a dummy-wall particle with prescribed velocity
    v_w (Adami, Hu & Adams (2012), eqs. 22-23), or v_w where no body particle is in reach: the
    body's velocity field continued linearly through the wall, for L only.  dest: a wall,
    sources: the bodies."""

    def initialize(self, d_idx, d_ug, d_vg, d_wg, d_wij):
        d_ug[d_idx] = 0.0
        d_vg[d_idx] = 0.0
        d_wg[d_idx] = 0.0
        d_wij[d_idx] = 0.0

    def loop(self, d_idx, d_ug, d_vg, d_wg, d_wij, s_idx, s_u, s_v, s_w, WIJ):
        d_ug[d_idx] += s_u[s_idx] * WIJ
        d_vg[d_idx] += s_v[s_idx] * WIJ
        d_wg[d_idx] += s_w[s_idx] * WIJ
        d_wij[d_idx] += WIJ

    def post_loop(self, d_idx, d_u, d_v, d_w, d_ug, d_vg, d_wg, d_wij):
        s = d_wij[d_idx]
        if s > 0.0:
            d_ug[d_idx] = 2.0 * d_u[d_idx] - d_ug[d_idx] / s
            d_vg[d_idx] = 2.0 * d_v[d_idx] - d_vg[d_idx] / s
            d_wg[d_idx] = 2.0 * d_w[d_idx] - d_wg[d_idx] / s
        else:
            d_ug[d_idx] = d_u[d_idx]
            d_vg[d_idx] = d_v[d_idx]
            d_wg[d_idx] = d_w[d_idx]


class GhostVelocityGradient(RenormalisedVelocityGradient):
    """L_a = (sum_b m_b (v_g,a - v_g,b) (x) grad w_ab) H_a^-1: eq. 7 of Kincl, Peshkov, Pavelka &
    Klika (2023) on the velocities v_g of :class:`BodyGradientVelocity` and
    :class:`WallGradientVelocity` (walls whose velocity is extrapolated from the bodies)."""

    def loop(self, d_idx, d_H, d_L, d_ug, d_vg, d_wg, s_idx, s_m, s_ug, s_vg, s_wg, XIJ, DWIJ):
        mb = s_m[s_idx]
        vij = declare("matrix(3)")
        vij[0] = d_ug[d_idx] - s_ug[s_idx]
        vij[1] = d_vg[d_idx] - s_vg[s_idx]
        vij[2] = d_wg[d_idx] - s_wg[s_idx]
        for i in range(3):
            for j in range(3):
                d_H[9 * d_idx + 3 * i + j] += mb * XIJ[i] * DWIJ[j]
                d_L[9 * d_idx + 3 * i + j] += mb * vij[i] * DWIJ[j]
