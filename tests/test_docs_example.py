"""The worked example of docs/writing_equations.rst, run the way the page says.

``docs/examples/my_case.py`` is a user's own file (outside ``sphgen.applications``)
with its own equations, integrator, scheme and Application.  It is run as a script;
its ``results.json`` is checked against the exact decay of a sine mode,
T = exp(-(k^2 D + kappa) t) sin(k x), k = 2 pi.
"""
import json
import math
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
EXAMPLE = os.path.join(ROOT, "docs", "examples", "my_case.py")


def run_example(outdir, *args):
    """Run the example as the docs show (``python docs/examples/my_case.py ...``)."""
    cmd = [sys.executable, EXAMPLE, "-d", str(outdir), "--no-progress", *args]
    proc = subprocess.run(cmd, capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, f"{' '.join(cmd)} failed:\n{proc.stdout}\n{proc.stderr}"
    return proc.stdout


def results(outdir):
    with open(os.path.join(outdir, "results.json")) as f:
        return json.load(f)


def test_sine_mode_decays_at_the_analytic_rate(tmp_path):
    out = tmp_path / "diffusion"
    run_example(out, "--tf", "1.0", "--disable-output", "--no-openmp")
    res = results(out)
    D = 0.01
    exact = math.exp(-(2 * math.pi) ** 2 * D * 1.0)
    assert res["t"] == pytest.approx(1.0, abs=1e-12)
    assert res["amplitude_exact"] == pytest.approx(exact, rel=1e-12)
    # measured: +0.31 % at nx = 40 (Euler in time, Brookshaw Laplacian in space)
    assert abs(res["amplitude"] / exact - 1.0) < 0.01, res
    rate = -math.log(res["amplitude"]) / res["t"]
    assert rate == pytest.approx((2 * math.pi) ** 2 * D, rel=0.02), res
    info = json.load(open(out / "info.json"))
    assert info["completed"] and info["n_particles"] == 1600 and info["backend"] == "cython"


def test_switch_and_vector_output(tmp_path):
    """kappa > 0 adds exactly kappa to the decay rate; gradT (stride 3) is written."""
    out = tmp_path / "reaction"
    run_example(out, "--tf", "0.5", "--kappa", "0.5", "--output-gradient", "--pfreq", "1000")
    res = results(out)
    exact = math.exp(-((2 * math.pi) ** 2 * 0.01 + 0.5) * 0.5)
    assert res["amplitude_exact"] == pytest.approx(exact, rel=1e-12)
    assert abs(res["amplitude"] / exact - 1.0) < 0.01, res

    from sphgen import io
    files = io.output_files(out)
    assert os.path.exists(out / "my_case.xdmf") and len(files) == 2   # step 0 and the last step
    last = io.load(files[-1])
    slab = last["arrays"]["slab"]
    assert last["solver_data"]["t"] == pytest.approx(0.5)
    grad = slab.data["gradT"].reshape(-1, 3)
    dTdx = 2 * math.pi * res["amplitude"] * np.cos(2 * math.pi * slab.data["x"])
    err = np.abs(grad[:, 0] - dTdx).max() / np.abs(dTdx).max()
    assert err < 0.02, err
    assert np.abs(grad[:, 1:]).max() < 1e-8 * np.abs(dTdx).max()


def test_show_plan_reflects_switches_and_outputs(tmp_path):
    plain = run_example(tmp_path / "p0", "--show-plan")
    assert "keep  HeatEquation[slab<-slab]: initialize, loop\n" in plain
    assert "prune TemperatureGradient[slab<-slab]: nothing reads what it writes (gradT)" in plain
    assert "declared, not allocated: gradT" in plain
    full = run_example(tmp_path / "p1", "--show-plan", "--kappa", "0.5", "--output-gradient")
    assert "keep  HeatEquation[slab<-slab]: initialize, loop, post_loop" in full
    assert "keep  TemperatureGradient[slab<-slab]: initialize, loop" in full
    assert not os.path.exists(tmp_path / "p0")    # --show-plan exits before running


def test_python_backend_runs_the_same_equations(tmp_path):
    """The debugging path of the docs: --backend python agrees with the compiled module."""
    args = ["--nx", "12", "--max-steps", "3", "--disable-output"]
    run_example(tmp_path / "cy", *args, "--no-openmp")
    run_example(tmp_path / "py", *args, "--backend", "python")
    a, b = results(tmp_path / "cy"), results(tmp_path / "py")
    assert a["t"] == b["t"] and a["t"] > 0
    assert b["amplitude"] == pytest.approx(a["amplitude"], rel=1e-12)
    assert a["amplitude"] < 1.0
