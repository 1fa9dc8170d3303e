"""``shtc_impulse_of_shear`` (Kincl's thesis (2023), sec. 2.2): a Gaussian shear layer in the
SHTC-SPH fluid regime follows the linearised SHTC (telegraph) solution, thesis eq. 2.25, and
not the Navier-Stokes one when cs is small; the analytic pieces checked on their own."""
import json
import math

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.applications.shtc_impulse_of_shear import layer_solution, mode_factors
from sphgen.errors import InputError


def test_mode_factors_solve_the_telegraph_equation():
    """(nu/cs^2) a'' + a' + nu k^2 a = 0 by finite differences, a(0) = 1, and the
    Navier-Stokes limit exp(-nu k^2 t) as cs grows."""
    k, nu, cs, t, h = 2 * math.pi * np.arange(8.0), 0.01, 0.5, 0.05, 1e-5
    a = lambda s: mode_factors(k, s, nu, cs)
    resid = nu / cs ** 2 * (a(t + h) - 2 * a(t) + a(t - h)) / h ** 2 + (a(t + h) - a(t - h)) / (2 * h) + nu * k * k * a(t)
    assert np.abs(resid).max() < 1e-5
    assert np.allclose(a(0.0), 1.0, atol=1e-14)
    assert np.allclose(mode_factors(k, t, nu, 1e4), np.exp(-nu * k * k * t), atol=1e-7)


def test_layer_solution_keeps_the_momentum_and_starts_from_the_profile():
    f = lambda y: np.exp(-(y - 0.5) ** 2 / (2 * 0.05 ** 2))
    y = np.linspace(0.0, 1.0, 2001)[:-1]
    assert np.abs(layer_solution(f, y, 0.0, 0.01, 0.3) - f(y)).max() < 1e-12
    later = layer_solution(f, y, 0.1, 0.01, 0.3)
    assert later.mean() == pytest.approx(f(y).mean(), rel=1e-10)
    assert later.max() < 0.95


def test_layer_follows_the_telegraph_solution(tmp_path):
    """20 per side, w = 0.1, cs = 0.3, t = 0.1: RMS error 0.42 % of U against eq. 2.25,
    2.4 % against Navier-Stokes (measured; 0.13 % / 2.1 % at 40 per side)."""
    app = load_application("shtc_impulse_of_shear")()
    app.run(["-d", str(tmp_path), "--disable-output", "--no-progress", "--threads", "1",
             "--nx", "20", "--width", "0.1"])
    res = json.loads((tmp_path / "results.json").read_text())
    assert len(res["profile_errors"]) == 3
    assert res["profile_error"] < 0.01, res
    assert res["profile_error_navier_stokes"] > 3 * res["profile_error"], res
    assert (tmp_path / "profile.png").exists()


def test_unresolved_layer_is_refused(tmp_path):
    with pytest.raises(InputError):
        load_application("shtc_impulse_of_shear")().run(["-d", str(tmp_path), "--nx", "20", "--debug"])
