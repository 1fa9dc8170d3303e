"""Response to an impulse of shear (Kincl's thesis (2023), sec. 2.2, analytic only there): a
smooth shear layer in SHTC-SPH's fluid regime against the linearised SHTC solution.

Doubly periodic unit box, u = U exp(-(y - 1/2)^2 / (2 w^2)), v = 0, A = I at t = 0 (the
set-up of the shear wave, ``shtc_shear_wave``, with this profile).  Linearised about A = I,
SHTC gives the telegraph equation (nu/cs^2) v_tt + v_t = nu v_yy (thesis eqs. 2.24-2.25),
whose Green function is thesis eq. 2.26; u(y, t) is the initial profile convolved with it.
In the periodic box that convolution is done per Fourier mode k = 2 pi n (the same
solution, with the periodic images included): each mode obeys
(nu/cs^2) a'' + a' + nu k^2 a = 0 with a'(0) = 0 (sigma = 0 at t = 0, eq. 2.24).  The
Navier-Stokes limit (cs -> infinity, thesis eq. 2.16) is a = exp(-nu k^2 t).

``results.json``: the RMS difference over the particles between u and the telegraph solution
at their y, over U (``profile_error``; the digest proposes < 5 %), the same against
Navier-Stokes (``profile_error_navier_stokes``), dt/tau and the step's ``viscosity_factor``.
Plot: profile.png (u against y at three times, both analytic solutions).
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.errors import InputError

from ..schemes.shtc import viscosity_factor
from .shtc_shear_wave import SHTCShearWave

U_LAYER = 0.02        # small: the linearisation needs sigma ~ U/cs << 1
FOURIER_SAMPLES = 4096


def mode_factors(k, t, nu, cs):
    """a_k(t) of (nu/cs^2) a'' + a' + nu k^2 a = 0, a(0) = 1, a'(0) = 0 (thesis eq. 2.25 per mode)."""
    if math.isinf(cs):
        return np.exp(-nu * k * k * t)
    theta = nu / cs ** 2
    root = np.sqrt((1.0 - 4.0 * theta * nu * k * k).astype(complex))
    l1, l2 = (-1.0 + root) / (2.0 * theta), (-1.0 - root) / (2.0 * theta)
    double = np.abs(l1 - l2) < 1e-12 / theta
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (l2 * np.exp(l1 * t) - l1 * np.exp(l2 * t)) / (l2 - l1)
    lam = -1.0 / (2.0 * theta)
    a = np.where(double, (1.0 - lam * t) * np.exp(lam * t), a)
    return a.real


def layer_solution(profile, y, t, nu, cs):
    """u(y, t) in the periodic unit interval from u(y, 0) = ``profile`` (a function):
    the initial profile's Fourier series, each mode scaled by ``mode_factors``."""
    grid = np.arange(FOURIER_SAMPLES) / FOURIER_SAMPLES
    c = np.fft.rfft(profile(grid)) / FOURIER_SAMPLES
    k = 2.0 * math.pi * np.arange(c.size)
    c = c * mode_factors(k, t, nu, cs)
    phase = np.exp(1j * np.outer(np.asarray(y), k))
    weight = np.full(c.size, 2.0)
    weight[0] = 1.0
    if FOURIER_SAMPLES % 2 == 0:
        weight[-1] = 1.0
    return (phase @ (weight * c)).real


class SHTCImpulseOfShear(SHTCShearWave):
    """Smooth shear layer, periodic unit box, SHTC-SPH fluid, against the telegraph equation."""

    tf = 0.1
    history_columns = None
    error_key = "profile_error"

    def add_user_options(self, group):
        super().add_user_options(group)
        group.set_defaults(nu=0.01, cs=0.3)
        group.add_argument("--width", type=float, default=0.05,
                           help="standard deviation w of the Gaussian layer (default %(default)s)")

    def consume_user_options(self, o):
        super().consume_user_options(o)
        if not (math.isfinite(o.width) and 2 * self.dr <= o.width <= 0.15):
            raise InputError(f"--width must be in [2 dr, 0.15] (resolved, and periodic images "
                             f"negligible), got {o.width}")
        self.snapshots = []

    def initial_velocity(self, y):
        """The Gaussian shear layer centred on y = 1/2."""
        return U_LAYER * np.exp(-(np.asarray(y) - 0.5) ** 2 / (2.0 * self.options.width ** 2))

    def post_step(self, solver):
        tf = self.options.tf
        target = (len(self.snapshots) + 1) * tf / 3.0
        if len(self.snapshots) < 3 and solver.t >= target - 0.5 * solver.dt:
            f = self.scene.by_name["fluid"]
            self.snapshots.append((solver.t, f.y.copy(), f.u.copy(), f.m.copy()))

    def post_process(self, outdir):
        """results.json (profile errors at the end) and profile.png."""
        o = self.options
        nu, cs = o.nu, o.cs
        errors = []
        snapshots = self.snapshots
        if not snapshots:     # stopped (--max-steps) before tf / 3: the state it reached
            f = self.scene.by_name["fluid"]
            snapshots = [(self.solver.t, f.y.copy(), f.u.copy(), f.m.copy())]
        for t, y, u, m in snapshots:
            e = [math.sqrt(np.sum(m * (u - layer_solution(self.initial_velocity, y, t, nu, c)) ** 2) / np.sum(m))
                 / U_LAYER for c in (cs, math.inf)]
            errors.append((t, *e))
        t, err, err_ns = errors[-1]
        dt_over_tau = self.solver.dt / self.tau
        results = {"t": t, "nx": o.nx, "nu": nu, "cs": cs, "width": o.width, "tau": self.tau,
                   "dt_over_tau": dt_over_tau, "viscosity_factor": viscosity_factor(dt_over_tau),
                   "profile_error": err, "profile_error_navier_stokes": err_ns,
                   "profile_errors": [list(e) for e in errors],
                   "relaxation_time_telegraph": nu / cs ** 2}
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(os.path.join(outdir, "profile.png"))
        print(f"shtc_impulse_of_shear: t = {t:.4g}  RMS error / U {err:.4f} (telegraph), {err_ns:.4f} "
              f"(Navier-Stokes); dt/tau = {dt_over_tau:.3g}")
        return results

    def plot(self, path):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        o = self.options
        fig, ax = plt.subplots(figsize=(7, 4.2))
        yy = np.linspace(0.0, 1.0, 801)
        ax.plot(yy, self.initial_velocity(yy) / U_LAYER, color="0.6", lw=0.8, label="t = 0")
        for (t, y, u, m), col in zip(self.snapshots, ("C0", "C1", "C2")):
            ax.plot(y, u / U_LAYER, ".", ms=1.5, color=col)
            ax.plot(yy, layer_solution(self.initial_velocity, yy, t, o.nu, o.cs) / U_LAYER, "-", color=col,
                    lw=1.0, label=f"t = {t:.3g}: SHTC linearised (thesis 2.25)")
            ax.plot(yy, layer_solution(self.initial_velocity, yy, t, o.nu, math.inf) / U_LAYER, "--", color=col,
                    lw=0.8, label="Navier-Stokes (thesis 2.16)")
        ax.set_xlabel("y")
        ax.set_ylabel("u / U")
        ax.set_title(f"impulse of shear: nu = {o.nu:g}, cs = {o.cs:g}, {o.nx} per side (dots: particles)",
                     fontsize=9)
        ax.legend(fontsize=7)
        fig.tight_layout()
        fig.savefig(path, dpi=100)
        plt.close(fig)
