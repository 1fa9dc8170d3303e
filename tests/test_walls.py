"""Adami walls and repulsive walls: compiled == Python, exactness, switches that vanish."""
import re

import numpy as np
import pytest

from sphgen.codegen.passes import plan_scene
from sphgen.codegen.render import render
from sphgen.equation import Group
from sphgen.equations.walls import (LennardJonesWallForce, MonaghanKajtarForce, WallArtificialViscosity,
                                    WallContinuity, WallDensity, WallEDACPressureRate, WallGhostVelocity,
                                    WallPressure, WallViscosity)
from sphgen.equations.wcsph import TaitEOS
from sphgen.geometry import rectangle, wall_layers_box
from sphgen.kernels import QuinticSpline
from sphgen.particles import ParticleArray
from sphgen.scene import Scene

from conftest import assert_close

DX = 0.1


def tank(moving=False, jitter=0.2, seed=0):
    """A jittered block of fluid resting on a 3-layer wall box, random u, v, p, rho."""
    rng = np.random.default_rng(seed)
    x, y = rectangle(0.0, 0.8, 0.0, 0.6, DX)
    x = x + jitter * DX * rng.uniform(-1, 1, x.size)
    y = y + jitter * DX * rng.uniform(-1, 1, y.size)
    n = x.size
    fluid = ParticleArray("fluid", x=x, y=y, u=rng.uniform(-1, 1, n), v=rng.uniform(-1, 1, n),
                          rho=1000.0 * (1 + 0.01 * rng.uniform(-1, 1, n)), m=np.full(n, 10.0),
                          h=np.full(n, DX))
    for p in ("arho", "au", "av", "aw", "ap"):   # accumulators: allocated (zero) by the plan
        fluid.add_property(p)
    fluid.add_property("p", data=rng.uniform(0, 100, n))
    xw, yw, nx, ny = wall_layers_box(0.0, 0.8, 0.0, 1.0, DX, 3)
    nw = xw.size
    wall = ParticleArray("wall", x=xw, y=yw, m=np.full(nw, 10.0), h=np.full(nw, DX), rho=np.full(nw, 1000.0))
    wall.add_property("normal", stride=3, data=np.column_stack([nx, ny, 0 * nx]).ravel())
    for p in ("p", "wij", "ug", "vg", "wg", "uw", "vw", "ww", "auw", "avw", "aww"):
        wall.add_property(p)
    if moving:
        for p in ("uw", "vw", "auw", "avw"):
            wall.add_property(p, data=rng.uniform(-1, 1, nw))
    return fluid, wall


def all_wall_equations(slip, moving, eos):
    w = [WallPressure("wall", ["fluid"], gy=-9.81, gx=0.5, accelerating=moving, clamp=slip, dim=2),
         WallDensity("wall", eos=eos, rho0=1000.0, c0=20.0),
         WallGhostVelocity("wall", ["fluid"], slip=slip, moving=moving, dim=2)]
    f = [WallContinuity("fluid", ["wall"], moving=moving, dim=2),
         WallViscosity("fluid", ["wall"], nu=0.01, dim=2),
         WallArtificialViscosity("fluid", ["wall"], alpha=0.2, beta=0.1, c0=20.0, moving=moving, dim=2),
         WallEDACPressureRate("fluid", ["wall"], c0=20.0, nu_edac=0.05, moving=moving, dim=2),
         MonaghanKajtarForce("fluid", ["wall"], K=2.0, beta=1.0),
         LennardJonesWallForce("fluid", ["wall"], D=3.0, r0=DX, power=1 if slip else 2)]
    return [Group(w), Group(f)]


def evaluate(backend, slip, moving, eos):
    fluid, wall = tank(moving)
    eqs = all_wall_equations(slip, moving, eos)
    sc = Scene([fluid, wall], eqs, kernel=QuinticSpline(2), dim=2, backend=backend,
               outputs={"fluid": ["arho", "au", "av", "ap"], "wall": ["p", "rho", "ug", "vg"]})
    sc.compute(0, 0.0, 1e-4)
    return fluid, wall, sc


@pytest.mark.parametrize("slip,moving,eos", [(False, True, "tait"), (True, False, "linear")])
def test_wall_equations_compiled_match_python(slip, moving, eos):
    a_f, a_w, sc = evaluate("cython", slip, moving, eos)
    b_f, b_w, _ = evaluate("python", slip, moving, eos)
    kept = {type(ep.eq).__name__ for ep in sc.plan.eqplans if ep.kept}
    assert len(kept) == 9, kept
    for pa, pb in ((a_f, b_f), (a_w, b_w)):
        assert sorted(pa.data) == sorted(pb.data)
        for name in pa.data:
            assert_close(pa.data[name], pb.data[name], 1e-11, what=f"{pa.name}.{name}")
    assert np.abs(a_w.p).max() > 0 and np.abs(a_f.au).max() > 0 and np.abs(a_f.arho).max() > 0


def python_scene(arrays, eqs, outputs):
    return Scene(arrays, eqs, kernel=QuinticSpline(2), dim=2, backend="python", outputs=outputs)


def test_wall_pressure_is_exact_for_a_hydrostatic_fluid():
    """AHA eq. 27 reproduces p = rho0 g (H - y) at every wall particle near the fluid."""
    fluid, wall = tank(jitter=0.3)
    rho0, g, H = 1000.0, 9.81, 0.6
    fluid.set("rho", rho0)
    fluid.set("p", rho0 * g * (H - fluid.y))
    python_scene([fluid, wall], [WallPressure("wall", ["fluid"], gy=-g)], {"wall": ["p"]}).compute(0, 0.0, 0.0)
    near = wall.wij > 0
    assert near.sum() > 50
    np.testing.assert_allclose(wall.p[near], rho0 * g * (H - wall.y[near]), rtol=1e-12)
    assert np.all(wall.p[~near] == 0.0)


def test_wall_density_inverts_the_equation_of_state():
    fluid, wall = tank()
    wall.add_property("p", data=np.linspace(-1000.0, 5e4, wall.n))
    python_scene([fluid, wall], [WallDensity("wall", eos="tait", rho0=1000.0, c0=20.0, gamma=7.0)],
                 {"wall": ["rho"]}).compute(0, 0.0, 0.0)
    # back through the fluid's Tait equation
    back = ParticleArray("fluid", x=wall.x, y=wall.y, rho=wall.rho.copy(), h=wall.h, m=wall.m)
    back.add_property("p")
    python_scene([back], [TaitEOS("fluid", None, rho0=1000.0, c0=20.0, gamma=7.0)],
                 {"fluid": ["p"]}).compute(0, 0.0, 0.0)
    np.testing.assert_allclose(back.p, wall.p, rtol=1e-9, atol=1e-9)
    python_scene([fluid, wall], [WallDensity("wall", eos="linear", rho0=1000.0, c0=20.0)],
                 {"wall": ["rho"]}).compute(0, 0.0, 0.0)
    np.testing.assert_allclose(wall.rho, 1000.0 + wall.p / 400.0, rtol=1e-14)


@pytest.mark.parametrize("slip", [False, True])
def test_ghost_velocity_mirrors_a_uniform_flow(slip):
    """Uniform fluid velocity U: no slip gives 2 u_w - U; free slip keeps U's tangential part
    and mirrors its normal part about u_w (AHA eqs. 22-23)."""
    fluid, wall = tank(moving=True)
    U = np.array([0.7, -0.4])
    fluid.set("u", U[0])
    fluid.set("v", U[1])
    eqs = [Group([WallPressure("wall", ["fluid"]),
                  WallGhostVelocity("wall", ["fluid"], slip=slip, moving=True, dim=2)])]
    python_scene([fluid, wall], eqs, {"wall": ["ug", "vg"]}).compute(0, 0.0, 0.0)
    near = wall.wij > 0
    uw = np.column_stack([wall.uw, wall.vw])[near]
    ug = np.column_stack([wall.ug, wall.vg])[near]
    if slip:
        n = wall.normal.reshape(-1, 3)[near, :2]
        dn = 2 * np.sum((uw - U) * n, axis=1)
        expect = U + dn[:, None] * n
        # tangential part is the fluid's, normal part mirrored
        t = np.column_stack([-n[:, 1], n[:, 0]])
        np.testing.assert_allclose(np.sum(ug * t, axis=1), U @ t.T, atol=1e-12)
    else:
        expect = 2 * uw - U
    np.testing.assert_allclose(ug, expect, atol=1e-12)


def test_repulsive_forces_push_away_from_the_wall_and_vanish_far_from_it():
    wall = ParticleArray("wall", x=np.array([0.0]), y=np.array([0.0]), m=np.array([1.0]), h=np.array([DX]))
    y = np.array([0.02, 0.05, 0.09, 0.15, 0.25])
    for eq in (LennardJonesWallForce("fluid", ["wall"], D=1.0, r0=DX),
               MonaghanKajtarForce("fluid", ["wall"], K=1.0, beta=1.0)):
        fluid = ParticleArray("fluid", x=0 * y, y=y, m=np.ones(y.size), h=np.full(y.size, DX))
        for p in ("au", "av", "aw"):
            fluid.add_property(p)
        python_scene([fluid, wall], [eq], {"fluid": ["au", "av"]}).compute(0, 0.0, 0.0)
        radius = DX if isinstance(eq, LennardJonesWallForce) else 2 * DX
        assert np.all(fluid.av[y < radius] > 0) and np.all(fluid.av[y >= radius] == 0)
        assert np.all(np.diff(fluid.av[y < radius]) < 0)   # stronger closer to the wall
        assert np.all(fluid.au == 0)


def rendered(eqs, arrays, outputs):
    """Generated Cython source of a scene, without compiling it."""
    plan = plan_scene(arrays, eqs, {}, QuinticSpline(2), 2, None, outputs)
    return render(plan).source, plan


def test_wall_at_rest_has_no_velocity_arrays_in_the_generated_code():
    outputs = {"fluid": ["arho", "au", "av", "ap"], "wall": ["p", "rho"]}
    src_rest, plan_rest = rendered(all_wall_equations(False, False, "tait"), tank(False), outputs)
    src_move, plan_move = rendered(all_wall_equations(False, True, "tait"), tank(True), outputs)
    for prop in ("uw", "vw", "auw", "avw"):
        assert f"wall_{prop}" not in src_rest, prop
        assert prop not in plan_rest.allocation["wall"]
        assert f"wall_{prop}" in src_move, prop
        assert prop in plan_move.allocation["wall"]
    # the wall's own u, v are never read: its velocity is the prescribed one or the ghost one
    for plan in (plan_rest, plan_move):
        assert not {"u", "v", "w"} & plan.allocation["wall"]
    # 2D: no z components anywhere
    assert not re.search(r"\bwall_ww\b", src_move) and not re.search(r"\bfluid_w\b", src_move)
    assert "ww" not in plan_move.allocation["wall"] and "w" not in plan_move.allocation["fluid"]


def test_free_slip_reads_normals_and_no_slip_does_not():
    outputs = {"fluid": ["au", "av"], "wall": ["p"]}
    eqs = lambda slip: [Group([WallPressure("wall", ["fluid"]),
                               WallGhostVelocity("wall", ["fluid"], slip=slip, dim=2)]),
                        Group([WallViscosity("fluid", ["wall"], nu=0.1, dim=2)])]
    src_slip, plan_slip = rendered(eqs(True), tank(), outputs)
    src_noslip, plan_noslip = rendered(eqs(False), tank(), outputs)
    def ghost_args(plan):
        ep = [e for e in plan.eqplans if type(e.eq).__name__ == "WallGhostVelocity"][0]
        return set(ep.methods["post_loop"].args)
    assert "d_normal" in ghost_args(plan_slip) and "d_normal" not in ghost_args(plan_noslip)
    assert re.search(r"WallGhostVelocity_\d+_post_loop\([^)]*wall_normal", src_slip)
    assert not re.search(r"WallGhostVelocity_\d+_post_loop\([^)]*wall_normal", src_noslip)
    # nu = 0: the viscous wall term, and with it the ghost velocity, disappear
    src_inviscid, plan = rendered([Group([WallPressure("wall", ["fluid"]),
                                          WallGhostVelocity("wall", ["fluid"], dim=2)]),
                                   Group([WallViscosity("fluid", ["wall"], nu=0.0, dim=2)])],
                                  tank(), {"fluid": ["au"], "wall": ["p"]})
    assert "WallViscosity" not in src_inviscid and "WallGhostVelocity" not in src_inviscid
    assert not {"ug", "vg"} & plan.allocation["wall"]
