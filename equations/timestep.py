"""Per-particle time-step limits written by equations, read by the adaptive solver."""
from math import sqrt

from sphgen.equation import Equation


class TimeStepLimits(Equation):
    """dt_cfl = h/(c0 + |u|), dt_visc = h^2/nu, dt_force = sqrt(h/|a|) (Adepu & Ramachandran
    (2024), eq. 61, without its 0.25 safety factors, which the solver's ``cfl`` applies).
    Place it after the momentum equations; the solver takes ``cfl * min`` over all particles."""

    positive = ("c0",)
    nonnegative = ("nu",)

    def initialize(self, d_idx, d_h, d_u, d_v, d_w, d_au, d_av, d_aw, d_dt_cfl):
        h = d_h[d_idx]
        speed = sqrt(d_u[d_idx] * d_u[d_idx] + d_v[d_idx] * d_v[d_idx] + d_w[d_idx] * d_w[d_idx])
        dt = h / (self.c0 + speed)
        if self.nu > 0.0:
            dt = min(dt, h * h / self.nu)
        acc = sqrt(d_au[d_idx] * d_au[d_idx] + d_av[d_idx] * d_av[d_idx] + d_aw[d_idx] * d_aw[d_idx])
        if acc > 0.0:
            dt = min(dt, sqrt(h / acc))
        d_dt_cfl[d_idx] = dt
