"""The superfluid fountain (Kincl 2023, thesis sec. 3.6): heater, superleak, flux counter, the application.

Default suite: the superleak stage on numpy arrays (v_n decays as exp(-k dt), v_s untouched,
energy returned as entropy), the flux counter on permuted particles, the apparatus, and a
few steps of the quick preset (one compiled scene): the heater injects the set power, mass
is conserved, the counter counts nothing before the jet exists, the post-processing runs.
``-m slow``: the quick preset at 80 W/m to its end (minutes on one core), its flux against
eq. 3.56.
"""
import json

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.applications.fountain import (LEVEL, R_CAP, SUPERLEAK, Y_EXIT, FluxCounter, apparatus,
                                          inside_solid)
from sphgen.equations.superfluid import ADIABATIC, COOLER, FLUID
from sphgen.equations.superfluid_energy import HELIUM_1_65K as MODEL
from sphgen.equations.superfluid_fountain import source_kernel, superleak_rate
from sphgen.schemes.superfluid_fountain import FountainStep


def test_source_kernel_is_normalised():
    """W_H integrates to 1 over the plane and vanishes beyond 2H."""
    H = 2e-3
    r = np.linspace(0.0, 2.5 * H, 20001)
    w = np.array([source_kernel(ri, H) for ri in r])
    assert np.trapezoid(2 * np.pi * r * w, r) == pytest.approx(1.0, rel=1e-6)
    assert source_kernel(2.0 * H, H) == 0.0 and source_kernel(2.1 * H, H) == 0.0


def test_superleak_relaxes_normal_velocity_and_returns_its_energy():
    """Stage 8: rho_n v_n -> exp(-k dt) rho_n v_n with v_s fixed; the kinetic energy it takes
    reappears as heat, T ds, to first order; outside the band and on walls nothing changes."""
    rng = np.random.default_rng(3)
    n = 200
    x = rng.uniform(-20e-3, 20e-3, n)
    y = rng.uniform(-2e-3, 4e-3, n)
    ptype = np.where(rng.uniform(size=n) < 0.1, ADIABATIC, FLUID).astype(np.int32)
    u, v, us, vs = (rng.normal(0, 0.05, n) for _ in range(4))
    s = MODEL.s0 * (1 + rng.normal(0, 1e-4, n))
    m = np.full(n, 1e-6)
    u0, v0, us0, vs0, s0 = u.copy(), v.copy(), us.copy(), vs.copy(), s.copy()
    step = FountainStep(2, T0=MODEL.T0, s0=MODEL.s0, rhon0=MODEL.rhon0, cv=MODEL.cv, gamma=MODEL.gamma,
                        **SUPERLEAK)
    dt = 1.356e-6
    for i in range(n):
        step.stage8(i, ptype, x, y, u, v, us, vs, s, dt)
    assert np.array_equal(us, us0) and np.array_equal(vs, vs0)
    k = np.array([superleak_rate(x[i], y[i], SUPERLEAK["k0"], SUPERLEAK["y_sl"], SUPERLEAK["d_sl"],
                                 SUPERLEAK["r_sl"]) for i in range(n)]) * (ptype == FLUID)
    rhos = 1.0 - MODEL.rhon(s0)
    assert (k > 0).sum() > 50 and (k == 0).sum() > 20
    np.testing.assert_allclose(u - rhos * us, np.exp(-k * dt) * (u0 - rhos * us0), rtol=1e-12, atol=1e-18)
    np.testing.assert_allclose(v - rhos * vs, np.exp(-k * dt) * (v0 - rhos * vs0), rtol=1e-12, atol=1e-18)
    untouched = k == 0
    assert np.array_equal(u[untouched], u0[untouched]) and np.array_equal(s[untouched], s0[untouched])

    def energy(s, u, v):
        vel, vsl = np.column_stack([u, v]), np.column_stack([us, vs])
        return np.sum(m * (MODEL.kinetic_energy(s, vel, vsl) + MODEL.heat_energy(s)))

    removed = energy(s0, u, v) - energy(s0, u0, v0)          # the kinetic energy taken, < 0
    assert removed < 0
    change = energy(s, u, v) - energy(s0, u0, v0)
    assert abs(change) < 1e-3 * abs(removed), (change, removed)
    assert np.all(s >= s0)                                   # the superleak only produces entropy


def test_flux_counter_counts_net_crossings_by_id():
    """Up minus down through the segment, by gid, whatever the memory order."""
    c = FluxCounter(1.0, 0.5)
    gid = np.arange(6)
    x = np.array([0.0, 0.1, -0.2, 0.9, 0.0, 0.3])
    c.update(gid, x, np.array([0.9, 0.8, 1.1, 0.5, 0.2, 1.2]))
    assert c.count == 0
    perm = np.array([5, 3, 0, 4, 1, 2])
    y1 = np.array([0.9, 0.8, 1.1, 0.5, 0.2, 1.2])
    y1[[0, 1, 3]] = 1.05        # 0, 1 cross up inside; 3 crosses up outside |x| < 0.5
    y1[2] = 0.95                # 2 crosses down inside
    assert c.update(gid[perm], x[perm], y1[perm]) == 1
    y2 = y1.copy()
    y2[4] = 1.3                 # 4 up
    assert c.update(gid, x, y2) == 2


def test_apparatus():
    """The cell, the capillary and the reservoir hold fluid; solids and the box walls none."""
    dr = R_CAP / 2
    x, y, ptype, _ = apparatus(dr, 3)
    fluid = ptype == FLUID
    assert not inside_solid(x[fluid], y[fluid]).any()
    assert (y[fluid] < LEVEL).all() and (np.abs(x[fluid]) < 25e-3).all()
    assert inside_solid(x[ptype == ADIABATIC], y[ptype == ADIABATIC]).all()
    cooler = ptype == COOLER
    assert ((np.abs(x[cooler]) > 25e-3) | (y[cooler] < -10e-3)).all()
    # fluid in the cell, in the capillary, and the capillary walls exist up to the exit
    assert (fluid & (np.abs(x) < 7e-3) & (y > 2e-3) & (y < 16e-3)).sum() > 100
    assert (fluid & (np.abs(x) < R_CAP) & (y > 17e-3)).sum() >= 10
    assert not inside_solid(np.array([0.0, 0.0, 0.0]), np.array([5e-3, 20e-3, 33e-3])).any()
    assert inside_solid(np.array([1.5e-3, -1.5e-3]), np.array([33e-3, 33e-3])).all()
    assert not inside_solid(np.array([1.5e-3]), np.array([Y_EXIT + 1e-4])).any()


def run(out, *extra):
    app = load_application("fountain")()
    app.run(["--preset", "quick", "-d", str(out), "--disable-output", "--no-progress", "--threads", "1",
             *extra])
    with open(out / "results.json") as f:
        res = json.load(f)
    with open(out / "history.json") as f:
        hist = json.load(f)
    return app, res, hist


@pytest.fixture(scope="module")
def short(tmp_path_factory):
    """The quick preset, 60 W/m, 60 steps, a history row every 10 steps."""
    dt = 0.4 * 1.4 * R_CAP / MODEL.c1            # the quick preset: dr = r_cap, h = 1.4 dr
    return run(tmp_path_factory.mktemp("fountain") / "short", "--power", "60", "--max-steps", "60",
               "--tf", str(200 * 10 * dt))


def test_quick_preset_few_steps(short):
    app, res, hist = short
    rows = np.array(hist["rows"])
    cols = {c: rows[:, i] for i, c in enumerate(hist["columns"])}
    assert rows.shape[0] >= 5
    # the heater gives the particles min(1, t/t_ramp) W_dot, to the partition of unity of W_H
    dt = app.solver.dt
    t_eval = cols["t"] - 0.5 * dt           # the entropy rate is taken at the half step
    np.testing.assert_allclose(cols["heater_power"], 60.0 * t_eval / 0.02, rtol=2e-3)
    # no particle is created or lost
    assert np.all(cols["mass"] == cols["mass"][0])
    pa = app.scene.by_name["helium"]
    assert pa.m.sum() == cols["mass"][0]
    # the jet has not reached the exit: nothing crossed; the cell has warmed slightly
    assert np.all(cols["crossed"] == 0) and res["flux"] == 0.0
    assert 0.0 < res["dT_cell"] < 1e-3
    assert res["mass_drift"] == 0.0
    # nothing flows yet: the pair entropy fluxes through the superleak and the capillary are small
    assert abs(res["entropy_flux_J_capillary"]) < 1e-3 and np.isfinite(res["entropy_flux_J_superleak"])
    # the heat received went into the fluid: sum m s grew by about the heat over T0
    energy_in = np.sum(np.diff(np.concatenate([[0.0], cols["t"]])) * cols["heater_power"])
    assert cols["entropy"][-1] > cols["entropy"][0]
    assert energy_in > 0


@pytest.mark.slow
def test_quick_preset_jet(tmp_path):
    """Quick preset at 80 W/m to t = 0.12 s (minutes on one core): the jet leaves the capillary,
    the cell is a few mK above T0, mass is conserved (the flux against eq. 3.56 is reported in
    docs/superfluid.md; the 5 % check is the paper preset's, below)."""
    app, res, hist = run(tmp_path / "quick80", "--power", "80")
    assert res["t"] == pytest.approx(0.12, rel=1e-9)
    assert res["flux"] > 0 and res["jet_height"] > 0
    assert 0.0 < res["dT_cell"] < 0.02
    assert res["mass_drift"] == 0.0


@pytest.mark.slow
@pytest.mark.parametrize("power", [60.0, 80.0])
def test_paper_preset_flux_within_5_percent_of_eq_3_56(tmp_path, power):
    """Issue 13: the paper preset (149 195 particles, 221 239 steps: days on one core), mean flux
    over the last 0.1 s within 5 % of eq. 3.56 with the measured s_cell, T_cell."""
    app = load_application("fountain")()
    out = tmp_path / f"paper{power:g}"
    app.run(["--preset", "paper", "--power", str(power), "-d", str(out), "--disable-output",
             "--no-progress"])
    with open(out / "results.json") as f:
        res = json.load(f)
    assert abs(res["flux_error"]) < 0.05, res


def test_compiled_matches_python_evaluator():
    """Three steps of the fountain scheme (heater on, superleak band across the cloud, gravity,
    beta, mu, ADIABATIC and COOLER particles): generated code = Python evaluator to round-off."""
    from test_superfluid import M, cloud

    from sphgen.scene import Scene
    from sphgen.schemes.superfluid_fountain import FountainScheme
    from sphgen.solver import Solver
    runs = []
    for backend in ("cython", "python"):
        pa, dx = cloud(nx=8, adiabatic=0.2, cooler=0.1, seed=5, vamp=0.1)
        sch = FountainScheme(["helium"], model=M, h=1.5 * dx, beta=1.0, mu=1e-4, gravity=(0.0, -9.8, 0.0),
                             calibrate_density=False,
                             heater=dict(x_heat=0.5e-3, y_heat=0.5e-3, H=0.2e-3, power=50.0, t_ramp=1e-9),
                             superleak=dict(k0=1e6, y_sl=0.3e-3, d_sl=0.2e-3, r_sl=0.6e-3))
        sch.setup_properties([pa])
        integ = sch.get_integrator()
        sc = Scene([pa], sch.get_equations(), steppers=integ.steppers, kernel=sch.kernel, dim=2,
                   outputs={"helium": list(sch.output_props)}, backend=backend, threads=1)
        Solver(sc, integ, dt=0.4 * 1.5 * dx / M.c1, tf=1.0, max_steps=3, progress=False).run()
        runs.append(pa)
    a, b = runs
    oa, ob = np.argsort(a.gid), np.argsort(b.gid)
    for p in ("x", "y", "u", "v", "us", "vs", "s", "rho", "p", "T", "sdot", "qheat", "au", "avs"):
        x, y = a.get(p)[oa], b.get(p)[ob]
        assert np.abs(x - y).max() <= 1e-12 * np.abs(y).max(), p
    assert np.abs(a.qheat).max() > 0 and (a.p[a.ptype != FLUID] >= 0).all()
