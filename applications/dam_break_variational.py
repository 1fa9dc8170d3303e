"""Dam break of da Silva & Giraldi (2024, section 6): variational (generalised midpoint) or
explicit leapfrog time integration, :class:`~sphgen.schemes.variational.VariationalScheme`.

Printed set-up: tank 0.58 x 0.29 m, water column 0.145 x 0.29 m of 29 x 58 = 1682
particles (dx = 0.005, m = 0.025 kg per metre of depth), rho0 = 1000, g = 9.8, Gaussian
kernel cut at h = 0.072, eps = 0.001, dt = 1e-4 s, alpha = 0.5.  Not printed, options
with these defaults (the project's digest of the paper, sections 3.6 and 6):

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

from sphgen import io, run_folder
from sphgen.app import Application
from sphgen.particles import ParticleArray
from sphgen.tools.probes import count_neighbours, front_position
from sphgen.tools import reference

from ..schemes.variational import DENSITIES, PREDICTORS, VariationalScheme
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
STEP_COLUMNS = ("t", "step", "iterations", "residual", "contraction", "budget")
"""steps.json, one row per step: fixed-point iterations (0: explicit or the start-up step),
last residual r_j (m), largest ratio r_j/r_{j-1}, momentum-budget residual (m/s)."""


class DamBreakVariational(Application):
    """Dam break of da Silva & Giraldi (2024): variational midpoint or explicit leapfrog."""

    tf = 1.0
    pfreq = 1000
    error_key = "position_error_rms"   # `sphgen precision ... --reference-run DIR`
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
                           help="time between history samples (default %(default)s s); the "
                                "per-step rows (iterations, residual, budget) go to steps.json")
        group.add_argument("--density", choices=DENSITIES, default="continuity",
                           help="continuity (eq. 67, the paper's runs), summation density (eq. 20) or "
                                "centred (eq. 67 interpolated like q, second order; variational only)")
        group.add_argument("--perturb", type=float, default=0.0,
                           help="random displacement of the fluid particles, in dx (default 0)")
        group.add_argument("--seed", type=int, default=1, help="seed of --perturb (default 1)")
        group.add_argument("--reference-run", default=None, metavar="DIR",
                           help="a run of this case (e.g. at a fine dt) to measure the position "
                                "error against at the final time (results.json position_error_*)")

    def consume_user_options(self, o):
        for name in ("tol", "h_cut", "c0", "D", "r0", "wall_spacing", "time_step", "record_every"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive finite number, got {v}")
        if not 0.0 <= o.alpha <= 1.0:
            raise InputError(f"--alpha must be in [0, 1], got {o.alpha}")
        if o.max_iter < 1:
            raise InputError(f"--max-iter must be >= 1, got {o.max_iter}")
        if o.density == "centred" and o.integrator != "variational":
            raise InputError("--density centred needs --integrator variational")
        if not (np.isfinite(o.perturb) and 0.0 <= o.perturb < 0.5):
            raise InputError(f"--perturb must be in [0, 0.5), got {o.perturb}")
        if o.reference_run is not None and not (os.path.isdir(o.reference_run)
                                                and io.output_files(o.reference_run)):
            raise InputError(f"--reference-run {o.reference_run}: no output files there")
        self.history = []
        self.steps = []            # one row per step: STEP_COLUMNS
        self._next_record = 0.0
        self._p_prev = None
        self._window_start = 0     # first row of self.steps since the last history sample

    def create_scheme(self):
        o = self.options
        return VariationalScheme(["fluid"], ["wall"], dim=2, rho0=RHO0, c0=o.c0, gy=-G, kernel=o.kernel,
                                 dx=DX, h_cut=o.h_cut, av_a=o.av_a, av_b=o.av_b, D=o.D, r0=o.r0,
                                 wall_power=o.wall_power, integrator=o.integrator, alpha=o.alpha,
                                 tol=o.tol, max_iter=o.max_iter, predictor=o.predictor, dt=o.time_step,
                                 density=o.density)

    def create_particles(self):
        o = self.options
        h = VariationalScheme(["fluid"], [], kernel=o.kernel, dx=DX, h_cut=o.h_cut).h
        ax, ay = (np.arange(NX) + 0.5) * DX, (np.arange(NY) + 0.5) * DX
        x, y = (g.ravel() for g in np.meshgrid(ax, ay, indexing="ij"))
        n = x.size
        if o.perturb > 0:
            rng = np.random.default_rng(o.seed)
            x = x + o.perturb * DX * rng.uniform(-1, 1, n)
            y = y + o.perturb * DX * rng.uniform(-1, 1, n)
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
        self.E0 = float(np.sum(fluid.m * G * fluid.y))   # at rest, rho = rho0: gravity only
        return [fluid, wall]

    def history_meta(self):
        o = self.options
        return {"integrator": o.integrator, "alpha": o.alpha, "tol": o.tol, "kernel": o.kernel,
                "density": o.density, "L": L, "M": self.M, "E0": self.E0}

    def _write_progress(self, **state):
        """history.json and info.json (base class) and steps.json: one row per step."""
        super()._write_progress(**state)
        write_steps(self)

    def _signature(self, arrays):
        """The scene's identity for restarts: --reference-run only changes the analysis."""
        sig = super()._signature(arrays)
        sig["options"].pop("reference_run", None)
        return sig

    def _restart(self, path, data, dt):
        """Continue the time series exactly: the per-step rows, the last half-step momentum
        (Q is the mean of two), the next sample time and the steps since the last sample."""
        super()._restart(path, data, dt)
        self.steps = earlier_steps(path, self.solver.t)
        f = self.scene.by_name["fluid"]
        self._p_prev = np.array([np.sum(f.m * f.u), np.sum(f.m * f.v)])
        if self.history:
            last = self.history[-1][0]
            self._next_record = last + self.options.record_every
            self._window_start = sum(1 for r in self.steps if r[0] <= last + 1e-12 * max(1.0, last))
        else:
            self._window_start = len(self.steps)

    # ------------------------------------------------------------ diagnostics
    def post_step(self, solver):
        f = self.scene.by_name["fluid"]
        integ = solver.integrator
        it, res, con = 0, float("nan"), float("nan")    # explicit, or the start-up step
        if hasattr(integ, "iterations") and integ.k > 1:
            it, res, con = integ.iterations, integ.residual, integ.contraction
        p = np.array([np.sum(f.m * f.u), np.sum(f.m * f.v)])   # sum m v_{k+1/2} after the step
        budget = float("nan")
        if self._p_prev is not None:
            # momentum budget: sum m dv = dt sum m (Gamma_k + g), to round-off
            imp = solver.last_dt * np.array([np.sum(f.m * f.gwx), np.sum(f.m * (f.gwy - G))])
            budget = float(np.abs(p - self._p_prev - imp).max()) / self.M
        self.steps.append([solver.t, solver.step, it, res, con, budget])
        p_mid = p if self._p_prev is None else 0.5 * (p + self._p_prev)
        self._p_prev = p
        if solver.t + 1e-12 >= self._next_record or solver.t >= solver.tf - 1e-12:
            w = np.array(self.steps[self._window_start:], dtype=float)
            self._window_start = len(self.steps)
            iterated = w[:, 2] >= 1
            e = self.scheme.energies([f])
            toe = front_position(f.x, f.y, 0.0, DX) / L
            self.history.append([
                solver.t, solver.t * sqrt(2.0 * G / L), toe, float(np.hypot(*p_mid)) / self.M,
                float(p_mid[0]), float(p_mid[1]),
                float(w[iterated, 2].max()) if iterated.any() else 0.0,
                float(w[iterated, 3].max()) if iterated.any() else 0.0,
                float(np.nanmax(w[:, 4])) if np.isfinite(w[:, 4]).any() else float("nan"),
                float(np.nanmax(w[:, 5])) if np.isfinite(w[:, 5]).any() else 0.0,
                float(f.rho.min()), float(f.rho.max()), e["kinetic"], e["potential"], e["internal"]])
            self._next_record = solver.t + self.options.record_every

    # ------------------------------------------------------------ results
    def ejected_final(self, outdir):
        """Ejected fluid particles at the end: from the last output file, or from the state
        in memory if the run wrote none (``--disable-output``)."""
        if io.output_files(outdir):
            x, y = final_positions(outdir)
        elif getattr(self, "solver", None) is not None:
            f = self.scene.by_name["fluid"]
            x, y = f.x, f.y
        else:
            return None
        return int(ejected(x, y).sum())

    def post_process(self, outdir):
        hist, rows = io.read_history(outdir)
        cols = {c: rows[:, i] for i, c in enumerate(hist["columns"])}
        T, Z = cols["T"], cols["toe"]
        ok = np.isfinite(Z)
        results = {k: hist.get(k) for k in ("integrator", "alpha", "tol", "kernel", "density")}
        results.update(iteration_statistics(outdir))
        energy = cols["kinetic"] + cols["potential"] + cols["internal"]
        results.update({"t": float(cols["t"][-1]), "T": float(T[-1]), "n_samples": int(rows.shape[0]),
                        "Q_max": float(cols["Q"].max()), "t_Q_max": float(cols["t"][np.argmax(cols["Q"])]),
                        "Q_final": float(cols["Q"][-1]),
                        "momentum_budget_residual_max": float(cols["budget_max"].max()),
                        "rho_min": float(cols["rho_min"].min()), "rho_max": float(cols["rho_max"].max()),
                        "max_density_error": float(max(abs(cols["rho_min"].min() / RHO0 - 1.0),
                                                       abs(cols["rho_max"].max() / RHO0 - 1.0))),
                        "energy_final": float(energy[-1]) / hist["E0"] - 1.0,
                        "energy_error": float(np.abs(energy / hist["E0"] - 1.0).max()),
                        "ejected_final": self.ejected_final(outdir)})
        if self.options.reference_run:
            results.update(position_error(outdir, self.options.reference_run))
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
        it = _iterations(outdir)
        if it.size == 0:
            return
        fig, (a1, a2, a3) = plt.subplots(3, 1, figsize=(6, 7), sharex=True)
        a1.plot(it[:, 0], it[:, 2], "k.", ms=2)
        a1.set_ylabel("iterations")
        a2.semilogy(it[:, 0], np.maximum(it[:, 3], 1e-300), "k.", ms=2)
        a2.set_ylabel("last residual (m)")
        a3.plot(it[:, 0], it[:, 4], "k.", ms=2)
        a3.set_ylabel("contraction (max ratio)")
        a3.set_xlabel("t (s)")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "iterations.png"), dpi=100)
        plt.close(fig)


def write_steps(app):
    """steps.json of a variational application: its per-step rows (STEP_COLUMNS) and the
    integrator's evaluation counts."""
    io.write_json(os.path.join(app.outdir, "steps.json"),
                  {"columns": list(STEP_COLUMNS), "rows": app.steps,
                   "evaluations": getattr(app.solver.integrator, "evaluations", None)})


def earlier_steps(path, t):
    """The steps.json rows (STEP_COLUMNS) of the run restarted from ``path``, up to time ``t``."""
    steps = run_folder.earlier_history(path, t, "steps.json")
    return [list(r) for r in steps["rows"]] if steps is not None else []


# ---------------------------------------------------------------- analysis of finished runs
def _steps(outdir):
    """(rows of steps.json as an array (STEP_COLUMNS), evaluations) of a run."""
    with open(os.path.join(outdir, "steps.json")) as fh:
        data = json.load(fh)
    return np.array(data["rows"], dtype=float).reshape(-1, len(STEP_COLUMNS)), data.get("evaluations")


def _iterations(outdir):
    """The per-step rows of the steps that iterated (t, step, iterations, residual, contraction)."""
    rows, _ = _steps(outdir)
    return rows[rows[:, 2] >= 1, :5]


def iteration_statistics(outdir):
    """Per-step fixed-point statistics of a run (None for the explicit integrator), and the
    number of equation-set evaluations of the time loop (since the last restart)."""
    it = _iterations(outdir)
    evaluations = _steps(outdir)[1]
    if it.size == 0:
        return {"steps_iterated": 0, "iterations_mean": None, "iterations_max": None,
                "iteration_counts": None, "residual_max": None, "contraction_max": None,
                "evaluations": evaluations}
    n, counts = np.unique(it[:, 2].astype(int), return_counts=True)
    c = it[:, 4][np.isfinite(it[:, 4])]
    return {"steps_iterated": int(it.shape[0]), "iterations_mean": float(it[:, 2].mean()),
            "iterations_max": int(it[:, 2].max()),
            "iteration_counts": {str(k): int(v) for k, v in zip(n, counts)},
            "residual_max": float(it[:, 3].max()), "contraction_max": float(c.max()) if c.size else None,
            "evaluations": evaluations}


def positions(path):
    """(gid, x, y) of the fluid in an output file, sorted by persistent id."""
    f = io.load(path)["arrays"]["fluid"]
    order = np.argsort(f.gid)
    return f.gid[order], f.x[order], f.y[order]


def final_positions(outdir):
    """(x, y) of the fluid in the last output file of a run."""
    _, x, y = positions(io.output_files(outdir)[-1])
    return x, y


def ejected(x, y):
    """Fluid particles out of the fluid volume: fewer than a quarter of the median number of
    neighbours within 2.5 dx (the rule of :func:`sphgen.tools.probes.front_position`)."""
    counts = count_neighbours((np.asarray(x), np.asarray(y)), 2.5 * DX)
    return counts < 0.25 * np.median(counts)


def outputs_by_time(outdir):
    """{t: path} of a run's output files."""
    return {round(float(io.read_solver_data(p)["t"]), 9): p for p in io.output_files(outdir)}


def scheme_difference(dir_a, dir_b):
    """D(t) = max_i |q_i^a - q_i^b| (da Silva & Giraldi 2024, eq. 70), particles paired by
    their persistent id, at the output times the two runs share: (t, D) arrays."""
    a, b = outputs_by_time(dir_a), outputs_by_time(dir_b)
    ts = sorted(set(a) & set(b))
    d = []
    for t in ts:
        ga, xa, ya = positions(a[t])
        gb, xb, yb = positions(b[t])
        if not np.array_equal(ga, gb):
            raise InputError(f"{a[t]} and {b[t]} do not hold the same particles")
        d.append(float(np.hypot(xa - xb, ya - yb).max()))
    return np.array(ts), np.array(d)


def position_error(outdir, reference_dir, period=None):
    """Position error of a run's last output against the output of ``reference_dir`` at the
    same time: max and rms over the fluid of |q_i - q_i^ref| (metres); with ``period`` (a
    periodic square of that side) the nearest periodic image is compared."""
    last = io.output_files(outdir)[-1]
    t = round(float(io.read_solver_data(last)["t"]), 9)
    ref = outputs_by_time(reference_dir).get(t)
    if ref is None:
        raise InputError(f"--reference-run {reference_dir} has no output at t={t:g}")
    g, x, y = positions(last)
    gr, xr, yr = positions(ref)
    if not np.array_equal(g, gr):
        raise InputError(f"--reference-run {reference_dir} holds other particles")
    dx, dy = x - xr, y - yr
    if period is not None:
        dx -= period * np.round(dx / period)
        dy -= period * np.round(dy / period)
    e = np.hypot(dx, dy)
    return {"position_error_max": float(e.max()), "position_error_rms": float(np.sqrt(np.mean(e * e))),
            "reference_run": os.path.abspath(reference_dir)}
