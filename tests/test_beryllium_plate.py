"""Beryllium plate (Kincl, Peshkov, Pavelka & Klika 2023, sec. 4.1): energy, period, tearing.

Default suite: a coarse plate (8 particles across, ~380 particles) over a third of a period,
with and without the tensile penalty.  Slow: one period at 20 across (the paper-size run,
40 across, is recorded in docs/shtc.md).
"""
import json
import math

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.applications.beryllium_plate import (OMEGA, PERIOD_CONTINUUM, euler_bernoulli_period,
                                                 finite_element_period, isometric_lattice, measured_period,
                                                 zero_crossings)


def run_plate(out, *args):
    app = load_application("beryllium_plate")()
    app.run(["-d", str(out), "--disable-output", "--no-progress", "--threads", "1", *args])
    with open(out / "results.json") as f:
        res = json.load(f)
    with open(out / "history.json") as f:
        hist = np.array(json.load(f)["rows"])
    return res, hist


@pytest.fixture(scope="module")
def coarse(tmp_path_factory):
    d = tmp_path_factory.mktemp("be")
    return {cp: run_plate(d / f"cp{cp}", "--nw", "8", "--tf", "1e-5", "--cp-factor", cp) for cp in ("10", "0")}


def test_euler_bernoulli_period_and_lattice():
    # plane strain, K = mu: E' = 2.25 mu / (1 - 1/64); omega = (beta L)^2/L^2 sqrt(E' W^2 / (12 rho))
    Ep = 2.25 / (1 - 1 / 64) * 9046.59 ** 2
    omega = 4.730040745 ** 2 / 0.06 ** 2 * math.sqrt(Ep * 0.01 ** 2 / 12)
    assert euler_bernoulli_period() == pytest.approx(2 * math.pi / omega, rel=1e-12)
    assert euler_bernoulli_period() == pytest.approx(2.561e-5, rel=1e-3)
    # the short plate (L/W = 6) bends slower than Euler-Bernoulli: shear and rotary inertia
    # (coarse elements are too stiff, so this is a lower bound of the continuum period)
    t_fe = finite_element_period(30, 5)
    assert 1.07 * euler_bernoulli_period() < t_fe < PERIOD_CONTINUUM
    x, y = isometric_lattice(0.01 / 40, 0.06, 0.01)
    assert np.min(x * x + y * y) == 0.0          # the centre is a material point
    assert abs(x.size - 0.06 * 0.01 / (0.01 / 40) ** 2) < 0.02 * 9600
    t = np.linspace(0, 1, 2001)
    assert measured_period(t, np.sin(2 * math.pi * t / 0.8))[0] == pytest.approx(0.8, rel=1e-5)
    tc, up = zero_crossings(t, np.sin(2 * math.pi * t / 0.8))
    assert up.tolist() == [-1, 1]


def test_coarse_plate_conserves_energy_while_it_bends(coarse):
    res, hist = coarse["10"]
    t, yc, ek, eb, es, ep, et = hist.T
    # energy flows from kinetic into bulk + shear and back (past a quarter period)
    assert ek.min() < 0.2 * ek[0] and es.max() > 0.3 * et[0] and ek[-1] > 2 * ek.min()
    assert res["energy_drift"] < 1e-4, res
    # the centre goes up first, peaks near a quarter period of the initial omega
    assert yc[np.argmax(np.abs(yc))] > 0
    assert 0.2 < res["t_centre_max"] * OMEGA / (2 * math.pi) < 0.32, res
    assert res["void_fraction"] == 0 and res["clump_fraction"] == 0 and not res["torn"]


def test_without_the_penalty_the_plate_tears(coarse):
    res, hist = coarse["0"]
    assert res["torn"] and res["clump_fraction"] > 0.05, res
    assert hist[:, 5].max() == 0.0                 # no penalty energy at all
    assert res["energy_drift"] < 1e-4, res         # tearing is no energy error


@pytest.mark.slow
def test_continuum_period_by_extrapolated_finite_elements():
    t60, t96 = finite_element_period(60, 10), finite_element_period(96, 16)
    h60, h96 = 1 / 60 ** 2, 1 / 96 ** 2
    assert t96 + (t96 - t60) * h96 / (h60 - h96) == pytest.approx(PERIOD_CONTINUUM, rel=5e-4)


@pytest.mark.slow
def test_one_period_at_20_across(tmp_path):
    """The paper's checks at half its resolution: energy over one period, the period, tearing.
    The period is checked against the linear continuum (finite elements): the issue's
    Euler-Bernoulli target is 8.8 % below it for this short plate (docs/shtc.md)."""
    res, _ = run_plate(tmp_path / "cp10", "--nw", "20")
    assert res["energy_drift"] < 1e-4, res
    assert res["period_from"] == "full"
    assert abs(res["period_error_continuum"]) < 0.05, res
    assert not res["torn"]
    res0, _ = run_plate(tmp_path / "cp0", "--nw", "20", "--cp-factor", "0")
    assert res0["torn"], res0
