"""Corrected transport-velocity formulation (CTVF) for fluids, Adepu & Ramachandran (2021).

Particles move with the transport velocity u~ = u + dt/2 (du/dt)_c (eq. 55), where the
homogenisation acceleration (du/dt)_c comes from any technique of
:mod:`sphgen.equations.shifting` (SPST eq. 36 by default, IPST eqs. 37-41, GTVF, TVF).
The pressure follows the EDAC equation with the CTVF terms (eq. 26), the momentum
equation keeps both transport terms of eq. 19 (eq. 27), and the density is summed
(Taylor-Green, cavity) or evolved by the corrected continuity equation (eq. 25).
Kick-drift-kick (eqs. 54-60); time step eq. 61.  Each correction is a switch, so the
paper's "without corrections" runs are the same scene with the terms switched off.

Fluids only, periodic or open: walls (section 3.6) and solids enter later as extra
sources (``_sources``) and extra groups before the momentum group (``_wall_groups``).
"""
from math import sqrt

from sphgen.equation import Group
from sphgen.integrators import IntegratorStep, KickDriftKick
from sphgen.kernels import get_kernel
from sphgen.scheme import Bound, Scheme

from ..equations.basic import SummationDensity, Vorticity2D
from ..equations.ctvf import (ContinuityTransportCorrection, EDACTransportCorrection,
                              MomentumTransportDivergence)
from ..equations.edac import EDACPressureRate
from ..equations.momentum import ArtificialViscosity, AveragePressure, LaminarViscosity, PressureGradient
from ..equations.shifting import Shifting
from ..equations.transport import TransportContinuity, TransportStress
from ..equations.wcsph import BodyForce

DENSITIES = ("summation", "continuity")
CORRECTIONS = ("edac", "stress", "divergence", "continuity")


class TransportVelocityStep(IntegratorStep):
    """Kick-drift-kick stages with the transport velocity (Adepu & Ramachandran 2021,
    eqs. 54-60).  Switches: ``shift`` (move with u~, else with u), ``pressure`` (evolve p
    by dp/dt, eq. 57), ``density`` (evolve rho by drho/dt, eq. 56)."""

    switches = ("dim", "shift", "pressure", "density")

    def __init__(self, dim, shift=True, pressure=True, density=False):
        self.dim, self.shift = int(dim), int(bool(shift))
        self.pressure, self.density = int(bool(pressure)), int(bool(density))

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

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_uhat, d_vhat, d_what, d_p, d_ap,
               d_rho, d_arho, dt):
        """Drift: density (eq. 56), pressure (eq. 57), positions with u~^{n+1/2} (eq. 59)."""
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
    (:class:`~sphgen.equations.shifting.Shifting`), properties, the KDK integrator, the
    time step (eq. 61) and the guards.  Subclasses give ``get_equations``."""

    output_props = ("x", "y", "z", "u", "v", "w", "p", "rho", "m", "h")
    evolve_pressure = True

    def __init__(self, fluids, dim, rho0, c0, nu, h, dx, umax=1.0, shifting="spst",
                 density="summation", alpha=0.0, mach=None, pb=None, p_ref=None,
                 kernel="quintic", gx=0.0, gy=0.0, gz=0.0, ipst_tolerance=0.02,
                 ipst_max_iterations=10, ipst_interval=1):
        for name, v in (("rho0", rho0), ("c0", c0), ("h", h), ("dx", dx), ("umax", umax)):
            if not v > 0:
                raise ValueError(f"{type(self).__name__}: {name}={v!r} must be > 0")
        if not nu >= 0:
            raise ValueError(f"{type(self).__name__}: nu={nu!r} must be >= 0")
        if density not in DENSITIES:
            raise ValueError(f"density must be one of {', '.join(DENSITIES)}; got {density!r}")
        self.fluids, self.dim = list(fluids), int(dim)
        self.rho0, self.c0, self.nu, self.h, self.dx, self.umax = rho0, c0, nu, h, dx, umax
        self.density, self.alpha = density, alpha
        self.gx, self.gy, self.gz = gx, gy, gz
        self.kernel = get_kernel(kernel, self.dim)
        self.shifting = shifting
        self.shift = Shifting(shifting, self.dim, h, dx, c0, umax, self.kernel, rho0=rho0, mach=mach,
                              pb=pb, p_ref=p_ref, ipst_tolerance=ipst_tolerance,
                              ipst_max_iterations=ipst_max_iterations, ipst_interval=ipst_interval)
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

    def _sources(self, dest):
        """Neighbour arrays of a fluid (walls will join here)."""
        return list(self.fluids)

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
    ``ipst_interval``.  Other keywords as :class:`TransportVelocityScheme`.
    """

    def __init__(self, fluids, dim, rho0, c0, nu, h, dx, umax=1.0, shifting="spst",
                 corrections=CORRECTIONS, alpha_edac=0.5, bql=False, **kw):
        super().__init__(fluids, dim, rho0, c0, nu, h, dx, umax=umax, shifting=shifting, **kw)
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
        """nu_edac = alpha_edac h c0 / 8 (Adepu & Ramachandran 2021, eq. 24)."""
        return self.alpha_edac * self.h * self.c0 / 8.0

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
                eqs.append(AveragePressure(d, self._sources(d)))
        return [Group(eqs)] if eqs else []

    def _momentum_group(self):
        """Eq. 27: pressure gradient, both transport terms, viscosity, homogenisation."""
        eqs = []
        for d in self.fluids:
            src = self._sources(d)
            eqs += [PressureGradient(d, src, bql=self.bql),
                    LaminarViscosity(d, src, nu=self.nu),
                    ArtificialViscosity(d, src, alpha=self.alpha, c0=self.c0),
                    TransportStress(d, src, enabled=self.stress_correction),
                    MomentumTransportDivergence(d, src, enabled=self.divergence_correction)]
            eqs += self._body_force(d) + self.shift.momentum_equations(d, src)
            if self.dim == 2:
                eqs.append(Vorticity2D(d, src))
        return Group(eqs)

    def get_equations(self):
        src = self._sources(self.fluids[0])
        second = self._density_groups() + [self._momentum_group()] + self.shift.groups(self.fluids, src)
        return [[self._rate_group()], second]
