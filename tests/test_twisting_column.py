"""Twisting column with SHTC-SPH (Kincl, Peshkov, Pavelka & Klika 2023, sec. 4.2).

Default suite: the material constants (Table 1's cs is the shear modulus; checked on the
neo-Hookean energy itself) and 4 cubes across for t = 0.01 s (726 steps): energy of column
and base conserved, the base at rest, the column twisting and shrinking.  Slow: the same
resolution to t = 0.2 s, the rotation reverses and the column bounces back.
"""
import json

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.equations.shtc_stress import shear_energy


def run_column(out, *args):
    app = load_application("twisting_column")()
    app.run(["-d", str(out), "--disable-output", "--no-progress", "--threads", "1", *args])
    with open(out / "results.json") as f:
        return json.load(f), app


def test_sound_speeds_are_table_1s_and_cs_is_the_shear_modulus():
    from sphgen.applications.twisting_column import RHO0, YOUNG, POISSON, sound_speeds
    c0, cs = sound_speeds()
    assert c0 == pytest.approx(715.3, abs=0.05) and cs == pytest.approx(71.9, abs=0.05)   # Table 1
    # simple shear by gamma: the neo-Hookean energy (eq. 17) per unit mass is cs^2 gamma^2/2 to
    # second order, i.e. rho0 cs^2 is the shear modulus Y/(2(1 + nu)) (the text's Y/(1 + nu) is not)
    g = 1e-4
    F = np.eye(3)
    F[0, 1] = g
    A = np.linalg.inv(F).ravel().tolist()
    eps = cs ** 2 * shear_energy(A, 1)
    assert RHO0 * 2 * eps / g ** 2 == pytest.approx(YOUNG / (2 * (1 + POISSON)), rel=1e-6)


@pytest.fixture(scope="module")
def short_run(tmp_path_factory):
    return run_column(tmp_path_factory.mktemp("tc") / "c", "--n", "4", "--tf", "0.01")


def test_column_twists_with_energy_conserved_and_base_at_rest(short_run):
    res, app = short_run
    a = app.scene.by_name
    base, col = a["base"], a["column"]
    assert base.n == 4 * 4 * 3 * 2 and col.n == 4 * 4 * 24 * 2       # BCC, base 3 cubes >= 2h deep
    assert np.all(base.u == 0) and np.all(base.v == 0) and np.all(base.w == 0) and np.all(base.z < 0)
    assert np.abs(base.A.reshape(-1, 3, 3) - np.eye(3)).max() > 1e-4     # the base runs the scheme's A
    assert res["energy_error"] < 1e-4, res
    assert res["detA_min"] > 0.5
    t, zt, om = np.array(app.history)[:, :3].T
    assert zt[-1] < zt[0] - 0.01             # the column shrinks as it twists
    assert np.all(om < 0) and -105 < om[0] < -100            # omega sin(pi z/2H), z > 0.95 H


@pytest.mark.slow
def test_rotation_reverses_and_the_column_bounces(tmp_path):
    res, _ = run_column(tmp_path / "c", "--n", "4")
    assert 0.05 < res["t_rotation_reverses"] < 0.15, res
    assert res["z_top_twisted_min"] < 0.96 and res["bounce"] > 0.02
    assert res["energy_error"] < 1e-4 and res["detA_min"] > 0.5
