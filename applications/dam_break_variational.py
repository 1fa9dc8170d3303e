"""Dam break of da Silva & Giraldi (2024, section 6): variational (generalised midpoint) or
explicit leapfrog time integration, :class:`~schemes.variational.VariationalScheme`.

Printed set-up: tank 0.58 x 0.29 m, water column 0.145 x 0.29 m of 29 x 58 = 1682
particles (dx = 0.005, m = 0.025 kg per metre of depth), rho0 = 1000, g = 9.8, Gaussian
kernel cut at h = 0.072, eps = 0.001, dt = 1e-4 s, alpha = 0.5.  Not printed, options
with these defaults (digest seed-004 section 3.6 / 6):

* ``--c0 23.841`` = 10 sqrt(2 g H) (A2); ``--av-a 1 --av-b 1`` (A3);
* ``--D 5.684`` = 2 g H and ``--r0 0.005`` = dx of the wall force eq. 58, ``--wall-power 1``
  (unit vector, as printed; A8);
* ``--kernel K3`` (normalised Gaussian, lam = 1.3 dx, rc = 3 lam, shifted cut); ``K1`` is
  eq. 69 as printed (pressureless, A1), ``K2`` the paper's cut-off ``--h-cut 0.072``;
* ``--max-iter 50`` (A17), ``--predictor verlet`` (A15), ``--tol 1e-3`` metres, global
  max-norm (A16);
* walls: one layer of fixed particles at spacing ``--wall-spacing 0.0025`` on x = -dx/2,
  x = 0.58 + dx/2, y = -dx/2 and (closed box, A23) y = 0.29 + dx/2; ``--open-top`` drops
  the lid and raises the side walls to 0.58 m (A9);
* fluid at rest at rho0, p = 0 (A13); t_end 1 s (A22).

``post_process`` writes ``results.json``: iteration statistics (mean/max iterations, largest
residual and contraction ratio), the momentum Q(t) = |sum m v|/M (v the mean of the two
half-step velocities around t_k, A25; Q is not conserved with gravity and walls, A24),
the largest momentum-budget residual |sum m (v_{k+1/2} - v_{k-1/2}) - dt sum m (Gamma_k + g)|/M
(the identity that holds to round-off with walls and gravity),
the toe against Koshizuka & Oka (1996) and Martin & Moyce (1952), report-only, and plots
``toe.png``, ``momentum.png``, ``iterations.png``.
"""
import json
import os
from math import sqrt

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.particles import ParticleArray
from sphgen.tools.probes import front_position
from sphgen.tools import reference

from ..schemes.variational import PREDICTORS, VariationalScheme
from .dam_break_2d import max_rel_deviation

try:
    from sphgen.errors import InputError
except ImportError:  # pragma: no cover
    InputError = ValueError

TANK_W, TANK_H = 0.58, 0.29
NX, NY = 29, 58
DX = 0.005
L = NX * DX        # column width 0.145
H = NY * DX        # column height 0.29
RHO0, G, MASS = 1000.0, 9.8, 0.025


class DamBreakVariational(Application):
    """Dam break of da Silva & Giraldi (2024): variational midpoint or explicit leapfrog."""

    tf = 1.0
    pfreq = 1000
    dim = 2
    history_columns = ("t", "T", "toe", "Q", "px", "py", "iterations_max", "residual_max",
                       "contraction_max", "budget_max", "rho_min", "rho_max", "kinetic", "potential", "internal")

    def add_user_options(self, group):
        group.add_argument("--integrator", choices=("variational", "explicit"), default="variational",
                           help="variational midpoint (eqs. 37, 63-65) or explicit leapfrog (59-62)")
        group.add_argument("--alpha", type=float, default=0.5, help="midpoint parameter (default %(default)s)")
        group.add_argument("--tol", type=float, default=1e-3,
                           help="fixed-point tolerance eps, metres, max-norm (default %(default)s)")
        group.add_argument("--max-iter", type=int, default=50, help="iteration cap (default %(default)s)")
        group.add_argument("--predictor", choices=tuple(PREDICTORS), default="verlet",
                           help="initial guess of the iteration (default %(default)s)")
        group.add_argument("--kernel", choices=("K1", "K2", "K3"), default="K3",
                           help="K1 eq. 69 as printed, K2 normalised with the paper's cut, K3 standard")
        group.add_argument("--h-cut", type=float, default=0.072, help="paper's kernel cut-off (K1, K2)")
        group.add_argument("--c0", type=float, default=10.0 * sqrt(2.0 * G * H),
                           help="speed of sound (default 10 sqrt(2 g H) = %(default).5g)")
        group.add_argument("--av-a", type=float, default=1.0, help="AV a (default %(default)s)")
        group.add_argument("--av-b", type=float, default=1.0, help="AV b (default %(default)s)")
        group.add_argument("--D", type=float, default=2.0 * G * H, help="wall force D (default 2gH)")
        group.add_argument("--r0", type=float, default=DX, help="wall force r0 (default dx)")
        group.add_argument("--wall-power", type=int, choices=(1, 2), default=1,
                           help="1: x/r as printed, 2: x/r^2 (default 1)")
        group.add_argument("--wall-spacing", type=float, default=0.5 * DX,
                           help="boundary particle spacing (default dx/2)")
        group.add_argument("--open-top", action="store_true", help="no lid; side walls to 2 x 0.29 m")
        group.add_argument("--time-step", type=float, default=1e-4, help="dt (default the paper's 1e-4 s)")
        group.add_argument("--record-every", type=float, default=1e-3,
                           help="time between history samples (default %(default)s s)")

    def consume_user_options(self, o):
        for name in ("tol", "h_cut", "c0", "D", "r0", "wall_spacing", "time_step", "record_every"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive finite number, got {v}")
        if not 0.0 <= o.alpha <= 1.0:
            raise InputError(f"--alpha must be in [0, 1], got {o.alpha}")
        if o.max_iter < 1:
            raise InputError(f"--max-iter must be >= 1, got {o.max_iter}")
        self.history = []
        self._next_record = 0.0
        self._p_prev = None
        self._budget = 0.0
        self._window = []
        self.all_iterations = []

    def create_scheme(self):
        o = self.options
        return VariationalScheme(["fluid"], ["wall"], dim=2, rho0=RHO0, c0=o.c0, gy=-G, kernel=o.kernel,
                                 dx=DX, h_cut=o.h_cut, av_a=o.av_a, av_b=o.av_b, D=o.D, r0=o.r0,
                                 wall_power=o.wall_power, integrator=o.integrator, alpha=o.alpha,
                                 tol=o.tol, max_iter=o.max_iter, predictor=o.predictor, dt=o.time_step)

    def create_particles(self):
        o = self.options
        h = VariationalScheme(["fluid"], [], kernel=o.kernel, dx=DX, h_cut=o.h_cut).h
        ax, ay = (np.arange(NX) + 0.5) * DX, (np.arange(NY) + 0.5) * DX
        x, y = (g.ravel() for g in np.meshgrid(ax, ay, indexing="ij"))
        n = x.size
        fluid = ParticleArray("fluid", x=x, y=y, u=np.zeros(n), v=np.zeros(n), m=np.full(n, MASS),
                              rho=np.full(n, RHO0), h=np.full(n, h))
        fluid.add_property("p")
        top = 2.0 * TANK_H if o.open_top else TANK_H
        x0, x1, y0, y1 = -0.5 * DX, TANK_W + 0.5 * DX, -0.5 * DX, top + 0.5 * DX
        s = o.wall_spacing
        bx = np.arange(x0, x1 + 1e-9, s)
        by = np.arange(y0 + s, y1 + 1e-9, s)
        xs = [bx, np.full(by.size, x0), np.full(by.size, x1)]
        ys = [np.full(bx.size, y0), by, by]
        if not o.open_top:
            inner = bx[(bx > x0 + 0.5 * s) & (bx < x1 - 0.5 * s)]
            xs.append(inner)
            ys.append(np.full(inner.size, y1))
        xw, yw = np.concatenate(xs), np.concatenate(ys)
        wall = ParticleArray("wall", x=xw, y=yw, m=np.full(xw.size, MASS), h=np.full(xw.size, h))
        self.M = float(fluid.m.sum())
        return [fluid, wall]

    def history_meta(self):
        o = self.options
        it = np.array(self.all_iterations, dtype=float).reshape(-1, 3) if self.all_iterations else None
        meta = {"integrator": o.integrator, "alpha": o.alpha, "tol": o.tol, "kernel": o.kernel,
                "L": L, "M": self.M}
        if it is not None and it.size:
            meta.update({"steps_iterated": int(it.shape[0]), "iterations_mean": float(it[:, 0].mean()),
                         "iterations_max": int(it[:, 0].max()), "residual_max": float(it[:, 1].max()),
                         "contraction_max": float(np.nanmax(it[:, 2])) if np.isfinite(it[:, 2]).any()
                         else None})
        return meta

    # ------------------------------------------------------------ diagnostics
    def post_step(self, solver):
        f = self.scene.by_name["fluid"]
        integ = solver.integrator
        if hasattr(integ, "iterations") and integ.k > 1:
            row = (integ.iterations, integ.residual, integ.contraction)
            self.all_iterations.append(row)
            self._window.append(row)
        p = np.array([np.sum(f.m * f.u), np.sum(f.m * f.v)])   # sum m v_{k+1/2} after the step
        if self._p_prev is not None:
            # momentum budget (digest 1.10): sum m dv = dt sum m (Gamma_k + g), to round-off
            imp = solver.last_dt * np.array([np.sum(f.m * f.gwx), np.sum(f.m * (f.gwy - G))])
            self._budget = max(self._budget, float(np.abs(p - self._p_prev - imp).max()) / self.M)
        p_mid = p if self._p_prev is None else 0.5 * (p + self._p_prev)
        self._p_prev = p
        if solver.t + 1e-12 >= self._next_record or solver.t >= solver.tf - 1e-12:
            w = np.array(self._window, dtype=float).reshape(-1, 3)
            self._window = []
            e = self.scheme.energies([f])
            toe = front_position(f.x, f.y, 0.0, DX) / L
            self.history.append([
                solver.t, solver.t * sqrt(2.0 * G / L), toe, float(np.hypot(*p_mid)) / self.M,
                float(p_mid[0]), float(p_mid[1]),
                float(w[:, 0].max()) if w.size else 0.0, float(w[:, 1].max()) if w.size else 0.0,
                float(np.nanmax(w[:, 2])) if w.size and np.isfinite(w[:, 2]).any() else float("nan"),
                self._budget,
                float(f.rho.min()), float(f.rho.max()), e["kinetic"], e["potential"], e["internal"]])
            self._next_record = solver.t + self.options.record_every
            self._budget = 0.0

    # ------------------------------------------------------------ results
    def post_process(self, outdir):
        with open(os.path.join(outdir, "history.json")) as fh:
            hist = json.load(fh)
        rows = np.array(hist["rows"], dtype=float)
        if rows.size == 0:
            raise InputError(f"{outdir}/history.json has no samples (run for at least one step)")
        cols = {c: rows[:, i] for i, c in enumerate(hist["columns"])}
        T, Z = cols["T"], cols["toe"]
        ok = np.isfinite(Z)
        results = {k: hist.get(k) for k in ("integrator", "alpha", "tol", "kernel", "steps_iterated",
                                              "iterations_mean", "iterations_max", "residual_max",
                                              "contraction_max")}
        results.update({"t": float(cols["t"][-1]), "T": float(T[-1]), "n_samples": int(rows.shape[0]),
                        "Q_max": float(cols["Q"].max()), "t_Q_max": float(cols["t"][np.argmax(cols["Q"])]),
                        "Q_final": float(cols["Q"][-1]),
                        "momentum_budget_residual_max": float(cols["budget_max"].max()),
                        "rho_min": float(cols["rho_min"].min()), "rho_max": float(cols["rho_max"].max())})
        refs = {"martin_moyce_a2.25in": reference.martin_moyce_1952(2.25),
                "martin_moyce_a1.125in": reference.martin_moyce_1952(1.125),
                "koshizuka_oka": reference.koshizuka_oka_1996()}
        for name, (Tr, Zr) in refs.items():   # report-only: the paper shows no toe
            dev, signed = max_rel_deviation(T[ok], Z[ok], np.asarray(Tr), np.asarray(Zr)) if ok.any() else (None, None)
            results[f"toe_max_rel_dev_{name}"] = dev
            results[f"toe_signed_dev_at_max_{name}"] = signed
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, cols, refs)
        print(f"dam_break_variational: {results['integrator']} alpha={results['alpha']}: "
              f"iterations mean {results['iterations_mean']}, max {results['iterations_max']}, "
              f"residual max {results['residual_max']}; Q max {results['Q_max']:.4g} at "
              f"t={results['t_Q_max']:.3g}\nresults: {os.path.join(outdir, 'results.json')}")
        return results

    @staticmethod
    def plot(outdir, cols, refs):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4.5))
        ax.plot(cols["T"], cols["toe"], "k-", label="sphgen variational scheme")
        for (name, (Tr, Zr)), m in zip(refs.items(), ("bo", "bs", "r^")):
            ax.plot(Tr, Zr, m, mfc="none", label=name)
        ax.set_xlabel("$T = t\\sqrt{2g/L}$")
        ax.set_ylabel("toe $x/L$")
        ax.legend(loc="upper left")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "toe.png"), dpi=100)
        plt.close(fig)
        fig, ax = plt.subplots(figsize=(6, 4.5))
        ax.plot(cols["t"], cols["Q"], "k-")
        ax.set_xlabel("t (s)")
        ax.set_ylabel("Q = |sum m v| / M (m/s)")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "momentum.png"), dpi=100)
        plt.close(fig)
        fig, (a1, a2) = plt.subplots(2, 1, figsize=(6, 6), sharex=True)
        a1.plot(cols["t"], cols["iterations_max"], "k.")
        a1.set_ylabel("iterations (max per sample)")
        a2.semilogy(cols["t"], np.maximum(cols["residual_max"], 1e-300), "k.")
        a2.set_ylabel("residual (m)")
        a2.set_xlabel("t (s)")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "iterations.png"), dpi=100)
        plt.close(fig)
