"""Classical weakly compressible SPH (Monaghan 1992, 1994, 2005) with Adami walls.

Fluid: continuity density (:class:`~sphgen.equations.wcsph.ContinuityEquation`), Tait
equation of state (gamma = 7, B = rho0 c0^2/gamma), momentum with Monaghan's symmetric
pressure gradient, Monaghan artificial viscosity (alpha, beta), optional Morris viscosity
``nu``, body force ``g``, and delta-SPH density diffusion (Antuono et al. 2010; ``delta=0``
removes it from the generated code, ``delta_correction=False`` gives the Molteni &
Colagrossi 2009 form).  Walls: Adami, Hu & Adams (2012) -- every evaluation gives each
wall particle the pressure extrapolated from the fluid (eq. 27, with rho g . r), the
density from it through the Tait equation, and for viscous runs the ghost velocity
(eqs. 22-23, no slip or free slip).

Time integration: a predictor-corrector (midpoint) with one evaluation per step,
:class:`WCSPHStep` under :class:`WCSPHIntegrator` (``sphgen.integrators.PEC`` plus an
evaluation before the first step).  Time step, see :meth:`WCSPHScheme.get_timestep`.
"""
import numpy as np

from sphgen.equation import Group
from sphgen.integrators import PEC, IntegratorStep
from sphgen.kernels import get_kernel
from sphgen.scheme import Scheme

try:  # the documented-bounds hook of sphgen.scheme (absent in older trees)
    from sphgen.scheme import Bound
except ImportError:  # pragma: no cover
    Bound = None

from ..equations.momentum import LaminarViscosity, PressureGradient
from ..equations.walls import (WallArtificialViscosity, WallContinuity, WallDensity,
                               WallGhostVelocity, WallPressure, WallViscosity)
from ..equations.wcsph import (BodyForce, ContinuityEquation, DensityDiffusion,
                               MonaghanArtificialViscosity, RenormalisedDensityGradient,
                               TaitEOS)


def tait_internal_energy(rho, rho0, B, gamma=7.0):
    """Specific internal energy of the Tait fluid, the integral of p/rho^2 from rho0 (numpy):
    e = B/((gamma - 1) rho0) ((rho/rho0)^(gamma-1) - 1) + B (1/rho - 1/rho0)."""
    r = rho / rho0
    return B / ((gamma - 1.0) * rho0) * (r ** (gamma - 1.0) - 1.0) + B * (1.0 / rho - 1.0 / rho0)


class WCSPHStep(IntegratorStep):
    """Predictor-corrector (midpoint) stages for x, u and rho.

    stage1 (predict): save the state q^n, then q^{n+1/2} = q^n + dt/2 (dq/dt) with the
    rates of the previous evaluation.  stage2 (correct), with the rates evaluated at
    the half step: u^{n+1} = u^n + dt a, x^{n+1} = x^n + dt (u^n + u^{n+1})/2,
    rho^{n+1} = rho^n + dt drho/dt.  Second order (Monaghan 1989; PySPH's WCSPHStep
    with its PEC integrator is the same family).
    """

    switches = ("dim",)

    def __init__(self, dim):
        self.dim = int(dim)

    def stage1(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_rho, d_x0, d_y0, d_z0, d_u0, d_v0, d_w0,
               d_rho0, d_au, d_av, d_aw, d_arho, dt):
        h = 0.5 * dt
        d_x0[d_idx] = d_x[d_idx]
        d_u0[d_idx] = d_u[d_idx]
        d_rho0[d_idx] = d_rho[d_idx]
        d_x[d_idx] += h * d_u[d_idx]
        d_u[d_idx] += h * d_au[d_idx]
        d_rho[d_idx] += h * d_arho[d_idx]
        if self.dim > 1:
            d_y0[d_idx] = d_y[d_idx]
            d_v0[d_idx] = d_v[d_idx]
            d_y[d_idx] += h * d_v[d_idx]
            d_v[d_idx] += h * d_av[d_idx]
        if self.dim > 2:
            d_z0[d_idx] = d_z[d_idx]
            d_w0[d_idx] = d_w[d_idx]
            d_z[d_idx] += h * d_w[d_idx]
            d_w[d_idx] += h * d_aw[d_idx]

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_rho, d_x0, d_y0, d_z0, d_u0, d_v0, d_w0,
               d_rho0, d_au, d_av, d_aw, d_arho, dt):
        d_u[d_idx] = d_u0[d_idx] + dt * d_au[d_idx]
        d_x[d_idx] = d_x0[d_idx] + 0.5 * dt * (d_u0[d_idx] + d_u[d_idx])
        d_rho[d_idx] = d_rho0[d_idx] + dt * d_arho[d_idx]
        if self.dim > 1:
            d_v[d_idx] = d_v0[d_idx] + dt * d_av[d_idx]
            d_y[d_idx] = d_y0[d_idx] + 0.5 * dt * (d_v0[d_idx] + d_v[d_idx])
        if self.dim > 2:
            d_w[d_idx] = d_w0[d_idx] + dt * d_aw[d_idx]
            d_z[d_idx] = d_z0[d_idx] + 0.5 * dt * (d_w0[d_idx] + d_w[d_idx])


class WCSPHIntegrator(PEC):
    """:class:`sphgen.integrators.PEC` (predict, evaluate at the half step, correct) that
    also evaluates once before the first step, so the first prediction has rates."""

    def initial_accelerations(self, t, dt):
        self.compute_accelerations(0, t, dt)


class WCSPHScheme(Scheme):
    """Monaghan's WCSPH with Adami, Hu & Adams walls.

    Parameters
    ----------
    fluids, walls : lists of array names (walls may be empty).
    dim : 1, 2 or 3.
    rho0, c0 : reference density and artificial sound speed (B = rho0 c0^2/gamma).
    h : smoothing length (for the time step and delta-SPH).
    gx, gy, gz : body force (gravity) per unit mass.
    alpha, beta : Monaghan artificial viscosity (fluid-fluid and fluid-wall).
    delta : delta-SPH coefficient (0 removes the term); ``delta_correction`` selects
        Antuono et al. 2010 (True, renormalised-gradient correction) or Molteni &
        Colagrossi 2009 (False).
    gamma : Tait exponent.
    nu : kinematic viscosity (Morris form; 0 removes it).
    umax : largest expected flow speed, for the CFL step and the c0 >= 10 U bound
        (default c0/10, the weak-compressibility assumption).
    slip : free-slip walls (only matters with nu > 0); default no slip.
    moving_walls : names of walls with a prescribed velocity ``uw, vw, ww``.
    clamp_wall_pressure : clamp the extrapolated wall pressure at 0 (free surfaces).
    tdamp : ramp the body force in over this time (Adami et al. 2012 eq. 13).
    wall_alpha : apply the artificial viscosity against the walls too (default True).
    """

    output_props = ("x", "y", "z", "u", "v", "w", "p", "rho", "m", "h")

    def __init__(self, fluids, walls, dim, rho0, c0, h, gx=0.0, gy=0.0, gz=0.0, alpha=0.1,
                 beta=0.0, delta=0.1, gamma=7.0, nu=0.0, umax=None, delta_correction=True,
                 slip=False, moving_walls=(), clamp_wall_pressure=False, tdamp=0.0,
                 wall_alpha=True, kernel="quintic"):
        for name, v in (("rho0", rho0), ("c0", c0), ("h", h), ("gamma", gamma)):
            if not v > 0:
                raise ValueError(f"WCSPHScheme: {name}={v!r} must be > 0")
        for name, v in (("alpha", alpha), ("beta", beta), ("delta", delta), ("nu", nu), ("tdamp", tdamp)):
            if not v >= 0:
                raise ValueError(f"WCSPHScheme: {name}={v!r} must be >= 0")
        if dim not in (1, 2, 3):
            raise ValueError(f"WCSPHScheme: dim must be 1, 2 or 3, got {dim!r}")
        self.fluids, self.walls, self.dim = list(fluids), list(walls), dim
        unknown = [w for w in moving_walls if w not in self.walls]
        if unknown:
            raise ValueError(f"WCSPHScheme: moving wall {unknown[0]!r} is not one of the walls {self.walls}")
        self.moving_walls = list(moving_walls)
        self.rho0, self.c0, self.h, self.gamma = rho0, c0, h, gamma
        self.gx, self.gy, self.gz = gx, gy, gz
        self.alpha, self.beta, self.delta, self.nu = alpha, beta, delta, nu
        self.delta_correction = bool(delta_correction)
        self.slip, self.clamp_wall_pressure = bool(slip), bool(clamp_wall_pressure)
        self.tdamp, self.wall_alpha = tdamp, bool(wall_alpha)
        self.umax = c0 / 10.0 if umax is None else umax
        self.B = rho0 * c0 * c0 / gamma
        self.kernel = get_kernel(kernel, dim)
        # weak compressibility assumes Mach << 1: a particle at Mach 1 means the run blew up
        self.speed_limit = c0
        skip = {1: ("y", "z", "v", "w"), 2: ("z", "w"), 3: ()}[dim]
        self.output_props = tuple(p for p in self.output_props if p not in skip)

    # ------------------------------------------------------------ properties
    def setup_properties(self, arrays):
        for pa in arrays:
            if pa.name in self.fluids:
                for p in ("p", "arho", "au", "av", "aw", "x0", "y0", "z0", "u0", "v0", "w0", "rho0", "pavg"):
                    pa.add_property(p)
                pa.add_property("gradrho", stride=3)
                pa.add_property("lmat", stride=9)
            elif pa.name in self.walls:
                for p in ("p", "wij", "ug", "vg", "wg"):
                    pa.add_property(p)
                for p in ("uw", "vw", "ww", "auw", "avw", "aww"):
                    if not pa.has(p):
                        pa.add_property(p)
                if not pa.has("normal"):
                    pa.add_property("normal", stride=3)

    # ------------------------------------------------------------ equations
    def get_equations(self):
        f, w = self.fluids, self.walls
        g = dict(gx=self.gx, gy=self.gy, gz=self.gz)
        first = [TaitEOS(d, None, rho0=self.rho0, c0=self.c0, gamma=self.gamma) for d in f]
        if self.delta > 0 and self.delta_correction:
            first += [RenormalisedDensityGradient(d, f, dim=self.dim) for d in f]
        groups = [Group(first)]
        if w:
            weqs = []
            for d in w:
                moving = d in self.moving_walls
                weqs += [WallPressure(d, f, clamp=self.clamp_wall_pressure, dim=self.dim, **g),
                         WallDensity(d, eos="tait", rho0=self.rho0, c0=self.c0, gamma=self.gamma),
                         WallGhostVelocity(d, f, slip=self.slip, moving=moving, dim=self.dim)]
            groups.append(Group(weqs))
        eqs = []
        for d in f:
            eqs.append(ContinuityEquation(d, f))
            eqs += [WallContinuity(d, [s], moving=s in self.moving_walls, dim=self.dim) for s in w]
            eqs.append(DensityDiffusion(d, f, delta=self.delta, c0=self.c0,
                                        correction=self.delta_correction))
            eqs.append(PressureGradient(d, f + w, bql=False))
            eqs.append(MonaghanArtificialViscosity(d, f, alpha=self.alpha, beta=self.beta, c0=self.c0))
            if self.wall_alpha:
                eqs += [WallArtificialViscosity(d, [s], alpha=self.alpha, beta=self.beta, c0=self.c0,
                                                moving=s in self.moving_walls, dim=self.dim) for s in w]
            eqs.append(LaminarViscosity(d, f, nu=self.nu))
            if w:
                eqs.append(WallViscosity(d, w, nu=self.nu, dim=self.dim))
            eqs.append(BodyForce(d, tdamp=self.tdamp, **g))
        groups.append(Group(eqs))
        return groups

    def get_integrator(self):
        step = WCSPHStep(self.dim)
        return WCSPHIntegrator(**{name: step for name in self.fluids})

    # ------------------------------------------------------------ time step
    def get_timestep(self):
        """dt = min(0.25 h / ((1 + 0.6 alpha) c0 + U), 0.125 h^2/nu, 0.25 sqrt(h/|g|)).

        Acoustic CFL with the artificial-viscosity correction of Monaghan (1992, eq. 10.4:
        h/(c + 0.6 alpha c), beta's term neglected) and Courant number 0.25; viscous
        limit of Morris, Fox & Zhu (1997, eq. 20: 0.125 h^2/nu); body-force limit of
        Monaghan (1992, eq. 10.5 with safety factor 0.25).
        """
        dt = 0.25 * self.h / ((1.0 + 0.6 * self.alpha) * self.c0 + self.umax)
        if self.nu > 0:
            dt = min(dt, 0.125 * self.h * self.h / self.nu)
        gmag = (self.gx ** 2 + self.gy ** 2 + self.gz ** 2) ** 0.5
        if gmag > 0:
            dt = min(dt, 0.25 * (self.h / gmag) ** 0.5)
        return dt

    def stability_bounds(self, dt):
        """The time-step criteria of :meth:`get_timestep` and weak compressibility."""
        if Bound is None:
            return []
        return [Bound("--dt", dt, self.get_timestep(), True,
                      "min(0.25 h/((1 + 0.6 alpha) c0 + U), 0.125 h^2/nu, 0.25 sqrt(h/|g|)), "
                      "Monaghan 1992 eqs. 10.4-10.5, Morris et al. 1997 eq. 20"),
                Bound("--c0", self.c0, 10.0 * self.umax, False,
                      "c0 >= 10 U keeps density variations near 1% (Monaghan 1994)")]

    def density_bounds(self):
        """A Tait fluid at Mach <= 0.1 stays within a few % of rho0: a factor 2 is a blow-up."""
        return {f: (0.5 * self.rho0, 2.0 * self.rho0) for f in self.fluids}

    # ------------------------------------------------------------ diagnostics
    def energies(self, arrays):
        """{'kinetic', 'potential', 'internal', 'total'} of the fluid arrays (numpy).

        Kinetic sum m |u|^2/2; potential -sum m g . x; internal sum m e(rho) with the Tait
        energy e = B/((gamma - 1) rho0) ((rho/rho0)^(gamma-1) - 1) + B (1/rho - 1/rho0),
        the integral of p/rho^2 from rho0 (zero at rest at rho0).
        """
        ke = pe = ie = 0.0
        g = (self.gx, self.gy, self.gz)
        for pa in arrays:
            if pa.name not in self.fluids:
                continue
            m, rho = pa.m, pa.rho
            vel = [pa.data.get(c, 0.0) for c in ("u", "v", "w")[:self.dim]]
            pos = [pa.data.get(c, 0.0) for c in ("x", "y", "z")[:self.dim]]
            ke += 0.5 * float(np.sum(m * sum(c * c for c in vel)))
            pe -= float(np.sum(m * sum(gi * xi for gi, xi in zip(g, pos))))
            ie += float(np.sum(m * tait_internal_energy(rho, self.rho0, self.B, self.gamma)))
        return {"kinetic": ke, "potential": pe, "internal": ie, "total": ke + pe + ie}
