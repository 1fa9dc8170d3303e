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
from sphgen.applications.beryllium_plate import (BETA_L, OMEGA, PERIOD_CONTINUUM, euler_bernoulli_period,
                                                 finite_element_period, isometric_lattice, measured_period,
                                                 plane_strain_modulus, timoshenko_period, zero_crossings)


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



def free_free_mode(xi):
    """The first free-free Euler-Bernoulli mode w and its derivatives 1-3 on xi in (0, 1)."""
    b = BETA_L
    sg = (math.cosh(b) - math.cos(b)) / (math.sinh(b) - math.sin(b))
    ch, sh, c, s = np.cosh(b * xi), np.sinh(b * xi), np.cos(b * xi), np.sin(b * xi)
    return (ch + c - sg * (sh + s), b * (sh - s - sg * (ch + c)),
            b ** 2 * (ch - c - sg * (sh - s)), b ** 3 * (sh + s - sg * (ch - c)))


def test_timoshenko_period():
    t_eb = euler_bernoulli_period()
    # the paper's plate (L/W = 6): shear and rotary inertia lengthen the period by 8.9 %, to
    # within 0.1 % of the finite-element continuum period of the same linear model
    assert timoshenko_period() == pytest.approx(2.7879e-5, rel=1e-4)
    assert timoshenko_period() == pytest.approx(PERIOD_CONTINUUM, rel=1e-3)
    assert timoshenko_period() / t_eb == pytest.approx(1.0888, rel=1e-4)
    # the shear coefficient hardly matters: Cowper's 10(1 + nu)/(12 + 11 nu) at nu = 1/8
    assert timoshenko_period(kappa=10 * 1.125 / (12 + 11 * 0.125)) == pytest.approx(timoshenko_period(), rel=5e-4)
    # thin beams tend to Euler-Bernoulli as (W/L)^2, with the first-order coefficient of the
    # Rayleigh quotient on the Euler-Bernoulli mode: T/T_EB - 1 = (r^2/2)(R1 + E'/(kappa mu) R3),
    # r^2 = W^2/12, R1 = int w'^2 / int w^2, R3 = int (w''')^2 / int (w'')^2 (rotary inertia, shear)
    xi = np.linspace(0.0, 1.0, 200001)
    w, d1, d2, d3 = free_free_mode(xi)
    r1 = np.trapezoid(d1 ** 2, xi) / np.trapezoid(w ** 2, xi)
    r3 = np.trapezoid(d3 ** 2, xi) / np.trapezoid(d2 ** 2, xi)
    coefficient = 0.5 / 12 * (r1 + plane_strain_modulus() / (5 / 6 * 9046.59 ** 2) * r3)
    for ratio in (100, 1000):
        width = 0.06 / ratio
        excess = timoshenko_period(width=width) / euler_bernoulli_period(width=width) - 1
        assert excess * ratio ** 2 == pytest.approx(coefficient, rel=2 / ratio), ratio
    assert timoshenko_period(width=0.06 / 20) / euler_bernoulli_period(width=0.06 / 20) > 1

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
    assert res["period_timoshenko"] == timoshenko_period() and res["period_euler_bernoulli"] == euler_bernoulli_period()


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
    assert abs(res["period_error_timoshenko"]) < 0.05, res
    assert not res["torn"]
    res0, _ = run_plate(tmp_path / "cp0", "--nw", "20", "--cp-factor", "0")
    assert res0["torn"], res0
