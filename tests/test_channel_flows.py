"""EDAC with Adami walls: compiled == Python, Poiseuille and Couette against their exact solutions."""
import json

import numpy as np
import pytest

from sphgen.app import load_application


def run_app(name, args, tmp_path, tag=""):
    app = load_application(name)()
    out = tmp_path / f"{name}{tag}"
    app.run(["--no-progress", "--disable-output", "-d", str(out)] + args)
    return app, json.load(open(out / "results.json"))


@pytest.mark.parametrize("name", ["poiseuille", "couette"])
def test_edac_with_walls_compiled_matches_python(name, tmp_path):
    """A few steps of the channel flows, compiled and in the plain-Python evaluator."""
    args = ["--ny", "8", "--max-steps", "3"]
    a, _ = run_app(name, args, tmp_path, "_c")
    b, _ = run_app(name, args + ["--backend", "python"], tmp_path, "_p")
    kept = {type(ep.eq).__name__ for ep in a.scene.plan.eqplans if ep.kept}
    assert {"WallPressure", "WallDensity", "WallGhostVelocity", "WallViscosity",
            "WallEDACPressureRate"} <= kept
    assert ("BodyForce" in kept) == (name == "poiseuille")
    for pa in a.scene.arrays:
        pb = b.scene.by_name[pa.name]
        assert sorted(pa.data) == sorted(pb.data)
        for prop in pa.data:
            # fields that are zero up to round-off (v of a channel flow) compare absolutely
            np.testing.assert_allclose(pa.data[prop], pb.data[prop], rtol=1e-10,
                                       atol=1e-12 * max(1.0, np.abs(pb.data[prop]).max()),
                                       err_msg=f"{name} {pa.name}.{prop}")
    assert np.abs(a.scene.by_name["fluid"].u).max() > 0
    # only the moving wall of the Couette flow has velocity arrays
    top, bottom = a.scene.by_name["top"], a.scene.by_name["bottom"]
    assert "uw" not in bottom.data
    assert ("uw" in top.data) == (name == "couette")


@pytest.mark.parametrize("name,tol", [("poiseuille", 0.02), ("couette", 0.005)])
def test_channel_flow_reaches_the_exact_profile(name, tol, tmp_path):
    """ny = 16 to t = d^2/nu (Re = 1): within 2 % (Poiseuille) / 0.5 % (Couette) of u_max, at
    all times within a few % of the exact transient after the start-up."""
    app, res = run_app(name, ["--ny", "16", "--tf", "1.0", "--record-every", "0.05"], tmp_path)
    assert res["t"] == pytest.approx(1.0)
    assert res["max_dev_steady_over_umax"] < tol
    hist = json.load(open(tmp_path / name / "history.json"))
    rows = np.array(hist["rows"])
    t, dev_tr = rows[:, 0], rows[:, 1]
    assert np.all(dev_tr[t >= 0.1] < 0.03)
    assert abs(res["u_mid"] - res["u_mid_exact"]) < tol


@pytest.mark.slow
@pytest.mark.parametrize("name", ["poiseuille", "couette"])
def test_channel_flow_full_run(name, tmp_path):
    """Default set-up (30 particles across, Re = 1, t = 1.5 d^2/nu): within 2 % of u_max."""
    _, res = run_app(name, [], tmp_path)
    assert res["t_over_d2_nu"] == pytest.approx(1.5)
    assert res["max_dev_steady_over_umax"] < 0.02
