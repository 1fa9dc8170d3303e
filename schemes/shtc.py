"""SHTC-SPH: one scheme for elastic solids and viscous fluids (Kincl, Peshkov, Pavelka & Klika
(2023), "Unified description of fluids and solids in Smoothed Particle Hydrodynamics").

State per particle: position, velocity and the distortion A (3x3, stride 9, also in 2D).
Density by kernel summation with a constant that makes rho = rho0 at t = 0 (eq. 4); the
renormalised velocity gradient L = (sum m v_ab (x) grad w) H^-1 (eq. 7); the force
sum_b m_b (T_a + T_b) grad w_ab with T = -p/rho^2 I + A^T eps_A H^-1 (eqs. 10-12, 16, 18);
the tensile penalty of eqs. 19-21 (``cp``); strain relaxation with time tau (eq. 24c).

Time step (eqs. 23, 25), :class:`SHTCIntegrator`:

#. kick v += dt/2 a (stage1); drift x += dt/2 v (stage2); neighbour update;
#. evaluation 0 at the half step: H and L (eq. 7);
#. stage3: A* = A (I - dt/2 L)(I + dt/2 L)^-1 (Cayley), RK4 relaxation of A* over dt if
   tau < infinity (eq. 25d), drift x += dt/2 v; neighbour update;
#. evaluation 1: rho, lambda, H, then p and T; then the force;
#. kick v += dt/2 a (stage1 again).

``integrator`` names another kick-drift sequence of :mod:`sphgen.splitting` (symplectic Euler,
Ruth's third order, Yoshida's fourth order composition) with this drift and kick.

Evaluation 2 runs once before the first step: the masses (``masses='kernel'``: m = rho0 /
sum_b w_ab, the paper's sec. 3.1; ``'lattice'``: the masses given), then the constants C_rho
and C_lambda.  Walls (dummy particles) carry their own A, rho, lambda and T and run the
same equations (they enter the bodies' sums and forces through T_b and lambda_b); their
positions and velocities are prescribed (``Integrator.add_motion``), never integrated, and
their A is updated from their own L.  A lid's prescribed velocity therefore enters only L.
With ``wall_velocity='extrapolated'`` the walls show, in L only, the ghost velocity 2 v_w minus
the Shepard mean of the bodies' velocities around them (Adami, Hu & Adams 2012, eqs. 22-23),
which removes most of the dummy walls' slip (docs/shtc.md).
"""
import math

import numpy as np

from sphgen.equation import Group, helper
from sphgen.errors import InputError
from sphgen.integrators import IntegratorStep
from sphgen.splitting import INTEGRATORS, Splitting, Verlet
from sphgen.kernels import get_kernel
from sphgen.scheme import Bound, Scheme

from ..equations.shtc_density import DensityConstant, KernelVolumeMass, SummationDensityWithConstant
from ..equations.shtc_distortion import cayley_update
from ..equations.shtc_penalty import PenaltyLambda, PenaltyLambdaConstant, TensilePenaltyForce
from ..equations.shtc_relaxation import relax_rk4
from ..equations.shtc_stress import MODELS, SHTCMomentum, SHTCStress
from ..equations.shtc_velocity_gradient import (BodyGradientVelocity, GhostVelocityGradient, KernelMoment,
                                                 RenormalisedVelocityGradient, WallGradientVelocity)
from sphgen.equation import declare

WALL_VELOCITIES = ("prescribed", "extrapolated")
"""What a wall particle's velocity is in L: its own (the paper) or the bodies' extrapolated."""

RK4_REAL_STABILITY = 2.785293563405282
"""|z| where classical RK4's stability region meets the negative real axis."""

RELAXATION_DT_LIMIT = RK4_REAL_STABILITY / 6.0
"""dt/tau bound of the explicit RK4 relaxation: the stiffest rate at A = I is 6/tau (0.4642)."""

def rk4_factor(z):
    """Classical RK4's amplification 1 + z + z^2/2 + z^3/6 + z^4/24 of dy/dt = (z/dt) y."""
    return 1.0 + z + z * z / 2.0 + z ** 3 / 6.0 + z ** 4 / 24.0


def viscosity_factor(dt_over_tau):
    """nu_effective / nu of the step in steady simple shear, linearised about A = I.

    Each step shears A by dt L (Cayley) and then relaxes it by the RK4 factor R = R(-6 dt/tau);
    the stress is read after the relaxation, so the steady strain is R dt L/(1 - R) instead of
    tau L/6: nu_eff/nu = 6 (dt/tau) R/(1 - R).  0.86 at dt/tau = 0.05, 0.73 at 0.1 (the
    paper's cavity), 1 at 1/3, 3.0 at 0.4 (derived here, not in the papers; docs/shtc.md).
    """
    r = rk4_factor(-6.0 * dt_over_tau)
    return 6.0 * dt_over_tau * r / (1.0 - r)


SHTC_INTEGRATORS = tuple(n for n in INTEGRATORS if n != "viscous_verlet")
"""The kick-drift sequences of sphgen.splitting the scheme takes (``integrator``)."""

THETA_DETPOW = 5.0 / 3.0
"""theta = tau cs^2/3 |det A|^(-5/3) (paper footnote 1; thesis eq. 2.11)."""


@helper
def add_scaled(i=0, dim=3, c=0.0, x=[0.0], y=[0.0], z=[0.0], u=[0.0], v=[0.0], w=[0.0]):
    """(x, y, z)_i += c (u, v, w)_i on the first ``dim`` components (the kicks and drifts of
    Kincl et al. (2023), eqs. 25a, b, e, f)."""
    x[i] += c * u[i]
    if dim > 1:
        y[i] += c * v[i]
    if dim > 2:
        z[i] += c * w[i]


class SHTCStep(IntegratorStep):
    """Per-particle stages of the SHTC-SPH step (Kincl et al. (2023), eqs. 25a-f).

    ``move`` = 0 for walls: only A is updated (stage3), positions and velocities are
    prescribed.  ``rate`` = 3/tau (0 for tau = infinity removes the relaxation from the code),
    ``detpow`` the power of |det A| in 1/theta (0: the paper's choice).
    """

    switches = ("dim", "model", "rate", "detpow", "move")

    def __init__(self, dim, model=0, rate=0.0, detpow=0.0, move=True):
        self.dim, self.model, self.move = int(dim), int(model), int(move)
        self.rate, self.detpow = float(rate), float(detpow)

    def stage1(self, d_idx, d_u, d_v, d_w, d_au, d_av, d_aw, dt):
        """Kick v += dt/2 a (eqs. 25a, f)."""
        if self.move:
            add_scaled(d_idx, self.dim, 0.5 * dt, d_u, d_v, d_w, d_au, d_av, d_aw)

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, dt):
        """Drift x += dt/2 v (eq. 25b)."""
        if self.move:
            add_scaled(d_idx, self.dim, 0.5 * dt, d_x, d_y, d_z, d_u, d_v, d_w)

    def stage3(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_A, d_L, dt):
        """A by the Cayley transform (eq. 25c), RK4 relaxation (eq. 25d); drift (eq. 25e)."""
        a = declare("matrix(9)")
        l = declare("matrix(9)")
        b = declare("matrix(9)")
        for i in range(9):
            a[i] = d_A[9 * d_idx + i]
            l[i] = d_L[9 * d_idx + i]
        cayley_update(a, l, dt, b)
        if self.rate != 0.0:
            relax_rk4(b, dt, self.rate, self.model, self.detpow)
        for i in range(9):
            d_A[9 * d_idx + i] = b[i]
        if self.move:
            add_scaled(d_idx, self.dim, 0.5 * dt, d_x, d_y, d_z, d_u, d_v, d_w)


class SHTCIntegrator(Splitting):
    """Verlet for (x, v), the mid-point (Cayley) rule for A and RK4 relaxation (Kincl et al.
    (2023), eqs. 23 and 25), with two neighbour-list builds per step as in the paper.

    A splitting (:mod:`sphgen.splitting`) whose drift over tau is stage2 (x += tau/2 v),
    evaluation 0 (L at the half drift), stage3 (A over tau, x += tau/2 v) and whose kick over
    tau is stage1 with 2 tau; ``sequence`` (default: Verlet, the paper's eq. 25) may be any of
    ``sphgen.splitting.INTEGRATORS`` but the viscous Verlet (the relaxation is already the
    dissipative step between the half drifts).  Equation sets: 0 = L at the half drift, 1 =
    state and force, 2 = the start-up (masses, C_rho, C_lambda), run once before evaluation 1
    at t = 0.
    """

    n_evaluations = 3
    force_set = 1
    sequence = Verlet.sequence
    startup_sets = (2,)

    def evaluated_sets(self):
        """Every drift evaluates set 0 (L at the half drift)."""
        return super().evaluated_sets() | {0}

    def kick(self, tau):
        self.forces()
        self.run_stage("stage1", 2.0 * tau, self._t)

    def drift(self, tau):
        t0 = self._t
        self.run_stage("stage2", tau, t0 + 0.5 * tau)
        self.positions_moved()
        self._t = t0 + 0.5 * tau
        self.evaluate(0)
        self._t = t0 + tau
        self.run_stage("stage3", tau, self._t)
        self.positions_moved()


def identity_tensors(n):
    """n identity 3x3 tensors, flat (the initial distortion)."""
    return np.tile(np.eye(3).ravel(), n)


class SHTCScheme(Scheme):
    """SHTC-SPH of Kincl, Peshkov, Pavelka & Klika (2023) for solids and fluids.

    ``bodies``: arrays integrated in time (solid or fluid); ``walls``: dummy-particle arrays
    with prescribed motion (``moving_walls`` among them carry velocities: lids, rotating
    walls).  Material: ``rho0``, bulk sound speed ``c0``, shear sound speed ``cs``, strain
    relaxation time ``tau`` (``math.inf``: elastic solid; a Newtonian fluid of kinematic
    viscosity nu has tau = 6 nu/cs^2, eq. 29), ``model`` 'dprz' (eq. 15) or 'neo-hookean'
    (eq. 17), tensile penalty velocity ``cp`` (0 removes it).  Numerics: smoothing length
    ``h`` (the paper uses 1.5 dr with support 2h), particle spacing ``dr``, ``cfl`` of the
    time step dt = cfl dr / sqrt(c0^2 + 4/3 cs^2) (eq. 26, cfl = 0.05), ``masses`` 'kernel'
    (sec. 3.1) or 'lattice' (the masses of the arrays as given), ``theta_det``: relaxation
    with the |det A|^(5/3) factor of the thesis' eq. 2.11 (the paper omits it).  ``motions``:
    {moving wall: f(t, pa) -> {property: values}} prescribed at every stage's time (e.g. a
    rotating ring: positions and velocities), see ``Integrator.add_motion``.
    ``wall_velocity``: the velocity a wall particle shows in L: 'prescribed' (the paper's
    dummy walls and lid) or 'extrapolated' (2 v_w minus the Shepard mean of the bodies'
    velocities around it, Adami, Hu & Adams (2012), eqs. 22-23; see docs/shtc.md).
    """

    def __init__(self, bodies, dim, rho0, c0, cs, h, dr, tau=math.inf, model="dprz", cp=0.0,
                 walls=(), moving_walls=(), cfl=0.05, masses="kernel", theta_det=False,
                 kernel="wendland", motions=None, wall_velocity="prescribed", integrator="verlet"):
        if integrator not in SHTC_INTEGRATORS:
            raise InputError(f"SHTCScheme: integrator must be one of {', '.join(SHTC_INTEGRATORS)}, got "
                             f"{integrator!r} (no viscous_verlet: the relaxation is already the dissipative "
                             "step between the half drifts of eq. 25)")
        self.integrator = integrator
        if wall_velocity not in WALL_VELOCITIES:
            raise InputError(f"SHTCScheme: wall_velocity must be one of {', '.join(WALL_VELOCITIES)}, "
                             f"got {wall_velocity!r}")
        self.wall_velocity = wall_velocity
        self.bodies, self.walls, self.moving_walls = list(bodies), list(walls), list(moving_walls)
        self.motions = dict(motions or {})
        if any(w not in self.moving_walls for w in self.motions):
            raise InputError(f"SHTCScheme: motions {sorted(self.motions)} must be among moving_walls {self.moving_walls}")
        if not self.bodies:
            raise InputError("SHTCScheme: needs at least one body array")
        if any(w not in self.walls for w in self.moving_walls):
            raise InputError(f"SHTCScheme: moving_walls {self.moving_walls} must be among walls {self.walls}")
        for name, v in (("rho0", rho0), ("c0", c0), ("h", h), ("dr", dr), ("cfl", cfl)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"SHTCScheme: {name}={v!r} must be a positive finite number")
        for name, v in (("cs", cs), ("cp", cp)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v >= 0):
                raise InputError(f"SHTCScheme: {name}={v!r} must be a non-negative finite number")
        if not (tau > 0):
            raise InputError(f"SHTCScheme: tau={tau!r} must be > 0 (math.inf for an elastic solid)")
        if model not in MODELS:
            raise InputError(f"SHTCScheme: model must be one of {', '.join(MODELS)}, got {model!r}")
        if masses not in ("kernel", "lattice"):
            raise InputError(f"SHTCScheme: masses must be 'kernel' or 'lattice', got {masses!r}")
        if cs == 0 and math.isfinite(tau):
            raise InputError("SHTCScheme: relaxation (finite tau) needs a shear sound speed cs > 0")
        self.dim = dim
        self.rho0, self.c0, self.cs, self.h, self.dr = float(rho0), float(c0), float(cs), float(h), float(dr)
        self.tau, self.model, self.cp, self.cfl = float(tau), model, float(cp), float(cfl)
        self.masses, self.theta_det = masses, bool(theta_det)
        self.kernel = get_kernel(kernel, dim)
        self.speed_limit = self.wave_speed()
        skip = {1: ("y", "z", "v", "w"), 2: ("z", "w"), 3: ()}[dim]
        self.output_props = tuple(p for p in ("x", "y", "z", "u", "v", "w", "p", "rho", "m", "h", "A", "lam")
                                  if p not in skip)
        if self.cp == 0:
            self.output_props = tuple(p for p in self.output_props if p != "lam")

    # ---------------------------------------------------------------- parameters
    def wave_speed(self):
        """The longitudinal (P-wave) speed sqrt(c0^2 + 4/3 cs^2) of the linearised material."""
        return math.sqrt(self.c0 ** 2 + 4.0 / 3.0 * self.cs ** 2)

    @property
    def relaxation_rate(self):
        """3/tau (0 for an elastic solid)."""
        return 0.0 if math.isinf(self.tau) else 3.0 / self.tau

    def get_timestep(self):
        """dt = cfl dr / sqrt(c0^2 + 4/3 cs^2) (Kincl et al. (2023), eq. 26 with cfl = 0.05)."""
        return self.cfl * self.dr / self.wave_speed()

    def stability_bounds(self, dt):
        """The explicit RK4 relaxation: dt <= 2.785 tau/6 = 0.464 tau (stiffest rate 6/tau at A = I)."""
        if math.isinf(self.tau):
            return []
        return [Bound("--dt", dt, RELAXATION_DT_LIMIT * self.tau, True,
                      "dt <= 2.785 tau/6 = 0.464 tau: RK4 on the relaxation rate 6/tau of Kincl et al. "
                      "(2023) eq. 24c")]

    def density_bounds(self):
        """(0.2, 5) rho0: summation density with C_rho stays near rho0 in every case of the paper."""
        return {a: (0.2 * self.rho0, 5.0 * self.rho0) for a in self.bodies}

    # ---------------------------------------------------------------- particles
    def setup_properties(self, arrays):
        for pa in arrays:
            if pa.name not in self.bodies + self.walls:
                continue
            for p in ("p", "crho", "lam", "clam", "au", "av", "aw", "hflag"):
                if not pa.has(p):
                    pa.add_property(p)
            if self.wall_velocity == "extrapolated" and self.walls:
                for p in ("ug", "vg", "wg", "wij"):
                    if not pa.has(p):
                        pa.add_property(p)
            for p in ("H", "L", "T"):
                pa.add_property(p, stride=9)
            if not pa.has("A") or "A" not in pa.data:
                pa.add_property("A", stride=9, data=identity_tensors(pa.n))
            # unused coordinates are zero (the kicks and drifts pass all three, see add_scaled);
            # a wall at rest has v = 0 in L, a moving wall's motion sets its velocity
            for c in ("x", "y", "z", "u", "v", "w"):
                if c not in pa.data:
                    pa.add_property(c, default=0.0)

    # ---------------------------------------------------------------- equations
    def get_equations(self):
        every = self.bodies + self.walls
        model = MODELS[self.model]
        if self.wall_velocity == "extrapolated" and self.walls:
            gradient = [Group([BodyGradientVelocity(b) for b in self.bodies]
                              + [WallGradientVelocity(w, self.bodies) for w in self.walls]),
                        Group([GhostVelocityGradient(d, every, dim=self.dim) for d in every])]
        else:
            gradient = [Group([RenormalisedVelocityGradient(d, every, dim=self.dim) for d in every])]
        state = []
        for d in every:
            state += [SummationDensityWithConstant(d, every),
                      PenaltyLambda(d, every, cp=self.cp),
                      KernelMoment(d, every),
                      SHTCStress(d, dim=self.dim, model=model, rho0=self.rho0, c0=self.c0, cs=self.cs)]
        force = []
        for d in self.bodies:
            force += [SHTCMomentum(d, every), TensilePenaltyForce(d, every, cp=self.cp, rho0=self.rho0)]
        start = []
        if self.masses == "kernel":
            start.append(Group([KernelVolumeMass(d, every, rho0=self.rho0) for d in every]))
        constants = [DensityConstant(d, every, rho0=self.rho0) for d in every]
        constants += [PenaltyLambdaConstant(d, every, cp=self.cp) for d in every]
        start.append(Group(constants))
        return [gradient, [Group(state), Group(force)], start]

    def get_integrator(self):
        model = MODELS[self.model]
        detpow = THETA_DETPOW if self.theta_det else 0.0
        steps = {b: SHTCStep(self.dim, model, self.relaxation_rate, detpow, move=True) for b in self.bodies}
        steps.update({w: SHTCStep(self.dim, model, self.relaxation_rate, detpow, move=False)
                      for w in self.walls})
        integrator = SHTCIntegrator(INTEGRATORS[self.integrator].sequence, **steps)
        for array, motion in self.motions.items():
            integrator.add_motion(array, motion)
        return integrator

    def output_properties(self, pa):
        props = super().output_properties(pa)
        return props + [p for p in ("hflag",) if pa.has(p)]

    # ---------------------------------------------------------------- diagnostics
    def shear_energy_density(self, A):
        """eps_s / cs^2 per particle from flat (n*9) A, numpy (eqs. 15, 17)."""
        A = np.asarray(A).reshape(-1, 3, 3)
        if self.model == "dprz":
            G = np.einsum("nki,nkj->nij", A, A)
            dev = G - np.trace(G, axis1=1, axis2=2)[:, None, None] / 3.0 * np.eye(3)
            return 0.25 * np.einsum("nij,nij->n", dev, dev)
        Ai = np.linalg.inv(A)
        return 0.5 * (np.einsum("nij,nij->n", Ai, Ai) - 3.0 + 2.0 * np.log(np.linalg.det(A)))

    def energies(self, arrays, include_walls=False):
        """{kinetic, bulk, shear, penalty, total} over the bodies (and the walls if asked):
        sum m v^2/2, sum m c0^2/2 (rho0/rho - 1)^2 (eq. 13), sum m eps_s (eqs. 15, 17),
        1/2 sum m cp^2 (lambda/rho0)^2 (eq. 19)."""
        names = self.bodies + (self.walls if include_walls else [])
        e = {"kinetic": 0.0, "bulk": 0.0, "shear": 0.0, "penalty": 0.0}
        for pa in arrays:
            if pa.name not in names or pa.n == 0:
                continue
            m = pa.m
            if "u" in pa.data:
                e["kinetic"] += 0.5 * float(np.sum(m * sum(pa.data[c] ** 2 for c in "uvw"[:self.dim])))
            e["bulk"] += float(np.sum(m * 0.5 * self.c0 ** 2 * (self.rho0 / pa.rho - 1.0) ** 2))
            e["shear"] += float(np.sum(m * self.cs ** 2 * self.shear_energy_density(pa.A)))
            if self.cp > 0 and "lam" in pa.data:
                e["penalty"] += float(np.sum(0.5 * m * self.cp ** 2 * (pa.lam / self.rho0) ** 2))
        e["total"] = e["kinetic"] + e["bulk"] + e["shear"] + e["penalty"]
        return e

    def singular_moments(self, arrays):
        """Particles whose H was singular (regularised) in the last evaluation."""
        return int(sum(np.count_nonzero(pa.hflag) for pa in arrays
                       if pa.name in self.bodies + self.walls and "hflag" in pa.data))
