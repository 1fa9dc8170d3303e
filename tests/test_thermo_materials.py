"""Thermo-elastic materials of Ghavamian et al. (2021): stresses are energy derivatives.

P of eq. 12 must equal dE/dF at fixed entropy with H = cof F, J = det F (the chain rule
of eq. 11); the reference state is stress free; the linearisation recovers mu, kappa
and the thermal stress -3 kappa alpha (theta - theta_R) the calibration (eqs. 29, 32,
83) was built on.
"""
import numpy as np
import pytest

from sphgen.equations.large_strain import cross33, ddot33
from sphgen.equations.thermo_materials import (LinearThermoElastic, MieGruneisen,
                                               ModifiedEntropicElasticity, temperature_from_energy,
                                               temperature_from_entropy, wave_speeds)
from sphgen.errors import InputError

BASE = dict(E_young=50.05e3, nu=0.3, rho=1000.0, Cv=1.0, alpha=2.223e-4, theta_R=293.15, k_th=10.0)


def materials():
    return [MieGruneisen(**BASE), MieGruneisen(**BASE, q=0.5, f_fraction=0.6),
            MieGruneisen(**{**BASE, "nu": 0.499}), ModifiedEntropicElasticity(**BASE, f_fraction=0.7),
            LinearThermoElastic(**BASE)]


def cross(a, b):
    out = [0.0] * 9
    cross33(list(np.ravel(a)), list(np.ravel(b)), out)
    return np.reshape(out, (3, 3))


def cof(F):
    return np.linalg.det(F) * np.linalg.inv(F).T


def test_tensor_cross_product_identities():
    rng = np.random.default_rng(0)
    A, B, C = rng.normal(size=(3, 3, 3))
    eps = np.zeros((3, 3, 3))
    for i, j, k in ((0, 1, 2), (1, 2, 0), (2, 0, 1)):
        eps[i, j, k], eps[i, k, j] = 1.0, -1.0
    np.testing.assert_allclose(cross(A, B), np.einsum("ijk,IJK,jJ,kK->iI", eps, eps, A, B), atol=1e-13)
    np.testing.assert_allclose(cross(A, B), cross(B, A), atol=1e-13)
    np.testing.assert_allclose(0.5 * cross(A, A), cof(A), atol=1e-13)
    assert ddot33(list(A.ravel()), list(cross(B, C).ravel())) == pytest.approx(
        ddot33(list(cross(A, B).ravel()), list(C.ravel())), rel=1e-13)
    np.testing.assert_allclose(cross(A, np.eye(3)), np.trace(A) * np.eye(3) - A.T, atol=1e-13)


@pytest.mark.parametrize("mat", materials(), ids=lambda m: f"{type(m).__name__}")
def test_stress_is_the_energy_derivative_at_fixed_entropy(mat):
    """P (eq. 12) = dE/dF|_eta with H = cof F, J = det F, to 1e-6 relative (central differences)."""
    rng = np.random.default_rng(3)
    F = np.eye(3) + 0.15 * rng.normal(size=(3, 3))
    theta = 1.08 * mat.theta_R
    eta = mat.entropy_R(F, cof(F), np.linalg.det(F)) + mat.cv * np.log(theta / mat.theta_R)

    def energy(G):
        return mat.internal_energy(G, cof(G), np.linalg.det(G), eta)

    fd = np.zeros((3, 3))
    e = 1e-6
    for i in range(3):
        for k in range(3):
            d = np.zeros((3, 3))
            d[i, k] = e
            fd[i, k] = (energy(F + d) - energy(F - d)) / (2 * e)
    P = mat.stress(F, cof(F), np.linalg.det(F), theta)
    assert np.abs(P - fd).max() <= 1e-6 * np.abs(fd).max()
    # and theta = dE/deta (eq. 9)
    de = 1e-3 * mat.cv
    th_fd = (mat.internal_energy(F, cof(F), np.linalg.det(F), eta + de)
             - mat.internal_energy(F, cof(F), np.linalg.det(F), eta - de)) / (2 * de)
    assert th_fd == pytest.approx(theta, rel=1e-6)


@pytest.mark.parametrize("mat", materials(), ids=lambda m: f"{type(m).__name__}")
def test_reference_state_is_stress_free_and_linearisation_recovers_the_moduli(mat):
    I = np.eye(3)
    assert np.abs(mat.stress(I, I, 1.0, mat.theta_R)).max() < 1e-9 * mat.kappa
    assert mat.energy_R(I, I, 1.0) == 0.0 and mat.entropy_R(I, I, 1.0) == 0.0
    # isothermal small shear and dilatation at theta_R: mu and kappa (eqs. 29, 32, 83)
    e = 1e-7
    Fs = I.copy()
    Fs[0, 1] = e
    assert mat.stress(Fs, cof(Fs), 1.0, mat.theta_R)[0, 1] / e == pytest.approx(mat.mu, rel=1e-5)
    Fv = (1.0 + e) * I
    P = mat.stress(Fv, cof(Fv), np.linalg.det(Fv), mat.theta_R)
    assert np.trace(P) / 3.0 / (3.0 * e) == pytest.approx(mat.kappa, rel=1e-5)
    # thermal stress at J = 1: -3 kappa alpha (theta - theta_R)
    P = mat.stress(I, I, 1.0, mat.theta_R + 10.0)
    np.testing.assert_allclose(P, -3.0 * mat.kappa * mat.alpha * 10.0 * I, rtol=1e-12, atol=1e-9)


@pytest.mark.parametrize("mat", materials(), ids=lambda m: f"{type(m).__name__}")
def test_temperature_round_trips_and_wave_speeds(mat):
    rng = np.random.default_rng(5)
    F = np.eye(3) + 0.1 * rng.normal(size=(3, 3))
    H, J = cof(F), np.linalg.det(F)
    m = list(mat.constants())
    theta, kin = 1.05 * mat.theta_R, 123.0
    E = kin + mat.energy_R(F, H, J) + mat.cv * (theta - mat.theta_R)
    args = (list(F.ravel()), list(H.ravel()), J, m)
    assert temperature_from_energy(mat.model, E, kin, *args) == pytest.approx(theta, rel=1e-14)
    eta = mat.entropy_R(F, H, J) + mat.cv * np.log(theta / mat.theta_R)
    assert temperature_from_entropy(mat.model, eta, *args) == pytest.approx(theta, rel=1e-14)
    out = [0.0, 0.0]
    wave_speeds(mat.model, theta, m, out)
    np.testing.assert_allclose(out, mat.wave_speeds(theta), rtol=1e-14)


def test_adiabatic_p_wave_speed_is_the_fixed_entropy_modulus():
    """rho c_p^2 = d P11 / d F11 at fixed entropy under uniaxial strain at the reference state."""
    for mat in materials():
        I = np.eye(3)
        eta0 = mat.cv * np.log(1.0)

        def P11(e):
            F = I.copy()
            F[0, 0] += e
            H, J = cof(F), np.linalg.det(F)
            theta = mat.theta_R * np.exp((eta0 - mat.entropy_R(F, H, J)) / mat.cv)
            return mat.stress(F, H, J, theta)[0, 0]

        e = 1e-6
        modulus = (P11(e) - P11(-e)) / (2 * e)
        cp, cs = mat.wave_speeds(mat.theta_R)
        assert modulus == pytest.approx(mat.rho * cp ** 2, rel=1e-6)
        assert cs == pytest.approx(np.sqrt(mat.mu / mat.rho), rel=1e-14)


def test_paper_calibration_numbers():
    """Derived constants of the punch (nu = 0.499): Gamma_0 = 5.563, adiabatic c_p = 132 m/s."""
    m = MieGruneisen(**{**BASE, "nu": 0.499})
    assert m.Gamma0 == pytest.approx(5.5631, rel=1e-4)
    assert m.wave_speeds(m.theta_R)[0] == pytest.approx(132.05, rel=1e-4)


def test_bad_material_input_is_one_clear_error():
    with pytest.raises(InputError, match="MieGruneisen: nu=0.5 is out of range"):
        MieGruneisen(**{**BASE, "nu": 0.5})
    with pytest.raises(InputError, match="q=2"):
        MieGruneisen(**BASE, q=2)
