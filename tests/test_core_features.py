"""Core features the schemes build on, each compiled and checked quantitatively."""
import numpy as np
import pytest

from sphgen.equation import Equation, Group, declare
from sphgen.integrators import EPEC, IntegratorStep
from sphgen.linalg import inv3, matmul3
from sphgen.scene import Scene
from sphgen.equations.basic import SummationDensity

from conftest import lattice_cloud, periodic_box


class RenormalisedVelocityGradient(Equation):
    """grad u_a = [sum_b m_b u_ab (x) grad W_ab] [sum_b m_b x_ab (x) grad W_ab]^-1."""

    def initialize(self, d_idx, d_L, d_H):
        for i in range(9):
            d_L[9 * d_idx + i] = 0.0
            d_H[9 * d_idx + i] = 0.0

    def loop(self, d_idx, d_L, d_H, s_idx, s_m, VIJ, XIJ, DWIJ):
        for i in range(3):
            for j in range(3):
                d_L[9 * d_idx + 3 * i + j] += s_m[s_idx] * VIJ[i] * DWIJ[j]
                d_H[9 * d_idx + 3 * i + j] += s_m[s_idx] * XIJ[i] * DWIJ[j]

    def post_loop(self, d_idx, d_L, d_H, d_gradv):
        h = declare("matrix(9)")
        hi = declare("matrix(9)")
        lm = declare("matrix(9)")
        g = declare("matrix(9)")
        for i in range(9):
            h[i] = d_H[9 * d_idx + i]
            lm[i] = d_L[9 * d_idx + i]
        inv3(h, hi)
        matmul3(lm, hi, g)
        for i in range(9):
            d_gradv[9 * d_idx + i] = g[i]


@pytest.mark.parametrize("backend", ["cython", "python"])
def test_renormalised_velocity_gradient_is_exact_for_linear_fields(backend):
    pa = lattice_cloud(nx=6, dim=3, jitter=0.3, seed=5)
    G = np.array([[0.3, -1.2, 0.5], [2.0, 0.1, -0.7], [-0.4, 0.9, 1.1]])
    X = np.stack([pa.x, pa.y, pa.z], axis=1)
    U = X @ G.T + np.array([0.2, -0.1, 0.3])
    pa.u, pa.v, pa.w = U[:, 0], U[:, 1], U[:, 2]
    for p in ("L", "H", "gradv"):
        pa.add_property(p, stride=9)
    sc = Scene([pa], [RenormalisedVelocityGradient("fluid", ["fluid"])], dim=3,
               outputs={"fluid": ["gradv"]}, backend=backend)
    sc.compute(0, 0.0, 0.1)
    grad = pa.gradv.reshape(-1, 3, 3)
    err = np.abs(grad - G).max() / np.abs(G).max()
    assert err < 1e-12, err


class ReferenceSum(Equation):
    """rho0_a = sum_b m_b W(X_ab) on the reference configuration; counts neighbours."""

    def initialize(self, d_idx, d_rho0):
        d_rho0[d_idx] = 0.0

    def loop(self, d_idx, d_rho0, s_idx, s_m, WIJ):
        d_rho0[d_idx] += s_m[s_idx] * WIJ

    def loop_all(self, d_idx, d_nref, NBRS, N_NBRS):
        d_nref[d_idx] = N_NBRS


def test_reference_neighbour_lists_stay_fixed_while_particles_move():
    pa = lattice_cloud(nx=10, jitter=0.1, seed=2)
    for p in ("x0", "y0"):
        pa.add_property(p, data=pa.get(p[0]).copy())
    pa.add_property("rho0")
    pa.add_property("nref")
    eqs = [Group([ReferenceSum("fluid", ["fluid"])], reference=True),
           Group([SummationDensity("fluid", ["fluid"])])]
    sc = Scene([pa], eqs, dim=2, outputs={"fluid": ["rho0", "rho", "nref"]})
    sc.compute(0, 0.0, 0.1)
    rho0, nref, rho = pa.rho0.copy(), pa.nref.copy(), pa.rho.copy()
    assert np.allclose(rho0, rho, rtol=1e-14)          # same configuration at t = 0
    rng = np.random.default_rng(0)
    pa.x[:] += 0.05 * rng.standard_normal(pa.n)       # move far: a quarter of the support
    pa.y[:] += 0.05 * rng.standard_normal(pa.n)
    sc.update_nnps()
    sc.compute(0, 0.0, 0.1)
    assert np.array_equal(pa.nref, nref)              # neighbours fixed at t = 0
    assert np.allclose(pa.rho0, rho0, rtol=1e-14)     # pair geometry from x0, y0
    assert np.abs(pa.rho - rho).max() > 1e-2          # the current configuration did change
    off, _ = sc.nnps.neighbours("fluid", "fluid")
    assert not np.array_equal(np.diff(off), nref.astype(np.int32))


class FixedPoint(Equation):
    """x <- cos(x) per particle; converged when the largest change is below tol."""

    def __init__(self, dest, tol):
        super().__init__(dest, None, tol=tol)
        self.change = np.inf

    def initialize(self, d_idx, d_xk, d_dxk):
        xn = cos(d_xk[d_idx])  # noqa: F821  (libc cos in C, math.cos below)
        d_dxk[d_idx] = abs(xn - d_xk[d_idx])
        d_xk[d_idx] = xn

    def reduce(self, dst, t, dt):
        self.change = float(dst.dxk.max())

    def converged(self):
        return 1 if self.change < self.tol else -1


def test_iterated_group_stops_on_converged_and_reports_iterations():
    import math
    import builtins
    builtins.cos = math.cos  # the Python evaluator's cos; C uses libc's
    try:
        pa = lattice_cloud(nx=4)
        pa.add_property("xk", data=np.linspace(-1.0, 1.0, pa.n))
        pa.add_property("dxk")
        g = Group([FixedPoint("fluid", tol=1e-13)], iterate=True, max_iterations=500)
        sc = Scene([pa], [g], dim=2, outputs={"fluid": ["xk"]})
        x0 = pa.xk.copy()
        sc.compute(0, 0.0, 0.1)
    finally:
        del builtins.cos
    assert np.allclose(pa.xk, 0.7390851332151607, atol=1e-12)
    # the same iteration in numpy takes the same number of sweeps
    x, n = x0, 0
    while True:
        xn = np.cos(x)
        n += 1
        done = np.abs(xn - x).max() < 1e-13
        x = xn
        if done:
            break
    assert g.iterations == n and 10 < n < 500


class CountA(Equation):
    def initialize(self, d_idx, d_ca):
        d_ca[d_idx] += 1.0


class CountB(Equation):
    def initialize(self, d_idx, d_cb, d_rho):
        d_cb[d_idx] += 1.0 + 0.0 * d_rho[d_idx]


class Drift(IntegratorStep):
    def stage1(self, d_idx, d_x, d_u, dt):
        d_x[d_idx] += 0.5 * dt * d_u[d_idx]

    def stage2(self, d_idx, d_x, d_u, d_ca, d_cb, dt):
        d_x[d_idx] += 0.5 * dt * d_u[d_idx] + 0.0 * (d_ca[d_idx] + d_cb[d_idx])


def test_epec_runs_different_sets_per_evaluation_and_updates_neighbours_twice():
    pa = lattice_cloud(nx=8)
    pa.add_property("ca", default=0.0)
    pa.add_property("cb", default=0.0)
    integ = EPEC(fluid=Drift())
    sets = [[Group([CountA("fluid")])], [Group([SummationDensity("fluid", ["fluid"])]),
                                         Group([CountB("fluid")])]]
    sc = Scene([pa], sets, steppers=integ.steppers, dim=2, domain=periodic_box(2),
               outputs={"fluid": ["ca", "cb"]})
    integ.attach(sc)
    before = sc.nnps.n_updates
    x0 = pa.x.copy()
    for step in range(3):
        integ.one_timestep(0.01 * step, 0.01)
    assert np.all(pa.ca == 3) and np.all(pa.cb == 3)
    assert integ.nnps_updates == 6 and sc.nnps.n_updates - before == 6
    dx = (pa.x - x0 + 0.5) % 1.0 - 0.5
    assert np.allclose(dx, 0.03 * pa.u, atol=1e-12)


class RhoRange(Equation):
    """Global min and max of rho, stored in constants for later groups."""

    def initialize(self, d_idx, d_rho):
        pass

    def reduce(self, dst, t, dt):
        dst.rhomin[0] = dst.rho.min()
        dst.rhomax[0] = dst.rho.max()


class Normalise(Equation):
    def initialize(self, d_idx, d_rho, d_rhon, d_rhomin, d_rhomax):
        d_rhon[d_idx] = (d_rho[d_idx] - d_rhomin[0]) / (d_rhomax[0] - d_rhomin[0])


def test_min_max_reductions_between_groups():
    pa = lattice_cloud(nx=10, jitter=0.3)
    pa.add_constant("rhomin", 0.0)
    pa.add_constant("rhomax", 0.0)
    pa.add_property("rhon")
    eqs = [Group([SummationDensity("fluid", ["fluid"]), RhoRange("fluid")]),
           Group([Normalise("fluid")])]
    sc = Scene([pa], eqs, dim=2, outputs={"fluid": ["rhon"]})
    sc.compute(0, 0.0, 0.1)
    assert pa.rhon.min() == 0.0 and pa.rhon.max() == 1.0
    assert pa.rhomax[0] == pa.rho.max() and pa.rhomin[0] < pa.rhomax[0]


class Nudge(Equation):
    def initialize(self, d_idx, d_x, dt):
        d_x[d_idx] += dt


def test_group_condition_and_update_nnps():
    pa = lattice_cloud(nx=6)
    g = Group([Nudge("fluid")], condition=lambda t, dt: t >= 1.0, update_nnps=True)
    sc = Scene([pa], [g], dim=2, domain=periodic_box(2), outputs={"fluid": ["x"]})
    x0, n0 = pa.x.copy(), sc.nnps.n_updates
    sc.compute(0, 0.5, 0.01)                      # condition false: skipped
    assert np.array_equal(pa.x, x0) and g.iterations == 0 and sc.nnps.n_updates == n0
    sc.compute(0, 1.0, 0.01)                      # runs, then rebuilds the neighbour lists
    assert np.allclose((pa.x - x0) % 1.0, 0.01) and g.iterations == 1
    assert sc.nnps.n_updates == n0 + 1


def test_check_finite_names_the_property_and_particle():
    """The compiled guard (one sweep per array and stride, then per property) finds an inf
    or a NaN in a scalar or a 3x3 property, and nothing in a finite state."""
    pa = lattice_cloud(nx=6, dim=3, jitter=0.3, seed=5)
    for p in ("L", "H", "gradv"):
        pa.add_property(p, stride=9)
    sc = Scene([pa], [RenormalisedVelocityGradient("fluid", ["fluid"])], dim=3,
               outputs={"fluid": ["gradv"]})
    sc.compute(0, 0.0, 0.1)
    assert sc.check_finite() is None
    for prop, k, bad in (("gradv", 9 * 17 + 4, np.inf), ("rho", 40, np.nan), ("x", 0, -np.inf)):
        keep = pa.get(prop)[k]
        pa.get(prop)[k] = bad
        assert sc.check_finite() == ("fluid", prop, k // pa.props[prop].stride)
        pa.get(prop)[k] = keep
    assert sc.check_finite() is None


def test_two_scenes_sharing_one_module_keep_their_own_neighbour_rows():
    """Two live scenes with the same generated source share one loaded module; each takes
    it back (arrays and neighbour rows) before running, so interleaved steps with skin
    lists give what each scene gives alone."""
    def scene(seed):
        pa = lattice_cloud(nx=10, seed=seed)
        return pa, Scene([pa], [SummationDensity("fluid", ["fluid"])], dim=2, domain=periodic_box(2),
                         outputs={"fluid": ["rho"]}, skin=0.2)

    def steps(pairs, n=6):
        out = []
        for k in range(n):
            for pa, sc in pairs:
                pa.x[:] += 0.001 * pa.u
                pa.y[:] += 0.001 * pa.v
                sc.update_nnps()
                sc.compute(0, 0.0, 0.001)
                out.append(pa.rho.copy())
        return out

    (a, sa), (b, sb) = scene(1), scene(2)
    assert sa.engine.module is sb.engine.module
    together = steps([(a, sa), (b, sb)])
    alone = steps([scene(1)]), steps([scene(2)])
    for k in range(6):
        np.testing.assert_array_equal(together[2 * k], alone[0][k])
        np.testing.assert_array_equal(together[2 * k + 1], alone[1][k])
    assert sa.nnps.n_builds < sa.nnps.n_updates         # the rows were cut from kept lists


def test_rows_cut_in_place_are_not_handed_to_the_module_again():
    """While the skin lists stand, each update cuts the rows inside the buffers the module
    already holds: binding then costs no look at them (no rows_of, no module call); a
    rebuild, a sort or new thread parts hands them over again, and the densities stay
    those of a scene without a skin (to round-off: the two sorts order differently)."""
    def run(skin, watch=None):
        pa = lattice_cloud(nx=10, seed=3, gid=np.arange(100.0))
        sc = Scene([pa], [SummationDensity("fluid", ["fluid"])], dim=2, domain=periodic_box(2),
                   outputs={"fluid": ["rho"]}, skin=skin, threads=2)
        if watch is not None:
            rows_of = sc.nnps.rows_of
            sc.nnps.rows_of = lambda *args: watch.append(sc.nnps.n_builds) or rows_of(*args)
        out = []
        for k in range(8):
            pa.x[:] += 0.0005 * pa.u
            pa.y[:] += 0.0005 * pa.v
            if k == 5:
                sc.sort()
            sc.update_nnps()
            sc.compute(0, 0.0, 0.001)
            out.append(pa.rho[np.argsort(pa.gid)].copy())
        return sc, out

    calls = []
    sa, with_skin = run(0.3, calls)
    _, without = run(0.0)
    for a, b in zip(with_skin, without):
        np.testing.assert_allclose(a, b, rtol=1e-13)
    assert sa.nnps.n_builds == 3 + 2                 # construction (build, sort: two), the sort
    # the sort hands over new rows; it and the first update are followed by a re-plan for
    # the parts the module cut; the five other updates cut in place and bind nothing
    assert calls == [3, 5, 5], calls
    sa.set_threads(1)                                # new parts: looked at again
    sa.update_nnps()
    assert len(calls) == 4
