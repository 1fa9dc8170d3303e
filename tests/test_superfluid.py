"""Two-fluid helium-4 (Kincl 2023, thesis ch. 3): energy model, conservation identities of
Theorems 9-10 on random clouds, the classical limit, pruning, compiled vs Python, reversibility.

The compiled checks share two modules, both with the adiabatic mask on: beta, mu > 0, and
beta = mu = 0 (the reversible rates; the irreversible equations are folded away).  A module
generated for non-zero beta and mu has their tests folded too, so it refuses beta = 0 (a
switch changed after generation): the reversible rates need their own scene.
"""
import ast

import numpy as np
import pytest

from sphgen.equations.superfluid import ADIABATIC, COOLER, FLUID
from sphgen.equations.superfluid_energy import HELIUM_1_9K, LinearHelium
from sphgen.particles import ParticleArray
from sphgen.scene import Scene
from sphgen.schemes.superfluid import SuperfluidScheme, velocities
from sphgen.solver import Solver

M = HELIUM_1_9K
BETA, MU = 2e-3, 3e-4


# ---------------------------------------------------------------- the energy model
def test_energy_derivatives_are_those_of_eq_3_14():
    """de = v_n.dv - rho_s v_ns.dv_s + T ds + p/rho^2 drho, by central differences of e."""
    rng = np.random.default_rng(4)
    n = 50
    rho = M.rho0 * (1 + 0.02 * rng.uniform(-1, 1, n))
    s = M.s0 * (1 + 0.05 * rng.uniform(-1, 1, n))
    v, vs = rng.uniform(-1, 1, (n, 3)), rng.uniform(-1, 1, (n, 3))
    dv, dvs, T, prr = M.energy_derivatives(rho, s, v, vs)

    def fd(f, x, eps):
        return (f(x + eps) - f(x - eps)) / (2 * eps)
    np.testing.assert_allclose(fd(lambda r: M.energy(r, s, v, vs), rho, 1e-3), prr, rtol=1e-6, atol=2e-9)
    np.testing.assert_allclose(fd(lambda q: M.energy(rho, q, v, vs), s, 1e-3), T, rtol=1e-7)
    for k in range(3):
        e = np.eye(3)[k]
        np.testing.assert_allclose(fd(lambda a: M.energy(rho, s, v + a[:, None] * e, vs), np.zeros(n), 1e-5),
                                   dv[:, k], rtol=1e-6, atol=1e-9)
        np.testing.assert_allclose(fd(lambda a: M.energy(rho, s, v, vs + a[:, None] * e), np.zeros(n), 1e-5),
                                   dvs[:, k], rtol=1e-6, atol=1e-9)
    # e_int(rho0, s0) = 0 and T0 at rest
    assert M.energy(M.rho0, M.s0, np.zeros(3), np.zeros(3)) == 0.0
    assert M.temperature(M.s0, np.zeros(3), np.zeros(3)) == pytest.approx(M.T0, rel=1e-15)


def test_heat_capacity_and_gamma_follow_eq_3_31():
    assert M.second_sound_speed() == pytest.approx(M.c2, rel=1e-14)
    assert M.cv == pytest.approx(3902.3, rel=1e-4)
    assert M.gamma == pytest.approx(5.697e-4, rel=1e-3)
    assert M.drhon_dT == pytest.approx(1.17, rel=1e-12)
    with pytest.raises(ValueError, match="rhon0"):
        LinearHelium(T0=1.9, rho0=145.0, s0=700.0, rhon0=1.5, c1=40.0, c2=18.0, gamma=0.0)


# ---------------------------------------------------------------- random clouds
def cloud(nx=12, dim=2, seed=0, adiabatic=0.0, cooler=0.0, vamp=1.0):
    """A jittered lattice of helium particles (side 1 mm) with unequal masses, random density
    constants and random s, v, v_s; a random share of ADIABATIC / COOLER particles."""
    L = 1e-3
    dx = L / nx
    rng = np.random.default_rng(seed)
    g = (np.arange(nx) + 0.5) * dx
    pos = [a.ravel() + 0.3 * dx * rng.uniform(-1, 1, nx ** dim)
           for a in np.meshgrid(*[g] * dim, indexing="ij")]
    n = pos[0].size
    props = dict(zip("xyz", pos))
    props.update(m=M.rho0 * dx ** dim * rng.uniform(0.7, 1.3, n), h=np.full(n, 1.5 * dx),
                 rho=M.rho0 * (1 + 0.01 * rng.uniform(-1, 1, n)), s=M.s0 * (1 + 0.05 * rng.uniform(-1, 1, n)),
                 crho=M.rho0 * 0.05 * rng.uniform(-1, 1, n))
    for c in ("u", "v", "w")[:dim] + ("us", "vs", "ws")[:dim]:
        props[c] = vamp * rng.uniform(-1, 1, n)
    pa = ParticleArray("helium", **props)
    r = rng.uniform(size=n)
    pt = np.where(r < adiabatic, ADIABATIC, np.where(r < adiabatic + cooler, COOLER, FLUID))
    pa.add_property("ptype", dtype="int", data=pt.astype(np.int32))
    return pa, dx


def scene(pa, dx, dim=2, backend="cython", beta=BETA, mu=MU, masked=True, **kw):
    """The scheme's scene on ``pa``; ``masked`` forces the adiabatic test into the code."""
    sch = SuperfluidScheme(["helium"], dim=dim, model=M, h=1.5 * dx, beta=beta, mu=mu,
                           calibrate_density=False, **kw)
    sch.setup_properties([pa])
    sch.masked = int(masked or sch.masked)
    integ = sch.get_integrator()
    sc = Scene([pa], sch.get_equations(), steppers=integ.steppers, kernel=sch.kernel, dim=dim,
               outputs={"helium": list(sch.output_props)}, backend=backend, threads=1)
    return sch, integ, sc


def rates(sc):
    sc.compute(0, 0.0, 1e-7)
    sc.compute(1, 0.0, 1e-7)


def pair_gradients(pa, kernel, dim):
    """x_ab and grad_a W_ab for all pairs (brute force, numpy)."""
    x = np.stack([pa.get(c) for c in "xyz"[:dim]], -1)
    xab = x[:, None] - x[None]
    r = np.linalg.norm(xab, axis=-1)
    dw = np.vectorize(lambda q: kernel.dwdr(q, pa.h[0]))(r)
    with np.errstate(invalid="ignore", divide="ignore"):
        grad = np.where(r[..., None] > 1e-12, (dw / r)[..., None] * xab, 0.0)
    return xab, grad


def energy_rate_terms(pa, kernel, dim):
    """m_a (v_n.dv/dt, -rho_s v_ns.dv_s/dt, T ds/dt, p/rho^2 drho/dt) per particle, with
    drho_a/dt = sum_b m_b v_ab . grad W_ab of the summation density."""
    s, v, vs = velocities(pa, dim)
    dv, dvs, T, prr = M.energy_derivatives(pa.rho, s, v, vs)
    a = np.stack([pa.get(c) for c in ("au", "av", "aw")[:dim]], -1)
    a_s = np.stack([pa.get(c) for c in ("aus", "avs", "aws")[:dim]], -1)
    _, grad = pair_gradients(pa, kernel, dim)
    rho_dot = np.einsum("b,abk,abk->a", pa.m, v[:, None] - v[None], grad)
    return [pa.m * np.sum(dv * a, -1), pa.m * np.sum(dvs * a_s, -1), pa.m * T * pa.sdot, pa.m * prr * rho_dot]


def relative(total, parts):
    return abs(total) / sum(np.abs(p).sum() for p in parts)


@pytest.fixture(scope="module")
def compiled():
    """The compiled scene with entropy diffusion and normal viscosity (beta, mu > 0)."""
    pa, dx = cloud(adiabatic=0.25, seed=1)
    return scene(pa, dx)


@pytest.fixture(scope="module")
def reversible():
    """The compiled scene without them (beta = mu = 0: the reversible rates)."""
    pa, dx = cloud(adiabatic=0.25, seed=1)
    return scene(pa, dx, beta=0.0, mu=0.0)


def load(sc, pa_new):
    """Copy the state of ``pa_new`` into the scene's array (same particles, same order)."""
    pa = sc.arrays[0]
    for p in ("x", "y", "m", "h", "rho", "s", "crho", "u", "v", "us", "vs", "ptype", "gid"):
        pa.get(p)[:] = pa_new.get(p)
    sc.update_nnps()


@pytest.mark.parametrize("adiabatic", [0.0, 0.3])
def test_reversible_rates_conserve_energy_momentum_entropy(reversible, adiabatic):
    """Theorem 9 (zero-order operators, summation density with its constant): the energy
    rate sum_a m_a (v_n.dv/dt - rho_s v_ns.dv_s/dt + T ds/dt + p/rho^2 drho/dt), sum m ds/dt and
    sum m dv/dt vanish to round-off, also with ADIABATIC particles masking pairs."""
    sch, integ, sc = reversible
    new, dx = cloud(adiabatic=adiabatic, seed=7)
    load(sc, new)
    rates(sc)
    pa = sc.arrays[0]
    terms = energy_rate_terms(pa, sch.kernel, 2)
    assert relative(sum(t.sum() for t in terms), terms) < 1e-12
    assert relative(np.sum(pa.m * pa.sdot), [pa.m * pa.sdot]) < 1e-12
    for c in ("au", "av"):
        assert relative(np.sum(pa.m * pa.get(c)), [pa.m * pa.get(c)]) < 1e-12
    assert np.abs(pa.sdot).max() > 1e3 and np.abs(pa.aus).max() > 1e3   # not trivially zero
    if adiabatic:
        assert np.any(pa.ptype == ADIABATIC)


@pytest.mark.parametrize("adiabatic", [0.0, 0.3])
def test_irreversible_rates_conserve_and_produce_entropy(compiled, reversible, adiabatic):
    """Theorem 10: the rates of eqs. 3.38-3.39 (full minus reversible, same state) keep
    energy, linear and angular momentum; zeta_a >= 0 and sum m ds/dt >= 0."""
    sch, integ, sc = compiled
    new, dx = cloud(adiabatic=adiabatic, seed=8)
    sc_rev = reversible[2]
    load(sc_rev, new)
    rates(sc_rev)
    rev = {c: sc_rev.arrays[0].get(c).copy() for c in ("au", "av", "aus", "avs", "sdot")}
    load(sc, new)
    pa = sc.arrays[0]
    rates(sc)
    irr = {c: pa.get(c) - rev[c] for c in rev}
    for c in ("aus", "avs"):     # no irreversible part (two modules: equal to round-off)
        assert np.abs(irr[c]).max() <= 1e-12 * np.abs(rev[c]).max(), c
    s, v, vs = velocities(pa, 2)
    vn, _, T, _ = M.energy_derivatives(pa.rho, s, v, vs)
    a = np.stack([irr["au"], irr["av"]], -1)
    terms = [pa.m * np.sum(vn * a, -1), pa.m * T * irr["sdot"]]
    assert relative(sum(t.sum() for t in terms), terms) < 1e-12
    for c in ("au", "av"):
        assert relative(np.sum(pa.m * irr[c]), [pa.m * irr[c]]) < 1e-12
    torque = pa.m * (pa.x * irr["av"] - pa.y * irr["au"])
    assert relative(torque.sum(), [torque]) < 1e-12
    assert pa.zeta.min() >= 0.0 and pa.zeta.max() > 0.0
    assert np.sum(pa.m * irr["sdot"]) > 0.0
    assert np.sum(pa.m * irr["sdot"]) == pytest.approx(np.sum(pa.m * pa.zeta / (T * pa.rho)), rel=1e-9)


def test_normal_fraction_one_is_classical_sph(reversible):
    """rho_n = 1 (rho_s = 0): dv/dt is the classical -sum m (p_a/rho_a^2 + p_b/rho_b^2) grad W
    and ds/dt = 0, whatever v_s is (Kincl 2023, remark after eq. 3.34)."""
    sch, integ, sc = reversible
    new, dx = cloud(seed=9)
    load(sc, new)
    pa = sc.arrays[0]
    rates(sc)
    au_two_fluid = pa.au.copy()
    state = [ep.eq for row in sc.plan.group_plans for gp in row for ep in gp.eqplans
             if type(ep.eq).__name__ == "SuperfluidState"]
    for eq in state:
        eq.rhon0, eq.gamma = 1.0, 0.0
    sc.bind()
    try:
        rates(sc)
        p = M.c1 ** 2 * (pa.rho - M.rho0)
        _, grad = pair_gradients(pa, sch.kernel, 2)
        pr = p / pa.rho ** 2
        classical = -np.einsum("b,ab,abk->ak", pa.m, pr[:, None] + pr[None], grad)
        np.testing.assert_allclose(np.stack([pa.au, pa.av], -1), classical, rtol=0, atol=1e-12 * np.abs(classical).max())
        assert np.abs(pa.sdot).max() == 0.0
        assert np.abs(au_two_fluid - pa.au).max() > 1e-3 * np.abs(pa.au).max()   # the counterflow mattered
    finally:
        for eq in state:
            eq.rhon0, eq.gamma = M.rhon0, M.gamma
        sc.bind()


def test_compiled_matches_python_evaluator(compiled):
    """Three steps of the printed integrator and two of the symmetric one, with beta, mu, the
    mask and COOLER particles: generated code = Python evaluator to round-off."""
    for reversible, steps in ((False, 3), (True, 2)):
        runs = []
        for backend in ("cython", "python"):
            pa, dx = cloud(nx=8, adiabatic=0.25, cooler=0.1, seed=11)
            sch, integ, sc = scene(pa, dx, backend=backend, reversible=reversible, rtol=1e-12)
            Solver(sc, integ, dt=0.4 * 1.5 * dx / M.c1, tf=1.0, max_steps=steps, progress=False).run()
            runs.append(pa)
        a, b = runs
        oa, ob = np.argsort(a.gid), np.argsort(b.gid)
        for p in ("x", "y", "u", "v", "us", "vs", "s", "rho", "T", "sdot", "zeta", "au", "avs"):
            x, y = a.get(p)[oa], b.get(p)[ob]
            assert np.abs(x - y).max() <= 1e-12 * np.abs(y).max(), p
        assert np.abs(a.sdot).max() > 0 and np.abs(a.zeta).max() > 0


def test_three_dimensional_rates_conserve_on_the_python_evaluator():
    """Theorems 9-10 in 3D (the dim > 2 branches), on the Python evaluator."""
    pa, dx = cloud(nx=5, dim=3, adiabatic=0.2, seed=3)
    sch, integ, sc = scene(pa, dx, dim=3, backend="python", beta=0.0, mu=0.0)
    rates(sc)
    terms = energy_rate_terms(pa, sch.kernel, 3)
    assert relative(sum(t.sum() for t in terms), terms) < 1e-12
    assert relative(np.sum(pa.m * pa.sdot), [pa.m * pa.sdot]) < 1e-12
    for c in ("au", "av", "aw"):
        assert relative(np.sum(pa.m * pa.get(c)), [pa.m * pa.get(c)]) < 1e-12
    assert np.abs(pa.aws).max() > 0


@pytest.mark.parametrize("adiabatic", [0.0, 0.2])
def test_renormalised_thermal_operators_conserve_on_the_python_evaluator(adiabatic):
    """renormalise=True (grad T and J divided by the first-moment normalisation lam): energy,
    sum m s and momentum are still conserved by the reversible rates (Theorem 9)."""
    pa, dx = cloud(nx=8, adiabatic=adiabatic, seed=13)
    sch, integ, sc = scene(pa, dx, backend="python", beta=0.0, mu=0.0, masked=adiabatic > 0,
                           renormalise=True)
    rates(sc)
    lam = pa.lam[pa.ptype != ADIABATIC]
    assert lam.min() > 0.1 and lam.max() < 1.5 and np.ptp(lam) > 0.2   # edges of the cloud < 1
    terms = energy_rate_terms(pa, sch.kernel, 2)
    assert relative(sum(t.sum() for t in terms), terms) < 1e-12
    assert relative(np.sum(pa.m * pa.sdot), [pa.m * pa.sdot]) < 1e-12
    for c in ("au", "av"):
        assert relative(np.sum(pa.m * pa.get(c)), [pa.m * pa.get(c)]) < 1e-12


def _methods(sc, name):
    return {m: ast.unparse(mp.fdef) for ep in sc.plan.eqplans if type(ep.eq).__name__ == name
            for m, mp in ep.methods.items()}


def test_zero_beta_mu_and_no_adiabatic_vanish_from_the_code():
    pa, dx = cloud(seed=2)
    sch, integ, sc = scene(pa, dx, backend="python", beta=0.0, mu=0.0, masked=False)
    plan = sc.describe()
    assert "prune EntropyProduction[helium<-helium]: switched off (dim=2, masked=0, beta=0.0, mu=0.0)" in plan
    assert "prune NormalViscosity[helium<-helium]: switched off (dim=2, mu=0.0)" in plan
    assert "zeta" in plan.split("declared, not allocated:")[1].splitlines()[0]
    for name in ("EntropyFlux", "Thermomechanical"):
        assert "ptype" not in " ".join(_methods(sc, name).values())
    pa2, _ = cloud(seed=2, adiabatic=0.2)
    sch2, _, sc2 = scene(pa2, dx, backend="python", beta=1.0, mu=0.0, masked=False)
    assert sch2.masked == 1
    assert "ptype" in _methods(sc2, "EntropyFlux")["loop"]
    loop = _methods(sc2, "EntropyProduction")["loop"]
    assert "beta" in loop and "un" not in loop.replace("under", "")   # the viscous part is gone


def test_density_constant_is_calibrated_to_the_initial_density():
    pa, dx = cloud(seed=5)
    rho0 = pa.rho.copy()
    gid = pa.gid.copy()
    sch = SuperfluidScheme(["helium"], dim=2, model=M, h=1.5 * dx)
    sch.setup_properties([pa])
    integ = sch.get_integrator()
    sc = Scene([pa], sch.get_equations(), steppers=integ.steppers, kernel=sch.kernel, dim=2,
               outputs={"helium": list(sch.output_props)}, backend="python")
    integ.attach(sc)
    integ.initial_accelerations(0.0, 1e-7)
    o = np.argsort(pa.gid)
    np.testing.assert_allclose(pa.rho[o], rho0[np.argsort(gid)], rtol=1e-13)


@pytest.mark.parametrize("backend", ["cython"])
def test_symmetric_integrator_is_time_reversible(reversible, backend):
    """beta = mu = 0 and the symmetric variant: 200 steps, v and v_s flipped, 200 steps
    recover x and s to 1e-9 relative (the particles move about 3 dx)."""
    sch, integ, sc = reversible
    new, dx = cloud(seed=3)
    load(sc, new)
    pa = sc.arrays[0]
    o0 = np.argsort(pa.gid)
    x0, y0, s0 = pa.x[o0].copy(), pa.y[o0].copy(), pa.s[o0].copy()
    integ.reversible, integ.calibrate = True, ["helium"]   # the summation starts at rho0 (1 +- 1%)
    try:
        dt = 0.4 * 1.5 * dx / M.c1
        Solver(sc, integ, dt=dt, tf=1.0, max_steps=200, progress=False).run()
        o = np.argsort(pa.gid)
        moved = np.hypot(pa.x[o] - x0, pa.y[o] - y0).max()
        for c in ("u", "v", "us", "vs"):
            pa.get(c)[:] *= -1
        Solver(sc, integ, dt=dt, tf=1.0, max_steps=200, progress=False).run()
    finally:
        integ.reversible, integ.calibrate = False, []
    o = np.argsort(pa.gid)
    print(f"moved {moved / dx:.2f} dx; reversal error x {max(np.abs(pa.x[o] - x0).max(), np.abs(pa.y[o] - y0).max()) / dx:.2e} dx, "
          f"s {np.abs(pa.s[o] - s0).max() / M.s0:.2e} s0; mean iterations {integ.iterations}")
    assert moved > dx
    assert max(np.abs(pa.x[o] - x0).max(), np.abs(pa.y[o] - y0).max()) < 1e-9 * 1e-3
    assert np.abs(pa.s[o] - s0).max() < 1e-9 * M.s0
    assert integ.unconverged == 0
