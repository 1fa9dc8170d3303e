"""Energy, pressure and the stress-like tensor T of SHTC-SPH, and the reversible force.

Internal energy eps(rho, A) = eps_0(rho) + eps_s(A) (Kincl, Peshkov, Pavelka & Klika (2023),
sec. 3.4): bulk eps_0 = c0^2/2 (rho0/rho - 1)^2 (eq. 13), pressure p = c0^2 rho0 (1 - rho0/rho)
(eq. 14); shear energy ``model`` 0 = DPRZ, eps_s = cs^2/4 |dev(A^T A)|_F^2 (eq. 15), or
1 = neo-Hookean, eps_s = cs^2/2 (tr B - 3 + 2 ln det A) (eq. 17) with B = A^-1 A^-T.

The paper's stress (18) writes B = A^-T A^-1; that has the same trace (so the same energy)
but is not the tensor A^T eps_A: the derivative of (17) is A^T eps_A = -cs^2 (A^-1 A^-T - I),
which is what the energy identity needs (tests/test_shtc.py checks it to round-off).

Tensors are flat 3x3 (stride 9), the deviator uses tr/3 of the 3x3 tensor also in 2D
(plane strain, A_33 = 1 initially and changed only by relaxation).
"""
from math import log

from sphgen.equation import Equation, declare, helper

from .shtc_velocity_gradient import moment_inverse

MODELS = {"dprz": 0, "neo-hookean": 1}


@helper
def inverse3(a=[0.0], out=[0.0]):
    """out = a^-1 of a 3x3 matrix; returns det a."""
    d = (a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
         + a[2] * (a[3] * a[7] - a[4] * a[6]))
    r = 1.0 / d
    out[0] = (a[4] * a[8] - a[5] * a[7]) * r
    out[1] = (a[2] * a[7] - a[1] * a[8]) * r
    out[2] = (a[1] * a[5] - a[2] * a[4]) * r
    out[3] = (a[5] * a[6] - a[3] * a[8]) * r
    out[4] = (a[0] * a[8] - a[2] * a[6]) * r
    out[5] = (a[2] * a[3] - a[0] * a[5]) * r
    out[6] = (a[3] * a[7] - a[4] * a[6]) * r
    out[7] = (a[1] * a[6] - a[0] * a[7]) * r
    out[8] = (a[0] * a[4] - a[1] * a[3]) * r
    return d


@helper
def shear_stress(a=[0.0], model=0, out=[0.0]):
    """out = A^T eps_A / cs^2 (symmetric): DPRZ G dev G with G = A^T A (Kincl et al. (2023)
    eq. 16); neo-Hookean I - A^-1 A^-T (eq. 18 with the left Cauchy-Green tensor A^-1 A^-T)."""
    g = declare("matrix(9)")
    e = declare("matrix(9)")
    if model == 0:
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += a[3 * k + i] * a[3 * k + j]
                g[3 * i + j] = s
        tr = (g[0] + g[4] + g[8]) / 3.0
        for i in range(9):
            e[i] = g[i]
        e[0] -= tr
        e[4] -= tr
        e[8] -= tr
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += g[3 * i + k] * e[3 * k + j]
                out[3 * i + j] = s
    else:
        inverse3(a, g)
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += g[3 * i + k] * g[3 * j + k]
                out[3 * i + j] = -s
        out[0] += 1.0
        out[4] += 1.0
        out[8] += 1.0


@helper
def shear_force(a=[0.0], model=0, out=[0.0]):
    """out = eps_A / cs^2, the derivative of the shear energy by A: DPRZ A dev(A^T A);
    neo-Hookean A^-T (I - A^-1 A^-T), i.e. A^-T times :func:`shear_stress`."""
    s = declare("matrix(9)")
    b = declare("matrix(9)")
    if model == 0:
        for i in range(3):
            for j in range(3):
                t = 0.0
                for k in range(3):
                    t += a[3 * k + i] * a[3 * k + j]
                s[3 * i + j] = t
        t = (s[0] + s[4] + s[8]) / 3.0
        s[0] -= t
        s[4] -= t
        s[8] -= t
        for i in range(3):
            for j in range(3):
                t = 0.0
                for k in range(3):
                    t += a[3 * i + k] * s[3 * k + j]
                out[3 * i + j] = t
    else:
        shear_stress(a, model, s)
        inverse3(a, b)
        for i in range(3):
            for j in range(3):
                t = 0.0
                for k in range(3):
                    t += b[3 * k + i] * s[3 * k + j]
                out[3 * i + j] = t


@helper
def shear_energy(a=[0.0], model=0):
    """eps_s / cs^2: DPRZ |dev(A^T A)|_F^2 / 4 (eq. 15); neo-Hookean (tr B - 3 + 2 ln det A)/2 (eq. 17)."""
    g = declare("matrix(9)")
    if model == 0:
        for i in range(3):
            for j in range(3):
                s = 0.0
                for k in range(3):
                    s += a[3 * k + i] * a[3 * k + j]
                g[3 * i + j] = s
        tr = (g[0] + g[4] + g[8]) / 3.0
        g[0] -= tr
        g[4] -= tr
        g[8] -= tr
        s = 0.0
        for i in range(9):
            s += g[i] * g[i]
        return 0.25 * s
    d = inverse3(a, g)
    s = 0.0
    for i in range(9):
        s += g[i] * g[i]
    return 0.5 * (s - 3.0 + 2.0 * log(d))


class SHTCStress(Equation):
    """p_a = c0^2 rho0 (1 - rho0/rho_a) and T_a = -p_a/rho_a^2 I + A_a^T eps_A H_a^-1
    (Kincl, Peshkov, Pavelka & Klika (2023), eqs. 10, 14, 16, 18).

    A post_loop: put it in the group that sums rho and H, after them.  ``hflag`` = 1 where H
    was singular and regularised (see :func:`moment_inverse`).
    """

    switches = ("dim", "model", "cs")
    positive = ("rho0", "c0")
    nonnegative = ("cs",)

    def post_loop(self, d_idx, d_rho, d_p, d_A, d_H, d_T, d_hflag):
        a = declare("matrix(9)")
        h = declare("matrix(9)")
        hi = declare("matrix(9)")
        s = declare("matrix(9)")
        rho = d_rho[d_idx]
        p = self.c0 * self.c0 * self.rho0 * (1.0 - self.rho0 / rho)
        d_p[d_idx] = p
        for i in range(9):
            a[i] = d_A[9 * d_idx + i]
            h[i] = d_H[9 * d_idx + i]
        d_hflag[d_idx] = moment_inverse(h, hi, self.dim)
        for i in range(9):
            s[i] = 0.0
        if self.cs != 0.0:
            shear_stress(a, self.model, s)
        cs2 = self.cs * self.cs
        for i in range(3):
            for j in range(3):
                t = 0.0
                for k in range(3):
                    t += s[3 * i + k] * hi[3 * k + j]
                d_T[9 * d_idx + 3 * i + j] = cs2 * t
        d_T[9 * d_idx] -= p / (rho * rho)
        d_T[9 * d_idx + 4] -= p / (rho * rho)
        d_T[9 * d_idx + 8] -= p / (rho * rho)


class SHTCMomentum(Equation):
    """dv_a/dt = sum_b m_b (T_a + T_b) grad w_ab (Kincl, Peshkov, Pavelka & Klika (2023), eq. 12)."""

    def initialize(self, d_idx, d_au, d_av, d_aw):
        d_au[d_idx] = 0.0
        d_av[d_idx] = 0.0
        d_aw[d_idx] = 0.0

    def loop(self, d_idx, d_au, d_av, d_aw, d_T, s_idx, s_m, s_T, DWIJ):
        mb = s_m[s_idx]
        i0 = declare("long")
        j0 = declare("long")
        i0 = 9 * d_idx
        j0 = 9 * s_idx
        d_au[d_idx] += mb * ((d_T[i0] + s_T[j0]) * DWIJ[0] + (d_T[i0 + 1] + s_T[j0 + 1]) * DWIJ[1]
                             + (d_T[i0 + 2] + s_T[j0 + 2]) * DWIJ[2])
        d_av[d_idx] += mb * ((d_T[i0 + 3] + s_T[j0 + 3]) * DWIJ[0] + (d_T[i0 + 4] + s_T[j0 + 4]) * DWIJ[1]
                             + (d_T[i0 + 5] + s_T[j0 + 5]) * DWIJ[2])
        d_aw[d_idx] += mb * ((d_T[i0 + 6] + s_T[j0 + 6]) * DWIJ[0] + (d_T[i0 + 7] + s_T[j0 + 7]) * DWIJ[1]
                             + (d_T[i0 + 8] + s_T[j0 + 8]) * DWIJ[2])
