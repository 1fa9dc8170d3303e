"""Upwind TL-SPH for thermo-elasticity (Ghavamian et al. 2021): identities on random clouds.

A jittered 4x4x4 lattice with random volumes, deformation (H and J independent of F),
velocities and a 10 % temperature noise.  Without external terms:

* pair sums conserve momentum (sum V t = 0) and, in the E-form, energy (sum V dE/dt = 0);
* the semi-discrete ballistic identities (eqs. 61-65, E-form; 69-71, eta-form):
  sum V nu . dU/dt = sum V theta_R/theta^2 Q . grad theta - D_total, with D_total
  recomputed here pair by pair in numpy from eqs. 66, 72-75 (raw jumps), heat <= 0 and
  D_total >= 0; with the limited reconstruction D_total = 1/2 sum raw jump . D stays >= 0;
* the corrected gradient is exact for linear fields at every particle;
* the projection of eqs. 79-82 zeroes sum V t and sum V X x t;
* compiled module == plain-Python evaluator.
Identity tests run on the Python evaluator (no compilation); one module is compiled.
"""
import ast

import numpy as np
import pytest

from sphgen.equations.thermo_materials import LinearThermoElastic, MieGruneisen, ModifiedEntropicElasticity
from sphgen.equations.thermo_upwind import projection_multipliers
from sphgen.errors import BlowUpError, InputError
from sphgen.particles import ParticleArray
from sphgen.scene import Scene
from sphgen.schemes.thermo_upwind import ThermoUpwindScheme

from conftest import assert_close

BASE = dict(E_young=50.05e3, nu=0.3, rho=1000.0, Cv=1.0, alpha=2.223e-4, theta_R=293.15, k_th=10.0)
MATERIALS = {"mg": lambda: MieGruneisen(**BASE), "mee": lambda: ModifiedEntropicElasticity(**BASE),
             "linear": lambda: LinearThermoElastic(**BASE)}


def cloud(n=4, jitter=0.15, seed=0, random_state=True):
    dx = 1.0 / (n - 1)
    g = np.arange(n) * dx
    X = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T
    rng = np.random.default_rng(seed)
    X = X + jitter * dx * rng.uniform(-1, 1, X.shape)
    N = len(X)
    pa = ParticleArray("body", x=X[:, 0], y=X[:, 1], z=X[:, 2])
    pa.add_property("V", data=dx ** 3 * rng.uniform(0.7, 1.3, N))
    if random_state:
        F = np.eye(3)[None] + 0.05 * rng.normal(size=(N, 3, 3))
        H = np.array([np.linalg.det(f) * np.linalg.inv(f).T for f in F]) + 0.01 * rng.normal(size=(N, 3, 3))
        vel = rng.normal(size=(N, 3))
        pa.add_property("F", stride=9, data=F.reshape(-1))
        pa.add_property("H", stride=9, data=H.reshape(-1))
        pa.add_property("J", data=np.linalg.det(F) + 0.01 * rng.normal(size=N))
        pa.add_property("theta", data=293.15 * (1 + 0.1 * rng.uniform(-1, 1, N)))
        for k, c in enumerate("uvw"):
            pa.set(c, vel[:, k])
    return pa, dx


def build(pa, dx, backend="python", material="mg", **kw):
    s = ThermoUpwindScheme(["body"], MATERIALS[material](), dx, **kw)
    s.setup_properties([pa])
    integ = s.get_integrator()
    sc = Scene([pa], s.get_equations(), steppers=integ.steppers, kernel=s.kernel, dim=3,
               outputs={"body": list(s.output_props) + ["Q", "gradT", "tint", "aF", "aH", "aJ", "SJ",
                                                         "L", "cp", "cs"]},
               backend=backend)
    integ.attach(sc)
    return s, sc, integ


def rates(pa, dx, **kw):
    """State and rates of a random cloud (Python evaluator)."""
    s, sc, integ = build(pa, dx, **kw)
    integ.initial_accelerations(0.0, 1e-3)
    sc.compute(0, 0.0, 1e-3)
    return s, sc


def tensors(pa, name, n=9):
    return pa.get(name).reshape(-1, 3, 3) if n == 9 else pa.get(name).reshape(-1, 3)


def pair_dissipation(s, sc, pa):
    """D_total = 1/2 sum_a sum_b raw jump . D^ab recomputed in numpy (eqs. 65, 71, 73-75) and
    the per-pair products (every one must be >= 0)."""
    off, nb = sc.nnps.reference_neighbours("body", "body")
    a = np.repeat(np.arange(pa.n), np.diff(off))
    b = nb.astype(int)
    keep = a != b
    a, b = a[keep], b[keep]
    X = np.stack([pa.x0, pa.y0, pa.z0], 1)
    xij = X[a] - X[b]
    r = np.linalg.norm(xij, axis=1)
    wd = np.array([s.kernel.dwdr(ri, s.h) for ri in r])
    dw = (wd / r)[:, None] * xij
    L, H = tensors(pa, "L"), tensors(pa, "H")
    vv = pa.V[a] * pa.V[b]
    la = np.einsum("pij,pj->pi", L[a], dw)
    lb = np.einsum("pij,pj->pi", L[b], dw)
    Csk = vv[:, None] * (la + lb)
    csk = vv[:, None] * (np.einsum("pij,pj->pi", H[a], la) + np.einsum("pij,pj->pi", H[b], lb))
    nC, nc = np.linalg.norm(Csk, axis=1), np.linalg.norm(csk, axis=1)
    n = csk / nc[:, None]
    vel = np.stack([pa.u, pa.v, pa.w], 1)
    thR = s.material.theta_R
    ra = thR / pa.theta if s.form == "E" else np.ones(pa.n)
    jv = vel[b] * ra[b, None] - vel[a] * ra[a, None]
    js = pa.SJ[b] * ra[b] - pa.SJ[a] * ra[a]
    used_v, used_s = jv.copy(), js.copy()
    if s.jumps == "limited":
        gw, gs = tensors(pa, "gw"), tensors(pa, "gs", 3)
        rec = jv + 0.5 * np.einsum("pik,pk->pi", gw[a] + gw[b], xij)
        rs = js + 0.5 * np.einsum("pk,pk->p", gs[a] + gs[b], xij)
        mm = lambda p, q: np.where(p * q <= 0, 0.0, np.where(np.abs(p) < np.abs(q), p, q))  # noqa: E731
        jn, rn = np.einsum("pi,pi->p", jv, n), np.einsum("pi,pi->p", rec, n)
        jt, rt = jv - jn[:, None] * n, rec - rn[:, None] * n
        d = np.einsum("pi,pi->p", jt, rt)
        fac = np.where(d > 0, np.sqrt(np.einsum("pi,pi->p", jt, jt) / np.maximum(np.einsum("pi,pi->p", rt, rt), 1e-300)), 0.0)
        used_v = mm(jn, rn)[:, None] * n + np.minimum(fac, 1.0)[:, None] * rt
        used_s = mm(js, rs)
    rho = 0.5 * (pa.rho[a] + pa.rho[b])
    cp, cs = 0.5 * (pa.cp[a] + pa.cp[b]), 0.5 * (pa.cs[a] + pa.cs[b])
    un = np.einsum("pi,pi->p", used_v, n)
    Dp = 0.5 * rho[:, None] * nC[:, None] * (cp[:, None] * un[:, None] * n + cs[:, None] * (used_v - un[:, None] * n))
    per_pair = np.einsum("pi,pi->p", jv, Dp)
    if not s.reduced:
        per_pair = per_pair + js * (nc * nc / (2 * rho * cp * nC)) * used_s
    return 0.5 * per_pair.sum(), per_pair


def ballistic_rate(s, pa):
    """sum_a V_a nu_a . dU_a/dt (eqs. 58, 67) with the conjugate stresses from the material."""
    mat = s.material
    F, H, aF, aH = tensors(pa, "F"), tensors(pa, "H"), tensors(pa, "aF"), tensors(pa, "aH")
    vel, t = np.stack([pa.u, pa.v, pa.w], 1), tensors(pa, "tint", 3)
    total = 0.0
    for i in range(pa.n):
        th = pa.theta[i]
        SF, SH, SJ = mat.conjugates(F[i], H[i], pa.J[i], th)
        mech = vel[i] @ t[i] + np.sum(SF * aF[i]) + np.sum(SH * aH[i]) + SJ * pa.aJ[i]
        if s.form == "E":
            total += pa.V[i] * (mat.theta_R / th * mech + (th - mat.theta_R) / th * pa.aE[i])
        else:
            total += pa.V[i] * (mech + (th - mat.theta_R) * pa.aeta[i])
    return total


def heat_term(s, pa):
    Q, g = tensors(pa, "Q", 3), tensors(pa, "gradT", 3)
    return float(np.sum(pa.V * s.material.theta_R / pa.theta ** 2 * np.einsum("ai,ai->a", Q, g)))


@pytest.mark.parametrize("form,jumps,material", [("E", "raw", "mg"), ("eta", "raw", "mg"),
                                                 ("E", "limited", "mee"), ("eta", "limited", "mg")])
def test_ballistic_identity_and_conservation_on_a_random_cloud(form, jumps, material):
    pa, dx = cloud(seed=1)
    s, sc = rates(pa, dx, form=form, jumps=jumps, material=material)
    t = tensors(pa, "tint", 3)
    # pair sums: momentum, and energy in the E-form
    assert np.abs((pa.V[:, None] * t).sum(0)).max() < 1e-12 * np.sum(pa.V * np.abs(t).sum(1))
    if form == "E":
        assert abs(np.sum(pa.V * pa.aE)) < 1e-12 * np.sum(pa.V * np.abs(pa.aE))
    heat = heat_term(s, pa)
    D, per_pair = pair_dissipation(s, sc, pa)
    lhs = ballistic_rate(s, pa)
    assert heat < 0 and D > 0 and per_pair.min() >= 0.0
    assert abs(lhs - (heat - D)) < 1e-10 * (abs(heat) + D), (lhs, heat, D)


def reduced_cloud(seed):
    """A random cloud in the reduced scheme's state space: H = cof F, J = det F."""
    pa, dx = cloud(seed=seed)
    F = tensors(pa, "F")
    pa.set("H", np.array([np.linalg.det(f) * np.linalg.inv(f).T for f in F]).reshape(-1))
    pa.set("J", np.linalg.det(F))
    return pa, dx


@pytest.mark.parametrize("form,jumps", [("E", "raw"), ("eta", "raw"), ("E", "limited"), ("eta", "limited")])
def test_reduced_scheme_conserves_and_has_no_J_equation(form, jumps):
    """The reduced scheme, E-form {p, F, H, E} (Fig. 16) and eta-form {p, F, H, eta} (ours):
    J = det F, no J rate; the pair sums conserve momentum, with the projection (eqs. 79-82)
    angular momentum, and in the E-form energy; the ballistic identity (eqs. 61-65, 69-71,
    J rate H : dF/dt with H = cof F) holds to round-off with D_J absent."""
    pa, dx = reduced_cloud(seed=2)
    s, sc = rates(pa, dx, form=form, jumps=jumps, reduced=True)
    F, H = tensors(pa, "F"), tensors(pa, "H")
    np.testing.assert_allclose(pa.J, np.linalg.det(F), rtol=1e-14)
    flux = [ep for ep in sc.plan.eqplans if type(ep.eq).__name__ == "UpwindFluxes"][0]
    assert all("d_aJ" not in ast.unparse(sp.fdef) for sp in flux.methods.values())
    t = tensors(pa, "tint", 3)
    assert np.abs((pa.V[:, None] * t).sum(0)).max() < 1e-12 * np.sum(pa.V * np.abs(t).sum(1))
    rate = pa.aE if form == "E" else pa.aeta
    assert np.abs(rate).max() > 0
    if form == "E":
        assert abs(np.sum(pa.V * pa.aE)) < 1e-12 * np.sum(pa.V * np.abs(pa.aE))
    pa.aJ[:] = np.einsum("pij,pij->p", H, tensors(pa, "aF"))     # d(det F)/dt = cof F : dF/dt
    heat = heat_term(s, pa)
    D, per_pair = pair_dissipation(s, sc, pa)
    lhs = ballistic_rate(s, pa)
    assert heat < 0 and D > 0 and per_pair.min() >= 0.0
    assert abs(lhs - (heat - D)) < 1e-10 * (abs(heat) + D), (lhs, heat, D)
    pa, dx = reduced_cloud(seed=2)
    s, sc, integ = build(pa, dx, form=form, jumps=jumps, reduced=True, projection=True)
    integ.initial_accelerations(0.0, 1e-3)
    sc.stage("stage1", 0.0, 1e-3)
    sc.compute(0, 0.0, 1e-3)
    x, t = np.stack([pa.x, pa.y, pa.z], 1), tensors(pa, "tint", 3)
    scale = np.sum(pa.V * np.abs(t).sum(1) * (1 + np.abs(x).sum(1)))
    assert np.abs((pa.V[:, None] * t).sum(0)).max() < 1e-14 * scale
    assert np.abs((pa.V[:, None] * np.cross(x, t)).sum(0)).max() < 1e-14 * scale


def test_corrected_gradients_are_exact_for_linear_fields_at_every_particle():
    pa, dx = cloud(seed=3, jitter=0.25, random_state=False)
    rng = np.random.default_rng(0)
    G, c = rng.normal(size=(3, 3)), rng.normal(size=3)
    X = np.stack([pa.x, pa.y, pa.z], 1)
    vel = X @ G.T + c
    for k, comp in enumerate("uvw"):
        pa.set(comp, vel[:, k])
    a = rng.normal(size=3)
    pa.add_property("theta", data=300.0 + X @ a)
    s, sc = rates(pa, dx, jumps="limited")
    np.testing.assert_allclose(tensors(pa, "aF"), np.broadcast_to(G, (pa.n, 3, 3)), atol=1e-11)
    np.testing.assert_allclose(tensors(pa, "gradT", 3), np.broadcast_to(a, (pa.n, 3)), atol=1e-11)
    # H = I, J = 1, F = I: dH/dt = I x grad v = tr(G) I - G^T, dJ/dt = tr G (eqs. 54c-d)
    np.testing.assert_allclose(tensors(pa, "aH"), np.broadcast_to(np.trace(G) * np.eye(3) - G.T, (pa.n, 3, 3)),
                               atol=1e-11)


@pytest.mark.parametrize("jumps", ["raw", "limited"])
def test_rigid_rotation_is_damped_by_raw_jumps_only(jumps):
    """Unstressed body in rigid rotation at uniform temperature: the only force is D_p.
    Raw jumps of a linear velocity field are not zero (the paper's dissipation damps the
    rotation); the limited reconstruction is exact for it (force zero to round-off)."""
    pa, dx = cloud(seed=4, random_state=False)
    X = np.stack([pa.x, pa.y, pa.z], 1)
    vel = np.cross([0.3, -0.5, 1.0], X)
    for k, comp in enumerate("uvw"):
        pa.set(comp, vel[:, k])
    s, sc = rates(pa, dx, jumps=jumps)
    t = tensors(pa, "tint", 3)
    scale = 1000.0 * s.material.wave_speeds(293.15)[0] * np.abs(vel).max() / dx   # rho c_p |v| / dx
    if jumps == "raw":
        assert np.abs(t).max() > 1e-2 * scale
    else:
        assert np.abs(t).max() < 1e-12 * scale


def test_projection_zeroes_the_momentum_sums():
    rng = np.random.default_rng(7)
    V, X, T = rng.uniform(0.5, 1.5, 50), rng.normal(size=(50, 3)), rng.normal(size=(50, 3))
    lam = projection_multipliers(V, X, T)
    Th = T + np.cross(lam[:3], X) + lam[3:]
    assert np.abs(V @ Th).max() < 1e-13 * np.abs(V @ np.abs(T)).max()
    assert np.abs(np.einsum("a,ai->i", V, np.cross(X, Th))).max() < 1e-13 * np.sum(V * np.abs(T).sum(1) * np.abs(X).sum(1))
    # the least-squares correction of forces that already satisfy both is zero
    lam0 = projection_multipliers(V, X, Th)
    assert np.abs(lam0).max() < 1e-12 * np.abs(lam).max()


def test_switches_vanish_from_the_plan():
    """Projection off: no projection, no projection point; dissipation off: no upwinding."""
    pa, dx = cloud(seed=5)
    s, sc, _ = build(pa, dx, projection=False)
    plan = sc.describe()
    assert "AngularMomentumProjection" not in plan and "stage4" not in plan
    assert "xc" in plan.split("declared, not allocated:")[1]
    pa, dx = cloud(seed=5)
    s, sc, _ = build(pa, dx, projection=True, jumps="limited")
    plan = sc.describe()
    assert "keep  AngularMomentumProjection[body]" in plan and "stage4" in plan
    off = [ep for ep in sc.plan.eqplans if type(ep.eq).__name__ == "UpwindFluxes"][0]
    pa, dx = cloud(seed=5)
    _, sc2, _ = build(pa, dx, dissipation=False)
    off2 = [ep for ep in sc2.plan.eqplans if type(ep.eq).__name__ == "UpwindFluxes"][0]
    assert "minmod" in ast.unparse(off.methods["loop"].fdef)
    assert "nC" not in ast.unparse(off2.methods["loop"].fdef)
    assert "gw" not in pa.data and "gs" not in pa.data


def run(backend, steps, **kw):
    pa, dx = cloud(seed=6)
    s, sc, integ = build(pa, dx, backend=backend, **kw)
    dt = s.get_timestep()
    integ.initial_accelerations(0.0, dt)
    t = 0.0
    for _ in range(steps):
        integ.one_timestep(t, dt)
        t += dt
    return pa, s, sc


COMPILED = dict(form="E", jumps="limited", projection=True)


def test_compiled_matches_python():
    a, _, _ = run("cython", 2, **COMPILED)
    b, _, _ = run("python", 2, **COMPILED)
    assert sorted(a.data) == sorted(b.data)
    for name in a.data:
        assert_close(a.data[name], b.data[name], 1e-11, what=name)
    assert np.abs(a.tint).max() > 0 and np.abs(a.aE).max() > 0


def test_free_body_keeps_energy_momentum_and_angular_momentum_over_100_steps():
    pa, dx = cloud(seed=6)
    s, sc, integ = build(pa, dx, backend="cython", **COMPILED)
    dt = s.get_timestep()
    integ.initial_accelerations(0.0, dt)

    def totals():
        X, vel = np.stack([pa.x, pa.y, pa.z], 1), np.stack([pa.u, pa.v, pa.w], 1)
        return (np.sum(pa.V * pa.E), (pa.m[:, None] * vel).sum(0),
                (pa.m[:, None] * np.cross(X, vel)).sum(0), np.sum(pa.m * np.abs(vel).sum(1)))
    E0, L0, A0, scale = totals()
    K0 = 0.5 * np.sum(pa.m * (pa.u ** 2 + pa.v ** 2 + pa.w ** 2))
    t = 0.0
    for _ in range(100):
        integ.one_timestep(t, dt)
        t += dt
    E1, L1, A1, _ = totals()
    K1 = 0.5 * np.sum(pa.m * (pa.u ** 2 + pa.v ** 2 + pa.w ** 2))
    assert abs(E1 - E0) < 1e-12 * abs(E0)
    assert np.abs(L1 - L0).max() < 1e-12 * scale
    assert np.abs(A1 - A0).max() < 1e-11 * np.abs(A0).max()
    assert K1 < K0      # the random velocities were damped (kinetic energy went into heat)
    assert s.energies([pa])["entropy"] > 0


def test_guard_stops_on_negative_temperature_and_bad_input():
    pa, dx = cloud(seed=8)
    s, sc, integ = build(pa, dx)
    pa.theta[:] = 293.15
    integ.initial_accelerations(0.0, 1e-3)
    pa.E[3] -= 1e9        # far more than the particle's heat content
    with pytest.raises(BlowUpError, match=rf"temperature theta = .* <= 0 at particle gid {pa.gid[3]} of 'body'"):
        integ.one_timestep(0.0, 1e-5)
    with pytest.raises(InputError, match="jumps 'muscl' must be one of raw, limited"):
        ThermoUpwindScheme(["body"], MieGruneisen(**BASE), dx, jumps="muscl")
    bad = ParticleArray("body", x=[0.0], y=[0.0], z=[0.0])
    with pytest.raises(InputError, match="needs the reference volume 'V'"):
        ThermoUpwindScheme(["body"], MieGruneisen(**BASE), dx).setup_properties([bad])


# ---------------------------------------------------------------------- term by term
def pair_geometry(s, sc, pa):
    """(a, b, C_ab, C_ba) for every ordered neighbour pair a != b (eq. 53)."""
    off, nb = sc.nnps.reference_neighbours("body", "body")
    a = np.repeat(np.arange(pa.n), np.diff(off))
    b = nb.astype(int)
    keep = a != b
    a, b = a[keep], b[keep]
    X = np.stack([pa.x0, pa.y0, pa.z0], 1)
    xij = X[a] - X[b]
    r = np.linalg.norm(xij, axis=1)
    dw = (np.array([s.kernel.dwdr(ri, s.h) for ri in r]) / r)[:, None] * xij
    L = tensors(pa, "L")
    vv = (pa.V[a] * pa.V[b])[:, None]
    return a, b, 2 * vv * np.einsum("pij,pj->pi", L[a], dw), -2 * vv * np.einsum("pij,pj->pi", L[b], dw)


def per_particle(a, values, n):
    out = np.zeros((n,) + values.shape[1:])
    np.add.at(out, a, values)
    return out


@pytest.mark.parametrize("form", ["E", "eta"])
def test_raw_jumps_satisfy_the_ballistic_identities_term_by_term(form):
    """Ghavamian et al. (2021) eqs. 54, 57 and 59-71 with raw jumps, each piece recomputed
    pair by pair in numpy from the scheme's state and compared with the scheme's rates:

    * the pair sums of (54a), (54d), (54e) / (57) with D_p, D_J of (66) / (72)-(75);
    * (62): sum_a sum_b theta_R/(2 theta_a)[(Q_a.C_ab) theta_b/theta_a - (Q_b.C_ba) theta_a/theta_b]
      = sum_a V_a theta_R/theta_a^2 Q_a . grad theta_a <= 0 (eta-form: sum_a V_a vartheta_a
      deta_a/dt equals it);
    * (61)/(63) = (64)/(65) (E-form) and (68)-(71) (eta-form): the per-particle form of
      D_total equals the symmetric pair form, every pair's term is >= 0;
    * (61) / (69): sum_a V_a nu_a . dU_a/dt = (62) - D_total;
    all to round-off (1e-12 relative)."""
    pa, dx = cloud(seed=11)
    s, sc = rates(pa, dx, form=form, jumps="raw")
    a, b, Cab, Cba = pair_geometry(s, sc, pa)
    n, thR, V = pa.n, s.material.theta_R, pa.V
    P, H, Q, th = tensors(pa, "P"), tensors(pa, "H"), tensors(pa, "Q", 3), pa.theta
    vel = np.stack([pa.u, pa.v, pa.w], 1)
    Xi = th / thR if form == "E" else np.ones(n)
    # upwinding coefficients (73)-(75) and the raw jumps of the entropy variables (66)/(72)
    Csk, csk = 0.5 * (Cab - Cba), 0.5 * (np.einsum("pij,pj->pi", H[a], Cab) - np.einsum("pij,pj->pi", H[b], Cba))
    nC, nc = np.linalg.norm(Csk, axis=1), np.linalg.norm(csk, axis=1)
    nn = csk / nc[:, None]
    rho, cp, cs = 0.5 * (pa.rho[a] + pa.rho[b]), 0.5 * (pa.cp[a] + pa.cp[b]), 0.5 * (pa.cs[a] + pa.cs[b])
    Amat = cp[:, None, None] * np.einsum("pi,pj->pij", nn, nn) + cs[:, None, None] * (
        np.eye(3) - np.einsum("pi,pj->pij", nn, nn))
    Sp = 0.5 * (rho * nC)[:, None, None] * Amat
    SJ = nc * nc / (2 * rho * cp * nC)
    jv = vel[b] / Xi[b, None] - vel[a] / Xi[a, None]
    js = pa.SJ[b] / Xi[b] - pa.SJ[a] / Xi[a]
    Dp, DJ = np.einsum("pij,pj->pi", Sp, jv), SJ * js
    # the scheme's rates are these pair sums
    PCab, PCba = np.einsum("pij,pj->pi", P[a], Cab), np.einsum("pij,pj->pi", P[b], Cba)
    T = per_particle(a, 0.5 * (PCab - PCba) + Dp, n)
    scale = np.abs(T).max()
    np.testing.assert_allclose(tensors(pa, "tint", 3) * V[:, None], T, rtol=0, atol=1e-12 * scale)
    gradv = per_particle(a, 0.5 * np.einsum("pi,pk->pik", vel[b] - vel[a], Cab), n) / V[:, None, None]
    aJ = np.einsum("aik,aik->a", H, gradv) + per_particle(a, DJ, n) / V
    np.testing.assert_allclose(pa.aJ, aJ, rtol=0, atol=1e-12 * np.abs(aJ).max())
    qa, qb = np.einsum("pi,pi->p", Q[a], Cab), np.einsum("pi,pi->p", Q[b], Cba)
    if form == "E":
        mech = 0.5 * (np.einsum("pi,pi->p", PCab, vel[b]) - np.einsum("pi,pi->p", PCba, vel[a]))
        heat_pairs = 0.5 * (qa * th[b] / th[a] - qb * th[a] / th[b])
        aE = per_particle(a, mech - heat_pairs, n) / V
        np.testing.assert_allclose(pa.aE, aE, rtol=0, atol=1e-12 * np.abs(aE).max())
        eq62 = np.sum(thR / th[a] * heat_pairs)
    else:
        heat_pairs = 0.5 * (qa / th[a] - qb / th[b])
        g = tensors(pa, "gradT", 3)
        aeta = per_particle(a, -heat_pairs, n) / V - np.einsum("ai,ai->a", Q, g) / th ** 2
        np.testing.assert_allclose(pa.aeta, aeta, rtol=0, atol=1e-12 * np.abs(aeta).max())
        # (68): the eta-form's heat pair sum, theta_R/2 [...] summed, vanishes by antisymmetry
        assert abs(np.sum(thR * heat_pairs)) < 1e-12 * np.sum(thR * np.abs(heat_pairs))
        # (69): the whole entropy equation, weighted by vartheta, is the conduction term
        eq62 = np.sum(V * (th - thR) * pa.aeta)
    # (62)
    heat = heat_term(s, pa)
    assert heat < 0
    assert abs(eq62 - heat) < 1e-12 * abs(heat)
    # (61)/(63) per-particle form = (64)-(65) / (70)-(71) symmetric form, pairs >= 0
    D_particle = np.sum(-(np.einsum("pi,pi->p", vel[a], Dp) + pa.SJ[a] * DJ) / Xi[a])
    pair_terms = np.einsum("pi,pi->p", jv, Dp) + js * DJ
    D_pairs = 0.5 * pair_terms.sum()
    assert pair_terms.min() >= 0.0 and D_pairs > 0
    assert abs(D_particle - D_pairs) < 1e-12 * D_pairs
    # (61) / (69)
    lhs = ballistic_rate(s, pa)
    assert abs(lhs - (heat - D_pairs)) < 1e-12 * (abs(heat) + D_pairs), (lhs, heat, D_pairs)


@pytest.mark.parametrize("form", ["E", "eta"])
def test_limited_jumps_leave_a_rigid_rotation_without_force(form):
    """The reconstruction is exact for linear entropy variables: a rigid rotation of an
    unstressed body gets no dissipative force, in the E-form at a uniform temperature and
    in the eta-form (jumps of v, not v/Xi) at any temperature."""
    pa, dx = cloud(seed=12, random_state=False)
    X = np.stack([pa.x, pa.y, pa.z], 1)
    vel = np.cross([0.7, 0.2, -0.4], X)
    for k, comp in enumerate("uvw"):
        pa.set(comp, vel[:, k])
    if form == "eta":
        pa.add_property("theta", data=293.15 + 20 * np.random.default_rng(1).uniform(-1, 1, pa.n))
    s, sc = rates(pa, dx, form=form, jumps="limited")
    scale = 1000.0 * s.material.wave_speeds(293.15)[0] * np.abs(vel).max() / dx
    # the stress is the thermal one only (F = I): subtract its pair force
    a, b, Cab, Cba = pair_geometry(s, sc, pa)
    P = tensors(pa, "P")
    T = per_particle(a, 0.5 * (np.einsum("pij,pj->pi", P[a], Cab) - np.einsum("pij,pj->pi", P[b], Cba)), pa.n)
    Dp = tensors(pa, "tint", 3) - T / pa.V[:, None]
    assert np.abs(Dp).max() < 1e-12 * scale


def spin(jumps, projection, steps=100, omega=(0.015, -0.025, 0.05), record=None):
    """A free cloud spun slowly about its centroid, 100 compiled TVD-RK2 steps (E-form,
    uniform theta_R): (K(0), K(end), A(0), A(end), S(0), S(end)); ``record`` (a list) gets
    (S, S_proj) after every step."""
    pa, dx = cloud(seed=4, random_state=False)
    X = np.stack([pa.x, pa.y, pa.z], 1)
    vel = np.cross(omega, X - X.mean(0))
    for k, comp in enumerate("uvw"):
        pa.set(comp, vel[:, k])
    s, sc, integ = build(pa, dx, backend="cython", form="E", jumps=jumps, projection=projection)
    dt = s.get_timestep()
    integ.initial_accelerations(0.0, dt)

    def state():
        x, v = np.stack([pa.x, pa.y, pa.z], 1), np.stack([pa.u, pa.v, pa.w], 1)
        e = s.energies([pa])
        return e["kinetic"], (pa.m[:, None] * np.cross(x, v)).sum(0), e["entropy"]
    K0, A0, S0 = state()
    t = 0.0
    for _ in range(steps):
        integ.one_timestep(t, dt)
        t += dt
        if record is not None:
            e = s.energies([pa])
            record.append((e["entropy"], e["S_proj"]))
    K1, A1, S1 = state()
    return K0, K1, A0, A1, S0, S1


def test_limited_jumps_leave_a_rigid_rotation_undamped_raw_jumps_stop_it():
    """Without the projection, over 100 steps (1.2 s, many raw-jump e-folding times of this
    small cloud): raw jumps take over 99 % of the kinetic energy and 95 %
    of the angular momentum; the limited reconstruction loses less than 1 % of either (what
    it loses is the dissipation of the elastic response to the centripetal load)."""
    K0, K1, A0, A1, S0, S1 = spin("raw", False)
    assert K1 < 0.01 * K0 and np.linalg.norm(A1) < 0.05 * np.linalg.norm(A0) and S1 > S0
    K0, K1, A0, A1, S0, S1 = spin("limited", False)
    assert K0 - K1 < 0.01 * K0 and np.linalg.norm(A1 - A0) < 0.01 * np.linalg.norm(A0) and S1 >= S0


@pytest.mark.parametrize("jumps", ["raw", "limited"])
def test_projection_keeps_angular_momentum_over_100_steps(jumps):
    """Eqs. 79-82: with raw jumps (which would stop the rotation, previous test) or limited
    ones, A is kept to 1e-11 relative over 100 steps and L stays zero."""
    K0, K1, A0, A1, S0, S1 = spin(jumps, True)
    assert np.abs(A1 - A0).max() < 1e-11 * np.linalg.norm(A0)


def test_projection_takes_the_entropy_that_falls_and_the_rest_never_falls():
    """A fast spin (omega = (0.3, -0.5, 1) rad/s) with raw jumps and the projection: S falls
    over 100 steps (the projection gives back, out of heat, the kinetic energy the raw jumps
    take from the rotation), the recorded S_proj = -sum dt sum V v . dt^ / theta is below
    that fall, and S - S_proj (the scheme without its projection term, what eqs. 61-65
    cover) never falls between steps; without the projection S_proj stays 0."""
    rec = []
    K0, K1, A0, A1, S0, S1 = spin("raw", True, omega=(0.3, -0.5, 1.0), record=rec)
    S, Sp = np.array(rec).T
    assert S1 < S0 and Sp[-1] < S1 - S0 < 0
    rest = np.diff(np.concatenate([[S0], S - Sp]))
    assert rest.min() >= 0.0, rest.min()
    rec = []
    spin("raw", False, omega=(0.3, -0.5, 1.0), steps=5, record=rec)
    assert all(sp == 0.0 for _, sp in rec)


def test_projection_in_the_scene_zeroes_the_sums_of_forces_and_torques():
    """The projection as the scheme runs it (after the pair loop, about x^n): the internal
    forces per volume t then satisfy sum V t = 0 and sum V x x t = 0 (eq. 79) to
    round-off, while the unprojected forces of the same random state had a torque."""
    sums = {}
    for projection in (False, True):
        pa, dx = cloud(seed=13)
        s, sc, integ = build(pa, dx, projection=projection, jumps="raw")
        integ.initial_accelerations(0.0, 1e-3)
        sc.stage("stage1", 0.0, 1e-3)
        sc.compute(0, 0.0, 1e-3)
        x = np.stack([pa.x, pa.y, pa.z], 1)
        t = tensors(pa, "tint", 3)
        scale = np.sum(pa.V * np.abs(t).sum(1) * (1 + np.abs(x).sum(1)))
        sums[projection] = (np.abs((pa.V[:, None] * t).sum(0)).max() / scale,
                            np.abs((pa.V[:, None] * np.cross(x, t)).sum(0)).max() / scale)
    assert sums[False][1] > 1e-6
    assert max(sums[True]) < 1e-14, sums


# ---------------------------------------------------------------------- S^E (eq. 76)
def _se_pairs(s, sc, pa):
    """(a, DE per ordered pair, S^E, bracket, dxi) recomputed in numpy: eq. 76 from the raw
    jumps, 0 where 1/Xi_a = 1/Xi_b or the bracket is negative, capped at theta_R k ||C^Skew||
    / |X_a - X_b|."""
    a, b, Cab, Cba = pair_geometry(s, sc, pa)
    thR, H = s.material.theta_R, tensors(pa, "H")
    Csk = 0.5 * (Cab - Cba)
    csk = 0.5 * (np.einsum("pij,pj->pi", H[a], Cab) - np.einsum("pij,pj->pi", H[b], Cba))
    nC, nc = np.linalg.norm(Csk, axis=1), np.linalg.norm(csk, axis=1)
    nn = csk / nc[:, None]
    rho, cp, cs = 0.5 * (pa.rho[a] + pa.rho[b]), 0.5 * (pa.cp[a] + pa.cp[b]), 0.5 * (pa.cs[a] + pa.cs[b])

    def quad(w):   # w . S^p w (eqs. 73-74)
        wn = np.einsum("pi,pi->p", w, nn)
        return 0.5 * rho * nC * (cp * wn * wn + cs * (np.einsum("pi,pi->p", w, w) - wn * wn))

    SJ = nc * nc / (2 * rho * cp * nC)
    vel, r = np.stack([pa.u, pa.v, pa.w], 1), thR / pa.theta
    d_eta = quad(vel[b] - vel[a]) + SJ * (pa.SJ[b] - pa.SJ[a]) ** 2                                 # (71)
    d_E = quad(vel[b] * r[b, None] - vel[a] * r[a, None]) + SJ * (pa.SJ[b] * r[b] - pa.SJ[a] * r[a]) ** 2
    dxi = r[a] - r[b]
    bracket = d_eta - d_E
    X = np.stack([pa.x0, pa.y0, pa.z0], 1)
    cap = thR * s.material.k_th * nC / np.linalg.norm(X[a] - X[b], axis=1)
    ok = (np.abs(dxi) > 1e-12 * r[a]) & (bracket > 0)
    SE = np.where(ok, np.minimum(np.where(ok, bracket, 0.0) / np.where(ok, dxi, 1.0) ** 2, cap), 0.0)
    return a, SE * dxi, SE, bracket, dxi, d_eta, d_E


def test_matched_SE_is_eq_76_guarded_and_keeps_the_entropy_identity():
    """S^E of eq. 76 (``se='matched'``): the scheme's extra energy rate is sum_b D_E^ab / V
    with D_E^ab = S^E (1/Xi_a - 1/Xi_b) (eq. 66); where the bracket is positive and the cap
    does not bind, the E-form pair dissipation equals the eta-form's (the matching); where it
    is negative (colder than theta_R pairs can do this) S^E = 0; energy is conserved and
    sum V nu . dU/dt = heat - D_total with every pair term >= 0."""
    pa0, dx = cloud(seed=11)
    s0, sc0 = rates(pa0, dx, form="E", jumps="raw")
    pa, _ = cloud(seed=11)
    s, sc = rates(pa, dx, form="E", jumps="raw", se="matched")
    a, DE, SE, bracket, dxi, d_eta, d_E = _se_pairs(s, sc, pa)
    assert (bracket < 0).sum() > 10 and (bracket > 0).sum() > 10     # both signs occur: the guard acts
    extra = per_particle(a, DE, pa.n) / pa.V
    np.testing.assert_allclose(pa.aE - pa0.aE, extra, rtol=0, atol=1e-12 * np.abs(pa0.aE).max())
    assert np.abs(extra).max() > 1e-6 * np.abs(pa0.aE).max()          # S^E does something
    capped = (SE > 0) & (SE * dxi ** 2 < bracket * (1 - 1e-12))
    free = (SE > 0) & ~capped
    assert free.sum() >= 5
    np.testing.assert_allclose((d_E + SE * dxi ** 2)[free], d_eta[free], rtol=1e-10)
    assert abs(np.sum(pa.V * pa.aE)) < 1e-12 * np.sum(pa.V * np.abs(pa.aE))
    D0, pairs0 = pair_dissipation(s0, sc0, pa0)
    D = D0 + 0.5 * np.sum(SE * dxi ** 2)
    assert SE.min() >= 0 and D > D0
    heat = heat_term(s, pa)
    lhs = ballistic_rate(s, pa)
    assert abs(lhs - (heat - D)) < 1e-10 * (abs(heat) + D), (lhs, heat, D)


def test_matched_SE_vanishes_at_uniform_temperature_and_is_E_form_only():
    """0/0 of eq. 76 at Xi_a = Xi_b: S^E = 0, the rates are those of S^E = 0 exactly."""
    pa0, dx = cloud(seed=3)
    pa0.theta[:] = 301.0
    rates(pa0, dx, form="E")
    pa, _ = cloud(seed=3)
    pa.theta[:] = 301.0
    rates(pa, dx, form="E", se="matched")
    assert np.all(np.isfinite(pa.aE))
    np.testing.assert_array_equal(pa.aE, pa0.aE)
    with pytest.raises(InputError, match="E-form"):
        ThermoUpwindScheme(["body"], MieGruneisen(**BASE), dx, form="eta", se="matched")
    with pytest.raises(InputError, match="zero"):
        ThermoUpwindScheme(["body"], MieGruneisen(**BASE), dx, se="yes")
