"""CTVF (Adepu & Ramachandran 2021): correction terms, shifting pieces and the scheme."""
import json
from functools import partial

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.equation import Equation, Group
from sphgen.equations import shifting, transport
from sphgen.equations.ctvf import (ContinuityTransportCorrection, EDACTransportCorrection,
                                   MomentumTransportDivergence)
from sphgen.equations.shifting import IPSTAcceleration, IPSTShift, IPSTStart, lattice_chi
from sphgen.equations.transport import TransportStress
from sphgen.kernels import QuinticSpline
from sphgen.scene import Scene
from sphgen.schemes.ctvf import CTVFScheme
from sphgen.solver import Solver

from conftest import assert_close, lattice_cloud, periodic_box

TWO_PI = 2.0 * np.pi


def build(scheme, pa, backend="cython", periodic=True):
    scheme.setup_properties([pa])
    integ = scheme.get_integrator()
    sc = Scene([pa], scheme.get_equations(), steppers=integ.steppers, kernel=scheme.kernel,
               dim=scheme.dim, domain=periodic_box(scheme.dim) if periodic else None,
               outputs={"fluid": list(scheme.output_props)}, backend=backend)
    integ.attach(sc)
    return sc, integ


def cloud(nx=10, seed=3):  # noqa: D103
    pa = lattice_cloud(nx=nx, jitter=0.25, seed=seed)
    rng = np.random.default_rng(seed + 1)
    pa.add_property("p", data=rng.uniform(-0.5, 0.5, pa.n))
    return pa


def steps(sc, integ, scheme, n):
    dt = scheme.get_timestep()
    integ.initial_accelerations(0.0, dt)
    for k in range(n):
        integ.one_timestep(k * dt, dt)


# ------------------------------------------------------------------ compiled == Python
@pytest.mark.parametrize("kw", [
    dict(shifting="spst", alpha=0.2, bql=True),
    dict(shifting="spst", density="continuity"),
    dict(shifting="ipst", ipst_max_iterations=3),
    dict(shifting="ipst", ipst_max_iterations=2, ipst_interval=2, dim=3),
    dict(shifting="gtvf", corrections=("edac",)),
    dict(shifting="tvf", corrections=("stress", "divergence"), dim=3),
], ids=["spst-bql-alpha", "spst-continuity", "ipst", "ipst-every-2nd-3d", "gtvf-shift", "tvf-3d"])
def test_ctvf_compiled_matches_python(kw):
    kw = dict(kw)
    dim = kw.pop("dim", 2)
    nx = {2: 10, 3: 6}[dim]
    out = {}
    for backend in ("cython", "python"):
        pa = lattice_cloud(nx=nx, dim=dim, jitter=0.25, seed=3)
        pa.add_property("p", data=np.random.default_rng(4).uniform(-0.5, 0.5, pa.n))
        s = CTVFScheme(["fluid"], dim=dim, rho0=1.0, c0=10.0, nu=0.01, h=1 / nx, dx=1 / nx, **kw)
        sc, integ = build(s, pa, backend)
        steps(sc, integ, s, 2)
        out[backend] = (pa, sc)
    a, sca = out["cython"]
    b, _ = out["python"]
    kept = {type(ep.eq).__name__ for ep in sca.plan.eqplans if ep.kept}
    on = kw.get("corrections", ("edac", "stress", "divergence"))
    assert ("EDACTransportCorrection" in kept) == ("edac" in on)
    assert ("TransportStress" in kept) == ("stress" in on)
    assert ("MomentumTransportDivergence" in kept) == ("divergence" in on)
    if kw.get("density") == "continuity":
        assert {"TransportContinuity", "ContinuityTransportCorrection"} <= kept
    if kw["shifting"] == "ipst":
        assert {"IPSTStart", "IPSTShift", "IPSTAcceleration"} <= kept
        assert ("ZeroHomogenisation" in kept) == (kw.get("ipst_interval", 1) > 1)
    assert sorted(a.data) == sorted(b.data)
    for name in a.data:
        assert_close(a.data[name], b.data[name], 1e-11, what=f"{kw}: {name}")
    assert np.abs(a.ap).max() > 0 and np.abs(a.auhat).max() > 0
    if dim == 3:
        assert np.abs(a.aw).max() > 0 and np.abs(a.awhat).max() > 0


# -------------------------------------------------- correction terms vs analytic values
class ZeroRates(Equation):
    def initialize(self, d_idx, d_ap, d_au, d_av, d_aw, d_arho):
        d_ap[d_idx] = 0.0
        d_au[d_idx] = 0.0
        d_av[d_idx] = 0.0
        d_aw[d_idx] = 0.0
        d_arho[d_idx] = 0.0


# smooth periodic fields: velocity u, shift delta = u~ - u, pressure p, density rho
def f_u(x, y):
    return np.sin(TWO_PI * x) * np.cos(TWO_PI * y)


def f_v(x, y):
    return -np.cos(TWO_PI * x) * np.sin(TWO_PI * y)


def f_dx(x, y):
    return 0.3 * np.sin(TWO_PI * x + 1.0) + 0.1 * np.cos(TWO_PI * y)


def f_dy(x, y):
    return 0.2 * np.cos(TWO_PI * y + 0.5) - 0.1 * np.sin(TWO_PI * x)


def f_p(x, y):
    return np.cos(TWO_PI * x) * np.sin(TWO_PI * y) + 0.4 * np.sin(TWO_PI * (x + y))


def f_rho(x, y):
    return 1.0 + 0.1 * np.sin(TWO_PI * x) * np.sin(TWO_PI * y)


FIELDS = {"u": f_u, "v": f_v, "dx": f_dx, "dy": f_dy}


def d(f, x, y, axis, eps=1e-6):
    """Central difference of an analytic field (error ~1e-11 of the derivative)."""
    if axis == 0:
        return (f(x + eps, y) - f(x - eps, y)) / (2 * eps)
    return (f(x, y + eps) - f(x, y - eps)) / (2 * eps)


def manufactured(nx, term, jitter=0.0, fields=None):
    """(discrete, exact) of one correction term on a periodic lattice (moved by up to
    ``jitter`` dx), h = dx; ``fields``: (u, v, delta_x, delta_y), default the module's."""
    f_u, f_v, f_dx, f_dy = fields or (FIELDS["u"], FIELDS["v"], FIELDS["dx"], FIELDS["dy"])
    dx = 1.0 / nx
    g = np.arange(nx) * dx + dx / 2
    x, y = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    if jitter:
        rng = np.random.default_rng(5)
        x = (x + rng.uniform(-jitter, jitter, x.size) * dx) % 1.0
        y = (y + rng.uniform(-jitter, jitter, y.size) * dx) % 1.0
    rho = f_rho(x, y) if term == "continuity" else np.ones_like(x)
    from sphgen.particles import ParticleArray
    pa = ParticleArray("fluid", x=x, y=y, u=f_u(x, y), v=f_v(x, y), rho=rho, m=rho * dx * dx,
                       h=np.full(x.size, dx))
    pa.add_property("uhat", data=f_u(x, y) + f_dx(x, y))
    pa.add_property("vhat", data=f_v(x, y) + f_dy(x, y))
    pa.add_property("what", default=0.0)
    pa.add_property("p", data=f_p(x, y))
    for p in ("ap", "au", "av", "aw", "arho"):
        pa.add_property(p)
    eqs = {"edac": [EDACTransportCorrection], "stress": [TransportStress],
           "divergence": [MomentumTransportDivergence], "continuity": [ContinuityTransportCorrection],
           "both": [TransportStress, MomentumTransportDivergence],
           "divergence_printed": [partial(MomentumTransportDivergence, printed=True)],
           "stress_difference": [partial(TransportStress, difference=True)],
           "both_difference": [partial(TransportStress, difference=True), MomentumTransportDivergence]}[term]
    eqs = [ZeroRates("fluid")] + [eq("fluid", ["fluid"]) for eq in eqs]
    out = {"edac": ["ap"], "continuity": ["arho"]}.get(term, ["au", "av"])
    sc = Scene([pa], [Group(eqs)], dim=2, domain=periodic_box(2), outputs={"fluid": out})
    sc.compute(0, 0.0, 1e-3)
    x, y = pa.x, pa.y   # the scene sorted the particles spatially
    divd = d(f_dx, x, y, 0) + d(f_dy, x, y, 1)
    if term == "edac":      # delta . grad p
        return [pa.ap], [f_dx(x, y) * d(f_p, x, y, 0) + f_dy(x, y) * d(f_p, x, y, 1)]
    if term == "continuity":  # div(rho delta)
        return [pa.arho], [d(lambda a, b: f_rho(a, b) * f_dx(a, b), x, y, 0)
                           + d(lambda a, b: f_rho(a, b) * f_dy(a, b), x, y, 1)]
    exact = []
    for f in (f_u, f_v):
        stress = d(lambda a, b: f(a, b) * f_dx(a, b), x, y, 0) + d(lambda a, b: f(a, b) * f_dy(a, b), x, y, 1)
        divt = divd + d(f_u, x, y, 0) + d(f_v, x, y, 1)   # div u~
        exact.append({"stress": stress, "divergence": -f(x, y) * divd, "both": stress - f(x, y) * divd,
                      "divergence_printed": -f(x, y) * divt, "stress_difference": stress,
                      "both_difference": stress - f(x, y) * divd}[term])
    return [pa.au, pa.av], exact


def rel_error(nx, term):
    got, exact = manufactured(nx, term)
    scale = max(np.abs(e).max() for e in exact)
    return max(np.abs(g - e).max() for g, e in zip(got, exact)) / scale


@pytest.mark.parametrize("term", ["edac", "stress", "divergence", "both", "continuity",
                                  "divergence_printed", "stress_difference", "both_difference"])
def test_correction_terms_converge_to_their_analytic_values(term):
    """delta.grad p (C2), div(u (x) delta), -u div delta (C3), (delta.grad) u, div(rho delta)
    (C1), eq. 27's printed -u div u~, the difference form of div(u (x) delta): the discrete
    term approaches the analytic one, about second order on a lattice."""
    e20, e40 = rel_error(20, term), rel_error(40, term)
    assert e40 < 0.35 * e20, (term, e20, e40)
    assert e40 < 0.05, (term, e40)


def test_difference_form_of_the_stress_term_has_no_zeroth_order_error():
    """u and delta uniform on a jittered cloud: div(u (x) delta) = 0.  The difference form
    gives 0 to round-off; the printed symmetric form gives 2 u (delta . sum_b V_b grad W),
    which is what drives Re 1000 Taylor-Green below the exact decay (docs/ctvf.md)."""
    def const(c):
        return lambda x, y: np.full_like(x, c)
    fields = (const(0.7), const(-0.4), const(0.2), const(0.1))
    got = {t: max(np.abs(g).max() for g in manufactured(16, t, jitter=0.25, fields=fields)[0])
           for t in ("stress_difference", "stress")}
    assert got["stress_difference"] < 1e-12, got
    assert got["stress"] > 1e-2, got


# ------------------------------------------------------------- switched off == absent
def test_switched_off_corrections_are_absent_from_plan_and_source():
    names = ("EDACTransportCorrection_", "TransportStress_", "MomentumTransportDivergence_")
    pa = cloud(8)
    on, _ = build(CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=0.125, dx=0.125), pa)
    assert all(n in on.source for n in names)
    pa = cloud(8)
    off, _ = build(CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=0.125, dx=0.125,
                              corrections=()), pa)
    assert not any(n in off.source for n in names)
    plan = off.describe()
    for n in names:
        assert f"prune {n[:-1]}[fluid<-fluid]: switched off (enabled=False" in plan
    pa = cloud(8)
    one, _ = build(CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=0.125, dx=0.125,
                              corrections=("divergence",)), pa)
    assert "MomentumTransportDivergence_" in one.source and "EDACTransportCorrection_" not in one.source


# ------------------------------------------------------------------ linear momentum
def momentum_drift(corrections, shift="spst", nsteps=40):
    pa = lattice_cloud(nx=16, jitter=0.3, seed=7)
    rng = np.random.default_rng(1)
    pa.add_property("p", data=rng.uniform(-1, 1, pa.n))
    s = CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.02, h=1 / 16, dx=1 / 16,
                   shifting=shift, corrections=corrections, bql=False, ipst_max_iterations=3)
    sc, integ = build(s, pa)
    p0 = np.array([np.sum(pa.m * pa.u), np.sum(pa.m * pa.v)])
    scale = np.sum(pa.m * np.hypot(pa.u, pa.v))
    solver = Solver(sc, integ, dt=s.get_timestep(), tf=1.0, max_steps=nsteps, progress=False)
    solver.run()
    assert solver.step == nsteps and np.abs(pa.auhat).max() > 1.0
    return np.abs(np.array([np.sum(pa.m * pa.u), np.sum(pa.m * pa.v)]) - p0).max() / scale


@pytest.mark.parametrize("corrections,shift", [((), "spst"), (("edac", "stress"), "spst"),
                                               (("edac", "stress"), "ipst")])
def test_momentum_conserved_to_round_off_without_the_divergence_term(corrections, shift):
    """Pressure gradient, viscosity and the stress term are antisymmetric pair by pair; the
    EDAC terms change only p.  So sum m u stays put with those (bql off)."""
    assert momentum_drift(corrections, shift) < 1e-12


def test_momentum_drift_with_the_divergence_term(capsys):
    """-u div(u~ - u) is not antisymmetric: report its drift (docs/ctvf.md)."""
    drift = momentum_drift(("edac", "stress", "divergence"))
    with capsys.disabled():
        print(f"\nCTVF (SPST, all corrections), 40 steps on a jittered cloud: "
              f"relative linear-momentum drift {drift:.2e}")
    assert 1e-10 < drift < 1e-2


# ---------------------------------------------------------------------- shifting
def test_spst_and_tvf_are_re_exported_from_transport():
    assert transport.SunShiftingAcceleration is shifting.SunShiftingAcceleration
    assert transport.BackgroundPressureAcceleration is shifting.BackgroundPressureAcceleration


def test_lattice_chi_is_the_initial_value_of_a_lattice():
    k = QuinticSpline(2)
    assert lattice_chi(k, 0.1, 0.1, 2) == pytest.approx(1.0001, abs=2e-4)
    pa = lattice_cloud(nx=10, jitter=0.0)
    pa.rho[:] = 1.0
    shifting.Shifting("ipst", 2, 0.1, 0.1, 10.0, 1.0, k).setup_properties(pa)
    sc = Scene([pa], [Group([IPSTShift("fluid", ["fluid"], chi_ref=1.0)])], dim=2, domain=periodic_box(2),
               outputs={"fluid": ["ipst_chi", "ipst_dx"]})
    x0 = pa.x.copy()
    sc.compute(0, 0.0, 1e-3)
    np.testing.assert_allclose(pa.ipst_chi, lattice_chi(k, 0.1, 0.1, 2), rtol=1e-12)
    assert np.abs(pa.ipst_dx).max() < 1e-15            # a lattice needs no shift
    assert np.abs(((pa.x - x0 + 0.5) % 1.0) - 0.5).max() < 1e-15


def ipst_scene(tol=0.02, max_it=10, nx=12, jitter=0.2):
    pa = lattice_cloud(nx=nx, jitter=jitter, seed=5)
    sh = shifting.Shifting("ipst", 2, 1 / nx, 1 / nx, 10.0, 1.0, QuinticSpline(2),
                           ipst_tolerance=tol, ipst_max_iterations=max_it)
    sh.setup_properties(pa)
    groups = sh.groups(["fluid"], ["fluid"])
    sc = Scene([pa], groups, dim=2, domain=periodic_box(2), outputs={"fluid": ["auhat", "avhat"]})
    return pa, sc, groups


def test_ipst_iterates_shifts_and_returns_the_displacement_as_an_acceleration():
    """Eqs. 37-41: positions are restored; (du/dt)_c dt^2/2 is the iterated displacement,
    which makes the distribution more uniform (max chi closer to the lattice value)."""
    pa, sc, groups = ipst_scene(max_it=6)
    x0, y0 = pa.x.copy(), pa.y.copy()
    dt = 0.01
    chi_ref = groups[1].equations[0].chi_ref
    sc.compute(0, 0.0, dt)
    first = groups[1].equations[0]
    assert groups[1].iterations == 6 and first.shifted        # 0.2 dx jitter: not converged
    assert np.array_equal(pa.x, x0) and np.array_equal(pa.y, y0)   # positions restored
    disp = 0.5 * dt * dt * np.array([pa.auhat, pa.avhat])
    assert np.abs(disp).max() > 1e-4 / 12
    # apply the displacement: the particles are more uniform than before
    chi = []
    for shift in (0.0, 1.0):
        q = lattice_cloud(nx=12, jitter=0.0)
        q.x[:] = pa.x + shift * disp[0]    # pa's order: the scene sorted its particles
        q.y[:] = pa.y + shift * disp[1]
        q.rho[:] = pa.rho
        shifting.Shifting("ipst", 2, 1 / 12, 1 / 12, 10.0, 1.0, QuinticSpline(2)).setup_properties(q)
        s2 = Scene([q], [Group([IPSTShift("fluid", ["fluid"], chi_ref=chi_ref)])], dim=2,
                   domain=periodic_box(2), outputs={"fluid": ["ipst_chi", "ipst_dx"]})
        s2.compute(0, 0.0, dt)
        chi.append(abs(q.ipst_chi.max() - chi_ref))
    assert chi[1] < 0.8 * chi[0], chi


def test_ipst_stops_when_converged():
    pa, sc, groups = ipst_scene(tol=0.5, max_it=10)
    sc.compute(0, 0.0, 0.01)
    # the first sweep always shifts; the second sees a converged configuration and stops
    assert groups[1].iterations == 2 and not groups[1].equations[0].shifted
    assert np.abs(pa.auhat).max() > 0


def test_ipst_every_k_steps_zeroes_the_acceleration_in_between():
    sh = shifting.Shifting("ipst", 2, 0.1, 0.1, 10.0, 1.0, QuinticSpline(2), ipst_interval=3)
    cond = sh.groups(["fluid"], ["fluid"])[0].condition
    dt = 1e-3
    assert [cond(k * dt, dt) for k in range(7)] == [True, False, False, True, False, False, True]
    assert [type(e).__name__ for e in sh.momentum_equations("fluid", ["fluid"])] == ["ZeroHomogenisation"]


# ------------------------------------------------------------------------ scheme
def test_time_step_and_stability_bounds():
    s = CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.01, h=0.02, dx=0.02)
    assert s.get_timestep() == pytest.approx(min(0.25 * 0.02 / 11.0, 0.25 * 0.02 ** 2 / 0.01))
    assert not s.check_stability(s.get_timestep())
    from sphgen.errors import StabilityError
    with pytest.raises(StabilityError, match="eq. 61"):
        s.check_stability(1.5 * s.get_timestep())
    g = CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.0, h=0.02, dx=0.02, gy=-9.81)
    assert g.get_timestep() == pytest.approx(0.25 * 0.02 / 11.0)
    with pytest.raises(ValueError, match="unknown correction"):
        CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.0, h=0.02, dx=0.02, corrections=("A",))
    with pytest.raises(ValueError, match="shifting must be one of"):
        CTVFScheme(["fluid"], dim=2, rho0=1.0, c0=10.0, nu=0.0, h=0.02, dx=0.02, shifting="sun")


def run_tg(tmp_path, *extra, nx=30, tf=0.3):
    out = tmp_path / "tg"
    app = load_application("taylor_green")()
    app.run(["--nx", str(nx), "--re", "100", "--tf", str(tf), "-d", str(out), "--disable-output",
             "--no-progress", *extra])
    with open(out / "results.json") as f:
        return json.load(f), app


@pytest.mark.parametrize("nx,extra,l1max,umax", [
    (40, ("--scheme", "ctvf"), 0.02, 0.015),
    (30, ("--scheme", "ctvf", "--shifting", "ipst"), 0.02, 0.03),
], ids=["spst", "ipst"])
def test_short_taylor_green_run(tmp_path, nx, extra, l1max, umax):
    """Measured (Re 100, t = 0.3, the default 0.1 dx perturbation): SPST nx 40 largest L1
    0.0120, largest |max|u|/exact - 1| 0.64 %; IPST nx 30 0.0098, 1.46 % (on the plain
    lattice: 0.108, 7.4 % and 0.074, 4.9 %)."""
    res, app = run_tg(tmp_path, *extra, nx=nx)
    assert type(app.scheme).__name__ == "CTVFScheme" and app.scheme.bql
    assert res["t"] == pytest.approx(0.3)
    assert res["l1_error_max"] <= l1max, res
    assert abs(res["max_u_rel_error"]) <= umax, res


@pytest.mark.slow
@pytest.mark.parametrize("nx,extra,bounds", [
    (50, ("--shifting", "ipst"), dict(l1=0.015, l1max=0.08, umax=0.02)),
    (100, ("--shifting", "spst"), dict(l1=0.01, l1max=0.08, umax=0.01)),
], ids=["ipst-nx50", "spst-nx100"])
def test_taylor_green_re100_to_t2(tmp_path, nx, extra, bounds):
    """docs/ctvf.md: Re 100, t = 2, plain lattice (measured: IPST nx 50 L1 0.0095, max 0.070,
    max|u| +1.04 %; SPST nx 100 L1 0.0046, max 0.069, max|u| +0.14 %)."""
    res, _ = run_tg(tmp_path, "--scheme", "ctvf", *extra, "--no-openmp", "--perturb", "0", nx=nx, tf=2.0)
    assert res["l1_error"] <= bounds["l1"] and res["l1_error_max"] <= bounds["l1max"], res
    assert abs(res["max_u_rel_error"]) <= bounds["umax"], res


# ------------------------------------------- issue 9, beyond the paper: whole-run errors
def tg_whole_run(tmp_path, scheme, re, *extra, nx=50):
    res, _ = run_tg(tmp_path / f"{scheme}{re}{''.join(extra)}", "--scheme", scheme, "--re", str(re),
                    *extra, "--threads", "1", nx=nx, tf=2.0)
    return res


@pytest.mark.slow
@pytest.mark.parametrize("re", [100, pytest.param(1000, marks=pytest.mark.xfail(
    reason="measured (docs/ctvf.md): on the same 0.1 dx perturbed start CTVF + SPST peaks at 0.0395 "
    "(at t = 2) against EDAC's 0.0306", strict=True))])
def test_ctvf_largest_l1_below_edac_and_gtvf(tmp_path, re):
    """nx 50, t = 2, largest L1 over the run, every scheme from the same 0.1 dx perturbed
    lattice (docs/ctvf.md): CTVF + SPST 0.0081 (Re 100) and 0.0395 (Re 1000), EDAC 0.0087
    and 0.0306, GTVF 0.104 and 0.163."""
    same = ("--perturb", "0.1")
    ctvf = tg_whole_run(tmp_path, "ctvf", re, *same)["l1_error_max"]
    assert ctvf < tg_whole_run(tmp_path, "edac", re, *same)["l1_error_max"]
    assert ctvf < tg_whole_run(tmp_path, "gtvf", re, *same)["l1_error_max"]


@pytest.mark.slow
def test_ctvf_max_u_within_three_percent_of_the_exact_decay(tmp_path):
    """Issue 9: max|u| within 3 % of exp(-8 pi^2 t / Re) over the whole run (measured with the
    default 0.1 dx perturbation: 0.77 %; 8.2 % on the plain lattice, docs/ctvf.md)."""
    tg_whole_run(tmp_path, "ctvf", 100)
    with open(tmp_path / "ctvf100" / "tg" / "history.json") as f:
        rows = np.array(json.load(f)["rows"])
    assert np.abs(rows[:, 1] / rows[:, 2] - 1).max() < 0.03


@pytest.mark.slow
def test_printed_divergence_form_holds_the_re1000_checks(tmp_path):
    """Eq. 27's printed -u div u~ (``--divergence-form printed``), Re 1000, nx 50, same 0.1 dx
    start for every scheme (docs/ctvf.md, measured: max|u| within 2.91 % of the exact decay,
    largest L1 0.0199 against EDAC's 0.0306 and GTVF's 0.163)."""
    same = ("--perturb", "0.1")
    res = tg_whole_run(tmp_path, "ctvf", 1000, "--divergence-form", "printed", *same)
    with open(tmp_path / "ctvf1000--divergence-formprinted--perturb0.1" / "tg" / "history.json") as f:
        rows = np.array(json.load(f)["rows"])
    assert np.abs(rows[:, 1] / rows[:, 2] - 1).max() < 0.03
    assert res["l1_error_max"] < tg_whole_run(tmp_path, "edac", 1000, *same)["l1_error_max"]
    assert res["l1_error_max"] < tg_whole_run(tmp_path, "gtvf", 1000, *same)["l1_error_max"]


@pytest.mark.slow
def test_ctvf_re1000_l1_falls_with_resolution(tmp_path, capsys):
    """Adepu & Ramachandran (2021) Fig. 9: Re 1000, SPST, t = 2, plain lattice (measured,
    docs/ctvf.md: 0.0929 at 50 x 50, 0.0226 at 100 x 100, order 2.04)."""
    e50 = tg_whole_run(tmp_path, "ctvf", 1000, "--perturb", "0", nx=50)["l1_error"]
    e100 = tg_whole_run(tmp_path / "100", "ctvf", 1000, "--perturb", "0", nx=100)["l1_error"]
    with capsys.disabled():
        print(f"\nTaylor-Green Re 1000 CTVF + SPST, t = 2: L1 {e50:.4f} (50), {e100:.4f} (100), "
              f"order {np.log(e50 / e100) / np.log(2):.2f}")
    assert e100 < e50


@pytest.mark.slow
@pytest.mark.xfail(reason="measured (docs/ctvf.md): at 100 x 100, Re 1000, SPST the run without corrections "
                   "ends lower (L1 0.0113 against 0.0226 with them); the -u div(delta) term raises it",
                   strict=True)
def test_ctvf_corrections_lower_the_l1_error(tmp_path):
    """Adepu & Ramachandran (2021) Fig. 10 (at 150 x 150 there; 100 x 100 here; plain lattice,
    as measured)."""
    with_ = tg_whole_run(tmp_path, "ctvf", 1000, "--perturb", "0", nx=100)["l1_error"]
    without = tg_whole_run(tmp_path, "ctvf", 1000, "--no-corrections", "--perturb", "0", nx=100)["l1_error"]
    assert with_ < without


def test_fluid_scheme_edac_damping_and_form_options():
    """edac_damping='paper' is eq. 26's printed damping, nu_edac / rho0 (digest A3); the
    momentum term forms are checked by name."""
    kw = dict(dim=2, rho0=1000.0, c0=10.0, nu=0.0, h=0.1, dx=0.1)
    consistent = CTVFScheme(["fluid"], **kw)
    paper = CTVFScheme(["fluid"], edac_damping="paper", **kw)
    assert consistent.nu_edac() == pytest.approx(0.5 * 0.1 * 10.0 / 8.0)
    assert paper.nu_edac() == pytest.approx(consistent.nu_edac() / 1000.0)
    for bad in (dict(edac_damping="printed"), dict(divergence_form="u"), dict(stress_form="x")):
        with pytest.raises(ValueError):
            CTVFScheme(["fluid"], **kw, **bad)


def test_step_without_shifting_sets_the_transport_velocity_to_u():
    """With no homogenisation (``--shifting none``) the kick leaves u~ = u, which the
    continuity equation and the transport terms read (before, nothing set u~ and such a
    run with continuity density stopped at start-up)."""
    from sphgen.schemes.ctvf import TransportVelocityStep
    n, dt = 3, 0.1
    a = {k: np.zeros(n) for k in ("u", "v", "w", "uhat", "vhat", "what", "auhat", "avhat", "awhat")}
    a.update(u=np.array([1.0, 2.0, 3.0]), v=np.array([-1.0, 0.5, 0.0]),
             au=np.array([2.0, 0.0, -4.0]), av=np.array([0.0, 2.0, 0.0]), aw=np.zeros(n),
             auhat=np.full(n, 7.0), avhat=np.full(n, 7.0))
    for shift in (False, True):
        b = {k: v.copy() for k, v in a.items()}
        step = TransportVelocityStep(2, shift=shift)
        for i in range(n):
            step.stage1(i, *(b[k] for k in ("u", "v", "w", "au", "av", "aw", "uhat", "vhat", "what",
                                            "auhat", "avhat", "awhat")), dt)
        assert np.allclose(b["u"], a["u"] + 0.5 * dt * a["au"]) and np.allclose(b["v"], a["v"] + 0.5 * dt * a["av"])
        extra = 0.5 * dt * 7.0 if shift else 0.0
        assert np.allclose(b["uhat"], b["u"] + extra) and np.allclose(b["vhat"], b["v"] + extra)


def test_taylor_green_mach_option_sets_the_spst_coefficient():
    """``--mach`` is Ma of eq. 35 (default U/c0 = 0.1) for every scheme; non-positive values are refused."""
    from sphgen.errors import InputError

    def scheme(*argv):
        app = load_application("taylor_green")()
        app.options = app.parser().parse_args(list(argv))
        app.consume_user_options(app.options)
        return app.create_scheme()

    assert scheme("--scheme", "ctvf").shift.mach == pytest.approx(0.1)
    assert scheme("--scheme", "ctvf", "--mach", "0.2").shift.mach == pytest.approx(0.2)
    assert scheme("--scheme", "gtvf", "--shifting", "spst", "--mach", "0.2").shift.mach == pytest.approx(0.2)
    assert scheme("--scheme", "edac", "--mach", "0.2").mach == pytest.approx(0.2)
    with pytest.raises(InputError):
        scheme("--scheme", "ctvf", "--mach", "0")
