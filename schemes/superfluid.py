"""Hamiltonian two-fluid SPH of helium-4 (Kincl 2023, thesis ch. 3): the scheme and its integrator.

Equations: :mod:`sphgen.equations.superfluid` (reversible eq. 3.34 with zero-order
operators and summation density with its constant, eq. 1.14; irreversible eqs. 3.38-3.39);
the linear energy model: :mod:`sphgen.equations.superfluid_energy`.

Time integration, the Verlet-type scheme of sec. 3.4 (:class:`SuperfluidVerlet`):

0. (first step only) rates of v and v_s;
1. kick v, v_s by dt/2;
2. drift x by dt/2;
3. rho (neighbour lists rebuilt);
4. rate of s;
5. s by dt;
6. drift x by dt/2;
7. rho (rebuilt);
8. rates of v and v_s;
9. kick v, v_s by dt/2.

Rates use the most recent values.  Solid particles (``ptype`` ADIABATIC or COOLER) are
never kicked: they keep v = v_s = 0, so they do not move, and v_n = v_ns = 0 on them;
COOLER particles also keep their entropy (s = s0 gives T = T0).

Mirrored dummy particles (``mirror_walls=True``): a COOLER particle (never integrated)
with an integer property ``mirror`` >= 0 is a dummy that becomes, before every neighbour
update and every evaluation of the rates, the mirror image of the fluid particle whose
``gid`` is ``mirror`` across one or two axis-aligned walls: along each axis its position
is ms x + mo and its v and v_s components are ms times the partner's (``msx, msy, msz`` =
-1 across a wall normal to that axis, ``mox`` = twice the wall's coordinate), and it takes
the partner's s.  So T is even and the normal components of v, v_s, v_n, J odd across the
wall: no heat and no normal flow cross it (eq. 3.45).  With enough layers (the dummies
within the support of the fluid must have full supports) the fluid evolves exactly as
one cell of the mirror-symmetric periodic extension, so sum m s and the energy of the
fluid are conserved as in a periodic box.
"""
import numpy as np

from sphgen.equation import Group
from sphgen.errors import InputError
from sphgen.integrators import Integrator, IntegratorStep
from sphgen.kernels import get_kernel
from sphgen.scheme import Bound, Scheme

from ..equations.basic import SummationDensityWithConstant
from ..equations.superfluid import (ADIABATIC, COOLER, FLUID, CounterflowCoupling, CounterflowStress,
                                    EntropyFlux, EntropyProduction, NormalViscosity, SuperfluidGravity,
                                    SuperfluidPressure, SuperfluidState, ThermalNormalisation,
                                    Thermomechanical)
from ..equations.superfluid_energy import HELIUM_1_9K

STATE_PROPS = ("s", "us", "vs", "ws", "rhon", "uns", "vns", "wns", "un", "vn", "wn", "p", "T",
               "jx", "jy", "jz", "sdot", "zeta", "au", "av", "aw", "aus", "avs", "aws", "crho",
               "ustart", "vstart", "wstart", "usstart", "vsstart", "wsstart", "sstart", "snew", "lam")
INPUT_PROPS = ("s", "u", "v", "w", "us", "vs", "ws", "crho")   # given, or at rest at s0 with C = 0


class SuperfluidStep(IntegratorStep):
    """Per-particle stages of the Verlet-type scheme of Kincl (2023), sec. 3.4."""

    switches = ("dim",)

    def __init__(self, dim=2):
        self.dim = dim

    def stage1(self, d_idx, d_ptype, d_u, d_v, d_w, d_us, d_vs, d_ws, d_au, d_av, d_aw, d_aus, d_avs,
               d_aws, dt):
        """Kick v and v_s by dt/2 (steps 1 and 9); solid particles keep v = v_s = 0."""
        if d_ptype[d_idx] == 0:
            d_u[d_idx] += 0.5 * dt * d_au[d_idx]
            d_v[d_idx] += 0.5 * dt * d_av[d_idx]
            d_us[d_idx] += 0.5 * dt * d_aus[d_idx]
            d_vs[d_idx] += 0.5 * dt * d_avs[d_idx]
            if self.dim > 2:
                d_w[d_idx] += 0.5 * dt * d_aw[d_idx]
                d_ws[d_idx] += 0.5 * dt * d_aws[d_idx]

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, dt):
        """Drift x by dt/2 with v (steps 2 and 6)."""
        d_x[d_idx] += 0.5 * dt * d_u[d_idx]
        d_y[d_idx] += 0.5 * dt * d_v[d_idx]
        if self.dim > 2:
            d_z[d_idx] += 0.5 * dt * d_w[d_idx]

    def stage3(self, d_idx, d_ptype, d_s, d_sdot, dt):
        """s by dt (step 5); COOLER particles keep theirs."""
        if d_ptype[d_idx] != 2:
            d_s[d_idx] += dt * d_sdot[d_idx]

    # the symmetric (exactly reversible) variant: implicit first kick, implicit-midpoint s
    def stage4(self, d_idx, d_u, d_v, d_w, d_us, d_vs, d_ws, d_s, d_ustart, d_vstart, d_wstart,
               d_usstart, d_vsstart, d_wsstart, d_sstart):
        """Keep v^n, v_s^n and s^n, the start of the fixed-point iterations."""
        d_ustart[d_idx] = d_u[d_idx]
        d_vstart[d_idx] = d_v[d_idx]
        d_usstart[d_idx] = d_us[d_idx]
        d_vsstart[d_idx] = d_vs[d_idx]
        d_sstart[d_idx] = d_s[d_idx]
        if self.dim > 2:
            d_wstart[d_idx] = d_w[d_idx]
            d_wsstart[d_idx] = d_ws[d_idx]

    def stage5(self, d_idx, d_ptype, d_u, d_v, d_w, d_us, d_vs, d_ws, d_ustart, d_vstart, d_wstart,
               d_usstart, d_vsstart, d_wsstart, d_au, d_av, d_aw, d_aus, d_avs, d_aws, dt):
        """One iteration of the implicit half kick v^{n+1/2} = v^n + dt/2 F(x^n, s^n, v^{n+1/2})."""
        if d_ptype[d_idx] == 0:
            d_u[d_idx] = d_ustart[d_idx] + 0.5 * dt * d_au[d_idx]
            d_v[d_idx] = d_vstart[d_idx] + 0.5 * dt * d_av[d_idx]
            d_us[d_idx] = d_usstart[d_idx] + 0.5 * dt * d_aus[d_idx]
            d_vs[d_idx] = d_vsstart[d_idx] + 0.5 * dt * d_avs[d_idx]
            if self.dim > 2:
                d_w[d_idx] = d_wstart[d_idx] + 0.5 * dt * d_aw[d_idx]
                d_ws[d_idx] = d_wsstart[d_idx] + 0.5 * dt * d_aws[d_idx]

    def stage6(self, d_idx, d_ptype, d_s, d_sstart, d_snew, d_sdot, dt):
        """One iteration of the implicit midpoint s^{n+1} = s^n + dt G((s^n + s^{n+1})/2):
        s^{n+1} from the rate at the current s, and s set to the new midpoint."""
        if d_ptype[d_idx] != 2:
            d_snew[d_idx] = d_sstart[d_idx] + dt * d_sdot[d_idx]
        else:
            d_snew[d_idx] = d_sstart[d_idx]
        d_s[d_idx] = 0.5 * (d_sstart[d_idx] + d_snew[d_idx])

    def stage7(self, d_idx, d_s, d_snew):
        """s = s^{n+1}, the converged end of the implicit midpoint step."""
        d_s[d_idx] = d_snew[d_idx]


class SuperfluidVerlet(Integrator):
    """The Verlet-type integrator of Kincl (2023), sec. 3.4 (steps 0-9 above).

    Evaluation 0 (at the half step): density and derived state, then the entropy rate;
    evaluation 1 (at the full step): density and state, then the velocity rates.
    ``calibrate``: arrays whose density constant C_a is set before the first step so that
    the summation gives the density the arrays start with (eq. 1.14).

    The printed scheme is not exactly time-reversible: the rates of v, v_s depend on v, v_s
    (counterflow) and the rate of s on s, so its explicit kick (step 1, with the rates of
    step 8 at v^{n-1/2}) and its explicit s update (step 5, rate at s^n) are not their own
    adjoints; reversal errors are O(dt^2) per step (docs/superfluid.md).
    ``reversible=True`` makes both symmetric: the first half kick is implicit,
    v^{n+1/2} = v^n + dt/2 F(x^n, s^n, v^{n+1/2}), and s takes the implicit midpoint
    s^{n+1} = s^n + dt G(x^{n+1/2}, (s^n + s^{n+1})/2, v^{n+1/2}), each solved by fixed-point
    iteration from the printed scheme's value until the largest change is below ``rtol``
    times the largest |v|, |v_s| or |s| (at most ``max_iterations``).  With beta = mu = 0 the
    step is then its own inverse under v, v_s -> -v, -v_s to round-off.  The iteration
    counts of the last step are in ``iterations``; steps that hit the cap in ``unconverged``.
    """

    n_evaluations = 2
    position_time = {"stage1": 0.0, "stage2": 0.5, "stage3": 0.5, "stage4": 0.0, "stage5": 0.0,
                     "stage6": 0.5, "stage7": 0.5}

    def __init__(self, calibrate=(), reversible=False, rtol=1e-14, max_iterations=30, mirror=(),
                 **steppers):
        super().__init__(**steppers)
        self.calibrate = list(calibrate)
        self.mirror = list(mirror)
        self.reversible = bool(reversible)
        self.rtol, self.max_iterations = float(rtol), int(max_iterations)
        self.iterations = {"kick": 0, "entropy": 0}
        self.unconverged = 0

    def calibrate_density(self, t, dt):
        """C_a = rho_a(0) - sum_b m_b W_ab(0), so that the summation starts at the given rho."""
        arrays = [self.scene.by_name[n] for n in self.calibrate]
        target = [pa.rho.copy() for pa in arrays]
        for pa in arrays:
            pa.crho[:] = 0.0
        self.scene.run_group(self.scene.plan.group_plans[1][0], t, dt)
        for pa, rho in zip(arrays, target):
            pa.crho[:] = rho - pa.rho

    def refresh_mirrors(self):
        for name in self.mirror:
            refresh_mirrors(self.scene.by_name[name])

    def update_nnps(self):
        """The neighbour lists, built with the mirrored dummies in place."""
        self.refresh_mirrors()
        super().update_nnps()

    def compute_accelerations(self, index, t, dt):
        """The rates, after the mirrored dummies took their partners' state."""
        self.refresh_mirrors()
        super().compute_accelerations(index, t, dt)

    def initial_accelerations(self, t, dt):
        if self.mirror:   # the density constants with the dummies in place
            self.update_nnps()
        if self.calibrate:
            self.calibrate_density(t, dt)
        self.compute_accelerations(1, t, dt)

    def one_timestep(self, t, dt):
        if self.reversible:
            return self._symmetric_step(t, dt)
        self.stage("stage1", t, dt)
        self.stage("stage2", t, dt)
        self.sources(t, dt)
        self.update_nnps()
        self.compute_accelerations(0, t + 0.5 * dt, dt)
        self.stage("stage3", t, dt)
        self.stage("stage2", t, dt)
        self.update_nnps()
        self.compute_accelerations(1, t + dt, dt)
        self.stage("stage1", t + dt, dt)

    def sources(self, t, dt):
        """Local source stages after the first drift (none here; the fountain's superleak)."""

    def _iterate(self, what, evaluate, stage, props, t, dt):
        """Fixed-point iterations: ``evaluate()``, then ``stage``, until ``props`` change by
        less than rtol times their largest magnitude."""
        arrays = [self.scene.by_name[n] for n in self.steppers]
        for k in range(1, self.max_iterations + 1):
            before = [[pa.get(p).copy() for p in props] for pa in arrays]
            evaluate()
            self.stage(stage, t, dt)
            change = scale = 0.0
            for pa, old in zip(arrays, before):
                for p, o in zip(props, old):
                    new = pa.get(p)
                    if new.size:
                        change = max(change, float(np.abs(new - o).max()))
                        scale = max(scale, float(np.abs(new).max()))
            if change <= self.rtol * scale:
                break
        else:
            self.unconverged += 1
        self.iterations[what] = k

    def _symmetric_step(self, t, dt):
        dim = next(iter(self.steppers.values())).dim
        vel = ("u", "v", "w")[:dim] + ("us", "vs", "ws")[:dim]
        self.stage("stage4", t, dt)
        self.stage("stage1", t, dt)                      # predictor: the printed explicit kick
        self._iterate("kick", lambda: self.compute_accelerations(1, t, dt), "stage5", vel, t, dt)
        self.stage("stage2", t, dt)
        self.update_nnps()
        self._iterate("entropy", lambda: self.compute_accelerations(0, t + 0.5 * dt, dt), "stage6",
                      ("snew",), t, dt)
        self.stage("stage7", t, dt)
        self.stage("stage2", t, dt)
        self.update_nnps()
        self.compute_accelerations(1, t + dt, dt)
        self.stage("stage1", t + dt, dt)


class SuperfluidScheme(Scheme):
    """Two-fluid helium-4 of Kincl (2023), ch. 3: reversible eq. 3.34 + irreversible eqs. 3.38-3.39.

    ``arrays``: names of the helium arrays (each particle FLUID, ADIABATIC or COOLER by its
    integer property ``ptype``); ``model``: a :class:`~sphgen.equations.superfluid_energy.LinearHelium`;
    ``h``: smoothing length of the Wendland C2 kernel (support 2h); ``beta`` entropy
    diffusion and ``mu`` normal-fluid viscosity (0 removes them from the code); ``eta2``
    the viscous regulariser eta^2 (default 0.04 h^2); ``gravity`` (gx, gy, gz) on v and v_s;
    ``dt`` the time step (default ``cfl`` h / c1); ``calibrate_density``: set the density
    constant C_a at t = 0 so the summation starts from the arrays' ``rho``; ``reversible``:
    the symmetric variant of the integrator (see :class:`SuperfluidVerlet`);
    ``mirror_walls``: COOLER particles with ``mirror`` >= 0 are mirrored dummies (module
    docstring); the diagnostics then leave them out.
    """

    output_props = ("x", "y", "z", "u", "v", "w", "us", "vs", "ws", "s", "rho", "p", "T", "rhon", "m",
                    "h", "ptype")

    def __init__(self, arrays=("helium",), dim=2, model=HELIUM_1_9K, h=None, beta=0.0, mu=0.0, eta2=None,
                 gravity=(0.0, 0.0, 0.0), kernel="wendland", dt=None, cfl=0.4, calibrate_density=True,
                 reversible=False, rtol=1e-14, max_iterations=30, renormalise=False, mirror_walls=False):
        if dim not in (2, 3):
            raise InputError(f"SuperfluidScheme: dim must be 2 or 3, got {dim!r}")
        if h is None or not h > 0:
            raise InputError(f"SuperfluidScheme: h={h!r} must be > 0")
        for name, val in (("beta", beta), ("mu", mu)):
            if not (np.isfinite(val) and val >= 0):
                raise InputError(f"SuperfluidScheme: {name}={val!r} must be a finite number >= 0")
        if dt is not None and not (np.isfinite(dt) and dt > 0):
            raise InputError(f"SuperfluidScheme: dt={dt!r} must be > 0")
        self.arrays, self.dim, self.model, self.h = list(arrays), dim, model, float(h)
        self.beta, self.mu = float(beta), float(mu)
        self.eta2 = 0.04 * self.h * self.h if eta2 is None else float(eta2)
        self.gx, self.gy, self.gz = (float(g) for g in gravity)
        self.kernel = get_kernel(kernel, dim)
        self.cfl, self.dt = float(cfl), dt
        self.calibrate = bool(calibrate_density)
        self.reversible, self.rtol, self.max_iterations = bool(reversible), float(rtol), int(max_iterations)
        self.renormalise = int(bool(renormalise))
        self.mirror_walls = bool(mirror_walls)
        self.masked = 0
        # the model is weakly compressible: a particle at the first-sound speed has blown up
        self.speed_limit = model.c1
        skip = {2: ("z", "w", "ws"), 3: ()}[dim]
        self.output_props = tuple(p for p in self.output_props if p not in skip)

    def parameters(self):
        out = super().parameters()
        out.update({f"model_{k}": v for k, v in vars(self.model).items()})
        return out

    def setup_properties(self, arrays):
        for pa in arrays:
            if pa.name not in self.arrays:
                continue
            if "ptype" in pa.data and pa.props["ptype"].dtype != "int":
                values = np.asarray(pa.ptype)
                if not np.array_equal(values, np.round(values)):
                    raise InputError(f"array '{pa.name}': ptype must hold integers 0, 1, 2")
                pa.release("ptype")
                pa.add_property("ptype", dtype="int", data=values.astype(np.int32))
            elif not pa.has("ptype"):
                pa.add_property("ptype", dtype="int", default=FLUID)
            if "ptype" in pa.data:
                bad = set(np.unique(pa.ptype)) - {FLUID, ADIABATIC, COOLER}
                if bad:
                    raise InputError(f"array '{pa.name}': unknown ptype {sorted(bad)} "
                                     f"(FLUID {FLUID}, ADIABATIC {ADIABATIC}, COOLER {COOLER})")
                self.masked = int(self.masked or bool(np.any(pa.ptype == ADIABATIC)))
            for p in STATE_PROPS:
                if not pa.has(p):
                    pa.add_property(p)
            if self.mirror_walls:
                check_mirrors(pa)
            for p in INPUT_PROPS:
                if p not in pa.data:   # a state the user did not give starts at rest at s0
                    pa.add_property(p, default=self.model.s0 if p == "s" else 0.0)

    # ------------------------------------------------------------ equations
    def _density_state(self):
        """[density + state] or, renormalised, [density], [thermal normalisation + state]."""
        a, m, rn = self.arrays, self.model.parameters(), self.renormalise
        density = [SummationDensityWithConstant(d, a) for d in a]
        state = [SuperfluidState(d, dim=self.dim, renormalise=rn, **m) for d in a]
        if not rn:
            return [Group([e for pair in zip(density, state) for e in pair])]
        lam = [ThermalNormalisation(d, a, dim=self.dim, masked=self.masked) for d in a]
        return [Group(density), Group([e for pair in zip(lam, state) for e in pair])]

    def _entropy_rate(self):
        a, dim, mk = self.arrays, self.dim, self.masked
        eqs = []
        for d in a:
            eqs += [EntropyFlux(d, a, dim=dim, masked=mk),
                    EntropyProduction(d, a, dim=dim, masked=mk, beta=self.beta, mu=self.mu, eta2=self.eta2)]
        return eqs

    def _velocity_rates(self):
        a, dim, mk = self.arrays, self.dim, self.masked
        eqs = []
        for d in a:
            eqs += [SuperfluidPressure(d, a, dim=dim), CounterflowStress(d, a, dim=dim),
                    CounterflowCoupling(d, a, dim=dim), Thermomechanical(d, a, dim=dim, masked=mk, renormalise=self.renormalise),
                    NormalViscosity(d, a, dim=dim, mu=self.mu, eta2=self.eta2)]
            if self.gx or self.gy or self.gz:
                eqs.append(SuperfluidGravity(d, dim=dim, gx=self.gx, gy=self.gy, gz=self.gz))
        return eqs

    def get_equations(self):
        return [self._density_state() + [Group(self._entropy_rate())],
                self._density_state() + [Group(self._velocity_rates())]]

    def get_integrator(self):
        step = SuperfluidStep(self.dim)
        return SuperfluidVerlet(calibrate=self.arrays if self.calibrate else (), reversible=self.reversible,
                                rtol=self.rtol, max_iterations=self.max_iterations,
                                mirror=self.arrays if self.mirror_walls else (),
                                **{name: step for name in self.arrays})

    # ------------------------------------------------------------ time step
    def get_timestep(self):
        """dt = cfl h / c1 (default cfl 0.4, the authors' 0.2 x support / c1), unless given."""
        return self.dt if self.dt is not None else self.cfl * self.h / self.model.c1

    def stability_bounds(self, dt):
        """The acoustic bound of the Verlet scheme on the first sound."""
        return [Bound("--dt", dt, self.stable_dt(), True, STABLE_RULE)]

    def stable_dt(self):
        return STABLE_CFL * self.h / self.model.c1

    def density_bounds(self):
        """(0.5, 2) rho0: the linear model is meant for |rho - rho0| of a few %."""
        return {a: (0.5 * self.model.rho0, 2.0 * self.model.rho0) for a in self.arrays}

    # ------------------------------------------------------------ diagnostics
    def energies(self, arrays):
        """{'kinetic', 'compression', 'heat', 'total', 'entropy'}: sums over all particles of
        m e_kin (coflow and counterflow, eq. 3.23), m c1^2 (ln(rho/rho0) + rho0/rho - 1) and
        m T0 ((s - s0) + (s - s0)^2/(2 C_V)) (eq. 3.32), their total, and sum m s.
        With ``mirror_walls`` the mirrored dummies are left out (their state is a copy)."""
        out = dict(kinetic=0.0, compression=0.0, heat=0.0, entropy=0.0)
        for pa in arrays:
            if pa.name not in self.arrays:
                continue
            s, v, vs = velocities(pa, self.dim)
            keep = (np.asarray(pa.mirror) < 0) if self.mirror_walls and pa.has("mirror") else slice(None)
            m, s, v, vs, rho = pa.m[keep], s[keep], v[keep], vs[keep], pa.rho[keep]
            out["kinetic"] += float(np.sum(m * self.model.kinetic_energy(s, v, vs)))
            out["compression"] += float(np.sum(m * self.model.compression_energy(rho)))
            out["heat"] += float(np.sum(m * self.model.heat_energy(s)))
            out["entropy"] += float(np.sum(m * s))
        out["total"] = out["kinetic"] + out["compression"] + out["heat"]
        return out


STABLE_CFL = 1.0
STABLE_RULE = "h/c1, the acoustic limit of the Verlet scheme measured with sphgen stress"


MIRROR_SIGNS = ("msx", "msy", "msz")
MIRROR_SHIFTS = ("mox", "moy", "moz")
AXES = (("x", "u", "us"), ("y", "v", "vs"), ("z", "w", "ws"))


def check_mirrors(pa):
    """Mirrored dummies: ``mirror`` (int, -1 for none) is the gid of a FLUID partner, the
    dummy is COOLER, its signs ``msx, msy, msz`` are +-1 and its shifts ``mox, moy, moz``
    are 0 where the sign is +1 (missing ones: +1 and 0)."""
    if not pa.has("mirror"):
        raise InputError(f"array '{pa.name}': mirror_walls needs the integer property 'mirror'")
    for p, default in [(p, 1.0) for p in MIRROR_SIGNS] + [(p, 0.0) for p in MIRROR_SHIFTS]:
        if p not in pa.data:
            pa.add_property(p, data=np.full(pa.n, default))
    mirror = np.asarray(pa.mirror)
    dummy = mirror >= 0
    ptype = np.asarray(pa.ptype)
    index = gid_index(pa)
    if np.any(mirror[dummy] >= index.size) or np.any(ptype[dummy] != COOLER):
        raise InputError(f"array '{pa.name}': a mirrored dummy must be COOLER with a partner gid")
    if np.any(index[mirror[dummy]] < 0) or np.any(ptype[index[mirror[dummy]]] != FLUID):
        raise InputError(f"array '{pa.name}': a mirrored dummy's partner must be FLUID")
    for sign, shift in zip(MIRROR_SIGNS, MIRROR_SHIFTS):
        sg, sh = np.asarray(pa.get(sign))[dummy], np.asarray(pa.get(shift))[dummy]
        if not (np.all(np.abs(sg) == 1.0) and np.all(sh[sg > 0] == 0.0)):
            raise InputError(f"array '{pa.name}': mirrored dummies need {sign} = +-1 and {shift} = 0 "
                             "where it is +1")


def gid_index(pa):
    """index[gid] = the particle's current position in memory (-1 for unused gids)."""
    gid = np.asarray(pa.gid)
    index = np.full(int(gid.max()) + 1 if gid.size else 0, -1, dtype=np.int64)
    index[gid] = np.arange(gid.size)
    return index


def refresh_mirrors(pa):
    """Each mirrored dummy becomes the image of its partner: along each axis,
    x = ms x_partner + mo, and v, v_s times ms; s copied."""
    mirror = np.asarray(pa.mirror)
    dummy = np.flatnonzero(mirror >= 0)
    if not dummy.size:
        return
    src = gid_index(pa)[mirror[dummy]]
    pa.s[dummy] = pa.s[src]
    for (x, u, us), sign, shift in zip(AXES, MIRROR_SIGNS, MIRROR_SHIFTS):
        if x not in pa.data:
            continue
        ms = pa.get(sign)[dummy]
        pa.get(x)[dummy] = ms * pa.get(x)[src] + pa.get(shift)[dummy]
        for c in (u, us):
            if c in pa.data:
                pa.get(c)[dummy] = ms * pa.get(c)[src]


def velocities(pa, dim):
    """(s, v, v_s) of an array as numpy arrays, velocities with the component last."""
    v = np.stack([pa.get(c) for c in ("u", "v", "w")[:dim]], axis=-1)
    vs = np.stack([pa.get(c) for c in ("us", "vs", "ws")[:dim]], axis=-1)
    return pa.s, v, vs
