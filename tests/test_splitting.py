"""The kick-drift splittings of Kincl (2023), sec. 1.4 (sphgen/splitting.py), on a harmonic
oscillator a = -k x per particle (no pairs; the Python evaluator): each integrator's order,
its force evaluations per step, and the viscous Verlet's order in the dissipative term."""
import math

import numpy as np
import pytest

from sphgen.equation import Equation, Group
from sphgen.particles import ParticleArray
from sphgen.scene import Scene
from sphgen.splitting import INTEGRATORS, ORDERS, KickDriftStep, get_splitting


class Spring(Equation):
    """a = -k x (the conservative force)."""

    def __init__(self, dest, sources=None, k=1.0):
        super().__init__(dest, sources, k=k)

    def initialize(self, d_idx, d_x, d_au, d_av):
        d_au[d_idx] = -self.k * d_x[d_idx]
        d_av[d_idx] = 0.0


class Damping(Equation):
    """a_visc = -gamma v (the dissipative force of the viscous step)."""

    def __init__(self, dest, sources=None, gamma=0.0):
        super().__init__(dest, sources, gamma=gamma)

    def initialize(self, d_idx, d_u, d_au_visc, d_av_visc):
        d_au_visc[d_idx] = -self.gamma * d_u[d_idx]
        d_av_visc[d_idx] = 0.0


def oscillator(name, gamma=0.0, startup=False):
    """Three particles on springs; equation set 0 the spring, set 1 the damping (for the
    viscous Verlet, or as a start-up set with ``startup``)."""
    x0 = np.array([1.0, 0.5, -0.25])
    pa = ParticleArray("body", x=x0.copy(), y=np.zeros(3), u=np.zeros(3), v=np.zeros(3), h=np.ones(3),
                       m=np.ones(3))
    for p in ("au", "av", "au_visc", "av_visc"):
        pa.add_property(p)
    integ = get_splitting(name, body=KickDriftStep(2, viscous=gamma > 0))
    sets = [[Group([Spring("body")])], [Group([Damping("body", gamma=gamma)])]]
    if startup:
        integ.n_evaluations, integ.startup_sets = 2, (1,)
    sets = sets[:integ.n_evaluations]
    sc = Scene([pa], sets, steppers=integ.steppers, dim=2, backend="python")
    integ.attach(sc)
    return pa, integ, x0


def end_error(name, dt, tf=1.0, gamma=0.0):
    """Largest |x(tf) - exact| for k = 1, v(0) = 0 (damped: x'' + gamma x' + x = 0)."""
    pa, integ, x0 = oscillator(name, gamma)
    steps = int(round(tf / dt))
    integ.initial_accelerations(0.0, dt)
    t = 0.0
    for _ in range(steps):
        integ.one_timestep(t, dt)
        t += dt
    w = math.sqrt(1.0 - 0.25 * gamma * gamma)
    exact = x0 * math.exp(-0.5 * gamma * tf) * (math.cos(w * tf) + 0.5 * gamma / w * math.sin(w * tf))
    return np.abs(pa.x - exact[pa.gid]).max()        # the scene sorts particles in memory


@pytest.mark.parametrize("name", [n for n in INTEGRATORS if n != "viscous_verlet"])
def test_order_on_the_harmonic_oscillator(name):
    """Error at t = 1 falls as dt^p with p the integrator's order (within 0.25)."""
    e = [end_error(name, dt) for dt in (0.1, 0.05)]
    assert math.log2(e[0] / e[1]) == pytest.approx(ORDERS[name], abs=0.25), e


def test_viscous_verlet_is_second_order_without_and_first_order_with_dissipation():
    """Eq. 1.82: Verlet when the dissipative force is zero; order 1 in the dissipative term."""
    e = [end_error("viscous_verlet", dt) for dt in (0.1, 0.05)]
    assert math.log2(e[0] / e[1]) == pytest.approx(2.0, abs=0.25), e
    e = [end_error("viscous_verlet", dt, gamma=0.5) for dt in (0.02, 0.01)]
    assert math.log2(e[0] / e[1]) == pytest.approx(1.0, abs=0.25), e


@pytest.mark.parametrize("name, evaluations", [("symplectic_euler", 1), ("verlet", 1), ("ruth3", 3),
                                               ("yoshida4", 3), ("viscous_verlet", 2)])
def test_force_evaluations_per_step(name, evaluations):
    """A kick re-evaluates the forces only after a drift: Verlet once per step, Ruth and
    Yoshida three times, the viscous Verlet once plus its dissipative evaluation."""
    pa, integ, _ = oscillator(name, gamma=0.1 if name == "viscous_verlet" else 0.0)
    integ.initial_accelerations(0.0, 0.01)
    integ.one_timestep(0.0, 0.01)          # symplectic Euler and Ruth end on a drift: steady from step 2
    calls = []
    real = integ.compute_accelerations
    integ.compute_accelerations = lambda index, t, dt: (calls.append(index), real(index, t, dt))
    for k in range(1, 4):
        integ.one_timestep(0.01 * k, 0.01)
    assert len(calls) == 3 * evaluations, calls


def test_startup_sets_run_once_before_the_first_forces():
    """``startup_sets`` (e.g. SHTC's masses and density constants) run once, before the forces."""
    pa, integ, _ = oscillator("verlet", startup=True)
    calls = []
    real = integ.compute_accelerations
    integ.compute_accelerations = lambda index, t, dt: (calls.append(index), real(index, t, dt))
    integ.initial_accelerations(0.0, 0.01)
    integ.one_timestep(0.0, 0.01)
    assert calls == [1, 0, 0], calls


@pytest.mark.parametrize("name, sets", [("verlet", {0}), ("ruth3", {0}), ("viscous_verlet", {0, 1})])
def test_evaluated_sets_are_the_force_set_and_the_dissipative_set_if_the_step_dissipates(name, sets):
    assert get_splitting(name, body=KickDriftStep(2)).evaluated_sets() == sets


def test_a_set_the_integrator_never_evaluates_is_not_generated_and_cannot_be_run():
    """Verlet with the viscous Verlet's two sets: the damping set is dropped from the plan."""
    pa, integ, _ = oscillator("verlet")
    sets = [[Group([Spring("body")])], [Group([Damping("body", gamma=0.5)])]]
    sc = Scene([pa], sets, steppers=integ.steppers, dim=2, backend="python",
               evaluated=integ.evaluated_sets())
    assert sc.plan.dropped == {1}
    assert [type(ep.eq).__name__ for ep in sc.plan.eqplans] == ["Spring"]
    sc.compute(0, 0.0, 0.1)
    with pytest.raises(ValueError, match="equation set 1 was declared never evaluated"):
        sc.compute(1, 0.0, 0.1)
