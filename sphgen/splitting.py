"""Kick-drift splitting integrators of Kincl's thesis (2023), sec. 1.4, for any scheme.

A step is a sequence of three operations, each a fraction c of the step dt:

* ``kick(c dt)``: v += c dt a, with the accelerations a of the force set at the current
  positions (evaluated only if the positions moved since the last evaluation);
* ``drift(c dt)``: x += c dt v (the neighbour lists are rebuilt before the next evaluation);
* ``dissipate(c dt)``: v += c dt a_visc, with the dissipative set evaluated at the current
  positions and velocities (the viscous step of eq. 1.82).

The shipped sequences (``INTEGRATORS``, selected by name):

========================  ======================================================  =====
``symplectic_euler``      K(dt) D(dt) (eq. 1.77)                                  1
``verlet``                K(dt/2) D(dt) K(dt/2) (eq. 1.78; one force evaluation)  2
``viscous_verlet``        K(dt/2) D(dt/2) V(dt) D(dt/2) K(dt/2) (eq. 1.82)        see below
``ruth3``                 Ruth (1983), three kicks and drifts                     3
``yoshida4``              Yoshida (1990): Verlet at w1 dt, w0 dt, w1 dt           4
========================  ======================================================  =====

(last column: order).  The viscous step V of eq. 1.82 is one explicit Euler step of the
dissipative force over dt (the thesis prints it without the dt): the scheme is second order
without dissipation and first order in the dissipative term (docs/shtc.md).  The compositions
(Ruth, Yoshida) take a negative sub-step; they are for conservative (Hamiltonian) problems.

A scheme uses them with a stepper whose stage methods are the operations: ``stage1`` the kick
(v += dt a), ``stage2`` the drift (x += dt v), ``stage3`` the dissipative kick (v += dt
a_visc) -- :class:`KickDriftStep` for a state of positions and velocities -- and equation sets
``force_set`` (0) and, for ``viscous_verlet``, ``dissipative_set`` (1).  A scheme whose kick or
drift is more than one stage (e.g. a drift that also updates a deformation, SHTC-SPH) subclasses
:class:`Splitting` and overrides ``kick``/``drift``; the sequences then apply unchanged.
"""
from .integrators import Integrator, IntegratorStep


class KickDriftStep(IntegratorStep):
    """Kick v += dt a (stage1), drift x += dt v (stage2), dissipative kick v += dt a_visc
    (stage3, only with ``viscous``: accelerations ``au_visc``, ``av_visc``, ``aw_visc``)."""

    switches = ("dim", "viscous")

    def __init__(self, dim, viscous=False):
        self.dim, self.viscous = int(dim), int(viscous)

    def stage1(self, d_idx, d_u, d_v, d_w, d_au, d_av, d_aw, dt):
        d_u[d_idx] += dt * d_au[d_idx]
        if self.dim > 1:
            d_v[d_idx] += dt * d_av[d_idx]
        if self.dim > 2:
            d_w[d_idx] += dt * d_aw[d_idx]

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, dt):
        d_x[d_idx] += dt * d_u[d_idx]
        if self.dim > 1:
            d_y[d_idx] += dt * d_v[d_idx]
        if self.dim > 2:
            d_z[d_idx] += dt * d_w[d_idx]

    def stage3(self, d_idx, d_u, d_v, d_w, d_au_visc, d_av_visc, d_aw_visc, dt):
        if self.viscous:
            d_u[d_idx] += dt * d_au_visc[d_idx]
            if self.dim > 1:
                d_v[d_idx] += dt * d_av_visc[d_idx]
            if self.dim > 2:
                d_w[d_idx] += dt * d_aw_visc[d_idx]


class Splitting(Integrator):
    """A step as a sequence of kicks, drifts and dissipative steps (``sequence``: (operation,
    fraction of dt) pairs; the constructor's ``sequence`` overrides the class's).

    The force set is evaluated before a kick only when the positions changed since its last
    evaluation, so Verlet evaluates it once per step (the last kick's forces start the next
    step) and the run starts with one evaluation (``initial_accelerations``).
    """

    sequence = ()
    n_evaluations = 1
    force_set = 0
    dissipative_set = 1
    startup_sets = ()       # equation sets run once, before the first force evaluation
    kick_stage, drift_stage, dissipate_stage = "stage1", "stage2", "stage3"

    def __init__(self, sequence=None, **steppers):
        super().__init__(**steppers)
        if sequence is not None:
            self.sequence = tuple(sequence)
        ops = {op for op, _ in self.sequence}
        if not ops or not ops <= {"kick", "drift", "dissipate"}:
            raise ValueError(f"{type(self).__name__}: a sequence of kick, drift and dissipate steps, "
                             f"got {self.sequence!r}")
        self._t, self._dt = 0.0, 0.0
        self._forces_current = False    # the force set was evaluated at the current positions
        self._lists_current = True      # the neighbour lists match the current positions

    # ------------------------------------------------------------ building blocks
    def run_stage(self, name, dt_stage, t_positions):
        """Stage ``name`` with step ``dt_stage``; prescribed motions and clamps re-imposed at
        ``t_positions``, the time the positions stand for after it."""
        self.scene.stage(name, t_positions, dt_stage)
        if self.motions or self.clamps:
            self.impose(t_positions)

    def positions_moved(self):
        """After a drift: forces and neighbour lists are out of date."""
        self._forces_current = False
        self._lists_current = False

    def evaluate(self, index):
        """Equation set ``index`` at the current time, after a neighbour update if positions moved."""
        if not self._lists_current:
            self.update_nnps()
            self._lists_current = True
        self.compute_accelerations(index, self._t, self._dt)

    def forces(self):
        """The force set at the current positions, unless already evaluated there."""
        if not self._forces_current:
            self.evaluate(self.force_set)
            self._forces_current = True

    # ------------------------------------------------------------ the operations
    def kick(self, tau):
        self.forces()
        self.run_stage(self.kick_stage, tau, self._t)

    def drift(self, tau):
        self._t += tau
        self.run_stage(self.drift_stage, tau, self._t)
        self.positions_moved()

    def dissipate(self, tau):
        self.evaluate(self.dissipative_set)
        self.run_stage(self.dissipate_stage, tau, self._t)

    # ------------------------------------------------------------ Integrator
    def evaluated_sets(self):
        """The force set, the start-up sets and, if the sequence dissipates, the dissipative set."""
        dissipates = any(op == "dissipate" for op, _ in self.sequence)
        return {self.force_set, *self.startup_sets} | ({self.dissipative_set} if dissipates else set())

    def initial_accelerations(self, t, dt):
        self._t, self._dt = t, dt
        for index in self.startup_sets:
            self.compute_accelerations(index, t, dt)
        self.forces()

    def restarted(self, step, t):
        """A restart file's accelerations are those of the forces at its positions when the
        sequence ends with a kick (Verlet, compositions); otherwise they are re-evaluated.
        The solver rebuilds the neighbour lists after loading."""
        self._forces_current = self.sequence[-1][0] == "kick"
        self._lists_current = True

    def one_timestep(self, t, dt):
        self._t, self._dt = t, dt
        for op, c in self.sequence:
            getattr(self, op)(c * dt)
        self._t = t + dt      # the drifts' fractions sum to 1; no round-off in the step's time


def composition(weights, base=(("kick", 0.5), ("drift", 1.0), ("kick", 0.5))):
    """The sequence of ``base`` (a symmetric step) taken at weights w_i dt in turn, consecutive
    kicks merged (Yoshida (1990): a symmetric composition of a second-order step)."""
    seq = []
    for w in weights:
        for op, c in base:
            if seq and op == "kick" and seq[-1][0] == "kick":
                seq[-1] = ("kick", seq[-1][1] + w * c)
            else:
                seq.append((op, w * c))
    return tuple(seq)


_CBRT2 = 2.0 ** (1.0 / 3.0)
YOSHIDA4_WEIGHTS = (1.0 / (2.0 - _CBRT2), -_CBRT2 / (2.0 - _CBRT2), 1.0 / (2.0 - _CBRT2))
"""w1, w0, w1 of Yoshida (1990), eq. 5.19: fourth order from the second-order Verlet step."""

RUTH3 = (("kick", 7.0 / 24.0), ("drift", 2.0 / 3.0), ("kick", 3.0 / 4.0), ("drift", -2.0 / 3.0),
         ("kick", -1.0 / 24.0), ("drift", 1.0))
"""Ruth (1983), the third-order canonical integrator (kick, drift) x 3."""


class SymplecticEuler(Splitting):
    """Symplectic Euler, Kincl (2023) eq. 1.77: v += dt a(x), then x += dt v (order 1)."""

    sequence = (("kick", 1.0), ("drift", 1.0))


class Verlet(Splitting):
    """Velocity Verlet / leap-frog, Kincl (2023) eq. 1.78: kick dt/2, drift dt, kick dt/2 (order 2,
    time-reversible, one force evaluation and one neighbour update per step)."""

    sequence = (("kick", 0.5), ("drift", 1.0), ("kick", 0.5))


class ViscousVerlet(Splitting):
    """Viscous Verlet, Kincl (2023) eq. 1.82 (with its missing dt): kick dt/2, drift dt/2,
    v += dt a_visc at the half step, drift dt/2, kick dt/2; two neighbour updates per step."""

    sequence = (("kick", 0.5), ("drift", 0.5), ("dissipate", 1.0), ("drift", 0.5), ("kick", 0.5))
    n_evaluations = 2


class Ruth3(Splitting):
    """Ruth (1983) third-order symplectic integrator (cited by Kincl (2023), sec. 1.4)."""

    sequence = RUTH3


class Yoshida4(Splitting):
    """Yoshida (1990) fourth-order composition of Verlet (cited by Kincl (2023), sec. 1.4): three
    Verlet steps of w1 dt, w0 dt, w1 dt (w0 < 0); three force evaluations per step."""

    sequence = composition(YOSHIDA4_WEIGHTS)


INTEGRATORS = {"symplectic_euler": SymplecticEuler, "verlet": Verlet, "viscous_verlet": ViscousVerlet,
               "ruth3": Ruth3, "yoshida4": Yoshida4}
"""The integrators of Kincl (2023), sec. 1.4, by name (``--integrator NAME``)."""

ORDERS = {"symplectic_euler": 1, "verlet": 2, "viscous_verlet": 2, "ruth3": 3, "yoshida4": 4}
"""Order of each for a conservative problem (viscous_verlet: 1 in its dissipative term)."""


def get_splitting(name, **steppers):
    """Integrator ``name`` of ``INTEGRATORS`` with these steppers."""
    try:
        cls = INTEGRATORS[name]
    except KeyError:
        raise ValueError(f"unknown integrator {name!r}; known: {', '.join(INTEGRATORS)}") from None
    return cls(**steppers)
