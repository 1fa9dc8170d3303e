"""Thermo-elastic materials of Ghavamian et al. (2021), sec. 2: Mie-Gruneisen, modified
entropic elasticity, and the linear model of their sec. 7.1.

A material is given by two functions of the strain triplet chi = {F, H, J} at the
reference temperature theta_R: the internal energy E_R(chi) and the entropy eta_R(chi)
(eqs. 19, 22).  With a constant heat capacity c_v = rho_R C_v everything else follows:

* temperature from the total energy, eq. 23:  theta = theta_R + (E - |p|^2/(2 rho_R) - E_R)/c_v,
* temperature from the entropy, eq. 20:       theta = theta_R exp((eta - eta_R)/c_v),
* conjugate stresses (eq. 10) at temperature theta:  Sigma_X = dE_R/dX - theta deta_R/dX,
* the first Piola-Kirchhoff stress, eq. 12:   P = Sigma_F + Sigma_H x F + Sigma_J H.

The per-particle functions are restricted Python (``@helper``): the equations call them
compiled, tests and the manufactured solution call them as plain Python.  They take the
material as a vector ``m`` of constants (``ThermoElasticMaterial.constants()``; the
scheme stores it on each body as the array constant ``mat``) and the model index
(0 Mie-Gruneisen, 1 modified entropic elasticity, 2 linear), which the equations fold
into the generated code.

Layout of ``m``: 0 mu, 1 kappa, 2-4 the model's three coefficients (MG: zeta_R, gamma_R,
chi_R; MEE: varsigma_R, xi_R, kappa_R; linear: lambda, 0, 0), 5 c_v, 6 Gamma_0,
7 theta_R, 8 q (MG; 1 otherwise), 9 thermal conductivity k (the paper's h), 10 rho_R.
"""
from math import exp, log, pow, sqrt  # noqa: F401  (the Python evaluator's math)

import numpy as np

from sphgen.equation import declare, helper
from sphgen.errors import InputError

from .large_strain import cross33, ddot33

MIE_GRUNEISEN, ENTROPIC, LINEAR = 0, 1, 2
SQRT27 = 3.0 * sqrt(3.0)


# ------------------------------------------------------------------ restricted Python
@helper
def isochoric_energy(F=[0.0], H=[0.0], J=1.0, c1=0.0, c2=0.0):
    """c1 (J^-2/3 F:F - 3) + c2 (J^-2 (H:H)^3/2 - 3 sqrt 3): the Mooney-Rivlin part of eqs. 28, 30."""
    e = c1 * (pow(J, -2.0 / 3.0) * ddot33(F, F) - 3.0)
    if c2 != 0.0:
        hh = ddot33(H, H)
        e += c2 * (hh * sqrt(hh) / (J * J) - 5.196152422706632)
    return e


@helper
def isochoric_conjugates(F=[0.0], H=[0.0], J=1.0, c1=0.0, c2=0.0, SF=[0.0], SH=[0.0]):
    """Derivatives of ``isochoric_energy``: writes d/dF into SF, d/dH into SH, returns d/dJ."""
    jm23 = pow(J, -2.0 / 3.0)
    ff = ddot33(F, F)
    for i in range(9):
        SF[i] = 2.0 * c1 * jm23 * F[i]
        SH[i] = 0.0
    dj = -2.0 / 3.0 * c1 * jm23 * ff / J
    if c2 != 0.0:
        hh = ddot33(H, H)
        sh = sqrt(hh)
        for i in range(9):
            SH[i] = 3.0 * c2 * sh * H[i] / (J * J)
        dj -= 2.0 * c2 * hh * sh / (J * J * J)
    return dj


@helper
def small_strain(F=[0.0], eps=[0.0]):
    """eps = (F + F^T)/2 - I; returns tr(eps)."""
    for i in range(3):
        for k in range(3):
            eps[3 * i + k] = 0.5 * (F[3 * i + k] + F[3 * k + i])
        eps[4 * i] -= 1.0
    return eps[0] + eps[4] + eps[8]


@helper
def energy_R(model=0, F=[0.0], H=[0.0], J=1.0, m=[0.0]):
    """E_R(F, H, J): internal energy per unit reference volume at theta_R (eqs. 26, 30; sec. 7.1)."""
    eps = declare("matrix(9)")
    cg = m[5] * m[6]
    if model == 2:
        tr = small_strain(F, eps)
        return m[0] * ddot33(eps, eps) + 0.5 * m[2] * tr * tr + cg * m[7] * tr
    e = cg * m[7] * (J - 1.0)
    if model == 1:
        return e
    return e + isochoric_energy(F, H, J, m[2], m[3]) + 0.5 * m[4] * (J - 1.0) * (J - 1.0)


@helper
def entropy_R(model=0, F=[0.0], H=[0.0], J=1.0, m=[0.0]):
    """eta_R(F, H, J): entropy per unit reference volume at theta_R (eqs. 27-28, 31; sec. 7.1)."""
    cg = m[5] * m[6]
    if model == 2:
        return cg * (F[0] + F[4] + F[8] - 3.0)
    if model == 1:
        psi = isochoric_energy(F, H, J, m[2], m[3]) + 0.5 * m[4] * (J - 1.0) * (J - 1.0)
        return cg * (J - 1.0) - psi / m[7]
    if m[8] == 0.0:
        return cg * log(J)
    return cg * (pow(J, m[8]) - 1.0) / m[8]


@helper
def conjugate_stresses(model=0, F=[0.0], H=[0.0], J=1.0, theta=0.0, m=[0.0], SF=[0.0], SH=[0.0]):
    """Sigma_X = dE_R/dX - theta deta_R/dX (eq. 10 with eqs. 19, 22): writes Sigma_F, Sigma_H,
    returns Sigma_J."""
    cg = m[5] * m[6]
    if model == 2:
        tr = small_strain(F, SF)
        for i in range(9):
            SF[i] = 2.0 * m[0] * SF[i]
            SH[i] = 0.0
        for i in range(3):
            SF[4 * i] += m[2] * tr - cg * (theta - m[7])
        return 0.0
    dj = isochoric_conjugates(F, H, J, m[2], m[3], SF, SH)
    if model == 1:
        xi = theta / m[7]
        for i in range(9):
            SF[i] = xi * SF[i]
            SH[i] = xi * SH[i]
        return (1.0 - xi) * cg * m[7] + xi * (dj + m[4] * (J - 1.0))
    return dj + m[4] * (J - 1.0) + cg * (m[7] - theta * pow(J, m[8] - 1.0))


@helper
def first_piola(F=[0.0], H=[0.0], SF=[0.0], SH=[0.0], SJ=0.0, P=[0.0]):
    """P = Sigma_F + Sigma_H x F + Sigma_J H (eq. 12)."""
    cross33(SH, F, P)
    for i in range(9):
        P[i] += SF[i] + SJ * H[i]


@helper
def temperature_from_energy(model=0, E=0.0, kinetic=0.0, F=[0.0], H=[0.0], J=1.0, m=[0.0]):
    """theta = theta_R + (E - |p|^2/(2 rho_R) - E_R)/c_v (eq. 23)."""
    return m[7] + (E - kinetic - energy_R(model, F, H, J, m)) / m[5]


@helper
def temperature_from_entropy(model=0, eta=0.0, F=[0.0], H=[0.0], J=1.0, m=[0.0]):
    """theta = theta_R exp((eta - eta_R)/c_v) (eq. 20)."""
    return m[7] * exp((eta - entropy_R(model, F, H, J, m)) / m[5])


@helper
def wave_speeds(model=0, theta=0.0, m=[0.0], out=[0.0]):
    """Adiabatic small-strain p- and s-wave speeds at temperature theta: out = [c_p, c_s].

    The paper defers them to its refs. 50, 65; linearising at J = 1 at fixed entropy gives
    rho c_p^2 = kappa + c_v Gamma_0 (1 - q)(theta - theta_R) + 4 mu/3 + theta c_v Gamma_0^2
    (Mie-Gruneisen, linear with q = 1) and, for modified entropic elasticity, whose
    elastic moduli scale with theta/theta_R, rho c_p^2 = (kappa + 4 mu/3) theta/theta_R +
    theta c_v Gamma_0^2, rho c_s^2 = mu theta/theta_R.
    """
    cg2 = m[5] * m[6] * m[6]
    if model == 1:
        xi = theta / m[7]
        out[0] = sqrt(((m[1] + 4.0 / 3.0 * m[0]) * xi + theta * cg2) / m[10])
        out[1] = sqrt(m[0] * xi / m[10])
    else:
        bulk = m[1] + m[5] * m[6] * (1.0 - m[8]) * (theta - m[7])
        out[0] = sqrt((bulk + 4.0 / 3.0 * m[0] + theta * cg2) / m[10])
        out[1] = sqrt(m[0] / m[10])


# ------------------------------------------------------------------ the materials
class ThermoElasticMaterial:
    """Calibration from (E_young, nu) by eq. 83, with c_v = rho_R C_v and Gamma_0 = 3 kappa
    alpha / c_v (eqs. 29, 32).  ``k_th`` is the isotropic conductivity (the paper's h)."""

    model = None

    def __init__(self, E_young, nu, rho, Cv, alpha, theta_R, k_th):
        name = type(self).__name__
        checks = (("E_young", E_young, E_young > 0), ("nu", nu, -1.0 < nu < 0.5),
                  ("rho", rho, rho > 0), ("Cv", Cv, Cv > 0), ("alpha", alpha, alpha >= 0),
                  ("theta_R", theta_R, theta_R > 0), ("k_th", k_th, k_th >= 0))
        for what, value, ok in checks:
            if not (np.isfinite(value) and ok):
                raise InputError(f"{name}: {what}={value!r} is out of range "
                                 "(E_young, rho, Cv, theta_R > 0; -1 < nu < 0.5; alpha, k_th >= 0)")
        self.E_young, self.nu, self.rho, self.Cv = float(E_young), float(nu), float(rho), float(Cv)
        self.alpha, self.theta_R, self.k_th = float(alpha), float(theta_R), float(k_th)
        self.mu = E_young / (2.0 * (1.0 + nu))
        self.kappa = E_young / (3.0 * (1.0 - 2.0 * nu))
        self.lam = self.kappa - 2.0 * self.mu / 3.0
        self.cv = rho * Cv
        self.Gamma0 = 3.0 * self.kappa * alpha / self.cv
        self.q = 1.0

    def coefficients(self):
        """The model's three coefficients (entries 2-4 of ``constants``)."""
        raise NotImplementedError

    def constants(self):
        """The vector ``m`` the compiled functions read (layout in the module docstring)."""
        return np.array([self.mu, self.kappa, *self.coefficients(), self.cv, self.Gamma0,
                         self.theta_R, self.q, self.k_th, self.rho])

    def parameters(self):
        """Everything that defines the material, for results files."""
        return {"model": type(self).__name__, "E_young": self.E_young, "nu": self.nu,
                "rho": self.rho, "Cv": self.Cv, "alpha": self.alpha, "theta_R": self.theta_R,
                "k_th": self.k_th, "mu": self.mu, "kappa": self.kappa, "cv": self.cv,
                "Gamma0": self.Gamma0, "q": self.q, "coefficients": list(self.coefficients())}

    # plain-Python evaluation of one material point (tests, manufactured sources)
    def _m(self):
        return list(self.constants())

    def energy_R(self, F, H, J):
        return energy_R(self.model, list(np.ravel(F)), list(np.ravel(H)), float(J), self._m())

    def entropy_R(self, F, H, J):
        return entropy_R(self.model, list(np.ravel(F)), list(np.ravel(H)), float(J), self._m())

    def conjugates(self, F, H, J, theta):
        """(Sigma_F, Sigma_H, Sigma_J) as 3x3, 3x3, float."""
        SF, SH = [0.0] * 9, [0.0] * 9
        SJ = conjugate_stresses(self.model, list(np.ravel(F)), list(np.ravel(H)), float(J),
                                float(theta), self._m(), SF, SH)
        return np.reshape(SF, (3, 3)), np.reshape(SH, (3, 3)), SJ

    def stress(self, F, H, J, theta):
        """First Piola-Kirchhoff stress P(F, H, J, theta) (eq. 12), 3x3."""
        SF, SH, SJ = self.conjugates(F, H, J, theta)
        P = [0.0] * 9
        first_piola(list(np.ravel(F)), list(np.ravel(H)), list(SF.ravel()), list(SH.ravel()), SJ, P)
        return np.reshape(P, (3, 3))

    def internal_energy(self, F, H, J, eta):
        """E(F, H, J, eta) = E_R + c_v theta_R (exp((eta - eta_R)/c_v) - 1), eqs. 20, 22."""
        etaR = self.entropy_R(F, H, J)
        return self.energy_R(F, H, J) + self.cv * self.theta_R * (np.exp((eta - etaR) / self.cv) - 1.0)

    def wave_speeds(self, theta):
        """(c_p, c_s) at temperature theta (numpy, any shape); see ``wave_speeds``."""
        theta = np.asarray(theta, dtype=float)
        cg2 = self.cv * self.Gamma0 ** 2
        if self.model == ENTROPIC:
            xi = theta / self.theta_R
            return (np.sqrt(((self.kappa + 4.0 * self.mu / 3.0) * xi + theta * cg2) / self.rho),
                    np.sqrt(self.mu * xi / self.rho))
        bulk = self.kappa + self.cv * self.Gamma0 * (1.0 - self.q) * (theta - self.theta_R)
        return (np.sqrt((bulk + 4.0 * self.mu / 3.0 + theta * cg2) / self.rho),
                np.sqrt(self.mu / self.rho) + 0.0 * theta)


def _split(mu, fraction, name):
    """(c1, c2) with 2 c1 + 3 sqrt(3) c2 = mu and 2 c1 = fraction mu."""
    if not 0.0 <= fraction <= 1.0:
        raise InputError(f"{name}: the F-term fraction of mu {fraction!r} must lie in [0, 1]")
    return 0.5 * fraction * mu, (1.0 - fraction) * mu / SQRT27


class MieGruneisen(ThermoElasticMaterial):
    """Mie-Gruneisen, eqs. 30-32.  ``q`` (0 perfect gas .. 1 solids) and the split of mu
    between the F- and H-terms are not given in the paper: q = 1 and a neo-Hookean split
    (``f_fraction = 1``: 2 zeta_R = mu, gamma_R = 0) by default."""

    model = MIE_GRUNEISEN

    def __init__(self, E_young, nu, rho, Cv, alpha, theta_R, k_th, q=1.0, f_fraction=1.0):
        super().__init__(E_young, nu, rho, Cv, alpha, theta_R, k_th)
        if not 0.0 <= q <= 1.0:
            raise InputError(f"MieGruneisen: q={q!r} must lie in [0, 1]")
        self.q = float(q)
        self.zeta, self.gamma = _split(self.mu, f_fraction, "MieGruneisen")
        self.chi = self.kappa - self.cv * theta_R * self.Gamma0 * (1.0 - self.q)

    def coefficients(self):
        return (self.zeta, self.gamma, self.chi)


class ModifiedEntropicElasticity(ThermoElasticMaterial):
    """Modified entropic elasticity, eqs. 26-29 (neo-Hookean split by default, as above)."""

    model = ENTROPIC

    def __init__(self, E_young, nu, rho, Cv, alpha, theta_R, k_th, f_fraction=1.0):
        super().__init__(E_young, nu, rho, Cv, alpha, theta_R, k_th)
        self.varsigma, self.xi = _split(self.mu, f_fraction, "ModifiedEntropicElasticity")

    def coefficients(self):
        return (self.varsigma, self.xi, self.kappa)


class LinearThermoElastic(ThermoElasticMaterial):
    """The linear model of sec. 7.1 (not written out in the paper): with eps = sym F - I,
    E_R = mu eps:eps + lambda/2 (tr eps)^2 + c_v Gamma_0 theta_R tr eps and eta_R =
    c_v Gamma_0 tr eps, so P = Sigma_F = 2 mu eps + lambda tr(eps) I - c_v Gamma_0
    (theta - theta_R) I, Sigma_H = 0, Sigma_J = 0."""

    model = LINEAR

    def coefficients(self):
        return (self.lam, 0.0, 0.0)


MATERIALS = {"mie_gruneisen": MieGruneisen, "entropic": ModifiedEntropicElasticity,
             "linear": LinearThermoElastic}


@helper
def energy_from_temperature(model=0, theta=0.0, kinetic=0.0, F=[0.0], H=[0.0], J=1.0, m=[0.0]):
    """E = |p|^2/(2 rho_R) + E_R + c_v (theta - theta_R): the inverse of eq. 23."""
    return kinetic + energy_R(model, F, H, J, m) + m[5] * (theta - m[7])


@helper
def entropy_from_temperature(model=0, theta=0.0, F=[0.0], H=[0.0], J=1.0, m=[0.0]):
    """eta = eta_R + c_v ln(theta/theta_R): eq. 19, the inverse of eq. 20."""
    return entropy_R(model, F, H, J, m) + m[5] * log(theta / m[7])
