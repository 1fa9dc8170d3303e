"""The symplectic SPH of Kincl's thesis (2023, chapter 1) and its dam break (§1.6):
summation density with constant, Tait, MD viscosity (eq. 1.81), viscous Verlet (eq. 1.82),
dummy no-slip walls; against Koshizuka & Oka (1996) and Violeau (2012)."""
import json
import sys

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.particles import ParticleArray
from sphgen.schemes.symplectic import SymplecticSPHScheme
from sphgen.tools import reference

from conftest import assert_close, lattice_cloud, march
from test_shtc import build

HDX = 1.5


def cloud_and_wall(nx=10, seed=0, wall=True):
    """A jittered fluid block in [0, 1]^2 with random velocities over a 3-layer dummy floor at rest."""
    fluid = lattice_cloud("fluid", nx=nx, jitter=0.2, seed=seed)
    dx = 1.0 / nx
    fluid.h[:] = HDX * dx
    arrays = [fluid]
    if wall:
        xw, yw = np.meshgrid((np.arange(nx) + 0.5) * dx, -(np.arange(3) + 0.5) * dx)
        n = xw.size
        arrays.append(ParticleArray("wall", x=xw.ravel(), y=yw.ravel(), m=np.full(n, dx * dx),
                                    h=np.full(n, HDX * dx), rho=np.ones(n)))
    return arrays, dx


def scheme_for(arrays, dx, nu=0.05, g=0.0):
    walls = [pa.name for pa in arrays if pa.name == "wall"]
    return SymplecticSPHScheme(["fluid"], walls, dim=2, rho0=1.0, c0=10.0, h=HDX * dx, nu=nu, gy=-g)


def test_pair_forces_conserve_linear_and_angular_momentum():
    """Pressure (eq. 1.13) and viscous (eq. 1.81) pair forces on a random cloud (no walls, no
    gravity, random density constants so that p != 0): sum m a = 0 and sum x x m a = 0 to 1e-12."""
    arrays, dx = cloud_and_wall(nx=10, seed=3, wall=False)
    fluid = arrays[0]
    s = scheme_for(arrays, dx, nu=0.05)
    sc, integ = build(arrays, s, "python")
    integ.initial_accelerations(0.0, s.get_timestep())
    rng = np.random.default_rng(5)
    fluid.crho[:] += 0.02 * rng.uniform(-1, 1, fluid.n)      # any density field: the sums are pairwise
    sc.compute(1, 0.0, 0.0)
    sc.compute(0, 0.0, 0.0)
    m, x, y = fluid.m, fluid.x, fluid.y
    for name, (ax, ay) in {"pressure": (fluid.au, fluid.av), "viscous": (fluid.au_visc, fluid.av_visc)}.items():
        scale = np.sum(m * np.hypot(ax, ay))
        assert scale > 0, name
        assert abs(np.sum(m * ax)) < 1e-12 * scale and abs(np.sum(m * ay)) < 1e-12 * scale, name
        torque = np.sum(m * (x * ay - y * ax))
        assert abs(torque) < 1e-12 * scale * np.hypot(x, y).max(), name


def run_steps(backend, steps=4):
    arrays, dx = cloud_and_wall(nx=8, seed=1)
    s = scheme_for(arrays, dx, nu=0.05, g=9.8)
    sc, integ = build(arrays, s, backend)
    march(integ, s.get_timestep(), steps)
    return arrays, sc


@pytest.fixture(scope="module")
def compiled_and_python():
    return run_steps("cython"), run_steps("python")


def test_compiled_matches_python(compiled_and_python):
    """Four viscous Verlet steps with walls, viscosity and gravity: generated code == Python evaluator."""
    (ca, csc), (pa, psc) = compiled_and_python
    kept = {type(ep.eq).__name__ for ep in csc.plan.eqplans if ep.kept}
    assert {"MDViscosity", "PressureGradient", "TaitEOS", "SummationDensityWithConstant",
            "DensityConstant", "BodyForce"} <= kept
    for a, b in zip(ca, pa):
        assert sorted(a.data) == sorted(b.data)
        for name in a.data:
            assert_close(a.data[name], b.data[name], 1e-11, what=f"{a.name}.{name}")
    fluid, wall = ca
    assert np.abs(fluid.au_visc).max() > 0 and np.abs(fluid.p).max() > 0
    assert np.all(wall.u == 0) and np.all(wall.v == 0)            # dummy walls stay at rest
    assert np.abs(wall.rho - 1.0).max() > 0                       # ... but carry their own density


def test_nu_zero_removes_the_viscous_update():
    """nu = 0: no viscous group, and the step is plain Verlet (eq. 1.78)."""
    arrays, dx = cloud_and_wall(nx=4, seed=2)
    s = scheme_for(arrays, dx, nu=0.0)
    names = {type(e).__name__ for g in s.get_equations()[0] for e in g.equations}
    assert "MDViscosity" not in names
    integ = s.get_integrator()
    assert integ.steppers["fluid"].viscous == 0
    assert integ.sequence == (("kick", 0.5), ("drift", 1.0), ("kick", 0.5))   # one build per step
    assert integ.evaluated_sets() == {1, 2}      # set 0 (density + viscosity) is never generated


def run_app(tmp_path, *args, output=False):
    app = load_application("dam_break_2d")()
    out = tmp_path / "db"
    app.run(["--scheme", "symplectic", "--no-progress", "--threads", "1", "-d", str(out)]
            + ([] if output else ["--disable-output"]) + list(args))
    with open(out / "results.json") as f:
        res = json.load(f)
    with open(out / "history.json") as f:
        hist = json.load(f)
    return res, np.array(hist["rows"]), app, out


def test_coarse_dam_break_stays_in_the_tank_and_the_toe_advances(tmp_path):
    """dx = L/20 to t = 0.2 s (T = 0.885): the thesis' set-up (g = 9.8, tank 4L x 3L, Wendland
    h = 1.5 dx, 3 wall layers, c0 = 50); fluid inside the tank, toe moving forward and
    near Violeau's curve, energy (kinetic + potential + fluid and wall internal) conserved."""
    res, rows, app, out = run_app(tmp_path, "--dx", "0.05", "--tf", "0.2", "--pfreq", "200", output=True)
    s = app.scheme
    assert isinstance(s, SymplecticSPHScheme) and res["scheme"] == "symplectic"
    assert s.kernel.name == "wendland" and app.h == pytest.approx(1.5 * 0.05)
    assert app.n_layers == 3 and s.nu == 1e-6 and s.c0 == 50.0 and s.gy == -9.8
    f, w = app.scene.by_name["fluid"], app.scene.by_name["wall"]
    assert w.y.max() < 3.0 and w.x.max() < 4.0 + 3 * 0.05                # the thesis' tank
    assert np.all((f.x > -0.025) & (f.x < 4.0 + 0.025) & (f.y > -0.025))     # before the first wall layer
    assert res["n_outside_max"] == 0 and res["mass_drift"] == 0.0
    T, Z = rows[:, 1], rows[:, 2]
    assert T[-1] == pytest.approx(0.2 * np.sqrt(2 * 9.8), rel=1e-3)
    assert Z[0] == pytest.approx(1.0 - 0.025) and Z[-1] > 1.2
    assert np.all(np.diff(Z) >= -0.05 - 1e-12)                          # forward, up to one dx
    assert res["toe_max_rel_dev_violeau"] < 0.10
    assert abs(res["energy_change_rel"]) < 1e-5                         # measured 7.7e-7
    app_mod = sys.modules[type(app).__module__]
    png = app_mod.thesis_figure_1_3(str(out), str(tmp_path / "fig.png"))
    assert (tmp_path / "fig.png").exists() and png == str(tmp_path / "fig.png")
    png = app_mod.thesis_figure_1_2(str(out), times=(0.0, 0.1, 0.2))
    assert png.endswith("thesis_fig_1_2.png") and (out / "thesis_fig_1_2.png").exists()


def test_reference_curves_of_the_thesis():
    """Violeau (2012) and Kincl's Koshizuka & Oka digitisation: the authors' data, monotone in T and Z."""
    for T, Z in (reference.violeau_2012_dam_break_front(), reference.koshizuka_oka_1996_kincl()):
        assert np.all(np.diff(T) > 0) and np.all(np.diff(Z) > 0) and 1.0 <= Z[0] < 1.2
    T, Z = reference.violeau_2012_dam_break_front()
    assert T.size == 16 and T[-1] == pytest.approx(3.005, abs=1e-3) and Z[-1] == pytest.approx(3.989, abs=1e-3)
    assert "SmoothedParticles.jl" in reference.source("violeau_2012_dam_break_front.csv")


@pytest.mark.slow
def test_dam_break_against_violeau_and_koshizuka_oka(tmp_path):
    """dx = L/50 to t = 0.7 s (T = 3.1): the toe within 0.25 L of Violeau's curve at
    T = 1, 1.5, 2, 2.5 (the digest's proposed acceptance; the thesis gives no number; measured
    <= 0.031) and within 10 % of it over its data range (measured 4.1 %), monotone but for
    steps back of up to 3 dx when the leading particle leaves the floor band (measured 2.3 dx);
    the measured deviations are in docs/shtc.md."""
    res, rows, app, out = run_app(tmp_path, "--dx", "0.02", "--tf", "0.7")
    T, Z = rows[:, 1], rows[:, 2]
    Tv, Zv = reference.violeau_2012_dam_break_front()
    for t in (1.0, 1.5, 2.0, 2.5):
        assert abs(np.interp(t, T, Z) - np.interp(t, Tv, Zv)) <= 0.25, t
    assert np.all(np.diff(Z) >= -3 * 0.02)
    assert res["n_outside_max"] == 0 and res["toe_max_rel_dev_violeau"] < 0.10, res
