"""Laminar Taylor-Couette flow with SHTC-SPH in its fluid regime (Kincl, Peshkov, Pavelka &
Klika (2023), section 4.3).

Fluid in the annulus R1 < r < R2 (R1 = 1, R2 = 2), at rest at t = 0; the inner ring is
fixed and the outer ring turns rigidly counter-clockwise at omega = 1.  Both rings are
dummy walls of ceil(2h/dr) = 3 layers that carry their own rho, lambda, A and T and run the
scheme's own equations (they enter the fluid's sums and forces); the outer ring's positions
and velocities are prescribed, x(t) = Rot(omega t) x(0), v = omega (-y, x), at the times of
the integrator's stages (the half step for L, the full step for the force);
by default (``--wall-velocity extrapolated``) the rings show, in L only, 2 v_rigid minus the
fluid's Shepard mean around them (Adami et al. 2012); ``--wall-velocity rigid`` is the paper's
text (the rings show their rigid-body velocity, which slips by about a kernel width; the
choice is argued in docs/shtc.md).  DPRZ with
rho0 = 1, c0 = 20, cs = 40, c_p = 0.01 c0, nu = omega R2 (R2 - R1) / Re (Re = 20: nu = 0.1)
and tau = 6 nu / cs^2 (eq. 29).  Particles on Vogel's sunflower lattice (area dr^2 each, as in the authors'
code; ``--lattice rings``: concentric circles), dr = (R2 - R1) / ``--nr`` (paper, Table 1: 30), h = 1.5 dr, dt from eq. 26.

``results.json``: at the final time (paper: t = 10) the tangential velocity v_y along y = 0,
R1 <= x <= R2 (Shepard interpolation at 51 points over fluid and walls) against the steady
solution (eq. 28) v = omega R2 (r/R1 - R1/r) / (R2/R1 - R1/R2): its mean absolute error
divided by omega R2 (``profile_error``), the largest one, and the mean error over the fluid
particles.  Plots: profile.png (v and v - omega r, the paper's Fig. 8), Axy.png (the A_xy
field, Fig. 9), error.png (the mean particle error over time).
"""
import json
import math
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import layers_for_support, ring
from sphgen.particles import ParticleArray
from sphgen.tools.probes import line_probe, shepard

from ..schemes.shtc import SHTCScheme

R1, R2, OMEGA = 1.0, 2.0, 1.0
RHO0, C0, CS = 1.0, 20.0, 40.0
HDR = 1.5
PROBE_POINTS = 51


def exact_tangential_velocity(r):
    """Steady Couette profile between a fixed inner and a turning outer cylinder (eq. 28)."""
    r = np.asarray(r, dtype=float)
    return OMEGA * R2 * (r / R1 - R1 / r) / (R2 / R1 - R1 / R2)


GOLDEN_ANGLE = math.pi * (3.0 - math.sqrt(5.0))


def vogel_annulus(r_in, r_out, dr):
    """Vogel (sunflower) points x_n = k sqrt(n) (cos n phi, sin n phi), k = dr/sqrt(pi), phi the
    golden angle, with r_in <= k sqrt(n) < r_out: area dr^2 per point, no preferred direction."""
    k = dr / math.sqrt(math.pi)
    n = np.arange(int(math.ceil((r_in / k) ** 2)), int(math.ceil((r_out / k) ** 2)), dtype=float)
    r = k * np.sqrt(n)
    return r * np.cos(n * GOLDEN_ANGLE), r * np.sin(n * GOLDEN_ANGLE)


def rigid_rotation(omega, speed=None):
    """Motion of a rigidly rotating wall about the origin: positions Rot(omega t) (x0, y0) and
    velocities omega (-y, x) (or the tangential ``speed(r)`` if given); the reference positions
    x0, y0 are properties of the array."""
    def motion(t, pa):
        c, s = math.cos(omega * t), math.sin(omega * t)
        x = c * pa.x0 - s * pa.y0
        y = s * pa.x0 + c * pa.y0
        if speed is None:
            return {"x": x, "y": y, "u": -omega * y, "v": omega * x}
        r = np.hypot(x, y)
        vt = speed(r) / r
        return {"x": x, "y": y, "u": -vt * y, "v": vt * x}
    return motion


class TaylorCouette(Application):
    """Taylor-Couette flow between a fixed inner and a rotating outer cylinder (SHTC-SPH fluid)."""

    tf = 10.0
    pfreq = 20000
    dim = 2
    history_columns = ("t", "mean_error", "Axy_probe")
    error_key = "profile_error"

    def add_user_options(self, group):
        group.add_argument("--nr", type=int, default=30,
                           help="particles across the gap: dr = (R2 - R1)/nr (paper, Table 1: 30)")
        group.add_argument("--re", type=float, default=20.0,
                           help="Reynolds number omega R2 (R2 - R1)/nu (paper: 20)")
        group.add_argument("--cp-factor", type=float, default=0.01, help="tensile penalty c_p / c0 (paper: 0.01)")
        group.add_argument("--lattice", choices=("vogel", "rings"), default="vogel",
                           help="particle layout: Vogel's sunflower (the authors' code) or concentric "
                           "circles (default %(default)s)")
        group.add_argument("--wall-velocity", choices=("rigid", "extrapolated", "profile"), default="extrapolated",
                           help="rigid: the rings' rigid-body velocities (the paper's text); extrapolated: "
                           "in L the rings show 2 v_rigid minus the Shepard mean of the fluid's velocity "
                           "around them (Adami et al. 2012); profile: the exact profile (eq. 28) continued "
                           "into both rings, as the authors' code does (default %(default)s)")
        group.add_argument("--layers", type=int, default=None,
                           help="wall layers of each ring (default ceil(2h/dr) = 3, thesis eq. 1.83)")
        group.add_argument("--cfl", type=float, default=0.05,
                           help="dt = cfl dr / sqrt(c0^2 + 4/3 cs^2) (paper, eq. 26: 0.05)")

    def consume_user_options(self, o):
        if o.layers is not None and o.layers < 1:
            raise InputError(f"--layers must be at least 1, got {o.layers}")
        if o.nr < 4:
            raise InputError(f"--nr must be at least 4, got {o.nr}")
        for name in ("re", "cfl"):
            if not (math.isfinite(getattr(o, name)) and getattr(o, name) > 0):
                raise InputError(f"--{name} must be a positive number, got {getattr(o, name)}")
        if not (math.isfinite(o.cp_factor) and o.cp_factor >= 0):
            raise InputError(f"--cp-factor must be a non-negative number, got {o.cp_factor}")
        self.dr = (R2 - R1) / o.nr
        self.nu = OMEGA * R2 * (R2 - R1) / o.re
        self.tau = 6.0 * self.nu / CS ** 2

    def create_particles(self):
        dr, h = self.dr, HDR * self.dr
        nl = self.options.layers or layers_for_support(2.0, HDR)

        def array(name, x, y):
            n = x.size
            return ParticleArray(name, x=x, y=y, u=np.zeros(n), v=np.zeros(n), m=np.full(n, RHO0 * dr * dr),
                                 h=np.full(n, h), rho=np.full(n, RHO0))
        if self.options.lattice == "vogel":
            fluid = array("fluid", *vogel_annulus(R1, R2, dr))
            inner = array("inner", *vogel_annulus(R1 - nl * dr, R1, dr))
            outer = array("outer", *vogel_annulus(R2, R2 + nl * dr, dr))
        else:
            fluid = array("fluid", *ring(0.0, 0.0, R1, R2, dr))
            inner = array("inner", *ring(0.0, 0.0, R1 - nl * dr, R1, dr))
            outer = array("outer", *ring(0.0, 0.0, R2, R2 + nl * dr, dr))
        for pa in (inner, outer):
            pa.add_property("x0", data=pa.x.copy())
            pa.add_property("y0", data=pa.y.copy())
            motion = self.wall_motions().get(pa.name)
            if motion is not None:
                for k, val in motion(0.0, pa).items():
                    pa.get(k)[:] = val
        return [fluid, inner, outer]

    def wall_motions(self):
        """{wall: motion}: the outer ring turns at omega; with --wall-velocity profile both
        rings carry the exact profile continued into them (the inner ring stays in place)."""
        if self.options.wall_velocity != "profile":
            return {"outer": rigid_rotation(OMEGA)}
        return {"outer": rigid_rotation(OMEGA, exact_tangential_velocity),
                "inner": rigid_rotation(0.0, exact_tangential_velocity)}

    def create_scheme(self):
        o = self.options
        return SHTCScheme(["fluid"], 2, rho0=RHO0, c0=C0, cs=CS, h=HDR * self.dr, dr=self.dr, tau=self.tau,
                          model="dprz", cp=o.cp_factor * C0, walls=["inner", "outer"],
                          moving_walls=sorted(self.wall_motions()), motions=self.wall_motions(), cfl=o.cfl,
                          wall_velocity="extrapolated" if o.wall_velocity == "extrapolated" else "prescribed")

    def post_step(self, solver):
        every = max(1, int(round(0.05 / solver.dt)))
        if solver.step % every == 0 or solver.t >= solver.tf - 1e-12 * max(1.0, solver.tf):
            self.record(solver.t)

    def record(self, t):
        f = self.scene.by_name["fluid"]
        self.history.append([t, self.particle_error(f), self.probe_axy(self.scene.arrays)])

    @staticmethod
    def particle_error(f):
        """Mean |v - v_exact| over the fluid particles, divided by omega R2."""
        x, y = f.x, f.y
        r = np.hypot(x, y)
        ve = exact_tangential_velocity(r)
        return float(np.mean(np.hypot(f.u + ve * y / r, f.v - ve * x / r)) / (OMEGA * R2))

    def probe_axy(self, arrays):
        """A_xy at (1.5, 0) (Shepard over all arrays)."""
        x, y, h, m, rho, A = self._stack(arrays, "A")
        val = shepard((np.array([1.5]), np.array([0.0])), x, y, h, m, rho, A.reshape(-1, 9)[:, 1],
                      self.scheme.kernel)
        return float(val[0])

    @staticmethod
    def _stack(arrays, *extra):
        seq = arrays.values() if isinstance(arrays, dict) else arrays
        return [np.concatenate([np.asarray(pa[k] if isinstance(pa, dict) else pa.get(k)) for pa in seq])
                for k in ("x", "y", "h", "m", "rho") + extra]

    def history_meta(self):
        o = self.options
        return {"nr": o.nr, "re": o.re, "nu": self.nu, "tau": self.tau, "dr": self.dr, "cfl": o.cfl}

    def post_process(self, outdir):
        """results.json, profile.png, Axy.png and error.png from the run's files."""
        with open(os.path.join(outdir, "history.json")) as f:
            hist = json.load(f)
        if self.solver is not None:
            arrays, t = {pa.name: pa for pa in self.scene.arrays}, self.solver.t
            kernel = self.scheme.kernel
        else:
            last = io.load(io.output_files(outdir, self.name)[-1])
            arrays, t = last["arrays"], last["solver_data"]["t"]
            from sphgen.kernels import get_kernel
            kernel = get_kernel("wendland", 2)
        x, y, h, m, rho, v = self._stack(arrays, "v")
        pts, vy = line_probe((R1, 0.0), (R2, 0.0), PROBE_POINTS, x, y, h, m, rho, v, kernel)
        ve = exact_tangential_velocity(pts[0])
        err = np.abs(vy - ve) / (OMEGA * R2)
        rows = np.array(hist["rows"]) if hist["rows"] else np.zeros((0, 3))
        f = arrays["fluid"]
        fx = f["x"] if isinstance(f, dict) else f.x
        tail = rows[rows[:, 0] >= 0.8 * t, 2] if rows.size else np.zeros(0)
        results = {
            "t": float(t), "nr": hist["nr"], "re": hist["re"], "dr": hist["dr"], "tau": hist["tau"],
            "dt_over_tau": float(self.solver.dt / hist["tau"]) if self.solver is not None else None,
            "profile_error": float(err.mean()), "profile_error_max": float(err.max()),
            "particle_error": float(rows[-1, 1]) if rows.size else None,
            "n_fluid": int(np.size(fx)),
            "Axy_probe_std_last_20pc": float(np.std(tail)) if tail.size else None,
            "Axy_probe_max": float(np.abs(rows[:, 2]).max()) if rows.size else None,
            "profile_x": pts[0].tolist(), "profile_v": vy.tolist(), "profile_exact": ve.tolist(),
        }
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, pts[0], vy, ve, rows, arrays)
        print(f"taylor_couette: t={t:.4g}  mean |v - v_exact| / (omega R2) along y = 0: "
              f"{results['profile_error']:.4f} (max {results['profile_error_max']:.4f})\n"
              f"results: {os.path.join(outdir, 'results.json')}")
        return results

    def plot(self, outdir, xp, vy, ve, rows, arrays):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
        a.plot(xp, vy, "C1-", label="SHTC-SPH")
        a.plot(xp[::5], ve[::5], "bs", label="exact (eq. 28)")
        a.set_xlabel("x (y = 0)")
        a.set_ylabel("$v_y$")
        a.legend()
        b.plot(xp, vy - OMEGA * xp, "C1-", label="SHTC-SPH")
        b.plot(xp[::5], ve[::5] - OMEGA * xp[::5], "bs", label="exact")
        b.set_xlabel("x (y = 0)")
        b.set_ylabel("$v_y - \\omega x$")
        b.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "profile.png"), dpi=100)
        plt.close(fig)
        x, y, h, m, rho, A = self._stack(arrays, "A")
        fig, ax = plt.subplots(figsize=(5.5, 4.5))
        sc = ax.scatter(x, y, c=A.reshape(-1, 9)[:, 1], s=1, cmap="RdBu_r")
        fig.colorbar(sc, ax=ax, label="$A_{xy}$")
        ax.set_aspect("equal")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "Axy.png"), dpi=100)
        plt.close(fig)
        if rows.size:
            fig, ax = plt.subplots(figsize=(5, 3.5))
            ax.semilogy(rows[:, 0], rows[:, 1])
            ax.set_xlabel("t")
            ax.set_ylabel("mean $|v - v_{exact}|/(\\omega R_2)$ (fluid particles)")
            fig.tight_layout()
            fig.savefig(os.path.join(outdir, "error.png"), dpi=100)
            plt.close(fig)
