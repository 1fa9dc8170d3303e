"""Corrected transport-velocity formulation (CTVF) for fluids, Adepu & Ramachandran (2021).

Particles move with the transport velocity u~ = u + dt/2 (du/dt)_c (eq. 55), where the
homogenisation acceleration (du/dt)_c comes from any technique of
:mod:`sphgen.equations.shifting` (SPST eq. 36 by default, IPST eqs. 37-41, GTVF, TVF).
The pressure follows the EDAC equation with the CTVF terms (eq. 26), the momentum
equation keeps both transport terms of eq. 19 (eq. 27), and the density is summed
(Taylor-Green, cavity) or evolved by the corrected continuity equation (eq. 25).
Kick-drift-kick (eqs. 54-60); time step eq. 61.  Each correction is a switch, so the
paper's "without corrections" runs are the same scene with the terms switched off.

Walls (section 3.6): Adami et al. (2012) ghost particles (``walls``, ``moving_walls``), with
the free-slip ghost velocities of eqs. 46-49 in every divergence term (they are the walls'
``u, v, w`` and ``uhat, vhat, what``, :class:`~sphgen.equations.transport_walls.WallSlipVelocity`)
and the no-slip ghost velocity of eq. 50 in the viscous term; pressure extrapolated by
eq. 52 and the wall density from the linear equation of state.

Elastic solids (section 3.2): :class:`CTVFSolidScheme`, the same continuity (eq. 25), EDAC
(eq. 26), shifting and integrator, with the momentum equation eq. 30 (no A term), the
velocity gradient of the momentum velocity (eq. 31) and the Jaumann rate with its
transport correction (eq. 32); the pieces solids add to any transport-velocity scheme are
the mixin :class:`ElasticSolids` (the GTVF solid of ``schemes/gtvf.py`` uses it too).
Clamped particles are held by the integrator's prescribed values (``clamped``).
"""
from math import sqrt

from sphgen.equation import Group
from sphgen.integrators import IntegratorStep, KickDriftKick
from sphgen.kernels import get_kernel
from sphgen.scheme import Bound, Scheme

from ..equations.basic import SummationDensity, Vorticity2D
from ..equations.contact import ContactForce
from ..equations.ctvf import (ContinuityTransportCorrection, EDACTransportCorrection,
                              MomentumTransportDivergence)
from ..equations.edac import EDACPressureRate
from ..equations.elastic import (DeviatoricStressForce, HookeJaumannRate, JaumannTransportCorrection,
                                 PerfectPlasticity, VelocityGradient)
from ..equations.free_surface import (SurfacePressure, SurfaceShiftingFilter, free_surface_groups,
                                      setup_free_surface_properties)
from ..equations.momentum import ArtificialViscosity, AveragePressure, LaminarViscosity, PressureGradient
from ..equations.shifting import Shifting
from ..equations.transport import TransportContinuity, TransportStress
from ..equations.transport_walls import WallSlipVelocity
from ..equations.walls import (WallArtificialViscosity, WallDensity, WallGhostVelocity, WallPressure,
                               WallViscosity)
from ..equations.wcsph import BodyForce

DENSITIES = ("summation", "continuity")
CORRECTIONS = ("edac", "stress", "divergence", "continuity")
SOLID_CORRECTIONS = ("edac", "continuity", "jaumann")
# the -u div(delta) term of eq. 19 ("delta") or as eq. 27 prints it, -u div(u~) ("printed")
DIVERGENCE_FORMS = ("delta", "printed")
# the A term of eq. 27 in its printed symmetric form or as a difference (zeroth-order consistent)
STRESS_FORMS = ("symmetric", "difference")


class TransportVelocityStep(IntegratorStep):
    """Kick-drift-kick stages with the transport velocity (Adepu & Ramachandran 2021,
    eqs. 54-60).  Switches: ``shift`` (move with u~, else with u), ``pressure`` (evolve p
    by dp/dt, eq. 57), ``density`` (evolve rho by drho/dt, eq. 56), ``stress`` (evolve the
    deviatoric stress ``sd`` by ``asd``, eq. 58: elastic solids)."""

    switches = ("dim", "shift", "pressure", "density", "stress")

    def __init__(self, dim, shift=True, pressure=True, density=False, stress=False):
        self.dim, self.shift = int(dim), int(bool(shift))
        self.pressure, self.density = int(bool(pressure)), int(bool(density))
        self.stress = int(bool(stress))

    def stage1(self, d_idx, d_u, d_v, d_w, d_au, d_av, d_aw, d_uhat, d_vhat, d_what,
               d_auhat, d_avhat, d_awhat, dt):
        """Kick (eq. 54) and transport velocity (eq. 55)."""
        d_u[d_idx] += 0.5 * dt * d_au[d_idx]
        if self.dim > 1:
            d_v[d_idx] += 0.5 * dt * d_av[d_idx]
        if self.dim > 2:
            d_w[d_idx] += 0.5 * dt * d_aw[d_idx]
        if self.shift:
            d_uhat[d_idx] = d_u[d_idx] + 0.5 * dt * d_auhat[d_idx]
            if self.dim > 1:
                d_vhat[d_idx] = d_v[d_idx] + 0.5 * dt * d_avhat[d_idx]
            if self.dim > 2:
                d_what[d_idx] = d_w[d_idx] + 0.5 * dt * d_awhat[d_idx]
        else:   # no homogenisation: u~ = u (the continuity and the transport terms read u~)
            d_uhat[d_idx] = d_u[d_idx]
            if self.dim > 1:
                d_vhat[d_idx] = d_v[d_idx]
            if self.dim > 2:
                d_what[d_idx] = d_w[d_idx]

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_uhat, d_vhat, d_what, d_p, d_ap,
               d_rho, d_arho, d_sd, d_asd, dt):
        """Drift: density (eq. 56), pressure (eq. 57), deviatoric stress (eq. 58), positions
        with u~^{n+1/2} (eq. 59)."""
        if self.stress:
            for i in range(9):
                d_sd[9 * d_idx + i] += dt * d_asd[9 * d_idx + i]
        if self.pressure:
            d_p[d_idx] += dt * d_ap[d_idx]
        if self.density:
            d_rho[d_idx] += dt * d_arho[d_idx]
        if self.shift:
            d_x[d_idx] += dt * d_uhat[d_idx]
            if self.dim > 1:
                d_y[d_idx] += dt * d_vhat[d_idx]
            if self.dim > 2:
                d_z[d_idx] += dt * d_what[d_idx]
        else:
            d_x[d_idx] += dt * d_u[d_idx]
            if self.dim > 1:
                d_y[d_idx] += dt * d_v[d_idx]
            if self.dim > 2:
                d_z[d_idx] += dt * d_w[d_idx]

    def stage3(self, d_idx, d_u, d_v, d_w, d_au, d_av, d_aw, dt):
        """Kick (eq. 60)."""
        d_u[d_idx] += 0.5 * dt * d_au[d_idx]
        if self.dim > 1:
            d_v[d_idx] += 0.5 * dt * d_av[d_idx]
        if self.dim > 2:
            d_w[d_idx] += 0.5 * dt * d_aw[d_idx]


def transport_timestep(h, c0, umax, nu, g=0.0):
    """min(0.25 h/(c0 + U), 0.25 h^2/nu, 0.25 sqrt(h/|g|)) (Adepu & Ramachandran 2021, eq. 61,
    its last term read as sqrt(h/g), which has the dimension of a time)."""
    dt = 0.25 * h / (c0 + umax)
    if nu > 0:
        dt = min(dt, 0.25 * h * h / nu)
    if g > 0:
        dt = min(dt, 0.25 * sqrt(h / g))
    return dt


class TransportVelocityScheme(Scheme):
    """What the transport-velocity schemes share: checks, kernel, homogenisation
    (:class:`~sphgen.equations.shifting.Shifting`), properties, walls, the KDK integrator,
    the time step (eq. 61) and the guards.  Subclasses give ``get_equations``.

    ``walls``: names of wall arrays (fixed particles with ``m``, ``h``, ``rho`` and unit
    ``normal`` into the fluid, stride 3); ``moving_walls``: those among them with a
    prescribed velocity ``uw, vw, ww`` (Adepu & Ramachandran 2021, section 3.6);
    ``wall_alpha``: the artificial viscosity acts against the walls too, with their
    prescribed velocity (default; False leaves the walls out of it, docs/ctvf.md).
    ``free_surface``, ``surface_pressure``, ``cone_radius``: the free-surface treatment
    of sections 3.4-3.5 (see :class:`CTVFScheme`), shared by every transport scheme.
    """

    output_props = ("x", "y", "z", "u", "v", "w", "p", "rho", "m", "h")
    evolve_pressure = True

    def __init__(self, fluids, dim, rho0, c0, nu, h, dx, umax=1.0, shifting="spst",
                 density="summation", alpha=0.0, mach=None, pb=None, p_ref=None,
                 kernel="quintic", gx=0.0, gy=0.0, gz=0.0, ipst_tolerance=0.02,
                 ipst_max_iterations=10, ipst_interval=1, walls=(), moving_walls=(),
                 free_surface=False, surface_pressure=False, cone_radius=2.0, wall_alpha=True):
        for name, v in (("rho0", rho0), ("c0", c0), ("h", h), ("dx", dx), ("umax", umax)):
            if not v > 0:
                raise ValueError(f"{type(self).__name__}: {name}={v!r} must be > 0")
        if not nu >= 0:
            raise ValueError(f"{type(self).__name__}: nu={nu!r} must be >= 0")
        if density not in DENSITIES:
            raise ValueError(f"density must be one of {', '.join(DENSITIES)}; got {density!r}")
        self.fluids, self.dim = list(fluids), int(dim)
        self.walls, self.moving_walls = list(walls), list(moving_walls)
        if any(w not in self.walls for w in self.moving_walls):
            raise ValueError(f"{type(self).__name__}: moving_walls {self.moving_walls} must be among "
                             f"walls {self.walls}")
        self.rho0, self.c0, self.nu, self.h, self.dx, self.umax = rho0, c0, nu, h, dx, umax
        self.density, self.alpha = density, alpha
        self.gx, self.gy, self.gz = gx, gy, gz
        self.kernel = get_kernel(kernel, self.dim)
        self.shifting = shifting
        self.shift = Shifting(shifting, self.dim, h, dx, c0, umax, self.kernel, rho0=rho0, mach=mach,
                              pb=pb, p_ref=p_ref, ipst_tolerance=ipst_tolerance,
                              ipst_max_iterations=ipst_max_iterations, ipst_interval=ipst_interval)
        if self.shift.body_cap and not callable(getattr(self, "_eos_group", None)):
            raise ValueError(f"{type(self).__name__}: p_ref='body' needs the body's largest |p| after the "
                             "equation of state, which only the GTVF schemes compute")
        if surface_pressure and not free_surface:
            raise ValueError("surface_pressure needs free_surface=True")
        self.free_surface, self.surface_pressure = bool(free_surface), bool(surface_pressure)
        self.cone_radius = cone_radius
        self.wall_alpha = bool(wall_alpha)
        # weak compressibility assumes Mach << 1: a particle at Mach 1 means the run blew up
        self.speed_limit = c0
        skip = {1: ("y", "z", "v", "w"), 2: ("z", "w"), 3: ()}[self.dim]
        self.output_props = tuple(p for p in self.output_props if p not in skip)

    def parameters(self):
        out = super().parameters()
        out.update(self.shift.parameters())
        return out

    def setup_properties(self, arrays):
        for pa in arrays:
            for p in ("p", "ap", "rho", "arho", "au", "av", "aw", "omega", "pavg", "nnbr"):
                if not pa.has(p):
                    pa.add_property(p)
            if pa.name in self.fluids:
                self.shift.setup_properties(pa)
                if self.free_surface:
                    setup_free_surface_properties(pa)
            if pa.name in self.walls:
                for p in ("wij", "ug", "vg", "wg", "uw", "vw", "ww", "uhat", "vhat", "what"):
                    if not pa.has(p):
                        pa.add_property(p)
                if not pa.has("normal"):
                    raise ValueError(f"wall {pa.name!r} needs unit normals 'normal' (stride 3) into the fluid")

    def _sources(self, dest):
        """Neighbours of a fluid in the pressure gradient, the density, the divergence
        terms and the homogenisation: the fluids and the walls."""
        return list(self.fluids) + self.walls

    def _fluid_sources(self, dest):
        """Neighbours of a fluid in the viscous terms (walls enter through their ghost velocity)."""
        return list(self.fluids)

    def _viscous_equations(self, dest):
        """Morris viscosity and artificial viscosity, fluid-fluid, and against the walls with
        the no-slip ghost velocity (eq. 50) and the prescribed wall velocity."""
        src = self._fluid_sources(dest)
        eqs = [LaminarViscosity(dest, src, nu=self.nu),
               ArtificialViscosity(dest, src, alpha=self.alpha, c0=self.c0)]
        if self.walls:
            eqs.append(WallViscosity(dest, self.walls, nu=self.nu, dim=self.dim))
            if self.wall_alpha:
                eqs += [WallArtificialViscosity(dest, [w], alpha=self.alpha, c0=self.c0,
                                                moving=w in self.moving_walls, dim=self.dim)
                        for w in self.walls]
        return eqs

    def _shift_groups(self):
        """The homogenisation's groups after the momentum group (IPST), each medium with its
        own sources (one set of groups when every medium sees the same neighbours)."""
        sources = [self._sources(d) for d in self.fluids]
        if all(s == sources[0] for s in sources):
            return self.shift.groups(self.fluids, sources[0], near_surface=self.free_surface)
        return [g for d, s in zip(self.fluids, sources)
                for g in self.shift.groups([d], s, near_surface=self.free_surface)]

    def _wall_groups(self):
        """Wall pressure (eq. 52) and density (linear equation of state), the no-slip ghost
        velocity (eq. 50) and the free-slip ghost velocities (eqs. 46-49); [] without walls."""
        if not self.walls:
            return []
        eqs = []
        for w in self.walls:
            moving = w in self.moving_walls
            eqs += [WallPressure(w, self.fluids, gx=self.gx, gy=self.gy, gz=self.gz, dim=self.dim),
                    WallDensity(w, eos="linear", rho0=self.rho0, c0=self.c0),
                    WallGhostVelocity(w, self.fluids, slip=False, moving=moving, dim=self.dim),
                    WallSlipVelocity(w, self.fluids, moving=moving, dim=self.dim)]
        return [Group(eqs)]

    def _surface_groups(self):
        """Free-surface particles, normals and h_b (sections 3.4-3.5); [] without."""
        if not self.free_surface:
            return []
        return free_surface_groups(self.fluids, self.walls, rho0=self.rho0, radius=self.cone_radius,
                                   h_b_factor=self.kernel.radius_scale)

    def _surface_filter_groups(self):
        """After the homogenisation: eq. 44 near the free surface; [] without."""
        if self.free_surface and self.shift.active:
            return [Group([SurfaceShiftingFilter(d) for d in self.fluids])]
        return []

    def _surface_pressure_groups(self):
        """p = dp/dt = 0 on free-surface particles (``surface_pressure``); [] without."""
        if self.surface_pressure:
            return [Group([SurfacePressure(d) for d in self.fluids])]
        return []

    def _body_force(self, dest):
        if self.gx or self.gy or self.gz:
            return [BodyForce(dest, gx=self.gx, gy=self.gy, gz=self.gz)]
        return []

    def get_integrator(self):
        step = TransportVelocityStep(self.dim, shift=self.shift.active, pressure=self.evolve_pressure,
                                     density=self.density == "continuity")
        return KickDriftKick(**{name: step for name in self.fluids})

    def _g(self):
        return sqrt(self.gx ** 2 + self.gy ** 2 + self.gz ** 2)

    def get_timestep(self):
        """Adepu & Ramachandran 2021, eq. 61."""
        return transport_timestep(self.h, self.c0, self.umax, self.nu, self._g())

    def stability_bounds(self, dt):
        """The time-step criterion (eq. 61) and weak compressibility (c0 >= 10 U)."""
        return [Bound("--dt", dt, self.get_timestep(), True,
                      "min(0.25 h/(c0 + U), 0.25 h^2/nu, 0.25 sqrt(h/|g|)), Adepu & Ramachandran eq. 61"),
                Bound("--c0", self.c0, 10.0 * self.umax, False,
                      "c0 >= 10 U keeps density variations near 1%")]

    def density_bounds(self):
        """(0.2, 3) rho0, as for the EDAC scheme: far outside anything a stable run reaches."""
        return {f: (0.2 * self.rho0, 3.0 * self.rho0) for f in self.fluids}


class CTVFScheme(TransportVelocityScheme):
    """CTVF for fluids: EDAC pressure with corrections, transport velocity, KDK.

    ``shifting``: one of :data:`sphgen.equations.shifting.SHIFTINGS` ('spst' default).
    ``corrections``: the subset of :data:`CORRECTIONS` that is on (default all):
    'edac' (eq. 26 beyond eq. 22), 'stress' (div(u (x) delta)), 'divergence'
    (-u div delta), 'continuity' (+div(rho delta), only with ``density='continuity'``).
    ``density``: 'summation' (the paper's Taylor-Green and cavity) or 'continuity'
    (eq. 25).  ``bql``: subtract the local mean pressure in the pressure gradient (Basa,
    Quinlan & Lastiwka 2009; not in the paper, off by default).  ``alpha``: Monaghan
    artificial viscosity (eq. 28; 0 removes it).  ``alpha_edac``: eq. 24.  ``gx, gy,
    gz``: body force.  IPST: ``ipst_tolerance``, ``ipst_max_iterations``,
    ``ipst_interval``.  ``divergence_form``: 'delta' (eq. 19's -u div(u~ - u), default) or
    'printed' (eq. 27 as printed, -u div u~).  ``stress_form``: 'symmetric' (eq. 27's A
    term as printed, default) or 'difference' (the divergence of u (x) delta without the
    symmetric form's zeroth-order error; docs/ctvf.md).  ``edac_damping``: 'consistent'
    (default: the damping of eq. 26 as a Laplacian of p) or 'paper' (as printed, with an
    extra 1/rho: nu_edac / rho0).  Other keywords as :class:`TransportVelocityScheme`.

    Free surfaces (``free_surface=True``): every evaluation at new positions identifies
    the free-surface particles and their normals (section 3.4, cone test within
    ``cone_radius`` h) and h_b (section 3.5), and the SPST acceleration loses its normal
    part near the surface and all of it on the surface (eq. 44; with IPST, every
    iteration's shift, eq. 45).  ``surface_pressure``: also hold p = 0 on free-surface particles (not
    in the paper; see docs/ctvf.md).
    """

    def __init__(self, fluids, dim, rho0, c0, nu, h, dx, umax=1.0, shifting="spst",
                 corrections=CORRECTIONS, alpha_edac=0.5, bql=False, divergence_form="delta",
                 stress_form="symmetric", edac_damping="consistent", **kw):
        super().__init__(fluids, dim, rho0, c0, nu, h, dx, umax=umax, shifting=shifting, **kw)
        if edac_damping not in ("paper", "consistent"):
            raise ValueError(f"edac_damping must be 'paper' or 'consistent', got {edac_damping!r}")
        self.edac_damping = edac_damping
        if divergence_form not in DIVERGENCE_FORMS:
            raise ValueError(f"divergence_form must be one of {DIVERGENCE_FORMS}")
        self.divergence_form = divergence_form
        if stress_form not in STRESS_FORMS:
            raise ValueError(f"stress_form must be one of {STRESS_FORMS}")
        self.stress_form = stress_form
        bad = sorted(set(corrections) - set(CORRECTIONS))
        if bad:
            raise ValueError(f"unknown correction {bad[0]!r}; known: {', '.join(CORRECTIONS)}")
        self.alpha_edac, self.bql = alpha_edac, bool(bql)
        on = set(corrections) if self.shift.active else set()
        self.edac_correction = "edac" in on
        self.stress_correction = "stress" in on
        self.divergence_correction = "divergence" in on
        self.continuity_correction = "continuity" in on and self.density == "continuity"

    def nu_edac(self):
        """nu_edac = alpha_edac h c0 / 8 (Adepu & Ramachandran 2021, eq. 24), divided by rho0
        for the printed form of eq. 26 (``edac_damping='paper'``)."""
        nu = self.alpha_edac * self.h * self.c0 / 8.0
        return nu / self.rho0 if self.edac_damping == "paper" else nu

    def _rate_group(self):
        """Evaluation 0, at r^n with u^{n+1/2}, u~^{n+1/2}: dp/dt (eq. 26), drho/dt (eq. 25)."""
        eqs = []
        for d in self.fluids:
            src = self._sources(d)
            if self.density == "continuity":
                eqs += [TransportContinuity(d, src),
                        ContinuityTransportCorrection(d, src, enabled=self.continuity_correction)]
            eqs += [EDACPressureRate(d, src, c0=self.c0, nu_edac=self.nu_edac()),
                    EDACTransportCorrection(d, src, enabled=self.edac_correction)]
        return Group(eqs)

    def _density_groups(self):
        eqs = []
        for d in self.fluids:
            if self.density == "summation":
                eqs.append(SummationDensity(d, self._sources(d)))
            if self.bql:
                eqs.append(AveragePressure(d, self._fluid_sources(d)))
        return [Group(eqs)] if eqs else []

    def _momentum_group(self):
        """Eq. 27: pressure gradient, both transport terms, viscosity, homogenisation."""
        eqs = []
        for d in self.fluids:
            src = self._sources(d)
            eqs += [PressureGradient(d, src, bql=self.bql)] + self._viscous_equations(d)
            eqs += [TransportStress(d, src, enabled=self.stress_correction,
                                    difference=self.stress_form == "difference"),
                    MomentumTransportDivergence(d, src, enabled=self.divergence_correction,
                                                printed=self.divergence_form == "printed")]
            eqs += self._body_force(d) + self.shift.momentum_equations(d, src)
            if self.dim == 2:
                eqs.append(Vorticity2D(d, self._fluid_sources(d)))
        return Group(eqs)

    def get_equations(self):
        second = (self._density_groups() + self._wall_groups() + self._surface_groups()
                  + [self._momentum_group()] + self._shift_groups())
        first = self._wall_groups() + [self._rate_group()] + self._surface_pressure_groups()
        return [first, second + self._surface_filter_groups()]


def elastic_constants(E, poisson, rho0):
    """(c0, G): c0 = sqrt(E / (3 (1 - 2 nu) rho0)) (Adepu & Ramachandran 2021, section 2) and the
    shear modulus G = E / (2 (1 + nu))."""
    if not (E > 0 and rho0 > 0 and -1.0 < poisson < 0.5):
        raise ValueError(f"elastic constants need E > 0, rho0 > 0, -1 < poisson < 0.5; got E={E!r}, "
                         f"poisson={poisson!r}, rho0={rho0!r}")
    return sqrt(E / (3.0 * (1.0 - 2.0 * poisson) * rho0)), E / (2.0 * (1.0 + poisson))


class ElasticSolids:
    """What elastic solids add to a transport-velocity scheme (Adepu & Ramachandran 2021,
    section 3.2): the media (the scheme's ``fluids``) carry the deviatoric stress ``sd``
    (stride 9), its rate ``asd`` and the velocity gradient ``gradv``; evaluation 0 adds
    the velocity gradient (eq. 31; of u~ if ``transport_gradient``, as GTVF) and the
    Hooke-Jaumann rate (eq. 32, its transport correction when ``jaumann_correction``);
    the momentum group is eq. 30 (pressure, deviatoric stress, Monaghan artificial
    viscosity with beta = 0, body force, homogenisation); the drift evolves ``sd``
    (eq. 58); ``clamped`` ({array: gids}) particles are held at u = u~ = 0 by the
    integrator after every stage, ``driven`` ({array: (gids, velocity)}) particles at that
    constant velocity (u = u~: they move with it, a piston); ``yield_stress`` Y0 (if given) limits the updated
    stress to the von Mises surface (section 4.7).  ``contact``: each medium is a body of
    its own (every SPH sum over that medium alone) and the bodies touch only through
    :class:`~sphgen.equations.contact.ContactForce` (push, no tension; d0 = dx, k =
    rho0 c0^2 dx^(dim-2), docs/ctvf.md).  Mix in before the scheme class."""

    transport_gradient = False
    output_props = ("x", "y", "z", "u", "v", "w", "p", "rho", "m", "h", "sd")
    fixed = ()

    def _init_solid(self, G, clamped, jaumann_correction, yield_stress=None, contact=False, driven=None):
        if self.walls:
            raise ValueError(f"{type(self).__name__}: wall arrays for solids (stress extrapolation, eq. 53) "
                             "are not implemented; hold boundary particles with clamped={array: gids}")
        if not G > 0:
            raise ValueError(f"{type(self).__name__}: shear modulus G={G!r} must be > 0")
        self.G = G
        self.clamped = {a: list(g) for a, g in dict(clamped).items()}
        bad = sorted(set(self.clamped) - set(self.fluids))
        if bad:
            raise ValueError(f"{type(self).__name__}: clamped array {bad[0]!r} is not among {self.fluids}")
        self.jaumann_correction = bool(jaumann_correction) and self.shift.active
        if yield_stress is not None and not yield_stress > 0:
            raise ValueError(f"{type(self).__name__}: yield_stress={yield_stress!r} must be > 0")
        self.yield_stress = yield_stress
        if contact and len(self.fluids) < 2:
            raise ValueError(f"{type(self).__name__}: contact needs at least two bodies (arrays), got {self.fluids}")
        self.contact = bool(contact)
        self.driven = {a: (list(g), tuple(float(c) for c in vel)) for a, (g, vel) in dict(driven or {}).items()}
        bad = sorted(set(self.driven) - set(self.fluids))
        if bad:
            raise ValueError(f"{type(self).__name__}: driven array {bad[0]!r} is not among {self.fluids}")
        if any(len(vel) != self.dim for _, vel in self.driven.values()):
            raise ValueError(f"{type(self).__name__}: driven velocities need {self.dim} components")

    def parameters(self):
        out = super().parameters()
        out.update(G=self.G, transport_gradient=self.transport_gradient,
                   jaumann_correction=self.jaumann_correction, yield_stress=self.yield_stress,
                   contact=self.contact)
        return out

    def contact_stiffness(self):
        """k = rho0 c0^2 dx^(dim-2): a contact overlap of delta across one particle spacing
        is a strain delta/dx under the bulk modulus rho0 c0^2, carried by one pair per
        dx^(dim-1) of contact area."""
        return self.rho0 * self.c0 ** 2 * self.dx ** (self.dim - 2)

    @property
    def neighbour_exempt(self):
        """Pairs of bodies whose neighbour count grows from nothing at contact: not a
        sign of clumping (the solver's guard skips them)."""
        return [(d, s) for d in self.fluids for s in self.fluids if self.contact and d != s]

    def _sources(self, dest):
        """With ``contact`` a body sees only itself (and the walls); the ``fixed`` arrays too."""
        if self.contact:
            return [dest] + self.walls + list(self.fixed)
        return super()._sources(dest) + list(self.fixed)

    def setup_properties(self, arrays):
        super().setup_properties(arrays)
        for pa in arrays:
            if pa.name in self.fluids:
                for p in ("sd", "asd", "gradv"):
                    if not pa.has(p):
                        pa.add_property(p, stride=9)
            if pa.name in self.fixed:      # at rest, unstressed: u = u~ = 0, p = 0, sd = 0
                for p in ("u", "v", "w", "uhat", "vhat", "what", "p", "sd"):
                    if p not in pa.data:
                        pa.add_property(p, stride=9 if p == "sd" else 1, default=0.0)

    def _stress_rate_groups(self):
        """Eq. 31, then eq. 32 (rate and transport correction): evaluation 0."""
        grad = [VelocityGradient(d, self._sources(d), transport=self.transport_gradient, dim=self.dim)
                for d in self.fluids]
        rate = []
        for d in self.fluids:
            rate += [HookeJaumannRate(d, G=self.G),
                     JaumannTransportCorrection(d, self._sources(d), enabled=self.jaumann_correction)]
        return [Group(grad), Group(rate)]

    def _momentum_group(self):
        """Eq. 30 with Pi_ab as a pressure-like term (the printed sign would be anti-dissipative)."""
        eqs = []
        for d in self.fluids:
            src = self._sources(d)
            eqs += [PressureGradient(d, src, bql=False), DeviatoricStressForce(d, src),
                    ArtificialViscosity(d, src, alpha=self.alpha, c0=self.c0)]
            if self.contact:
                eqs.append(ContactForce(d, [b for b in self.fluids if b != d], k=self.contact_stiffness(),
                                        d0=self.dx))
            eqs += self._body_force(d) + self.shift.momentum_equations(d, src)
        return Group(eqs)

    def get_equations(self):
        first, second = super().get_equations()
        if self.yield_stress is not None:     # on the stress the drift updated (eq. 58)
            second = [Group([PerfectPlasticity(d, yield_stress=self.yield_stress) for d in self.fluids])] + second
        return [list(first) + self._stress_rate_groups(), second]

    def get_integrator(self):
        step = TransportVelocityStep(self.dim, shift=self.shift.active, pressure=self.evolve_pressure,
                                     density=True, stress=True)
        integrator = KickDriftKick(**{name: step for name in self.fluids})
        held = {p: 0.0 for vel in ("u", "v", "w")[:self.dim] for p in (vel, vel + "hat")}
        for array, gids in self.clamped.items():
            integrator.clamp(array, gids, **held)
        for array, (gids, vel) in self.driven.items():
            integrator.clamp(array, gids, **{p: c for v, c in zip(("u", "v", "w"), vel) for p in (v, v + "hat")})
        return integrator

    def stability_bounds(self, dt):
        """Eq. 62: dt <= 0.25 h / (c0 + |U|)."""
        return [Bound("--dt", dt, self.get_timestep(), True,
                      "0.25 h/(c0 + U), Adepu & Ramachandran eq. 62")]


class CTVFSolidScheme(ElasticSolids, CTVFScheme):
    """CTVF for elastic solids (Adepu & Ramachandran 2021, sections 3.1-3.2).

    ``solids``: the solid arrays; ``E``, ``poisson``, ``rho0``: c0 and G follow
    (:func:`elastic_constants`).  Pressure by EDAC with its correction (eq. 26), density by
    the corrected continuity equation (eq. 25), velocity gradient of the momentum velocity
    (eq. 31), Jaumann rate with its correction (eq. 32), momentum eq. 30 with Monaghan's
    artificial viscosity ``alpha`` (paper: 1), SPST (default) or IPST, kick-drift-kick,
    time step eq. 62 (``umax`` is the largest expected speed).  ``corrections``: subset of
    :data:`SOLID_CORRECTIONS`.  ``free_surface`` (default on): the surface treatment of
    sections 3.4-3.5 as for fluids.  ``clamped``: {array: gids} held fixed; ``driven``:
    {array: (gids, velocity)} moved at a constant velocity.
    ``edac_damping``: 'paper' (default) is the printed eq. 26, whose damping term carries
    an extra 1/rho against the Laplacian (nu_edac / rho0 here: rho stays within 1% of
    rho0); 'consistent' is the fluid scheme's form.  For rho0 = 1000 the consistent
    damping diffuses the bending pressure across a plate within a fraction of a period
    and makes it far too soft (docs/ctvf.md).  ``yield_stress``: Y0 of the elastic,
    perfectly plastic limiter (section 4.7; None: elastic).  ``contact``: the arrays are
    separate bodies that touch through a contact force without tension
    (:class:`ElasticSolids`).
    """

    def __init__(self, solids, dim, rho0, E, poisson, h, dx, umax=1.0, shifting="spst", alpha=1.0,
                 corrections=SOLID_CORRECTIONS, clamped=None, free_surface=True, edac_damping="paper",
                 yield_stress=None, contact=False, driven=None, **kw):
        bad = sorted(set(corrections) - set(SOLID_CORRECTIONS))
        if bad:
            raise ValueError(f"unknown solid correction {bad[0]!r}; known: {', '.join(SOLID_CORRECTIONS)}")
        c0, G = elastic_constants(E, poisson, rho0)
        self.E, self.poisson = E, poisson
        fluid_corrections = tuple(c for c in corrections if c in ("edac", "continuity"))
        super().__init__(solids, dim, rho0, c0, 0.0, h, dx, umax=umax, shifting=shifting,
                         corrections=fluid_corrections, density="continuity", alpha=alpha,
                         free_surface=free_surface, edac_damping=edac_damping, **kw)
        self._init_solid(G, clamped or {}, "jaumann" in corrections, yield_stress, contact, driven)

