"""Taylor-Couette flow with SHTC-SPH (Kincl, Peshkov, Pavelka & Klika 2023, sec. 4.3): dummy
walls that carry their own state, a rotating outer ring, the steady profile (eq. 28).

Default suite: 10 particles across the gap, Re = 2 (nu = 1: steady after t = 1, the profile
does not depend on nu), dt = 0.2 dr / c (four times the paper's eq. 26 step; dt/tau = 0.11).
Slow: the paper's case (30 across, Re = 20, t = 10).
"""
import json
import math

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.applications.taylor_couette import (OMEGA, R1, R2, exact_tangential_velocity, rigid_rotation,
                                                vogel_annulus)

FAST = ("--nr", "10", "--re", "2", "--cfl", "0.2", "--tf", "1")


def run_tc(out, *args):
    app = load_application("taylor_couette")()
    app.run(["-d", str(out), "--disable-output", "--no-progress", "--threads", "1", *args])
    with open(out / "results.json") as f:
        return json.load(f), app


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    d = tmp_path_factory.mktemp("tc")
    return {w: run_tc(d / w, *FAST, "--wall-velocity", w) for w in ("rigid", "profile", "extrapolated")}


def test_exact_profile_layout_and_rotation():
    assert exact_tangential_velocity([1.0, 1.5, 2.0]) == pytest.approx([0.0, 4 / 3 * (1.5 - 1 / 1.5), 2.0])
    x, y = vogel_annulus(R1, R2, 0.05)
    r = np.hypot(x, y)
    assert r.min() >= R1 and r.max() < R2
    assert x.size == pytest.approx(math.pi * (R2 ** 2 - R1 ** 2) / 0.05 ** 2, abs=2)

    class Ring:
        x0, y0 = np.array([2.0, 0.0]), np.array([0.0, 2.5])
    m = rigid_rotation(0.5)(1.0, Ring)
    c, s = math.cos(0.5), math.sin(0.5)
    assert m["x"] == pytest.approx([2 * c, -2.5 * s]) and m["y"] == pytest.approx([2 * s, 2.5 * c])
    assert m["u"] == pytest.approx(-0.5 * m["y"]) and m["v"] == pytest.approx(0.5 * m["x"])


def test_walls_carry_their_own_state_and_the_outer_ring_turns(coarse):
    res, app = coarse["rigid"]
    arrays, t = app.scene.by_name, app.solver.t
    outer, inner = arrays["outer"], arrays["inner"]
    c, s = math.cos(OMEGA * t), math.sin(OMEGA * t)
    assert np.abs(outer.x - (c * outer.x0 - s * outer.y0)).max() < 1e-12
    assert np.abs(outer.v - OMEGA * outer.x).max() < 1e-12
    assert np.array_equal(inner.x, inner.x0) and np.all(inner.u == 0) and np.all(inner.v == 0)
    for wall in (inner, outer):   # the walls ran the scheme's equations: their A, rho moved
        A = wall.A.reshape(-1, 3, 3)
        assert np.abs(A - np.eye(3)).max() > 1e-2
        assert np.abs(wall.rho - 1.0).max() > 0 and np.all(np.isfinite(wall.T))
    assert res["dt_over_tau"] < 0.2


def test_coarse_profile_against_eq_28(coarse):
    rigid, _ = coarse["rigid"]
    profile, _ = coarse["profile"]
    # the exact profile continued into the rings (the authors' code) is exact to 1% at 10 across
    assert profile["profile_error"] < 0.01, profile
    # rigid-body rings: the no-slip layer is a kernel wide; 4.75% at 10 across (3.1% at 20)
    assert rigid["profile_error"] < 0.06, rigid
    v, ve = np.array(rigid["profile_v"]), np.array(rigid["profile_exact"])
    assert np.all(np.diff(v) > 0) and abs(v[-1] - OMEGA * R2) < 0.1


def test_extrapolated_ring_velocity_halves_the_slip(coarse):
    """Rigid rings whose velocity in L is extrapolated from the fluid (Adami et al. 2012): 2.25 %
    against 4.75 % at 10 across (docs/shtc.md); the rings' own velocities stay rigid."""
    rigid, _ = coarse["rigid"]
    extra, app = coarse["extrapolated"]
    assert extra["profile_error"] < 0.5 * rigid["profile_error"], (extra, rigid)
    inner = app.scene.by_name["inner"]
    assert np.all(inner.u == 0) and np.all(inner.v == 0) and np.abs(inner.vg).max() > 0.01


def test_extrapolated_ring_velocity_is_the_default():
    """The rings show the extrapolated velocity in L unless told (docs/shtc.md, "Why the paper's
    walls miss 2 %"); the paper's rigid rings are one option away."""
    app = load_application("taylor_couette")()
    assert app.parser().parse_args([]).wall_velocity == "extrapolated"
    assert app.parser().parse_args(["--wall-velocity", "rigid"]).wall_velocity == "rigid"


@pytest.mark.slow
@pytest.mark.xfail(reason="at 10 across (a third of the paper's resolution) the profile error at one instant "
                   "is particle noise: measured 1.20 % and 4.09 % at t = 10 in two runs that differ only by "
                   "round-off, 1.0-4.3 % over the outputs t >= 4 on four half-axes; at the paper's 30 across "
                   "it is 1.43 % (test_paper_case_profile_error_below_two_percent; docs/shtc.md)",
                   strict=False)
def test_paper_re20_at_10_across_below_two_percent(tmp_path):
    """The paper's Re = 20 with eq. 26's step to t = 10 at dr = 1/10 (100 665 steps), extrapolated ring
    velocity: the issue's 2 % on the instantaneous profile at t = 10 (docs/shtc.md)."""
    res, _ = run_tc(tmp_path / "re20", "--nr", "10")
    assert res["re"] == 20 and res["t"] == pytest.approx(10.0)
    assert res["profile_error"] < 0.02, res


@pytest.mark.slow
def test_table_1_resolution_extrapolated_rings_below_two_percent(tmp_path):
    """Table 1's dr = 1/30, Re = 2 (steady by t = 1), extrapolated ring velocity: measured 1.53 % (docs/shtc.md)."""
    res, _ = run_tc(tmp_path / "e30", "--nr", "30", "--re", "2", "--cfl", "0.2", "--tf", "1",
                    "--wall-velocity", "extrapolated")
    assert res["profile_error"] < 0.02, res


@pytest.mark.slow
def test_paper_case_profile_error_below_two_percent(tmp_path):
    """Kincl et al. (2023) Table 1 (dr = 1/30, Re = 20, dt from eq. 26) at t = 10."""
    res, _ = run_tc(tmp_path / "paper", "--no-progress")
    assert res["profile_error"] < 0.02, res
