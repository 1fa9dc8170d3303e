"""The volume map J of the full {p, F, H, J, E} scheme against det F (Ghavamian et al. 2021,
eqs. 54b-d, 66, 73), on a smooth deformation of a unit cube (vertex lattice):

* without D_J, J-dot = H : grad v is the time derivative of det F (H = cof F): the rates agree to
  round-off and TVD-RK2 steps keep J = det F and H = cof F to its second-order time error;
* D_J moves J off det F at the rate sum_b D_J^ab / V_a.  With the paper's raw jumps this rate
  falls with the spacing inside the body but NOT at the surface (the raw jump of a linear
  Sigma_J is O(dx) and the one-sided sum does not cancel it: an O(1) inconsistency, here
  ~13 x the true volumetric rate); with the limited reconstruction it falls at first order
  at the surface and faster inside;
* once J is not slaved to det F, an isotropic local expansion of F is resisted with a
  *negative* stiffness (Mie-Gruneisen: Sigma_J(I) = -mu, and P = Sigma_F + Sigma_J H carries
  the geometric term Sigma_J dH): the mechanism of the full scheme's blow-up on the L-block
  (docs/thermo.md).
"""
import numpy as np
import pytest

from sphgen.equations.thermo_materials import MieGruneisen
from sphgen.particles import ParticleArray

from test_thermo_upwind import BASE, build

EPS = 0.02          # size of the quadratic deformation


def cof(F):
    return np.linalg.det(F)[..., None, None] * np.linalg.inv(F).transpose(0, 2, 1)


def box_lattice(shape, dx):
    """A box of shape[0] x shape[1] x shape[2] vertices spaced dx from the origin, with
    cell-fraction volumes (halved on each face); at rest."""
    axes = [np.arange(m) * dx for m in shape]
    X = np.array(np.meshgrid(*axes, indexing="ij")).reshape(3, -1).T
    pa = ParticleArray("body", x=X[:, 0], y=X[:, 1], z=X[:, 2])
    V = np.full(len(X), dx ** 3)
    for k in range(3):
        V *= np.where((X[:, k] < 1e-9) | (X[:, k] > axes[k][-1] - 1e-9), 0.5, 1.0)
    pa.add_property("V", data=V)
    return pa


def smooth_cube(n):
    """Unit cube, vertex lattice n^3 (cell-fraction volumes); phi = X + EPS (x^2 y, y^2 z, z^2 x),
    F = grad phi, H = cof F, J = det F; a smooth velocity with non-zero divergence; theta_R."""
    dx = 1.0 / (n - 1)
    pa = box_lattice((n, n, n), dx)
    x, y, z = pa.x, pa.y, pa.z
    X = np.stack([x, y, z], 1)
    F = np.tile(np.eye(3), (len(X), 1, 1))
    F[:, 0, 0] += 2 * EPS * x * y
    F[:, 0, 1] += EPS * x * x
    F[:, 1, 1] += 2 * EPS * y * z
    F[:, 1, 2] += EPS * y * y
    F[:, 2, 2] += 2 * EPS * z * x
    F[:, 2, 0] += EPS * z * z
    pa.add_property("F", stride=9, data=F.reshape(-1))
    pa.add_property("H", stride=9, data=cof(F).reshape(-1))
    pa.add_property("J", data=np.linalg.det(F))
    vel = 0.1 * np.stack([np.sin(x + y), np.cos(y) * z, x * z], 1)
    for k, c in enumerate("uvw"):
        pa.set(c, vel[:, k])
    return pa, dx


def drift_rates(n, **kw):
    """(max over the inner cube [0.3, 0.7]^3, max over all particles) of |J-dot - H : grad v|
    = |sum_b D_J^ab / V_a|, and max |H : grad v| (the true volumetric rate)."""
    pa, dx = smooth_cube(n)
    s, sc, integ = build(pa, dx, backend="cython", **kw)
    integ.initial_accelerations(0.0, 1e-3)
    sc.compute(0, 0.0, 1e-3)
    hg = np.einsum("aij,aij->a", pa.H.reshape(-1, 3, 3), pa.aF.reshape(-1, 3, 3))
    d = np.abs(pa.aJ - hg)
    X = np.stack([pa.x0, pa.y0, pa.z0], 1)
    inner = np.all((X > 0.3 - 1e-9) & (X < 0.7 + 1e-9), axis=1)
    return d[inner].max(), d.max(), np.abs(hg).max()


def test_without_D_J_the_volume_map_follows_det_F():
    inner, every, true = drift_rates(6, jumps="raw", dissipation="p")
    assert every < 1e-13 * true
    errors = []
    for k in (1, 2):                            # 20 steps, then 40 half steps to the same time
        pa, dx = smooth_cube(6)
        s, sc, integ = build(pa, dx, backend="cython", jumps="raw", dissipation="p")
        dt = s.get_timestep() / k
        integ.initial_accelerations(0.0, dt)
        J0 = pa.J.copy()
        t = 0.0
        for _ in range(20 * k):
            integ.one_timestep(t, dt)
            t += dt
        F = pa.F.reshape(-1, 3, 3)
        moved = np.abs(np.linalg.det(F) - J0).max()
        errors.append((np.abs(pa.J - np.linalg.det(F)).max(), np.abs(pa.H.reshape(-1, 3, 3) - cof(F)).max()))
        assert moved > 0.1 and max(errors[-1]) < 1e-3 * moved
    # the time-stepping error of TVD-RK2: second order in dt
    assert errors[0][0] / errors[1][0] > 3.5 and errors[0][1] / errors[1][1] > 3.5


def test_raw_D_J_is_inconsistent_at_the_surface_limited_is_first_order():
    raw = [drift_rates(n, jumps="raw") for n in (6, 11)]
    lim = [drift_rates(n, jumps="limited") for n in (6, 11)]
    true = raw[1][2]
    order = lambda a, b: np.log2(a / b)  # noqa: E731  (dx halves from n = 6 to 11)
    # raw jumps: inside, the rate falls (at least first order); at the surface it does not
    assert order(raw[0][0], raw[1][0]) > 1.0
    assert raw[1][1] > 0.9 * raw[0][1] and raw[1][1] > 5 * true
    # limited reconstruction: first order at the surface, second inside
    assert order(lim[0][1], lim[1][1]) > 0.9 and lim[1][1] < 0.5 * true
    assert order(lim[0][0], lim[1][0]) > 2.0


@pytest.mark.parametrize("nu", [0.3, 0.499])
def test_an_isotropic_expansion_at_fixed_J_or_Sigma_J_has_negative_stiffness(nu):
    """d(tr P / 3)/ds for F = s I at s = 1: positive with J = det F (the continuum), negative
    with J held (what D_J does to J relative to det F) or with Sigma_J held at its
    neighbours' value (D_J's fixed point)."""
    m = MieGruneisen(**{**BASE, "nu": nu})
    th = m.theta_R
    S0 = m.conjugates(np.eye(3), np.eye(3), 1.0, th)[2]
    assert S0 == pytest.approx(-m.mu, rel=1e-12)

    def J_at_fixed_sigma(F, H):
        lo, hi = 0.5, 2.0
        for _ in range(80):
            mid = 0.5 * (lo + hi)
            lo, hi = (mid, hi) if m.conjugates(F, H, mid, th)[2] < S0 else (lo, mid)
        return 0.5 * (lo + hi)

    def mean_P(s, mode):
        F = s * np.eye(3)
        H = cof(F[None])[0]
        J = {"det": np.linalg.det(F), "fixed": 1.0, "sigma": None}[mode]
        if J is None:
            J = J_at_fixed_sigma(F, H)
        return np.trace(m.stress(F, H, J, th)) / 3.0

    e = 1e-5
    k = {mode: (mean_P(1 + e, mode) - mean_P(1 - e, mode)) / (2 * e) / m.mu for mode in ("det", "fixed", "sigma")}
    assert k["det"] == pytest.approx(3 * m.kappa / m.mu, rel=1e-6)
    assert k["fixed"] == pytest.approx(-3.0, rel=1e-6)
    assert -1.4 < k["sigma"] < -0.99


# ---------------------------------------------------------------------------------------
# dj="volumetric" (variant full-vol, not the paper's): D_J on the jump of the mean stress
# varsigma = (Sigma_F : F + 2 Sigma_H : H + 3 J Sigma_J) / 3J, applied to J, F and H together


def test_volumetric_D_J_moves_J_F_H_together():
    """J-dot = H : F-dot exactly (so J stays det F) on the smooth deformation, at every
    particle, while the dissipation is on (the J rate differs from the one without D_J)."""
    inner, every, true = drift_rates(6, jumps="raw", dj="volumetric")
    assert every < 1e-12 * true
    pa, dx = smooth_cube(6)
    s, sc, integ = build(pa, dx, backend="cython", jumps="raw", dj="volumetric")
    integ.initial_accelerations(0.0, 1e-3)
    sc.compute(0, 0.0, 1e-3)
    assert np.abs(pa.SD - pa.SJ).max() > 1.0        # it jumps the mean stress, not Sigma_J [Pa]
    # and it does act: J-dot differs from the plain H : grad v (the paper-free rate)
    plain = drift_rates(6, jumps="raw", dissipation="p")
    assert np.abs(pa.aJ).max() != pytest.approx(plain[2], rel=1e-6)


@pytest.mark.parametrize("form,jumps", [("E", "raw"), ("eta", "limited")])
def test_volumetric_D_J_keeps_the_ballistic_identity(form, jumps):
    """Eqs. 61/69 with varsigma in place of Sigma_J: sum V nu . dU/dt = heat - D_total,
    D_total = 1/2 sum raw jump of varsigma (/Xi) times D^ab, every pair >= 0 (random
    cloud, H and J independent of F)."""
    from test_thermo_upwind import ballistic_rate, cloud, heat_term, pair_dissipation, rates
    pa, dx = cloud(seed=3)
    s, sc = rates(pa, dx, form=form, jumps=jumps, dj="volumetric")
    heat, lhs = heat_term(s, pa), ballistic_rate(s, pa)
    sj = pa.SJ.copy()
    pa.SJ[:] = pa.SD           # the pair recomputation jumps pa.SJ
    D, per_pair = pair_dissipation(s, sc, pa)
    pa.SJ[:] = sj
    assert heat < 0 and D > 0 and per_pair.min() >= 0.0
    assert abs(lhs - (heat - D)) < 1e-10 * (abs(heat) + D), (lhs, heat, D)


# ---------------------------------------------------------------------------------------
# dj="pressure" (variant full-pJ, a diagnostic of round 10, not the paper's): D_J on the jump
# of the volumetric part of Sigma_J only


def test_pressure_D_J_ignores_an_isochoric_shear_the_paper_s_does_not():
    """A non-uniform simple shear F = I + g(X) e_1 (x) e_2 at rest (det F = J = 1, theta_R):
    Sigma_J = -(2/3) zeta_R J^(-5/3) F : F varies with the shear, so the paper's D_J moves J;
    the volumetric part kappa (J - 1) + c_v Gamma_0 (theta_R - theta) is 0 everywhere, so the
    diagnostic's D_J does not."""
    out = {}
    for dj in ("paper", "pressure"):
        pa, dx = smooth_cube(6)
        x, y = pa.x, pa.y
        F = np.tile(np.eye(3), (pa.n, 1, 1))
        F[:, 0, 1] = 0.3 * np.sin(2.0 * x + y)
        pa.F[:] = F.reshape(-1)
        pa.H[:] = cof(F).reshape(-1)
        pa.J[:] = 1.0
        for c in "uvw":
            pa.get(c)[:] = 0.0
        s, sc, integ = build(pa, dx, backend="cython", jumps="raw", dj=dj)
        integ.initial_accelerations(0.0, 1e-3)
        sc.compute(0, 0.0, 1e-3)
        out[dj] = (np.abs(pa.aJ).max(), np.abs(pa.SD).max(), np.ptp(pa.SJ))
    m = MieGruneisen(**BASE)
    assert out["paper"][2] > 1e-3 * m.mu                  # Sigma_J varies with the shear
    assert out["paper"][0] > 1e-3                         # and the paper's D_J moves J [1/s]
    assert out["pressure"][1] < 1e-9 * m.mu               # the volumetric part is 0
    assert out["pressure"][0] < 1e-12 * out["paper"][0]


# ---------------------------------------------------------------------------------------
# Round 10: the rest state of the paper's full scheme is linearly unstable


def rest_growth(shape, **kw):
    """Largest real part of the eigenvalues of the linearised semi-discrete rates (v, F, H, J,
    E of every particle) at rest (F = H = I, J = 1, theta_R, v = 0) on a box lattice with
    dx = 0.1 m, in units of c_p / dx, and the top mode's share of F and H (scaled norms)."""
    from sphgen.applications._thermo_modes import central_jacobian
    dx = 0.1
    pa = box_lattice(shape, dx)
    s, sc, integ = build(pa, dx, backend="cython", jumps="raw", **kw)
    integ.initial_accelerations(0.0, 1e-3)
    cp = float(pa.cp[0])
    names = ("u", "v", "w", "F", "H", "J", "E")
    y0 = np.concatenate([pa.get(nm).copy() for nm in names])

    def rates(y):
        k = 0
        for nm in names:
            a = pa.get(nm)
            a[:] = y[k:k + a.size]
            k += a.size
        integ.initial_accelerations(0.0, 1e-3)
        sc.compute(0, 0.0, 1e-3)
        acc = pa.tint.reshape(-1, 3) / pa.rho[:, None]
        return np.concatenate([acc[:, 0], acc[:, 1], acc[:, 2], pa.aF, pa.aH, pa.aJ, pa.aE])

    lam, vec = np.linalg.eig(central_jacobian(rates, y0, floor=1.0))
    i = int(np.argmax(lam.real))
    n = pa.n
    w = np.abs(vec[:, i]) ** 2
    w[:3 * n] /= cp ** 2                                  # velocities in units of c_p
    w[-n:] /= s.material.kappa ** 2                       # E in units of the bulk modulus
    return lam[i].real * dx / cp, w[3 * n:21 * n].sum() / w.sum()


def test_paper_D_J_makes_the_rest_state_linearly_unstable_full_vol_does_not():
    """On a 3 x 2 x 2 block at rest the paper's D_J (raw jumps, E-form) gives a real eigenvalue
    of about +0.1 c_p/dx, a mode of F and H with J nearly held (Sigma_F(I) = mu I and
    Sigma_J(I) = -mu: the rest state is not a minimum of the ballistic energy once J may leave
    det F); with D_J moving J, F, H together (full-vol) the largest real part is the finite
    differences' noise, as without D_J."""
    paper, share = rest_growth((3, 2, 2))
    assert paper > 0.05 and share > 0.9
    vol, _ = rest_growth((3, 2, 2), dj="volumetric")
    assert vol < 1e-6
