"""Symplectic weakly compressible SPH of Kincl's thesis, chapter 1 (O. Kincl (2023), "Extension
of smoothed particle hydrodynamics based on Poisson brackets", Charles University, §1.2-1.6):
the method of its dam break (§1.6, the "SYM" curve of Fig. 1.3).

* density by kernel summation with a constant fixed at t = 0 so that rho = rho0 there (the
  stress-free initial state of a free surface; eq. 1.14), for fluid and walls alike;
* the Tait equation of state (eq. 1.15, gamma = 7);
* the symmetric pressure force -sum_b m_b (p_a/rho_a^2 + p_b/rho_b^2) grad w_ab (eq. 1.13)
  and gravity;
* physical viscosity mu = rho0 nu in the molecular-dynamics form (eq. 1.81, with the vector
  factor grad w_ab the print omits), :class:`~sphgen.equations.md_viscosity.MDViscosity`;
* the viscous Verlet step (eq. 1.82, with the dt the print omits in the viscous update):
  kick dt/2 with the conservative force, drift dt/2, neighbour update, viscous update
  v += dt a_visc at the half step, drift dt/2, neighbour update, force, kick dt/2
  (:class:`sphgen.splitting.ViscousVerlet`).  With nu = 0 the viscous update is absent from
  the generated code and the step is Verlet (1.78);
* dummy walls (§1.6): "identical to fluid particles, except their velocity and positions are
  fixed" -- they take part in every sum, carry their own summation density, constant and
  Tait pressure, and have v = 0 in the viscous sum (no slip); ceil(2h/dr) layers (eq. 1.83).

Kernel: the Wendland C2 kernel (eq. 1.6 with the factor (1 + 2r/h), support 2h).  The
thesis gives neither h, dr, c nor dt for the dam break; see docs/shtc.md ("Thesis §1.6 dam
break") for the values taken from the authors' code and why.
"""
import math

from sphgen.equation import Group
from sphgen.errors import InputError
from sphgen.kernels import get_kernel
from sphgen.scheme import Bound, Scheme
from sphgen.splitting import KickDriftStep, Verlet, ViscousVerlet

from ..equations.basic import SummationDensityWithConstant
from ..equations.md_viscosity import MDViscosity
from ..equations.momentum import PressureGradient
from ..equations.shtc_density import DensityConstant
from ..equations.wcsph import BodyForce, TaitEOS
from .wcsph import WCSPHScheme, tait_internal_energy


class ThesisViscousVerlet(ViscousVerlet):
    """Kincl (2023), eq. 1.82 (:class:`sphgen.splitting.ViscousVerlet`) on this scheme's equation
    sets: 0 = density and the viscous acceleration at the half step, 1 = state and force, 2 =
    the density constants, run once before the first force evaluation.  Two neighbour-list
    builds per step, as the thesis says; with nu = 0 the scheme passes Verlet's sequence
    (eq. 1.78: one evaluation and one build per step)."""

    n_evaluations = 3
    force_set, dissipative_set = 1, 0
    startup_sets = (2,)


class SymplecticSPHScheme(Scheme):
    """Kincl (2023), chapter 1: summation density with constant, Tait, viscous Verlet, dummy walls.

    ``fluids`` are integrated; ``walls`` are dummy particles at rest.  ``rho0``, sound speed
    ``c0`` (Tait B = rho0 c0^2/7), kinematic viscosity ``nu`` (0 removes the viscous update),
    smoothing length ``h`` (support 2h of the Wendland kernel), gravity ``gx, gy, gz``, the
    viscosity regulariser ``eta2`` (default 0.04 h^2, the authors' code), time step
    dt = ``cfl`` h/c0 (default 0.2: the authors' dt = 0.1 (2h)/c).
    """

    def __init__(self, fluids, walls, dim, rho0, c0, h, nu=0.0, gx=0.0, gy=0.0, gz=0.0, eta2=None,
                 cfl=0.2, gamma=7.0, kernel="wendland"):
        for name, v in (("rho0", rho0), ("c0", c0), ("h", h), ("cfl", cfl), ("gamma", gamma)):
            if not (isinstance(v, (int, float)) and math.isfinite(v) and v > 0):
                raise InputError(f"SymplecticSPHScheme: {name}={v!r} must be a positive finite number")
        if not (math.isfinite(nu) and nu >= 0):
            raise InputError(f"SymplecticSPHScheme: nu={nu!r} must be a non-negative finite number")
        if not fluids:
            raise InputError("SymplecticSPHScheme: needs at least one fluid array")
        self.fluids, self.walls, self.dim = list(fluids), list(walls), dim
        self.rho0, self.c0, self.h, self.nu, self.cfl, self.gamma = rho0, c0, h, nu, cfl, gamma
        self.gx, self.gy, self.gz = gx, gy, gz
        self.eta2 = 0.04 * h * h if eta2 is None else float(eta2)
        self.B = rho0 * c0 * c0 / gamma
        self.kernel = get_kernel(kernel, dim)
        self.speed_limit = c0
        skip = {1: ("y", "z", "v", "w"), 2: ("z", "w"), 3: ()}[dim]
        self.output_props = tuple(p for p in ("x", "y", "z", "u", "v", "w", "p", "rho", "m", "h")
                                  if p not in skip)

    def setup_properties(self, arrays):
        for pa in arrays:
            if pa.name not in self.fluids + self.walls:
                continue
            for p in ("p", "crho", "pavg", "au", "av", "aw", "au_visc", "av_visc", "aw_visc"):
                if not pa.has(p):
                    pa.add_property(p)
            for c in ("x", "y", "z", "u", "v", "w"):
                if c not in pa.data:
                    pa.add_property(c, default=0.0)

    def get_equations(self):
        every = self.fluids + self.walls
        density = Group([SummationDensityWithConstant(d, every) for d in every])
        eos = Group([TaitEOS(d, None, rho0=self.rho0, c0=self.c0, gamma=self.gamma) for d in every])
        force = []
        for d in self.fluids:
            force += [PressureGradient(d, every, bql=False), BodyForce(d, gx=self.gx, gy=self.gy, gz=self.gz)]
        viscous = [density]
        if self.nu > 0:
            viscous.append(Group([MDViscosity(d, every, dim=self.dim, mu=self.rho0 * self.nu, eta2=self.eta2)
                                  for d in self.fluids]))
        start = [Group([DensityConstant(d, every, rho0=self.rho0) for d in every])]
        return [viscous, [density, eos, Group(force)], start]

    def get_integrator(self):
        step = KickDriftStep(self.dim, viscous=self.nu > 0)
        return ThesisViscousVerlet(None if self.nu > 0 else Verlet.sequence, **{f: step for f in self.fluids})

    def get_timestep(self):
        """dt = cfl h/c0 (cfl = 0.2: the authors' code's 0.1 times the support radius over c)."""
        return self.cfl * self.h / self.c0

    def stability_bounds(self, dt):
        """Acoustic CFL 0.25 h/c0 (Monaghan 1992, eq. 10.4) and Morris et al.'s viscous limit."""
        limit = 0.25 * self.h / self.c0
        if self.nu > 0:
            limit = min(limit, 0.125 * self.h * self.h / self.nu)
        return [Bound("--dt", dt, limit, True, "dt <= min(0.25 h/c0, 0.125 h^2/nu) (Monaghan 1992 eq. 10.4; "
                      "Morris, Fox & Zhu 1997 eq. 20)")]

    def density_bounds(self):
        """A Tait fluid at Mach <= 0.1 stays within a few % of rho0: a factor 2 is a blow-up."""
        return {f: (0.5 * self.rho0, 2.0 * self.rho0) for f in self.fluids}

    def energies(self, arrays):
        """{'kinetic', 'potential', 'internal', 'total'}: the fluid's (as
        :meth:`WCSPHScheme.energies`) plus the walls' Tait internal energy -- the walls'
        summation density depends on the fluid's positions, so it is part of the energy that
        the scheme conserves (Kincl 2023, eq. 1.76)."""
        e = WCSPHScheme.energies(self, arrays)
        for pa in arrays:
            if pa.name in self.walls and pa.n:
                e["internal"] += float((pa.m * tait_internal_energy(pa.rho, self.rho0, self.B, self.gamma)).sum())
        e["total"] = e["kinetic"] + e["potential"] + e["internal"]
        return e
