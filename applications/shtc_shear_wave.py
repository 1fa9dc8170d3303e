"""Decaying shear wave in a periodic box: the viscosity that SHTC-SPH's fluid regime (Kincl,
Peshkov, Pavelka & Klika (2023), eqs. 24c, 25, 29) actually produces.

u = U sin(2 pi y), v = 0 in the periodic unit box, A = I at t = 0; the Navier-Stokes limit
(tau = 6 nu/cs^2, eq. 29) gives u = U e^{-k^2 nu t} sin(k y), k = 2 pi.  The amplitude is
projected on sin(k y) over the particles, and ln(amplitude) is fitted linearly over the
second half of the run: nu_measured = -slope/k^2.  ``results.json`` reports nu_measured/nu
beside the step's predicted factor (``viscosity_factor`` of schemes/shtc.py: steady simple
shear, linearised).  Square lattice (the periodic box needs whole rows), c0 = 20.  Not a
test of the paper; a check of the scheme's viscosity that the cavity's accuracy rests on.
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.nnps import Domain
from sphgen.particles import ParticleArray

from ..schemes.shtc import SHTCScheme, viscosity_factor

RHO0, C0, U0, HDR = 1.0, 20.0, 0.1, 1.5
K = 2.0 * math.pi


def fluid_relaxation_time(o):
    """tau = 6 nu/cs^2 (Kincl et al. (2023), eq. 29) from the options --nu and --cs, checked."""
    for name in ("nu", "cs"):
        if not (math.isfinite(getattr(o, name)) and getattr(o, name) > 0):
            raise InputError(f"--{name} must be positive, got {getattr(o, name)}")
    return 6.0 * o.nu / o.cs ** 2


def amplitude(y, u, m):
    """Projection 2 sum m u sin(k y) / sum m of u on the wave sin(k y)."""
    return float(2.0 * np.sum(m * u * np.sin(K * y)) / np.sum(m))


def fitted_viscosity(t, a):
    """-slope/k^2 of a least-squares line through (t, ln a)."""
    return float(-np.polyfit(np.asarray(t), np.log(np.asarray(a)), 1)[0] / K ** 2)


class SHTCShearWave(Application):
    """Decaying shear wave, periodic unit box, SHTC-SPH fluid: the measured viscosity."""

    tf = 0.5
    pfreq = 100000
    dim = 2
    history_columns = ("t", "amplitude")
    error_key = "viscosity_error"

    def add_user_options(self, group):
        group.add_argument("--nx", type=int, default=40, help="particles per side (default %(default)s)")
        group.add_argument("--nu", type=float, default=0.05, help="kinematic viscosity (default %(default)s)")
        group.add_argument("--cs", type=float, default=10.0, help="shear sound speed (default %(default)s)")

    def consume_user_options(self, o):
        if o.nx < 8:
            raise InputError(f"--nx must be at least 8, got {o.nx}")
        self.dr = 1.0 / o.nx
        self.tau = fluid_relaxation_time(o)

    def create_particles(self):
        dr = self.dr
        x, y = np.mgrid[dr / 2:1:dr, dr / 2:1:dr]
        x, y = x.ravel(), y.ravel()
        n = x.size
        return [ParticleArray("fluid", x=x, y=y, u=self.initial_velocity(y), v=np.zeros(n), m=np.full(n, RHO0 * dr * dr),
                              h=np.full(n, HDR * dr), rho=np.full(n, RHO0))]

    def initial_velocity(self, y):
        """u(y) at t = 0: the wave U sin(k y)."""
        return U0 * np.sin(K * y)

    def create_domain(self):
        return Domain(0.0, 1.0, 0.0, 1.0, periodic_in_x=True, periodic_in_y=True)

    def create_scheme(self):
        return SHTCScheme(["fluid"], 2, rho0=RHO0, c0=C0, cs=self.options.cs, h=HDR * self.dr, dr=self.dr,
                          tau=self.tau, model="dprz", cp=0.0)

    def post_step(self, solver):
        f = self.scene.by_name["fluid"]
        self.history.append([solver.t, amplitude(f.y, f.u, f.m)])

    def history_meta(self):
        o = self.options
        return {"nx": o.nx, "nu": o.nu, "cs": o.cs, "tau": self.tau}

    def post_process(self, outdir):
        """results.json: nu_measured / nu and the predicted viscosity_factor."""
        rows = np.array(self.history)
        if rows.ndim != 2 or rows.shape[0] < 2:
            raise InputError("shtc_shear_wave: the decay needs two samples of the amplitude or more "
                             "(run at least two steps)")
        t, a = rows[:, 0], rows[:, 1]
        late = t >= 0.5 * t[-1]
        nu = self.options.nu
        ratio = fitted_viscosity(t[late], a[late]) / nu
        dt_over_tau = self.solver.dt / self.tau
        results = {"t": float(t[-1]), "nx": self.options.nx, "nu": nu, "cs": self.options.cs, "tau": self.tau,
                   "dt_over_tau": dt_over_tau, "viscosity_ratio": ratio,
                   "viscosity_factor": viscosity_factor(dt_over_tau),
                   "viscosity_error": abs(ratio - 1.0), "amplitude_end": float(a[-1]),
                   "amplitude_exact_end": float(U0 * math.exp(-K ** 2 * nu * t[-1]))}
        io.write_json(os.path.join(outdir, "results.json"), results)
        print(f"shtc_shear_wave: dt/tau = {dt_over_tau:.4g}  nu_measured/nu = {ratio:.4f}  "
              f"(viscosity_factor {results['viscosity_factor']:.4f})")
        return results
