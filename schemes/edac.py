"""Weakly compressible EDAC: the uncorrected baseline of Adepu & Ramachandran (2024), secs. 2-3.

Summation density, EDAC pressure (eq. 22 discretised as eq. 26 without the CTVF
corrections), momentum with pressure gradient, Morris viscosity and optional
artificial viscosity (eqs. 27-29), kick-drift-kick integration (eqs. 54-60).  With
``pst='sun2019'`` particles move with the transport velocity u~ = u + dt/2 (du/dt)_c
of the Sun et al. shifting acceleration (eq. 36, 55) and the momentum equation keeps
the TVF stress term; the corrections C1-C3 of CTVF are not applied.
"""
from sphgen.equation import Group
from sphgen.integrators import IntegratorStep, KickDriftKick
from sphgen.kernels import get_kernel
from sphgen.scheme import Bound, Scheme

from ..equations.basic import SummationDensity, Vorticity2D
from ..equations.edac import EDACPressureRate
from ..equations.momentum import (ArtificialViscosity, AveragePressure, LaminarViscosity,
                                 PressureGradient)
from ..equations.transport import (BackgroundPressureAcceleration, SunShiftingAcceleration,
                                  TransportStress)
from ..equations.walls import (WallArtificialViscosity, WallDensity, WallEDACPressureRate,
                               WallGhostVelocity, WallPressure, WallViscosity)
from ..equations.wcsph import BodyForce

PSTS = ("none", "sun2019", "tvf")


class EDACStep(IntegratorStep):
    """Kick-drift-kick stages of Adepu & Ramachandran (2024), eqs. 54-60 (``shift``: move with u~)."""

    switches = ("dim", "shift")

    def __init__(self, dim, shift):
        self.dim, self.shift = dim, int(shift)

    def stage1(self, d_idx, d_u, d_v, d_w, d_au, d_av, d_aw, d_uhat, d_vhat, d_what,
               d_auhat, d_avhat, d_awhat, dt):
        """Kick (eq. 54) and transport velocity (eq. 55)."""
        d_u[d_idx] += 0.5 * dt * d_au[d_idx]
        d_v[d_idx] += 0.5 * dt * d_av[d_idx]
        if self.dim > 2:
            d_w[d_idx] += 0.5 * dt * d_aw[d_idx]
        if self.shift:
            d_uhat[d_idx] = d_u[d_idx] + 0.5 * dt * d_auhat[d_idx]
            d_vhat[d_idx] = d_v[d_idx] + 0.5 * dt * d_avhat[d_idx]
            if self.dim > 2:
                d_what[d_idx] = d_w[d_idx] + 0.5 * dt * d_awhat[d_idx]

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_uhat, d_vhat, d_what, d_p, d_ap, dt):
        """Drift: pressure (eq. 57) and positions (eq. 59)."""
        d_p[d_idx] += dt * d_ap[d_idx]
        if self.shift:
            d_x[d_idx] += dt * d_uhat[d_idx]
            d_y[d_idx] += dt * d_vhat[d_idx]
            if self.dim > 2:
                d_z[d_idx] += dt * d_what[d_idx]
        else:
            d_x[d_idx] += dt * d_u[d_idx]
            d_y[d_idx] += dt * d_v[d_idx]
            if self.dim > 2:
                d_z[d_idx] += dt * d_w[d_idx]

    def stage3(self, d_idx, d_u, d_v, d_w, d_au, d_av, d_aw, dt):
        """Kick (eq. 60)."""
        d_u[d_idx] += 0.5 * dt * d_au[d_idx]
        d_v[d_idx] += 0.5 * dt * d_av[d_idx]
        if self.dim > 2:
            d_w[d_idx] += 0.5 * dt * d_aw[d_idx]


class EDACScheme(Scheme):
    """EDAC, Adepu & Ramachandran (2024) uncorrected baseline, with optional Adami walls and body force.

    Walls (``walls``: array names, fixed particles with ``m``, ``h``, ``rho``): every
    evaluation of the momentum equation first gives them the pressure extrapolated from
    the fluid with the body-force term (Adami, Hu & Adams 2012 eq. 27), the density of the
    linear equation of state rho0 + p/c0^2 and the ghost velocity (eqs. 22-23; no slip, or
    free slip with ``slip=True``).  Walls enter the summation density, the pressure
    gradient, the EDAC pressure equation (with the wall's prescribed velocity) and the
    shifting terms; viscosity and artificial viscosity use the ghost / prescribed wall
    velocity.  ``moving_walls`` names the walls with a prescribed velocity ``uw, vw, ww``.
    ``gx, gy, gz`` is a body force per unit mass, ramped in over ``tdamp`` if > 0.
    Without walls and body force the equations are exactly those of the periodic scheme.
    """

    output_props = ("x", "y", "z", "u", "v", "w", "p", "rho", "m", "h")

    def __init__(self, fluids, dim, rho0, c0, nu, h, dx, umax=1.0, pst="none", alpha=0.0,
                 alpha_edac=0.5, mach=None, pb=None, bql=True, kernel="quintic", walls=(),
                 gx=0.0, gy=0.0, gz=0.0, slip=False, moving_walls=(), tdamp=0.0):
        if pst not in PSTS:
            raise ValueError(f"pst must be one of {', '.join(PSTS)}; got {pst!r}")
        for name, v in (("rho0", rho0), ("c0", c0), ("h", h), ("dx", dx), ("umax", umax)):
            if not v > 0:
                raise ValueError(f"EDACScheme: {name}={v!r} must be > 0")
        if not nu >= 0:
            raise ValueError(f"EDACScheme: nu={nu!r} must be >= 0")
        self.fluids, self.dim = list(fluids), dim
        self.walls, self.moving_walls = list(walls), list(moving_walls)
        if any(w not in self.walls for w in self.moving_walls):
            raise ValueError(f"EDACScheme: moving_walls {self.moving_walls} must be among walls {self.walls}")
        self.gx, self.gy, self.gz, self.slip, self.tdamp = gx, gy, gz, bool(slip), tdamp
        self.rho0, self.c0, self.nu, self.h, self.dx, self.umax = rho0, c0, nu, h, dx, umax
        self.pst, self.alpha, self.alpha_edac = pst, alpha, alpha_edac
        self.mach = umax / c0 if mach is None else mach
        # the KDK transport velocity u + dt/2 a_c (Adepu & Ramachandran (2024) eq. 55) with p_b = 2 rho0 c0^2
        # equals Adami et al.'s u + dt a_c with their p_b = rho0 c0^2
        self.pb = 2.0 * rho0 * c0 * c0 if pb is None else pb
        self.bql = bool(bql)
        self.kernel = get_kernel(kernel, dim)
        # weak compressibility assumes Mach << 1: a particle at Mach 1 means the run blew up
        self.speed_limit = c0
        skip = {1: ("y", "z", "v", "w"), 2: ("z", "w"), 3: ()}[dim]
        self.output_props = tuple(p for p in self.output_props if p not in skip)

    def setup_properties(self, arrays):
        for pa in arrays:
            for p in ("p", "ap", "pavg", "nnbr", "au", "av", "aw", "uhat", "vhat", "what", "auhat", "avhat", "awhat", "omega"):
                pa.add_property(p)
            if pa.name in self.walls:
                for p in ("wij", "ug", "vg", "wg", "uw", "vw", "ww", "auw", "avw", "aww"):
                    if not pa.has(p):
                        pa.add_property(p)
                if not pa.has("normal"):
                    pa.add_property("normal", stride=3)

    def get_equations(self):
        f = self.fluids
        nu_edac = self.alpha_edac * self.h * self.c0 / 8.0  # Adepu & Ramachandran (2024) eq. 24
        shift = self.pst != "none"
        w, fw = self.walls, self.fluids + self.walls
        pressure = []
        for d in f:
            pressure.append(EDACPressureRate(d, f, c0=self.c0, nu_edac=nu_edac))
            pressure += [WallEDACPressureRate(d, [s], c0=self.c0, nu_edac=nu_edac,
                                              moving=s in self.moving_walls, dim=self.dim) for s in w]
        pressure = [Group(pressure)]
        momentum = []
        for d in f:
            momentum += [PressureGradient(d, fw, bql=self.bql),
                         LaminarViscosity(d, f, nu=self.nu),
                         ArtificialViscosity(d, f, alpha=self.alpha, c0=self.c0)]
            if w:
                momentum.append(WallViscosity(d, w, nu=self.nu, dim=self.dim))
                momentum += [WallArtificialViscosity(d, [s], alpha=self.alpha, c0=self.c0,
                                                     moving=s in self.moving_walls, dim=self.dim) for s in w]
            if shift:
                momentum.append(TransportStress(d, f))
            if self.pst == "sun2019":
                wdx = self.kernel.w(self.dx, self.h)
                momentum.append(SunShiftingAcceleration(d, fw, mach=self.mach, c0=self.c0, wdx=wdx))
            elif self.pst == "tvf":
                momentum.append(BackgroundPressureAcceleration(d, fw, pb=self.pb))
            if self.gx or self.gy or self.gz:
                momentum.append(BodyForce(d, gx=self.gx, gy=self.gy, gz=self.gz, tdamp=self.tdamp))
            if self.dim == 2:
                momentum.append(Vorticity2D(d, f))
        density = [SummationDensity(d, fw) for d in f]
        if self.bql:
            density += [AveragePressure(d, f) for d in f]
        density = Group(density)
        if not w:
            return [pressure, [density, Group(momentum)]]
        g = dict(gx=self.gx, gy=self.gy, gz=self.gz)
        walls = []
        for d in w:
            walls += [WallPressure(d, f, dim=self.dim, **g),
                      WallDensity(d, eos="linear", rho0=self.rho0, c0=self.c0),
                      WallGhostVelocity(d, f, slip=self.slip, moving=d in self.moving_walls, dim=self.dim)]
        return [pressure, [density, Group(walls), Group(momentum)]]

    def get_integrator(self):
        step = EDACStep(self.dim, self.pst != "none")
        return KickDriftKick(**{name: step for name in self.fluids})

    def stability_bounds(self, dt):
        """The time-step criterion (Adepu & Ramachandran eq. 61) and weak compressibility."""
        return [Bound("--dt", dt, self.get_timestep(), True,
                      "min(0.25 h/(c0 + U), 0.25 h^2/nu), Adepu & Ramachandran eq. 61"),
                Bound("--c0", self.c0, 10.0 * self.umax, False,
                      "c0 >= 10 U keeps density variations near 1%")]

    def density_bounds(self):
        """(0.2, 3) rho0: far outside anything a stable run reaches.

        Summation density dips where particles open voids (Taylor-Green at nx=50 reaches
        0.47 rho0 near t=0.27 and recovers), and cannot fall below an isolated particle's
        own m W(0) (0.31 rho0 for the quintic spline at h = dx); clumping drives it up.
        """
        return {f: (0.2 * self.rho0, 3.0 * self.rho0) for f in self.fluids}

    def get_timestep(self):
        """Adepu & Ramachandran (2024), eq. 61: min(0.25 h/(c0 + U), 0.25 h^2/nu)."""
        dt = 0.25 * self.h / (self.c0 + self.umax)
        if self.nu > 0:
            dt = min(dt, 0.25 * self.h * self.h / self.nu)
        return dt
