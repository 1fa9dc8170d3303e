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
from sphgen.linalg import dev3, inv3, matmul3, transpose3

from .shtc_velocity_gradient import moment_inverse

MODELS = {"dprz": 0, "neo-hookean": 1}


@helper
def right_gram(a=[0.0], out=[0.0]):
    """out = A^T A (the metric G of Kincl et al. (2023), eq. 15)."""
    t = declare("matrix(9)")
    transpose3(a, t)
    matmul3(t, a, out)


@helper
def left_inverse_gram(a=[0.0], out=[0.0]):
    """out = A^-1 A^-T (the B of the neo-Hookean energy, eq. 17); returns det A."""
    ai = declare("matrix(9)")
    t = declare("matrix(9)")
    d = inv3(a, ai)
    transpose3(ai, t)
    matmul3(ai, t, out)
    return d


@helper
def shear_stress(a=[0.0], model=0, out=[0.0]):
    """out = A^T eps_A / cs^2 (symmetric): DPRZ G dev G with G = A^T A (Kincl et al. (2023)
    eq. 16); neo-Hookean I - A^-1 A^-T (eq. 18 with the left Cauchy-Green tensor A^-1 A^-T)."""
    g = declare("matrix(9)")
    e = declare("matrix(9)")
    if model == 0:
        right_gram(a, g)
        dev3(g, e)
        matmul3(g, e, out)
    else:
        left_inverse_gram(a, g)
        for i in range(9):
            out[i] = -g[i]
        out[0] += 1.0
        out[4] += 1.0
        out[8] += 1.0


@helper
def shear_force(a=[0.0], model=0, out=[0.0]):
    """out = eps_A / cs^2, the derivative of the shear energy by A: DPRZ A dev(A^T A);
    neo-Hookean A^-T (I - A^-1 A^-T), i.e. A^-T times :func:`shear_stress`."""
    s = declare("matrix(9)")
    b = declare("matrix(9)")
    t = declare("matrix(9)")
    if model == 0:
        right_gram(a, s)
        dev3(s, s)
        matmul3(a, s, out)
    else:
        shear_stress(a, model, s)
        inv3(a, b)
        transpose3(b, t)
        matmul3(t, s, out)


@helper
def shear_energy(a=[0.0], model=0):
    """eps_s / cs^2: DPRZ |dev(A^T A)|_F^2 / 4 (eq. 15); neo-Hookean (tr B - 3 + 2 ln det A)/2 (eq. 17)."""
    g = declare("matrix(9)")
    if model == 0:
        right_gram(a, g)
        dev3(g, g)
        s = 0.0
        for i in range(9):
            s += g[i] * g[i]
        return 0.25 * s
    d = left_inverse_gram(a, g)
    return 0.5 * (g[0] + g[4] + g[8] - 3.0 + 2.0 * log(d))


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
