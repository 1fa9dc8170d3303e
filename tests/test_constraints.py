"""Prescribed motion and clamps, re-imposed after every integrator stage at the stage's time."""
import numpy as np

from conftest import lattice_cloud
from sphgen.integrators import PEC, IntegratorStep, KickDriftKick
from sphgen.scene import Scene
from sphgen.solver import Solver


class Drift(IntegratorStep):
    """Half-step predictor and full-step corrector of x under a constant acceleration."""

    def stage1(self, d_idx, d_x, d_u, d_x0, d_u0, dt):
        d_x0[d_idx] = d_x[d_idx]
        d_u0[d_idx] = d_u[d_idx]
        d_x[d_idx] += 0.5 * dt * d_u[d_idx]
        d_u[d_idx] += 0.5 * dt

    def stage2(self, d_idx, d_x, d_u, d_x0, d_u0, dt):
        d_x[d_idx] = d_x0[d_idx] + dt * (d_u0[d_idx] + 0.5 * dt)
        d_u[d_idx] = d_u0[d_idx] + dt


def scene_with(integrator_cls, steps):
    fluid = lattice_cloud("fluid", nx=4)
    piston = lattice_cloud("piston", nx=2, jitter=0.0)
    for pa in (fluid, piston):
        pa.add_property("x0")
        pa.add_property("u0")
    piston.add_property("xref", data=piston.x)   # reference positions travel with their particles
    integ = integrator_cls(fluid=steps)
    sc = Scene([fluid, piston], [], steppers=integ.steppers, dim=2,
               outputs={"fluid": ["x", "u"], "piston": ["x", "u"]})
    return sc, integ


def test_piston_follows_its_function_at_each_stage_time():
    sc, integ = scene_with(PEC, Drift())
    piston = sc.by_name["piston"]
    x_ref = piston.x.copy()
    A, w = 0.01, 3.0
    integ.add_motion("piston", lambda t, pa: {"x": pa.xref + A * np.sin(w * t), "u": A * w * np.cos(w * t)})
    seen = []
    evaluate = integ.compute_accelerations

    def record(index, t, dt):
        seen.append((t, piston.x[0] - x_ref[0]))
        evaluate(index, t, dt)
    integ.compute_accelerations = record
    solver = Solver(sc, integ, dt=0.01, tf=0.1, progress=False)
    solver.run()
    assert np.allclose(piston.x, x_ref + A * np.sin(w * solver.t), atol=1e-15, rtol=0)
    assert np.allclose(piston.u, A * w * np.cos(w * solver.t), atol=1e-15, rtol=0)
    # PEC evaluates at the half step, where the piston stands at its half-step position
    for t, dx in seen:
        assert abs(dx - A * np.sin(w * t)) < 1e-15


def test_clamped_particles_do_not_move_under_a_force():
    sc, integ = scene_with(PEC, Drift())
    fluid = sc.by_name["fluid"]
    fluid.u[:] = 0.0
    start = dict(zip(fluid.gid, fluid.x))
    gids = [fluid.gid[0], fluid.gid[5]]
    integ.clamp("fluid", gids, u=0.0, x=[start[g] for g in gids])
    solver = Solver(sc, integ, dt=0.01, tf=0.6, progress=False, sort_every=7)
    solver.run()                 # 60 steps, re-sorted every 7: clamps follow gid
    held = np.isin(fluid.gid, gids)
    assert held.sum() == 2 and np.all(fluid.u[held] == 0.0)
    assert all(x == start[g] for g, x in zip(fluid.gid[held], fluid.x[held]))
    moved = np.array([x - start[g] for g, x in zip(fluid.gid[~held], fluid.x[~held])])
    assert np.allclose(fluid.u[~held], 0.6) and np.allclose(moved, 0.5 * 0.6 ** 2)


def test_kick_drift_kick_stage_times():
    assert KickDriftKick.position_time == {"stage1": 0.0, "stage2": 1.0, "stage3": 1.0}


def test_an_array_that_interacts_with_nothing_gets_no_neighbour_search():
    from sphgen.equations.basic import SummationDensity
    fluid = lattice_cloud("fluid", nx=4)
    probe = lattice_cloud("probe", nx=2)
    sc = Scene([fluid, probe], [SummationDensity("fluid", ["fluid"])], dim=2, outputs={"fluid": ["rho"]})
    assert [pa.name for pa in sc.nnps.arrays] == ["fluid"]
    sc.update_nnps()
    sc.sort()


def test_two_live_scenes_with_the_same_module_keep_their_own_data():
    from sphgen.equations.basic import SummationDensity

    def scene(seed):
        pa = lattice_cloud("fluid", nx=6, seed=seed)
        return pa, Scene([pa], [SummationDensity("fluid", ["fluid"])], dim=2, outputs={"fluid": ["rho"]})
    a, sa = scene(1)
    b, sb = scene(2)
    assert sa.engine.module is sb.engine.module          # one loaded module, shared
    sa.compute(0, 0.0, 0.1)
    sb.compute(0, 0.0, 0.1)
    rho_a, rho_b = a.rho.copy(), b.rho.copy()
    a.x[:] += 0.01
    sa.update_nnps()
    sb.update_nnps()
    sa.compute(0, 0.0, 0.1)                               # must use a's lists, not b's
    fresh, sf = scene(1)
    fresh.x[:] += 0.01
    sf.update_nnps()
    sf.compute(0, 0.0, 0.1)
    assert np.array_equal(a.rho, fresh.rho) and not np.array_equal(a.rho, rho_a)
    sb.compute(0, 0.0, 0.1)
    assert np.array_equal(b.rho, rho_b)


def test_a_blow_up_raised_inside_a_step_keeps_the_last_good_state(tmp_path):
    from sphgen import io
    from sphgen.errors import BlowUpError
    import pytest

    class Diverges(PEC):
        def one_timestep(self, t, dt):
            super().one_timestep(t, dt)
            if t > 0.025:
                raise BlowUpError("iteration did not converge")
    sc, _ = scene_with(PEC, Drift())
    integ = Diverges(fluid=Drift())
    solver = Solver(sc, integ, dt=0.01, tf=1.0, progress=False, outdir=str(tmp_path), prefix="d")
    with pytest.raises(BlowUpError, match="did not converge; last good state .step 3"):
        solver.run()
    assert io.load(str(tmp_path / "d_last_good.h5"))["solver_data"]["step"] == 3
