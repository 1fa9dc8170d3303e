"""Generalised transport-velocity formulation (GTVF) of Zhang, Hu & Adams (2017), for fluids:
the baseline the CTVF of Adepu & Ramachandran (2021) improves on.

* density: continuity with the transport velocity, d~rho/dt = rho sum_b V_b u~_ab . grad W
  (Zhang et al. eq. 12), re-initialised every step by the Shepard-corrected summation
  (eq. 13); or plain summation density (``density='summation'``);
* pressure: the linear equation of state p = c0^2 (rho - rho0) (the Tait form with
  gamma = 1, as PySPH's GTVF runs it);
* momentum: symmetric pressure gradient, the transport stress div(u (x) (u~ - u))
  (eq. 17), Morris viscosity (which equals Zhang et al.'s inter-particle-averaged form
  for kinematic viscosity), optional artificial viscosity;
* homogenisation: their (du/dt)_c = -p0_a sum_b m_b/rho_a^2 grad W(r_ab, h/2),
  p0_a = min(10|p_a|, p_ref) by default, or any other technique of
  :mod:`sphgen.equations.shifting` (the paper's section 4.4 runs GTVF with SPST);
* kick-drift-kick as in the CTVF scheme, and its time step (Adepu & Ramachandran eq. 61)
  so that the two schemes differ only in their equations.

No CTVF corrections: no -u div(u~ - u) term, and the pressure follows the density.
Walls as in the CTVF scheme (Adami et al. 2012 ghost particles, free-slip ghost
velocities in the continuity and transport terms, no-slip in the viscous term).

Elastic solids: :class:`GTVFSolidScheme` (Zhang, Hu & Adams 2017, section on elastic
dynamics): the pieces of :class:`~sphgen.schemes.ctvf.ElasticSolids` with the velocity
gradient of the transport velocity, no correction terms, pressure from p = c0^2 (rho -
rho0), density by continuity with u~; their homogenisation ('gtvf', Fig. 18a of Adepu &
Ramachandran 2021) or SPST ('spst', Fig. 18b).
"""
from sphgen.equation import Group

from ..equations.basic import SummationDensity, Vorticity2D
from ..equations.density import CorrectedSummationDensity, SaveDensity
from ..equations.momentum import PressureGradient
from ..equations.transport import TransportContinuity, TransportStress
from ..equations.wcsph import TaitEOS
from .ctvf import ElasticSolids, TransportVelocityScheme, elastic_constants


class GTVFScheme(TransportVelocityScheme):
    """GTVF for fluids (Zhang, Hu & Adams 2017).

    ``shifting`` defaults to 'gtvf' (their homogenisation, ``p_ref`` = rho0 c0^2 by
    default, kernel gradient at h/2); ``density`` 'continuity' (their eqs. 12-13,
    default) or 'summation'.  Other keywords, the time step, the stability and density
    bounds are those of :class:`~sphgen.schemes.ctvf.TransportVelocityScheme`.
    """

    evolve_pressure = False

    def __init__(self, fluids, dim, rho0, c0, nu, h, dx, umax=1.0, shifting="gtvf",
                 density="continuity", **kw):
        super().__init__(fluids, dim, rho0, c0, nu, h, dx, umax=umax, shifting=shifting,
                         density=density, **kw)

    def setup_properties(self, arrays):
        super().setup_properties(arrays)
        for pa in arrays:
            for p in ("rhostar", "shepard"):
                if not pa.has(p):
                    pa.add_property(p)

    def _rate_groups(self):
        """Evaluation 0: drho/dt with u~ (Zhang et al. eq. 12), or nothing to do."""
        if self.density != "continuity":
            return []
        return [Group([TransportContinuity(d, self._sources(d)) for d in self.fluids])]

    def _density_groups(self):
        """Density (eq. 13, or summation), then p = c0^2 (rho - rho0)."""
        groups = []
        if self.density == "continuity":
            groups += [Group([SaveDensity(d) for d in self.fluids + self.walls]),
                       Group([CorrectedSummationDensity(d, self._sources(d)) for d in self.fluids])]
        else:
            groups.append(Group([SummationDensity(d, self._sources(d)) for d in self.fluids]))
        groups.append(self._eos_group())
        return groups

    def _eos_group(self):
        """p = c0^2 (rho - rho0), then (p_ref 'body') the body's largest |p|, the cap of p0."""
        eqs = [TaitEOS(d, rho0=self.rho0, c0=self.c0, gamma=1.0) for d in self.fluids]
        return Group(eqs + [e for d in self.fluids for e in self.shift.pressure_equations(d)])

    def _momentum_group(self):
        """Zhang et al. eq. 17: pressure gradient, transport stress, viscosity, (du/dt)_c."""
        eqs = []
        for d in self.fluids:
            src = self._sources(d)
            eqs += [PressureGradient(d, src, bql=False)] + self._viscous_equations(d)
            eqs += [TransportStress(d, src, enabled=self.shift.active)]
            eqs += self._body_force(d) + self.shift.momentum_equations(d, src)
            if self.dim == 2:
                eqs.append(Vorticity2D(d, self._fluid_sources(d)))
        return Group(eqs)

    def get_equations(self):
        second = (self._density_groups() + self._wall_groups() + self._surface_groups()
                  + [self._momentum_group()] + self._shift_groups()
                  + self._surface_filter_groups())
        rates = self._rate_groups()
        return [(self._wall_groups() + rates) if rates else [], second]


class GTVFSolidScheme(ElasticSolids, GTVFScheme):
    """GTVF for elastic solids (Zhang, Hu & Adams 2017), the baseline of Adepu & Ramachandran
    (2021), Fig. 18.  ``solids``, ``E``, ``poisson``, ``rho0`` as
    :class:`~sphgen.schemes.ctvf.CTVFSolidScheme`; ``shifting`` 'gtvf' (their
    homogenisation, p_ref = rho0 c0^2, the bulk modulus) or 'spst'; ``free_surface``
    (default off: the original GTVF has no surface detection) adds the surface treatment
    of the CTVF (sections 3.4-3.5) to the shifting.  Density by continuity with u~ (no
    summation re-initialisation: a solid with free surfaces), p = c0^2 (rho - rho0).
    ``contact``: separate bodies touching without tension, as the CTVF solid.
    ``fixed``: names of arrays of particles at rest and unstressed (u = u~ = 0, p = 0,
    deviatoric stress 0, rho = rho0 as given), neighbours of the solids in every sum and
    never updated: a clamp of fixed wall particles around a body."""

    transport_gradient = True

    def __init__(self, solids, dim, rho0, E, poisson, h, dx, umax=1.0, shifting="gtvf", alpha=1.0,
                 clamped=None, yield_stress=None, contact=False, driven=None, fixed=(), **kw):
        c0, G = elastic_constants(E, poisson, rho0)
        self.E, self.poisson = E, poisson
        super().__init__(solids, dim, rho0, c0, 0.0, h, dx, umax=umax, shifting=shifting,
                         density="continuity", alpha=alpha, **kw)
        self._init_solid(G, clamped or {}, False, yield_stress, contact, driven)
        self.fixed = tuple(fixed)
        if set(self.fixed) & set(self.fluids):
            raise ValueError(f"{type(self).__name__}: fixed arrays {self.fixed} must not be among the solids")

    def _density_groups(self):
        """p = c0^2 (rho - rho0), rho from the continuity equation."""
        return [self._eos_group()]
