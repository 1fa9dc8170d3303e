"""The linearised rates of the thermo-elastic applications (applications/_thermo_modes.py):
the TVD-RK2 amplification function, the Jacobian's consistency with the compiled rates, and
its null direction (a uniform velocity shift at the same internal energy, E + rho v . dv,
changes no strain rate: the rows of F, H and J)."""
import numpy as np
import pytest

from sphgen.applications.thermo_disk import ThermoDisk
from sphgen.applications._thermo_modes import (fast_mode_amplification, rate_jacobian, rates,
                                              rk2_amplification, state_vector)


def test_rk2_amplification_is_heuns():
    assert rk2_amplification(-1.0) == pytest.approx(0.5)
    x = np.array([0.3, 0.7, 1.2])
    assert np.allclose(rk2_amplification(1j * x), np.sqrt(1 + x ** 4 / 4))     # > 1 on the imaginary axis
    out = fast_mode_amplification(np.array([-1.0, 10j]), 0.1, [1.0, 0.2])
    assert out[1.0] == (pytest.approx(np.sqrt(1.25)), 1j) and out[0.2][0] == 0.0


@pytest.fixture(scope="module")
def small_disk(tmp_path_factory):
    """A disk of radius 2 at dx = 1 (24 particles), spun and heated for 0.05 s (7 steps), so
    that no jump is zero (the limiter's minmod has a kink at a zero jump); the paper's full
    scheme (the linearisation's unknowns include J; the disk's default is the reduced one)."""
    app = ThermoDisk()
    app.run(["-d", str(tmp_path_factory.mktemp("modes")), "--no-progress", "--disable-output", "--threads", "1",
             "--dx", "1", "--radius", "2", "--tf", "0.05", "--variant", "full"])
    return app


def test_rates_round_trip_and_jacobian_is_consistent(small_disk):
    app = small_disk
    pa, t = app.scene.by_name["body"], app.solver.t
    y0 = state_vector(pa).copy()
    r0 = rates(app, y0, t)
    assert np.array_equal(rates(app, y0, t), r0) and np.array_equal(state_vector(pa), y0)
    jac = rate_jacobian(app)
    assert jac.shape == (23 * pa.n, 23 * pa.n) and np.isfinite(jac).all()
    d = np.random.default_rng(3).standard_normal(y0.size) * np.maximum(np.abs(y0), 1e-3)
    e = 1e-7
    fd = (rates(app, y0 + e * d, t) - rates(app, y0 - e * d, t)) / (2 * e)
    assert np.abs(jac @ d - fd).max() <= 1e-5 * np.abs(fd).max()
    shift = np.zeros(y0.size)        # v_x + 1 at the same internal energy: E + rho v_x
    shift[:pa.n] = 1.0
    shift[22 * pa.n:] = pa.rho * pa.u
    strain = slice(3 * pa.n, 22 * pa.n)       # the rows of F, H and J
    assert np.abs((jac @ shift)[strain]).max() <= 1e-6 * np.abs(jac[strain]).max()
    assert np.abs((jac @ d)[strain]).max() > 1e3 * np.abs((jac @ shift)[strain]).max()
