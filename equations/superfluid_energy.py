"""The linear model of helium-4 near a reference temperature T0 (Kincl 2023, thesis sec. 3.3).

Specific energy e(rho, s, v, v_s) = e_kin + e_int with

* e_kin = v^2/2 + rho_s/(2 rho_n) |v - v_s|^2  (eq. 3.23; rho_n, rho_s are the relative
  densities rho_n/rho, rho_s/rho),
* rho_n = rho_n0 + gamma (s - s0), rho_s = 1 - rho_n  (eq. 3.25),
* e_int = c1^2 (ln(rho/rho0) + rho0/rho - 1) + T0 ((s - s0) + (s - s0)^2/(2 C_V))  (eq. 3.32),
  zero at (rho0, s0),

so that p = c1^2 (rho - rho0) (eq. 3.27), T = T0 (1 + (s - s0)/C_V) - gamma v_ns^2/2
(eq. 3.30), and de = v_n . dv - rho_s v_ns . dv_s + T ds + p/rho^2 drho (eq. 3.14), with
v_ns = (v - v_s)/rho_n and v_n = (v - rho_s v_s)/rho_n (eqs. 3.1-3.3).  C_V follows from the
second-sound speed, c2^2 = rho_s0 T0 s0^2/(rho_n0 C_V) (eq. 3.31).

The three per-particle formulas the compiled equations need are ``@helper`` functions of
plain arithmetic, so the same code runs compiled, in the Python evaluator and on numpy
arrays (:class:`LinearHelium` calls them).  Energies and the derivatives of eq. 3.14 are
numpy methods of :class:`LinearHelium`.

The thesis prints none of the constants (it names Donnelly & Barenghi 1998 as their
source and T0 = 1.65 K for the fountain).  The two presets are the values of the
authors' public code (Kincl, SmoothedParticles.jl, examples/superfluids), which
quotes the same tables: :data:`HELIUM_1_9K` for the second-sound wave, :data:`HELIUM_1_65K`
for the fountain.  c1 = 40 m/s is a numerical first-sound speed (the real one is
about 230 m/s): the fountain and the second-sound wave are far slower, and the time step
scales with 1/c1.
"""
from dataclasses import dataclass

import numpy as np

from sphgen.equation import helper


@helper
def normal_fraction(s=0.0, s0=0.0, rhon0=0.0, gamma=0.0):
    """rho_n/rho = rho_n0 + gamma (s - s0) (Kincl 2023, eq. 3.25)."""
    return rhon0 + gamma * (s - s0)


@helper
def linear_pressure(rho=0.0, rho0=0.0, c1=0.0):
    """p = c1^2 (rho - rho0) (Kincl 2023, eq. 3.27)."""
    return c1 * c1 * (rho - rho0)


@helper
def linear_temperature(s=0.0, vns2=0.0, T0=0.0, s0=0.0, cv=1.0, gamma=0.0):
    """T = T0 (1 + (s - s0)/C_V) - gamma |v_ns|^2 / 2 (Kincl 2023, eq. 3.30)."""
    return T0 * (1.0 + (s - s0) / cv) - 0.5 * gamma * vns2


def _dot(a, b):
    return np.sum(np.asarray(a) * np.asarray(b), axis=-1)


@dataclass(frozen=True)
class LinearHelium:
    """Constants of the linear model (SI units): T0 [K], rho0 [kg/m^3], s0 [J/(kg K)],
    rhon0 = rho_n/rho at T0, c1 and c2 [m/s], gamma = d(rho_n/rho)/ds [kg K/J].

    Velocities in the numpy methods are arrays whose last axis is the component.
    """

    T0: float
    rho0: float
    s0: float
    rhon0: float
    c1: float
    c2: float
    gamma: float

    def __post_init__(self):
        for name in ("T0", "rho0", "s0", "c1", "c2"):
            if not getattr(self, name) > 0:
                raise ValueError(f"LinearHelium: {name}={getattr(self, name)!r} must be > 0")
        if not 0.0 < self.rhon0 < 1.0:
            raise ValueError(f"LinearHelium: rhon0={self.rhon0!r} must be in (0, 1)")
        if not np.isfinite(self.gamma):
            raise ValueError(f"LinearHelium: gamma={self.gamma!r} must be finite")

    @classmethod
    def from_slope(cls, T0, rho0, s0, rhon0, c1, c2, drhon_dT):
        """The model with gamma from the slope d(rho_n/rho)/dT at T0: gamma = slope T0/C_V
        (dT/ds = T0/C_V at v_ns = 0, eq. 3.28)."""
        rhos0 = 1.0 - rhon0
        cv = rhos0 * T0 * s0 * s0 / (rhon0 * c2 * c2)
        return cls(T0=T0, rho0=rho0, s0=s0, rhon0=rhon0, c1=c1, c2=c2, gamma=drhon_dT * T0 / cv)

    # ------------------------------------------------------------ constants
    @property
    def rhos0(self):
        return 1.0 - self.rhon0

    @property
    def cv(self):
        """C_V = rho_s0 T0 s0^2 / (rho_n0 c2^2), eq. 3.31 solved for C_V."""
        return self.rhos0 * self.T0 * self.s0 * self.s0 / (self.rhon0 * self.c2 * self.c2)

    @property
    def drhon_dT(self):
        """d(rho_n/rho)/dT = gamma C_V / T0 (the slope of Fig. 3.1 at T0)."""
        return self.gamma * self.cv / self.T0

    def parameters(self):
        """The numbers the compiled equations take (keyword arguments)."""
        return dict(T0=self.T0, rho0=self.rho0, s0=self.s0, rhon0=self.rhon0, c1=self.c1,
                    cv=self.cv, gamma=self.gamma)

    # ------------------------------------------------------------ fields
    def rhon(self, s):
        return normal_fraction(np.asarray(s, dtype=float), self.s0, self.rhon0, self.gamma)

    def rhos(self, s):
        return 1.0 - self.rhon(s)

    def counterflow(self, s, v, vs):
        """v_ns = v_n - v_s = (v - v_s) / rho_n (eqs. 3.1-3.3)."""
        return (np.asarray(v) - np.asarray(vs)) / self.rhon(s)[..., None]

    def normal_velocity(self, s, v, vs):
        """v_n = (v - rho_s v_s) / rho_n (eq. 3.1)."""
        return (np.asarray(v) - self.rhos(s)[..., None] * np.asarray(vs)) / self.rhon(s)[..., None]

    def pressure(self, rho):
        return linear_pressure(np.asarray(rho, dtype=float), self.rho0, self.c1)

    def temperature(self, s, v, vs):
        vns = self.counterflow(s, v, vs)
        return linear_temperature(np.asarray(s, dtype=float), _dot(vns, vns), self.T0, self.s0,
                                  self.cv, self.gamma)

    # ------------------------------------------------------------ energies (per unit mass)
    def kinetic_energy(self, s, v, vs):
        """e_kin = v^2/2 + rho_s/(2 rho_n) |v - v_s|^2 (eq. 3.23): coflow and counterflow."""
        d = np.asarray(v) - np.asarray(vs)
        return 0.5 * _dot(v, v) + 0.5 * self.rhos(s) / self.rhon(s) * _dot(d, d)

    def compression_energy(self, rho):
        """c1^2 (ln(rho/rho0) + rho0/rho - 1), the rho part of eq. 3.32."""
        r = np.asarray(rho, dtype=float) / self.rho0
        return self.c1 * self.c1 * (np.log(r) + 1.0 / r - 1.0)

    def heat_energy(self, s):
        """T0 ((s - s0) + (s - s0)^2/(2 C_V)), the s part of eq. 3.32."""
        ds = np.asarray(s, dtype=float) - self.s0
        return self.T0 * (ds + 0.5 * ds * ds / self.cv)

    def energy(self, rho, s, v, vs):
        """e(rho, s, v, v_s), eqs. 3.23 + 3.32."""
        return self.kinetic_energy(s, v, vs) + self.compression_energy(rho) + self.heat_energy(s)

    def energy_derivatives(self, rho, s, v, vs):
        """The partial derivatives eq. 3.14 states: (de/dv, de/dv_s, de/ds, de/drho) =
        (v_n, -rho_s v_ns, T, p/rho^2)."""
        rho = np.asarray(rho, dtype=float)
        return (self.normal_velocity(s, v, vs), -self.rhos(s)[..., None] * self.counterflow(s, v, vs),
                self.temperature(s, v, vs), self.pressure(rho) / (rho * rho))

    def second_sound_speed(self):
        """c2 from eq. 3.31 with this C_V (equals c2 by construction)."""
        return float(np.sqrt(self.rhos0 * self.T0 * self.s0 ** 2 / (self.rhon0 * self.cv)))


HELIUM_1_9K = LinearHelium.from_slope(T0=1.9, rho0=145.4684, s0=725.5, rhon0=61.03 / 145.4684,
                                      c1=40.0, c2=18.83, drhon_dT=1.17)
"""He II at 1.9 K (second sound, Kincl 2023 sec. 3.5): rho_n = 61.03 of rho = 145.4684 kg/m^3,
s0 = 725.5 J/(kg K), c2 = 18.83 m/s, d(rho_n/rho)/dT = 1.17 /K (C_V = 3902 J/(kg K),
gamma = 5.697e-4 kg K/J); c1 = 40 m/s numerical.  Values of the authors' code."""

HELIUM_1_65K = LinearHelium.from_slope(T0=1.65, rho0=145.2352, s0=335.0, rhon0=28.09 / 145.2352,
                                       c1=40.0, c2=20.37, drhon_dT=0.66)
"""He II at 1.65 K (fountain, Kincl 2023 sec. 3.6): rho_n = 28.09 of rho = 145.2352 kg/m^3,
s0 = 335 J/(kg K), c2 = 20.37 m/s, d(rho_n/rho)/dT = 0.66 /K (C_V = 1861 J/(kg K),
gamma = 5.851e-4 kg K/J); c1 = 40 m/s numerical.  Values of the authors' code; the thesis'
"rho = 125 kg/m^3" is not He II at this temperature."""
