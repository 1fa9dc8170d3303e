"""Water at rest in a tank: the hydrostatic test of a wall boundary (Adami, Hu & Adams 2012,
section 4.1).

Water of depth H = 1 fills a tank of width W = ``--width`` H (default 1) with Adami walls
on the bottom and sides (open top); g = 9.81, rho0 = 1000, c0 = 10 sqrt(g H).  The water
starts in the *hydrostatic state* (decided: no gravity ramp): p = rho0 g (H - y), rho from
the Tait equation of that pressure and m = rho dx^2, at rest on a square lattice with
H/dx = ``--nh`` (default 40).  Only the SPH discretisation error then drives motion, which
artificial viscosity and delta-SPH damp.

After ``--tf`` = 10 sqrt(H/g) (3.19 s) ``post_process`` reports in ``results.json``: the
pressure at the bottom centre (x = W/2, y = 0, order-1 Shepard (MLS) interpolation of the
fluid pressure, :func:`sphgen.tools.probes.shepard`) relative to rho0 g H, the RMS particle
speed relative to sqrt(g H), their histories, and the pressure along the vertical
centre line against rho0 g (H - y); ``hydrostatic.png`` plots them.
"""
import os
from math import sqrt

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.geometry import layers_for_support, rectangle, wall_layers_box
from sphgen.particles import ParticleArray
from sphgen.tools.probes import line_probe, shepard

from ..schemes.wcsph import WCSPHScheme

try:
    from sphgen.errors import InputError
except ImportError:  # pragma: no cover
    InputError = ValueError

H = 1.0
RHO0 = 1000.0
G = 9.81


class HydrostaticTank(Application):
    """Water at rest in a tank, WCSPH with Adami walls: bottom pressure and residual speed."""

    tf = 10.0 * sqrt(H / G)
    pfreq = 2000
    dim = 2
    history_columns = ("t", "p_bottom_rel", "u_rms_rel", "u_max_rel")
    diagnostics = ("mass", "energies", "density_range", "pressure_range")
    diagnostics_every = 50

    def add_user_options(self, group):
        group.add_argument("--nh", type=int, default=40, help="H/dx, particles over the depth (default %(default)s)")
        group.add_argument("--width", type=float, default=1.0, help="tank width / H (default %(default)s)")
        group.add_argument("--hdx", type=float, default=1.0, help="h / dx (default %(default)s)")
        group.add_argument("--alpha", type=float, default=0.1, help="artificial viscosity (default %(default)s)")
        group.add_argument("--delta", type=float, default=0.1, help="delta-SPH coefficient (default %(default)s)")
        group.add_argument("--c0-factor", type=float, default=10.0,
                           help="c0 = factor * sqrt(g H) (default %(default)s)")
        group.add_argument("--record-every", type=float, default=0.02,
                           help="time between samples (default %(default)s s)")

    def consume_user_options(self, o):
        if o.nh < 4:
            raise InputError(f"--nh must be at least 4, got {o.nh}")
        for name in ("width", "hdx", "c0_factor", "record_every"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive finite number, got {v}")
        for name in ("alpha", "delta"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"--{name} must be a non-negative finite number, got {v}")
        self.dx = H / o.nh
        self.W = H * max(round(o.width * o.nh), 4) / o.nh
        self.h = o.hdx * self.dx
        self.c0 = o.c0_factor * sqrt(G * H)
        self.n_layers = layers_for_support(3.0, o.hdx)
        self.history = []
        self._next_record = 0.0

    def create_particles(self):
        dx = self.dx
        x, y = rectangle(0.0, self.W, 0.0, H, dx)
        b = RHO0 * self.c0 ** 2 / 7.0
        p = RHO0 * G * (H - y)
        rho = RHO0 * (1.0 + p / b) ** (1.0 / 7.0)
        fluid = ParticleArray("fluid", x=x, y=y, rho=rho, m=rho * dx * dx, h=np.full(x.size, self.h))
        fluid.add_property("p", data=p)
        xw, yw, nx, ny = wall_layers_box(0.0, self.W, 0.0, 1.5 * H, dx, self.n_layers, open_top=True)
        wall = ParticleArray("wall", x=xw, y=yw, rho=np.full(xw.size, RHO0),
                             m=np.full(xw.size, RHO0 * dx * dx), h=np.full(xw.size, self.h))
        wall.add_property("normal", stride=3, data=np.column_stack([nx, ny, 0 * nx]).ravel())
        return [fluid, wall]

    def create_scheme(self):
        o = self.options
        return WCSPHScheme(["fluid"], ["wall"], dim=2, rho0=RHO0, c0=self.c0, h=self.h, gy=-G,
                           alpha=o.alpha, delta=o.delta, umax=sqrt(G * H))

    def history_meta(self):
        return {"dx": self.dx, "W": self.W, "h": self.h, "c0": self.c0}

    def post_step(self, solver):
        if solver.t + 1e-12 >= self._next_record or solver.t >= solver.tf - 1e-12:
            self.history.append(self.history_row(self.scene.by_name["fluid"], solver.t, self.W,
                                                 self.scheme.kernel))
            self._next_record = solver.t + self.options.record_every

    @staticmethod
    def bottom_pressure(f, W, kernel):
        """Fluid pressure at (W/2, 0) by order-1 Shepard interpolation (exact for linear p)."""
        return float(shepard((np.array([0.5 * W]), np.array([0.0])), f.x, f.y, f.h, f.m, f.rho, f.p,
                             kernel, order=1)[0])

    @classmethod
    def history_row(cls, f, t, W, kernel):
        speed = np.hypot(f.u, f.v)
        return [t, cls.bottom_pressure(f, W, kernel) / (RHO0 * G * H) - 1.0,
                float(np.sqrt(np.mean(speed ** 2))) / sqrt(G * H), float(speed.max()) / sqrt(G * H)]

    def post_process(self, outdir):
        hist, rows = io.read_history(outdir)
        t, prel, urms, umax = rows.T
        if self.scene is not None:
            f = self.scene.by_name["fluid"]
            kernel = self.scheme.kernel
        else:
            last = io.load(io.output_files(outdir, self.name)[-1])
            f = last["arrays"]["fluid"]
            from sphgen.kernels import get_kernel
            kernel = get_kernel("quintic", 2)
        W = hist["W"]
        ys = np.linspace(0.0, H, 41)
        (_, py), pc = line_probe((0.5 * W, 0.0), (0.5 * W, H), 41, f.x, f.y, f.h, f.m, f.rho, f.p,
                                 kernel, order=1)
        inside = py <= H - 2 * hist["dx"]
        line_err = float(np.nanmax(np.abs(pc[inside] - RHO0 * G * (H - py[inside]))) / (RHO0 * G * H))
        last = t >= t[-1] - sqrt(H / G)
        results = {"t": float(t[-1]), "t_over_sqrt_H_g": float(t[-1] / sqrt(H / G)),
                   "nh": int(round(H / hist["dx"])), "c0": hist["c0"],
                   "p_bottom_rel_error": float(prel[-1]),
                   # the acoustic mode of the column (period 4H/c0) rides on it: its mean and
                   # extremes over the last sqrt(H/g)
                   "p_bottom_rel_error_last_mean": float(prel[last].mean()),
                   "p_bottom_rel_error_last_max_abs": float(np.abs(prel[last]).max()),
                   "u_rms_over_sqrt_gH": float(urms[-1]),
                   "u_max_over_sqrt_gH": float(umax[-1]),
                   "centreline_p_max_error_over_rho_g_H": line_err}
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, t, prel, urms, py, pc, ys)
        print(f"hydrostatic_tank: t={results['t']:.4g} ({results['t_over_sqrt_H_g']:.3g} sqrt(H/g))  "
              f"p_bottom/(rho g H) - 1 = {100 * results['p_bottom_rel_error']:+.2f}%  "
              f"u_rms/sqrt(gH) = {100 * results['u_rms_over_sqrt_gH']:.3f}%\n"
              f"results: {os.path.join(outdir, 'results.json')}\nfigure:  {os.path.join(outdir, 'hydrostatic.png')}")
        return results

    @staticmethod
    def plot(outdir, t, prel, urms, py, pc, ys):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
        a.plot(t, 100 * prel, "b-", label="bottom pressure error (%)")
        a.plot(t, 100 * urms, "r-", label="RMS speed / sqrt(gH) (%)")
        a.axhline(2, color="0.6", ls=":")
        a.axhline(-2, color="0.6", ls=":")
        a.set_xlabel("t (s)")
        a.legend()
        b.plot(RHO0 * G * (H - ys), ys, "k-", label="$\\rho_0 g (H - y)$")
        b.plot(pc, py, "r.", label="sphgen, x = W/2")
        b.set_xlabel("p (Pa)")
        b.set_ylabel("y (m)")
        b.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "hydrostatic.png"), dpi=100)
        plt.close(fig)
