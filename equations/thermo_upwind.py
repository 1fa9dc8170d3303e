"""Upwind Total Lagrangian SPH for thermo-elasticity: Ghavamian et al. (2021), secs. 4-5.

Every pair loop runs in a reference group: neighbours fixed at t = 0, pair geometry from
X = (x0, y0, z0).  With V the reference volume, DWIJ = grad W(X_a - X_b) and L_a the
correction matrix (eq. 52), the pair vectors of eq. 53 are

    C_ab = 2 V_a V_b L_a DWIJ,      C_ba = -2 V_a V_b L_b DWIJ,

and V_a grad f_a = sum_b (f_b - f_a) (x) C_ab / 2 is exact for linear f.  Rates are per
unit reference volume: ``tint`` is the internal force T_a / V_a (eq. 55), ``aF`` = grad v
(eq. 54b), ``aH`` = F x grad v (54c), ``aJ`` = H : grad v + sum D_J / V (54d), ``aE``
(54e) or ``aeta`` (57).  External terms enter through the per-volume body force ``fb``
(f_R + A_R t_B / V) and heat supply ``sb`` (s_R - A_R Q_B / V).

The dissipation (eqs. 66, 72-75) is S_ab times the jump of an entropy variable: v/Xi and
Sigma_J/Xi in the E-form (Xi = theta/theta_R), v and Sigma_J in the eta-form; S^eta = 0
and S^E = 0 or (``se``) eq. 76, guarded.  ``reconstruct`` replaces the raw jump by a
limited linear reconstruction (docs/thermo.md): zero for linear fields, and raw x used >= 0 per component so
the semi-discrete entropy inequality is kept.
"""
from math import fabs, log, sqrt  # noqa: F401  (the Python evaluator's math)

import numpy as np

from sphgen.equation import Equation, declare, helper
from sphgen.linalg import det3, inv3

from .large_strain import cross33, ddot33, dot3, matvec3, tmatvec3
from .thermo_materials import (conjugate_stresses, energy_from_temperature, entropy_from_temperature,
                               first_piola, isochoric_conjugates, temperature_from_energy,
                               temperature_from_entropy, wave_speeds)

E_FORM, ETA_FORM = 0, 1


@helper
def minmod(a=0.0, b=0.0):
    """The one of a, b closer to zero if they have the same sign, else 0."""
    if a * b <= 0.0:
        return 0.0
    if fabs(a) < fabs(b):
        return a
    return b


@helper
def load_tensor(src=[0.0], i=0, out=[0.0]):
    """out = the 3x3 tensor of particle i of a stride-9 property."""
    for k in range(9):
        out[k] = src[9 * i + k]


@helper
def load_vector(src=[0.0], i=0, out=[0.0]):
    """out = the 3-vector of particle i of a stride-3 property."""
    for k in range(3):
        out[k] = src[3 * i + k]


class CorrectionMatrix(Equation):
    """L_a = (sum_b V_b grad W_b(X_a) (x) (X_b - X_a))^-1, Ghavamian et al. (2021) eq. 52."""

    def initialize(self, d_idx, d_L):
        for k in range(9):
            d_L[9 * d_idx + k] = 0.0

    def loop(self, d_idx, d_L, s_idx, s_V, DWIJ, XIJ):
        for i in range(3):
            for k in range(3):
                d_L[9 * d_idx + 3 * i + k] -= s_V[s_idx] * DWIJ[i] * XIJ[k]

    def post_loop(self, d_idx, d_L):
        m = declare("matrix(9)")
        mi = declare("matrix(9)")
        load_tensor(d_L, d_idx, m)
        inv3(m, mi)
        for k in range(9):
            d_L[9 * d_idx + k] = mi[k]


class ThermoState(Equation):
    """Temperature (eq. 23 E-form, eq. 20 eta-form), the other thermal variable, Sigma_J and
    P (eqs. 10, 12) and the pressure -tr(J^-1 P F^T)/3, Ghavamian et al. (2021).

    ``reduced``: the {p, F, H, E} scheme, J = det F (no J equation).  ``SD`` is the stress
    the J dissipation jumps: Sigma_J (the paper's, eq. 66), or with ``volumetric`` the mean
    stress varsigma = (Sigma_F : F + 2 Sigma_H : H + 3 J Sigma_J) / (3 J) (= P : F / 3J, the
    conjugate of an isotropic change of F, H, J together; docs/thermo.md), or with
    ``volumetric`` 2 the volumetric part of Sigma_J, Sigma_J minus d/dJ of the isochoric terms
    (a diagnostic of docs/thermo.md, round 10: not an entropy conjugate).
    """

    switches = ("model", "form", "reduced", "volumetric")

    def initialize(self, d_idx, d_u, d_v, d_w, d_rho, d_F, d_H, d_J, d_E, d_eta, d_theta, d_P,
                   d_SJ, d_SD, d_p, d_mat):
        F = declare("matrix(9)")
        H = declare("matrix(9)")
        SF = declare("matrix(9)")
        SH = declare("matrix(9)")
        P = declare("matrix(9)")
        load_tensor(d_F, d_idx, F)
        load_tensor(d_H, d_idx, H)
        if self.reduced:
            J = det3(F)
            d_J[d_idx] = J
        else:
            J = d_J[d_idx]
        kin = 0.5 * d_rho[d_idx] * (d_u[d_idx] * d_u[d_idx] + d_v[d_idx] * d_v[d_idx]
                                    + d_w[d_idx] * d_w[d_idx])
        if self.form == 0:
            theta = temperature_from_energy(self.model, d_E[d_idx], kin, F, H, J, d_mat)
            d_eta[d_idx] = 0.0
            if theta > 0.0:    # else the integrator's guard stops the run
                d_eta[d_idx] = entropy_from_temperature(self.model, theta, F, H, J, d_mat)
        else:
            theta = temperature_from_entropy(self.model, d_eta[d_idx], F, H, J, d_mat)
            d_E[d_idx] = energy_from_temperature(self.model, theta, kin, F, H, J, d_mat)
        d_theta[d_idx] = theta
        sj = conjugate_stresses(self.model, F, H, J, theta, d_mat, SF, SH)
        first_piola(F, H, SF, SH, sj, P)
        d_SJ[d_idx] = sj
        d_SD[d_idx] = sj
        if self.volumetric == 1:
            d_SD[d_idx] = (ddot33(SF, F) + 2.0 * ddot33(SH, H)) / (3.0 * J) + sj
        elif self.volumetric == 2 and self.model != 2:
            iso = isochoric_conjugates(F, H, J, d_mat[2], d_mat[3], SF, SH)
            if self.model == 1:
                iso = iso * theta / d_mat[7]
            d_SD[d_idx] = sj - iso
        for k in range(9):
            d_P[9 * d_idx + k] = P[k]
        d_p[d_idx] = -ddot33(P, F) / (3.0 * J)


class WaveSpeeds(Equation):
    """p- and s-wave speeds at the particle temperature and the step limit h_min / c_p
    (eq. 78 with alpha_CFL applied by the solver), Ghavamian et al. (2021)."""

    switches = ("model",)
    positive = ("hmin",)

    def initialize(self, d_idx, d_theta, d_cp, d_cs, d_dt_cfl, d_mat):
        c = declare("matrix(2)")
        wave_speeds(self.model, d_theta[d_idx], d_mat, c)
        d_cp[d_idx] = c[0]
        d_cs[d_idx] = c[1]
        d_dt_cfl[d_idx] = self.hmin / c[0]


class EntropyVariableGradients(Equation):
    """grad theta and the heat flux Q = -K grad theta, K = k J^-1 H^T H (eq. 56), with the
    gradient of eq. 53; with ``reconstruct`` also the gradients of the entropy variables
    the dissipation jumps (v/Xi, Sigma_J/Xi in the E-form; v, Sigma_J in the eta-form),
    Ghavamian et al. (2021)."""

    switches = ("form", "reconstruct")

    def initialize(self, d_idx, d_gradT, d_gw, d_gs):
        for k in range(3):
            d_gradT[3 * d_idx + k] = 0.0
            if self.reconstruct:
                d_gs[3 * d_idx + k] = 0.0
        if self.reconstruct:
            for k in range(9):
                d_gw[9 * d_idx + k] = 0.0

    def loop(self, d_idx, d_L, d_theta, d_u, d_v, d_w, d_SD, d_gradT, d_gw, d_gs, d_mat,
             s_idx, s_V, s_theta, s_u, s_v, s_w, s_SD, DWIJ):
        L = declare("matrix(9)")
        g = declare("matrix(3)")
        jw = declare("matrix(3)")
        load_tensor(d_L, d_idx, L)
        matvec3(L, DWIJ, g)
        vb = s_V[s_idx]
        dT = s_theta[s_idx] - d_theta[d_idx]
        for k in range(3):
            d_gradT[3 * d_idx + k] += vb * dT * g[k]
        if self.reconstruct:
            ra = 1.0
            rb = 1.0
            if self.form == 0:
                ra = d_mat[7] / d_theta[d_idx]
                rb = d_mat[7] / s_theta[s_idx]
            jw[0] = s_u[s_idx] * rb - d_u[d_idx] * ra
            jw[1] = s_v[s_idx] * rb - d_v[d_idx] * ra
            jw[2] = s_w[s_idx] * rb - d_w[d_idx] * ra
            js = s_SD[s_idx] * rb - d_SD[d_idx] * ra
            for i in range(3):
                d_gs[3 * d_idx + i] += vb * js * g[i]
                for k in range(3):
                    d_gw[9 * d_idx + 3 * i + k] += vb * jw[i] * g[k]

    def post_loop(self, d_idx, d_gradT, d_Q, d_H, d_J, d_mat):
        H = declare("matrix(9)")
        g = declare("matrix(3)")
        hg = declare("matrix(3)")
        q = declare("matrix(3)")
        load_tensor(d_H, d_idx, H)
        load_vector(d_gradT, d_idx, g)
        matvec3(H, g, hg)
        tmatvec3(H, hg, q)
        f = -d_mat[9] / d_J[d_idx]
        for k in range(3):
            d_Q[3 * d_idx + k] = f * q[k]


class UpwindFluxes(Equation):
    """Pair sums of eqs. 54a-e (E-form) or 54a-d and 57 (eta-form), with the upwind
    dissipation D_p and D_J of eqs. 66/72 and coefficients 73-75, Ghavamian et al. (2021).

    ``dissipation`` 0 switches the upwinding off, 2 keeps D_p only (an ablation: no D_J);
    ``external`` 0 drops f_R, t_B, s_R, Q_B;
    ``reduced`` drops the J equation (J = det F);
    ``volumetric``: D_J on the jump of the mean stress SD, applied as the isotropic rate
    delta = sum_b D_J^ab / V to J, F and H together (J += delta, F += delta F / 3J,
    H += 2 delta H / 3J), so that J stays det F (not the paper's; docs/thermo.md);
    ``se`` 1 adds D_E^ab = S^E_ab (1/Xi_a - 1/Xi_b) of eq. 66 with S^E of eq. 76 (E-form;
    guarded and capped, docs/thermo.md), 0 keeps S^E = 0.
    """

    switches = ("form", "reconstruct", "reduced", "dissipation", "external", "volumetric", "se")

    def initialize(self, d_idx, d_tint, d_aF, d_aJ, d_aE, d_aeta):
        for k in range(3):
            d_tint[3 * d_idx + k] = 0.0
        for k in range(9):
            d_aF[9 * d_idx + k] = 0.0
        if not self.reduced:
            d_aJ[d_idx] = 0.0
        if self.form == 0:
            d_aE[d_idx] = 0.0
        else:
            d_aeta[d_idx] = 0.0

    def loop(self, d_idx, d_V, d_L, d_P, d_H, d_u, d_v, d_w, d_theta, d_Q, d_SD, d_rho, d_cp, d_cs,
             d_gw, d_gs, d_mat, d_tint, d_aF, d_aJ, d_aE, d_aeta,
             s_idx, s_V, s_L, s_P, s_H, s_u, s_v, s_w, s_theta, s_Q, s_SD, s_rho, s_cp, s_cs,
             s_gw, s_gs, DWIJ, XIJ):
        A = declare("matrix(9)")
        la = declare("matrix(3)")
        lb = declare("matrix(3)")
        cab = declare("matrix(3)")
        cba = declare("matrix(3)")
        pa = declare("matrix(3)")
        pb = declare("matrix(3)")
        va = declare("matrix(3)")
        vbb = declare("matrix(3)")
        qa = declare("matrix(3)")
        qb = declare("matrix(3)")
        csk = declare("matrix(3)")
        ha = declare("matrix(3)")
        hb = declare("matrix(3)")
        jv = declare("matrix(3)")
        rec = declare("matrix(3)")
        used = declare("matrix(3)")
        vv = d_V[d_idx] * s_V[s_idx]
        load_tensor(d_L, d_idx, A)
        matvec3(A, DWIJ, la)
        load_tensor(s_L, s_idx, A)
        matvec3(A, DWIJ, lb)
        for k in range(3):
            cab[k] = 2.0 * vv * la[k]
            cba[k] = -2.0 * vv * lb[k]
        load_tensor(d_P, d_idx, A)
        matvec3(A, cab, pa)
        load_tensor(s_P, s_idx, A)
        matvec3(A, cba, pb)
        va[0] = d_u[d_idx]
        va[1] = d_v[d_idx]
        va[2] = d_w[d_idx]
        vbb[0] = s_u[s_idx]
        vbb[1] = s_v[s_idx]
        vbb[2] = s_w[s_idx]
        for i in range(3):
            d_tint[3 * d_idx + i] += 0.5 * (pa[i] - pb[i])
            for k in range(3):
                d_aF[9 * d_idx + 3 * i + k] += 0.5 * (vbb[i] - va[i]) * cab[k]
        tha = d_theta[d_idx]
        thb = s_theta[s_idx]
        load_vector(d_Q, d_idx, qa)
        load_vector(s_Q, s_idx, qb)
        if self.form == 0:
            d_aE[d_idx] += 0.5 * (dot3(pa, vbb) - dot3(pb, va)) - 0.5 * (
                dot3(qa, cab) * thb / tha - dot3(qb, cba) * tha / thb)
        else:
            d_aeta[d_idx] -= 0.5 * (dot3(qa, cab) / tha - dot3(qb, cba) / thb)
        if self.dissipation:
            # C^Skew, c^Skew = (H_a C_ab - H_b C_ba)/2 and n^Skew (eqs. 73-75)
            for k in range(3):
                csk[k] = vv * (la[k] + lb[k])
            nC = sqrt(dot3(csk, csk))
            load_tensor(d_H, d_idx, A)
            matvec3(A, la, ha)
            load_tensor(s_H, s_idx, A)
            matvec3(A, lb, hb)
            for k in range(3):
                csk[k] = vv * (ha[k] + hb[k])
            nc = sqrt(dot3(csk, csk))
            if nC > 1e-300 and nc > 1e-300:
                ra = 1.0
                rb = 1.0
                if self.form == 0:
                    ra = d_mat[7] / tha
                    rb = d_mat[7] / thb
                for k in range(3):
                    csk[k] = csk[k] / nc
                    jv[k] = vbb[k] * rb - va[k] * ra
                js = s_SD[s_idx] * rb - d_SD[d_idx] * ra
                jn = dot3(jv, csk)
                if self.reconstruct:
                    # linear reconstruction at the pair midpoint, limited (docs/thermo.md)
                    for i in range(3):
                        rec[i] = jv[i]
                        for k in range(3):
                            rec[i] += 0.5 * (d_gw[9 * d_idx + 3 * i + k] + s_gw[9 * s_idx + 3 * i + k]) * XIJ[k]
                    rn = dot3(rec, csk)
                    for k in range(3):
                        jv[k] = jv[k] - jn * csk[k]
                        rec[k] = rec[k] - rn * csk[k]
                    jn = minmod(jn, rn)
                    dtr = dot3(jv, rec)
                    fac = 0.0
                    if dtr > 0.0:
                        fac = sqrt(dot3(jv, jv) / dot3(rec, rec))
                        if fac > 1.0:
                            fac = 1.0
                    for k in range(3):
                        used[k] = fac * rec[k]
                    rs = js
                    for k in range(3):
                        rs += 0.5 * (d_gs[3 * d_idx + k] + s_gs[3 * s_idx + k]) * XIJ[k]
                    js = minmod(js, rs)
                else:
                    for k in range(3):
                        used[k] = jv[k] - jn * csk[k]
                rho = 0.5 * (d_rho[d_idx] + s_rho[s_idx])
                cp = 0.5 * (d_cp[d_idx] + s_cp[s_idx])
                cs = 0.5 * (d_cs[d_idx] + s_cs[s_idx])
                f = 0.5 * rho * nC
                for k in range(3):
                    d_tint[3 * d_idx + k] += f * (cp * jn * csk[k] + cs * used[k])
                if not self.reduced and self.dissipation == 1:
                    d_aJ[d_idx] += nc * nc / (2.0 * rho * cp * nC) * js
                if self.se == 1 and self.form == 0:
                    # S^E of eq. 76 from the raw jumps, guarded (docs/thermo.md): 0 where
                    # 1/Xi_a = 1/Xi_b (0/0) or where the bracket is negative, capped at the
                    # pair's conductance theta_R k ||C^Skew|| / |X_a - X_b|
                    dxi = ra - rb
                    if fabs(dxi) > 1e-12 * ra:
                        for k in range(3):
                            rec[k] = vbb[k] - va[k]
                            used[k] = vbb[k] * rb - va[k] * ra
                        rn = dot3(rec, csk)
                        jn = dot3(used, csk)
                        brk = f * (cp * rn * rn + cs * (dot3(rec, rec) - rn * rn)) - f * (
                            cp * jn * jn + cs * (dot3(used, used) - jn * jn))
                        if not self.reduced and self.dissipation == 1:
                            rs = s_SD[s_idx] - d_SD[d_idx]
                            js = s_SD[s_idx] * rb - d_SD[d_idx] * ra
                            brk += nc * nc / (2.0 * rho * cp * nC) * (rs * rs - js * js)
                        if brk > 0.0:
                            sE = brk / (dxi * dxi)
                            cap = d_mat[7] * d_mat[9] * nC / sqrt(dot3(XIJ, XIJ))
                            if sE > cap:
                                sE = cap
                            d_aE[d_idx] += sE * dxi

    def post_loop(self, d_idx, d_V, d_F, d_H, d_J, d_u, d_v, d_w, d_theta, d_Q, d_gradT, d_fb, d_sb,
                  d_tint, d_aF, d_aH, d_aJ, d_aE, d_aeta):
        G = declare("matrix(9)")
        F = declare("matrix(9)")
        R = declare("matrix(9)")
        vi = 1.0 / d_V[d_idx]
        for k in range(9):
            G[k] = d_aF[9 * d_idx + k] * vi
            d_aF[9 * d_idx + k] = G[k]
        for k in range(3):
            d_tint[3 * d_idx + k] *= vi
        load_tensor(d_F, d_idx, F)
        cross33(F, G, R)
        for k in range(9):
            d_aH[9 * d_idx + k] = R[k]
        if not self.reduced:
            dj = d_aJ[d_idx] * vi
            if self.volumetric:
                f = dj / (3.0 * d_J[d_idx])
                for k in range(9):
                    d_aF[9 * d_idx + k] += f * F[k]
                    d_aH[9 * d_idx + k] += 2.0 * f * d_H[9 * d_idx + k]
            load_tensor(d_H, d_idx, F)
            d_aJ[d_idx] = ddot33(F, G) + dj
        if self.form == 0:
            d_aE[d_idx] *= vi
            if self.external:
                d_aE[d_idx] += (d_fb[3 * d_idx] * d_u[d_idx] + d_fb[3 * d_idx + 1] * d_v[d_idx]
                                + d_fb[3 * d_idx + 2] * d_w[d_idx] + d_sb[d_idx])
        else:
            th = d_theta[d_idx]
            qg = (d_Q[3 * d_idx] * d_gradT[3 * d_idx] + d_Q[3 * d_idx + 1] * d_gradT[3 * d_idx + 1]
                  + d_Q[3 * d_idx + 2] * d_gradT[3 * d_idx + 2])
            d_aeta[d_idx] = d_aeta[d_idx] * vi - qg / (th * th)
            if self.external:
                d_aeta[d_idx] += d_sb[d_idx] / th


class AngularMomentumProjection(Equation):
    """The least-squares correction of the internal forces that conserves linear and angular
    momentum, Ghavamian et al. (2021) eqs. 79-82, read per unit reference volume:
    t^_a = t_a + lambda_ang x X_a + lambda_lin with sum V t^ = 0 and sum V X x t^ = 0,
    X = ``xc`` (x^n in the first Runge-Kutta stage, the predicted x^{n+1} in the second).
    It also records in the array constant ``proj`` the stage's power of the correction,
    sum V v . dt^, and (E-form, ``form`` 0) its entropy rate -sum V v . dt^ / theta: E is
    untouched, so the kinetic energy it adds comes out of heat (eta-form: eta is untouched)."""

    switches = ("form",)

    def reduce(self, dst, t, dt):
        V = dst.V
        X = dst.xc.reshape(-1, 3)
        T = dst.tint.reshape(-1, 3)
        lam = projection_multipliers(V, X, T)
        dT = np.cross(lam[:3], X) + lam[3:]
        T += dT
        power = V * np.einsum("ai,ai->a", np.stack([dst.u, dst.v, dst.w], 1), dT)
        dst.proj[0] = float(np.sum(power))
        dst.proj[1] = -float(np.sum(power / dst.theta)) if self.form == 0 else 0.0


def skew(x):
    """The matrix of y -> x cross y, for rows of x: shape (..., 3, 3)."""
    z = np.zeros(np.shape(x)[:-1])
    return np.stack([np.stack([z, -x[..., 2], x[..., 1]], -1),
                     np.stack([x[..., 2], z, -x[..., 0]], -1),
                     np.stack([-x[..., 1], x[..., 0], z], -1)], -2)


def projection_multipliers(V, X, T):
    """(lambda_ang, lambda_lin) solving eq. 82 for volumes V, points X and forces per
    volume T (numpy; a 6x6 dense solve)."""
    xx = np.einsum("a,ai,ai->a", V, X, X)
    M = np.zeros((6, 6))
    M[:3, :3] = np.eye(3) * xx.sum() - np.einsum("a,ai,aj->ij", V, X, X)
    S = np.einsum("a,aij->ij", V, skew(X))
    M[:3, 3:] = S
    M[3:, :3] = S
    M[3:, 3:] = -V.sum() * np.eye(3)
    rhs = np.concatenate([-np.einsum("a,ai->i", V, np.cross(X, T)), V @ T])
    return np.linalg.solve(M, rhs)
