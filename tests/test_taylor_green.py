"""Taylor-Green vortex acceptance (issue: EDAC, Re = 100, tf = 0.5)."""
import json
import os

import numpy as np
import pytest

from sphgen.app import load_application


def run_tg(tmp_path, nx, *extra):
    out = tmp_path / f"tg{nx}"
    app = load_application("taylor_green")()
    app.run(["--nx", str(nx), "--re", "100", "--tf", "0.5", "-d", str(out), "--disable-output",
             "--no-progress", *extra])
    with open(out / "results.json") as f:
        return json.load(f), out


@pytest.fixture(scope="module")
def tg50(tmp_path_factory):
    return run_tg(tmp_path_factory.mktemp("tg"), 50)


def test_nx50_l1_error_and_decay(tg50):
    res, out = tg50
    assert res["t"] == pytest.approx(0.5)
    assert res["l1_error"] <= 0.06, res
    assert abs(res["max_u"] / res["max_u_exact"] - 1.0) <= 0.03, res
    assert res["max_u_exact"] == pytest.approx(np.exp(-8 * np.pi ** 2 * 0.5 / 100), rel=1e-12)
    assert os.path.getsize(out / "decay.png") > 10000
    info = json.load(open(out / "info.json"))
    assert info["completed"] and info["steps"] == 1100 and info["n_particles"] == 2500


def test_nx100_is_more_accurate_than_nx50(tg50, tmp_path):
    res50, _ = tg50
    res100, _ = run_tg(tmp_path, 100)
    assert res100["l1_error_mean"] < 0.8 * res50["l1_error_mean"], (res50, res100)
    assert res100["l1_error"] <= 0.06
    # from the default perturbed start the final error falls too (0.0070 -> 0.0028 measured;
    # on the plain lattice it did not: 0.041 -> 0.043, docs/validation.md)
    assert res100["l1_error"] < 0.6 * res50["l1_error"], (res50, res100)
