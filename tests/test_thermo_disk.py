"""The rotating disk of Ghavamian et al. (2021) sec. 7.3 (applications/thermo_disk.py).

Checks of issue 12: free flight with the projection, |L(t) - L(0)| <= 1e-10 max sum V|p|
and A constant to 1e-10 relative throughout; the E-form energy budget to 1e-10; after the
heat flux, E_tot flat, S never falls and B never rises (1e-3 of their change); the E-form
and eta-form probe v_Z within 5 % (relative L2 in time).  The fast tests squeeze the heat
flux into 0.2 s on the coarsest lattice; the slow one runs the paper's 10 s at dx = 0.5.
"""
import numpy as np
import pytest

from sphgen.applications._thermo_solid import cylinder_lattice, relative_l2_in_time, run_quietly
from sphgen.applications.thermo_disk import ThermoDisk, heat_flux, heated_area


def run(out, *args):
    return run_quietly(ThermoDisk, out, *args)


def check(r, h, form):
    assert r["L_drift"] <= 1e-10 and r["A_drift"] <= 1e-10
    assert r["entropy_rise"] > 0 and r["entropy_fall"] <= 1e-3
    assert r["ballistic_drop"] > 0 and r["ballistic_rise"] <= 1e-3
    assert r["J_min"] > 0 and r["theta_range"][0] > 0
    if form == "E":
        assert r["energy_residual"] <= 1e-10 and r["total_spread_after_heating"] <= 1e-10
        # the heat flux went in, then out: E_tot peaks near T/2 and ends where it began
        T = r["heat_time"]
        assert abs(h["t"][np.argmax(h["total"])] - 0.5 * T) <= 0.1 * T
        # (the exact heat input over [0, T] is 0; RK2 integrates sin with an O(dt^2) error)
        assert abs(h["total"][-1] - h["total"][0]) <= 1e-2 * (h["total"].max() - h["total"][0])


def test_heat_flux_is_the_papers():
    assert [heat_flux(t) for t in (0.0, 1.0, 2.0, 3.0, 4.5)] == pytest.approx([0.0, 1.0, 0.0, -1.0, 0.0], abs=1e-15)


def test_cylinder_lattice_is_symmetric_with_cell_fraction_volumes():
    x, y, z, V, f = cylinder_lattice(0.5, 5.0, -0.5, 0.5)
    assert x.size == 948 and np.all((V > 0) & (V <= 0.125 + 1e-15)) and np.all((f > 0) & (f <= 1))
    assert abs(np.sum(V * x)) < 1e-12 and abs(np.sum(V * y)) < 1e-12 and abs(np.sum(V * z)) < 1e-12
    assert abs(V.sum() / (np.pi * 25.0) - 1) < 0.03
    assert np.all(np.hypot(x, y)[f < 1] > 4.5)       # the cut cells are on the rim
    x, y, z, V, f = cylinder_lattice(0.25, 1.0, 0.0, 1.0, 0.5)     # the punch's hollow cylinder
    r = np.hypot(x, y)
    assert x.size == 200 and r.min() >= 0.5 - 1e-12 and r.max() <= 1.0 + 1e-12


def test_rim_heat_goes_to_the_tributary_areas_evenly_along_the_rim():
    """--heat-area tributary (default): each particle gets the part of the heated quarter of
    the rim nearest to it; the areas sum to pi R T / 2, lie within dx of r = R, and every 15
    degree sector of the quarter gets its share to 10 % from dx = 1/3 (the volume shares of
    the rim cells, the earlier default, put 0 % of the heat within 10 degrees of the probe's
    angle at dx = 1 and 1.19 x its share within 12 degrees at dx = 1/3: docs/thermo.md)."""
    for dx in (1.0, 0.5, 1.0 / 3.0):
        x, y, z, V, f = cylinder_lattice(dx, 5.0, -0.5, 0.5)
        a = heated_area(x, y, z, V, f, dx, 5.0, 1.0)
        b = heated_area(x, y, z, V, f, dx, 5.0, 1.0, "volume")
        quarter = 0.5 * np.pi * 5.0
        assert a.sum() == pytest.approx(quarter, rel=1e-12) and b.sum() == pytest.approx(quarter, rel=1e-12)
        r, phi = np.hypot(x, y), np.degrees(np.arctan2(y, x))
        assert np.all(5.0 - r[a > 0] < dx) and np.all((phi[a > 0] >= 0) & (phi[a > 0] <= 90))
        # the top and bottom vertices carry half a cell of the rim each
        assert a[z == z.max()].sum() == pytest.approx(0.5 * dx * quarter, rel=1e-12)
        if dx <= 0.5:     # every 30 degree arc: its share of the heat over 30/90
            def arcs(w):
                return np.array([w[np.abs(phi - c) <= 15].sum() / w.sum() * 3 for c in np.arange(15.0, 75.5, 1)])
            assert 0.75 < arcs(a).min() and arcs(a).max() < 1.2, (dx, arcs(a).min(), arcs(a).max())
            assert arcs(b).max() > 1.5, (dx, arcs(b).max())


@pytest.fixture(scope="module")
def short_runs(tmp_path_factory):
    d = tmp_path_factory.mktemp("disk")
    args = ["--dx", "1", "--heat-time", "0.2", "--tf", "0.4"]
    return run(d / "E", *args), run(d / "eta", *args, "--form", "eta")


def test_short_free_flight_keeps_momenta_budget_and_second_law(short_runs):
    (r, h), (re, he) = short_runs
    assert r["n_particles"] == 160 and r["variant"] == "reduced" and r["projection"]
    check(r, h, "E")
    check(re, he, "eta")
    assert np.linalg.norm(r["A_free"]) > 0
    # the projection's entropy is recorded (E-form; the eta-form's eta equation has no such term)
    assert r["entropy_projection"] < 0 and r["entropy_fall_without_projection"] <= 1e-3
    assert re["entropy_projection"] == 0


def paper_flux_at_dx_1(tmp_path, *args):
    r, h = run(tmp_path, "--dx", "1", *args)
    assert r["t"] == pytest.approx(10.0) and r["n_particles"] == 160
    return r, h


def test_dx_1_keeps_the_second_law_at_the_default_cfl(tmp_path):
    """The paper's heat flux to 4 s, 10 s on 160 particles at the disk's default alpha_CFL = 0.25
    (1388 steps): every check, S rising from 4 s although the projection takes more entropy
    than that rise (docs/thermo.md, "Decision (disk time step)")."""
    r, h = paper_flux_at_dx_1(tmp_path)
    assert r["cfl"] == 0.25
    check(r, h, "E")
    assert r["entropy_projection"] < -r["entropy_rise"] < 0


@pytest.mark.xfail(strict=True, reason="at alpha_CFL = 0.3 (the paper's, for raw jumps) the limited-jump scheme "
                                       "steps past the full scheme's limit at dx = 1 (between 0.28 and 0.29): "
                                       "the reduced scheme (default) gains S(10) - S(4) = +1.23 J/K "
                                       "but one step's S falls by 1.4 % of that gain at t = 9.956 s (> 1e-3; "
                                       "this test checks every step, stricter than the issue's output to "
                                       "output, which holds; measured 2026-11-24; the full scheme: S(10) - S(4) = -4.70 J/K; docs/thermo.md, "
                                       "\"Round 7\", 1 and \"Round 11\")")
def test_dx_1_keeps_the_second_law_at_the_papers_cfl(tmp_path):
    r, h = paper_flux_at_dx_1(tmp_path, "--cfl", "0.3")
    check(r, h, "E")


def test_energy_and_entropy_forms_agree_at_the_probe(short_runs):
    (r, h), (re, he) = short_runs
    assert relative_l2_in_time(h["t"], h["probe_vz"], he["t"], he["probe_vz"]) <= 0.05
    assert np.abs(h["probe_vz"]).max() > 0.1


@pytest.mark.slow
def test_paper_run_on_the_948_particle_lattice(tmp_path):
    """dx = 0.5, the paper's heat flux to 4 s, to 10 s, E- and eta-form."""
    r, h = run(tmp_path / "E", "--dx", "0.5")
    check(r, h, "E")
    re, he = run(tmp_path / "eta", "--dx", "0.5", "--form", "eta")
    check(re, he, "eta")
    assert relative_l2_in_time(h["t"], h["probe_vz"], he["t"], he["probe_vz"]) <= 0.05
