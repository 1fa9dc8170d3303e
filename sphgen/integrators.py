"""Integrator + IntegratorStep and the shipped families.

A stepper (``IntegratorStep``) holds per-particle stage methods in restricted Python,
compiled like equations::

    class KickDriftKickStep(IntegratorStep):
        def stage1(self, d_idx, d_u, d_au, dt):
            d_u[d_idx] += 0.5 * dt * d_au[d_idx]

An integrator sequences stages, equation evaluations and neighbour updates in plain
Python (``one_timestep``); the per-particle work is compiled.

Prescribed values are re-imposed after every stage: ``add_motion(array, f)`` sets what
``f(t, pa)`` returns ({property: values}) at the time the stage's positions stand for
(``position_time``: the fraction of dt each stage reaches), e.g. a moving piston or a
rotating wall; ``clamp(array, gids, u=0.0, ...)`` holds values of the particles with those
persistent ids fixed, e.g. a clamped base.  Particles are re-sorted in memory during a
run, so per-particle reference data a motion needs must be a property of the array
(it moves with its particle), and clamps name particles by ``gid``, not by index.
"""
import re

import numpy as np


class IntegratorStep:
    """Per-array stage methods ``stage1``, ``stage2``, ... (restricted Python)."""

    switches = ()

    def stage_methods(self):
        return sorted((m for m in dir(type(self)) if re.fullmatch(r"stage\d+", m)),
                      key=lambda m: int(m[5:]))


class Integrator:
    """Base class: ``Integrator(fluid=Step(), ...)``; subclasses write ``one_timestep``.

    ``n_evaluations`` is the number of equation sets the integrator asks for per step
    (a scheme may give one set, used for every evaluation, or exactly this many).
    """

    n_evaluations = 1
    position_time = {}     # stage -> fraction of dt its positions stand for (default 1)

    def __init__(self, **steppers):
        for name, st in steppers.items():
            if not isinstance(st, IntegratorStep):
                raise TypeError(f"stepper for '{name}' must be an IntegratorStep, got {st!r}")
        self.steppers = steppers
        self.scene = None
        self.nnps_updates = 0
        self.steps_taken = 0
        self.set_runs = {}  # equation set -> times run in this process (for the pair counts)
        self.motions = []      # (array, f(t, pa) -> {prop: values})
        self.clamps = []       # (array, gids, {prop: value})
        self.t_step, self.dt_step = 0.0, 0.0

    def add_motion(self, array, motion):
        """Prescribe properties of ``array`` in time: ``motion(t, pa) -> {prop: values}``."""
        self.motions.append((array, motion))

    def clamp(self, array, gids, **values):
        """Hold properties of the particles ``gids`` of ``array`` at fixed values (scalars,
        or arrays ordered like ``gids``) after every stage."""
        self.clamps.append((array, np.asarray(gids, dtype=np.int64), values))

    def impose(self, t):
        """Set the prescribed motions at time ``t`` and re-impose the clamps."""
        for array, motion in self.motions:
            pa = self.scene.by_name[array]
            for prop, value in motion(t, pa).items():
                pa.get(prop)[:] = value
        for array, gids, values in self.clamps:
            pa = self.scene.by_name[array]
            where = np.argsort(pa.gid)[np.searchsorted(pa.gid, gids, sorter=np.argsort(pa.gid))]
            for prop, value in values.items():
                pa.get(prop)[where] = value

    def advance(self, t, dt):
        """One step from t (what the solver calls): ``one_timestep`` with the step's times known."""
        self.t_step, self.dt_step = t, dt
        self.one_timestep(t, dt)
        self.steps_taken += 1

    def evaluated_sets(self):
        """The equation sets ``one_timestep`` and ``initial_accelerations`` can ever run, or
        ``None`` (every set); the scene generates nothing for the others."""
        return None

    def attach(self, scene):
        self.scene = scene
        n = len(scene.plan.group_plans)
        if n not in (1, self.n_evaluations):
            raise ValueError(f"{type(self).__name__} evaluates {self.n_evaluations} equation sets per step; "
                             f"the scheme gave {n}")

    # what one_timestep may call
    def stage(self, name, t, dt):
        self.scene.stage(name, t, dt)
        if self.motions or self.clamps:
            self.impose(self.t_step + self.position_time.get(name, 1.0) * self.dt_step)

    def compute_accelerations(self, index, t, dt):
        self.set_runs[index] = self.set_runs.get(index, 0) + 1
        self.scene.compute(index, t, dt)

    def update_nnps(self):
        self.nnps_updates += 1
        self.scene.update_nnps()

    def initial_accelerations(self, t, dt):
        """Evaluations needed before the first step (none by default)."""

    def restarted(self, step, t):
        """The solver loaded the state of ``step`` (time ``t``) from a restart file: an
        integrator that counts its steps (e.g. a start-up step) continues from there."""

    def one_timestep(self, t, dt):
        raise NotImplementedError


class KickDriftKick(Integrator):
    """Kick-drift-kick Verlet (Adepu & Ramachandran (2024) eqs. 54-60): two equation sets per step.

    stage1 kick (t^n -> half step), evaluation 0 at r^n, stage2 drift, neighbour
    update, evaluation 1 at r^{n+1}, stage3 kick.  Evaluation 1 also runs once before
    the first step so the first kick has accelerations.
    """

    n_evaluations = 2
    position_time = {"stage1": 0.0, "stage2": 1.0, "stage3": 1.0}

    def initial_accelerations(self, t, dt):
        self.compute_accelerations(1, t, dt)

    def one_timestep(self, t, dt):
        self.stage("stage1", t, dt)
        self.compute_accelerations(0, t + 0.5 * dt, dt)
        self.stage("stage2", t, dt)
        self.update_nnps()
        self.compute_accelerations(1, t + dt, dt)
        self.stage("stage3", t + dt, dt)


class PEC(Integrator):
    """Predict (half step), evaluate, correct (full step with midpoint rates)."""

    n_evaluations = 1
    position_time = {"stage1": 0.5, "stage2": 1.0}

    def one_timestep(self, t, dt):
        self.stage("stage1", t, dt)
        self.update_nnps()
        self.compute_accelerations(0, t + 0.5 * dt, dt)
        self.stage("stage2", t + dt, dt)


class EPEC(Integrator):
    """Evaluate, predict, evaluate, correct: two evaluations and two neighbour updates."""

    n_evaluations = 2
    position_time = {"stage1": 0.5, "stage2": 1.0}

    def one_timestep(self, t, dt):
        self.compute_accelerations(0, t, dt)
        self.stage("stage1", t, dt)
        self.update_nnps()
        self.compute_accelerations(1, t + 0.5 * dt, dt)
        self.stage("stage2", t + dt, dt)
        self.update_nnps()
