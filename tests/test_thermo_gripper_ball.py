"""The gripper (sec. 7.5) and the ball (sec. 7.6) of Ghavamian et al. (2021)
(applications/thermo_gripper.py, thermo_ball.py).

Checks of issue 12: both reach their end times with J, theta > 0 (the default reduced
{p, F, H, E} scheme; the paper's full scheme stops on both, docs/thermo.md); the E-form
energy budget closes to 1e-10 with the tractions' work, the heat drawn by the gripper's
280 K core and the ball's heat input.  Fast: the coarsest lattices over a short time;
slow: the end times.
"""
import numpy as np
import pytest

from sphgen.applications._thermo_solid import run_quietly
from sphgen.applications.thermo_ball import ThermoBall, perforated_area_fraction
from sphgen.applications.thermo_gripper import ThermoGripper


def test_gripper_is_held_cold_at_its_core_and_bends_its_four_arms_alike(tmp_path):
    r, h = run_quietly(ThermoGripper, tmp_path, "--dx", "0.02", "--tf", "0.05")
    assert r["variant"] == "reduced" and r["jumps"] == "raw" and r["n_particles"] == 1024
    assert r["t"] >= 0.05 and r["J_min"] > 0.9 and r["energy_residual"] <= 1e-10
    # the core is held at 280 K (heat drawn: E_Dir < 0), the ends started at 300 K
    assert r["theta_range"] == pytest.approx([280.0, 300.0], abs=0.05) and h["E_Dir"][-1] < 0
    # the traction pulls the ends down (W_ext > 0), the four tips move alike (the lattice is 4-fold symmetric)
    assert r["W_ext"] > 0 and max(r["tip_uz"]) < -0.01 and r["tip_uz_spread"] < 1e-9
    assert r["probe_u"][2] == pytest.approx(r["tip_uz"][0], rel=0.05)


def test_ball_punched_and_heated(tmp_path):
    r, h = run_quietly(ThermoBall, tmp_path, "--dx", "0.01", "--tf", "0.004")
    assert r["variant"] == "reduced" and r["n_particles"] == 1858
    assert r["t"] >= 0.004 and r["J_min"] > 0.9 and r["energy_residual"] <= 1e-10
    # the heat rate is Q_B times the perforated inner area (0.9 of 4 pi 0.09^2 for six holes of 0.025 m)
    area = 4 * np.pi * 0.09 ** 2 * perforated_area_fraction(0.025, 0.09)
    assert 0.85 < area / (4 * np.pi * 0.09 ** 2) < 0.95
    assert r["Q_in"] == pytest.approx(470.871e3 * area * r["t"], rel=1e-12)
    assert r["heated_theta_mean"] > 293.15 + 0.1 and h["probe_uz"].min() < -5e-4


@pytest.mark.slow
@pytest.mark.parametrize("app,args", [(ThermoGripper, ("--dx", "0.02")), (ThermoBall, ("--dx", "0.01"))])
def test_reaches_its_end_time(tmp_path, app, args):
    r, _ = run_quietly(app, tmp_path, *args)
    assert r["t"] >= app.tf - 1e-12 and r["J_min"] > 0 and r["theta_range"][0] > 0
    assert r["energy_residual"] <= 1e-10
