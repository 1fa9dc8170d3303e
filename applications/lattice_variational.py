"""A smooth periodic problem for the time integrators of da Silva & Giraldi (2024): an inviscid
Taylor-Green velocity field on a periodic lattice, :class:`~schemes.variational.VariationalScheme`.

The order of accuracy in dt and the long-time energy error of the variational midpoint
integrator (eqs. 37, 40-42, 63-65) against the explicit leapfrog (eqs. 59-62) are measured on
it (``python automate.py variational_order variational_energy``; docs/variational.md).

Set-up: nx x nx particles at spacing dx = 0.005 m in a periodic square of side L = nx dx, rho = rho0,
m = rho0 dx^2, u = U sin(kx) cos(ky), v = -U cos(kx) sin(ky), k = 2 pi / L; no walls, no gravity,
no artificial viscosity by default (``--av-a 0 --av-b 0``).  The initial internal acceleration is
zero (uniform density on a lattice), so the start rule v(-dt/2) = v(0) (eq. 60 with g = 0) is
second-order consistent.  ``--density summation`` (eq. 20, default: the scheme of eq. 37 whose
discrete Lagrangian the integrator is derived from) or ``continuity`` (eq. 67, the paper's runs).

History (every ``--record-every`` steps): the energy at t_k, E_k = sum m |v_k|^2 / 2 + sum m e(rho_i(q_k))
with v_k the mean of the two half-step velocities around t_k, e the Tait internal energy
(de/drho = p/rho^2) and rho_i(q_k) the summation density of eq. 20 at q_k (numpy, all pairs) --
the same measurement for both integrators, whatever density they carry -- and the linear momentum.
``results.json``: energy error max |E - E0|/E0 and its drift, iteration statistics, and with
``--reference-run DIR`` the position error at the final time against that run (periodic images).
"""
import os
from math import pi

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.nnps import Domain
from sphgen.particles import ParticleArray

from ..equations.variational import kernel_parameters
from ..schemes.variational import PREDICTORS, VariationalScheme
from .dam_break_variational import earlier_steps, iteration_statistics, position_error, write_steps

try:
    from sphgen.errors import InputError
except ImportError:  # pragma: no cover
    InputError = ValueError

DX, RHO0 = 0.005, 1000.0


class LatticeVariational(Application):
    """Inviscid Taylor-Green field on a periodic lattice: variational midpoint or explicit leapfrog."""

    tf = 0.004
    pfreq = 100000
    error_key = "position_error_max"   # `sphgen precision ... --dt-factor ... --reference-run DIR`
    dim = 2
    history_columns = ("t", "kinetic", "internal", "energy", "px", "py", "iterations_max", "residual_max")

    def add_user_options(self, group):
        group.add_argument("--nx", type=int, default=8, help="particles per side (default %(default)s)")
        group.add_argument("--U", type=float, default=1.0, help="velocity amplitude, m/s (default %(default)s)")
        group.add_argument("--integrator", choices=("variational", "explicit"), default="variational")
        group.add_argument("--alpha", type=float, default=0.5, help="midpoint parameter (default %(default)s)")
        group.add_argument("--tol", type=float, default=1e-14,
                           help="fixed-point tolerance, metres, max-norm (default %(default)s)")
        group.add_argument("--max-iter", type=int, default=80, help="iteration cap (default %(default)s)")
        group.add_argument("--predictor", choices=tuple(PREDICTORS), default="verlet")
        group.add_argument("--density", choices=("summation", "continuity", "centred"), default="summation",
                           help="summation (eq. 20, default), continuity (eq. 67) or centred continuity density")
        group.add_argument("--kernel", choices=("K1", "K2", "K3"), default="K3")
        group.add_argument("--c0", type=float, default=23.841, help="speed of sound (default %(default)s)")
        group.add_argument("--av-a", type=float, default=0.0, help="AV a (default %(default)s)")
        group.add_argument("--av-b", type=float, default=0.0, help="AV b (default %(default)s)")
        group.add_argument("--time-step", type=float, default=1e-4, help="dt (default %(default)s s)")
        group.add_argument("--record-every", type=int, default=10, help="steps between history samples")
        group.add_argument("--reference-run", default=None, metavar="DIR",
                           help="a run of this case at a finer dt: position error at the final time")

    def consume_user_options(self, o):
        if o.nx < 4:
            raise InputError(f"--nx must be at least 4, got {o.nx}")
        for name in ("tol", "c0", "time_step"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive finite number, got {v}")
        if not np.isfinite(o.U):
            raise InputError(f"--U must be finite, got {o.U}")
        if not 0.0 <= o.alpha <= 1.0:
            raise InputError(f"--alpha must be in [0, 1], got {o.alpha}")
        if o.density == "centred" and o.integrator != "variational":
            raise InputError("--density centred needs --integrator variational")
        if o.max_iter < 1 or o.record_every < 1:
            raise InputError("--max-iter and --record-every must be at least 1")
        if o.reference_run is not None and not (os.path.isdir(o.reference_run)
                                                and io.output_files(o.reference_run)):
            raise InputError(f"--reference-run {o.reference_run}: no output files there")
        self.L = o.nx * DX
        self.steps, self._prev = [], None

    def create_scheme(self):
        o = self.options
        return VariationalScheme(["fluid"], [], dim=2, rho0=RHO0, c0=o.c0, kernel=o.kernel, dx=DX,
                                 av_a=o.av_a, av_b=o.av_b, integrator=o.integrator, alpha=o.alpha,
                                 tol=o.tol, max_iter=o.max_iter, predictor=o.predictor,
                                 dt=o.time_step, density=o.density)

    def create_particles(self):
        o = self.options
        ax = (np.arange(o.nx) + 0.5) * DX
        x, y = (g.ravel() for g in np.meshgrid(ax, ax, indexing="ij"))
        k = 2.0 * pi / self.L
        n = x.size
        h = VariationalScheme(["fluid"], [], kernel=o.kernel, dx=DX).h
        fluid = ParticleArray("fluid", x=x, y=y, u=o.U * np.sin(k * x) * np.cos(k * y),
                              v=-o.U * np.cos(k * x) * np.sin(k * y), m=np.full(n, RHO0 * DX * DX),
                              rho=np.full(n, RHO0), h=np.full(n, h))
        fluid.add_property("p")
        # the state at t_0 (gid = creation order): u holds v_{-1/2} = v(0) (start rule, g = 0)
        self._prev = (x.copy(), y.copy(), fluid.u.copy(), fluid.v.copy(),
                      np.array([np.sum(fluid.m * fluid.u), np.sum(fluid.m * fluid.v)]))
        return [fluid]

    def create_domain(self):
        return Domain(0.0, self.L, 0.0, self.L, periodic_in_x=True, periodic_in_y=True)

    def history_meta(self):
        o = self.options
        meta = {k: getattr(o, k) for k in ("integrator", "alpha", "tol", "density", "nx", "U")}
        if o.integrator == "explicit":
            meta["alpha"] = meta["tol"] = None
        meta["time_step"] = self.solver.dt if self.solver is not None else o.time_step
        return meta

    def _write_progress(self, **state):
        super()._write_progress(**state)
        write_steps(self)

    def _restart(self, path, data, dt):
        """Continue the energy series exactly: the per-step rows, the state at t_k the next
        sample needs, and no sample at t_k twice (a sample is written a step after its time)."""
        super()._restart(path, data, dt)
        t = self.solver.t
        self.history = [r for r in self.history if r[0] < t - 0.5 * dt]
        self.steps = earlier_steps(path, t)
        f = self.scene.by_name["fluid"]
        order = np.argsort(f.gid)
        x, y, u, v, m = (a[order].copy() for a in (f.x, f.y, f.u, f.v, f.m))
        self._prev = (x, y, u, v, np.array([np.sum(m * u), np.sum(m * v)]))

    # ------------------------------------------------------------ diagnostics
    def energy(self, x, y, u, v, m):
        """E = sum m |v|^2/2 + sum m e(rho(q)), rho the summation density of eq. 20 at q (all pairs)."""
        s = self.scheme
        ell, lam, rc, shift = kernel_parameters(s.kernel_name, DX, s.h_cut)
        dx, dy = x[:, None] - x[None, :], y[:, None] - y[None, :]
        dx -= self.L * np.round(dx / self.L)
        dy -= self.L * np.round(dy / self.L)
        r2 = dx * dx + dy * dy
        w = np.where(r2 <= rc * rc, ell * (np.exp(-r2 / lam ** 2) - shift * (1.0 + (rc * rc - r2) / lam ** 2)), 0.0)
        rho = w @ m
        r = rho / s.rho0
        e = s.B / ((s.gamma - 1.0) * s.rho0) * (r ** (s.gamma - 1.0) - 1.0) + s.B * (1.0 / rho - 1.0 / s.rho0)
        ke = 0.5 * float(np.sum(m * (u * u + v * v)))
        return ke, float(np.sum(m * e))

    def post_step(self, solver):
        f = self.scene.by_name["fluid"]
        integ = solver.integrator
        it, res, con = 0, float("nan"), float("nan")
        if hasattr(integ, "iterations") and integ.k > 1:
            it, res, con = integ.iterations, integ.residual, integ.contraction
        order = np.argsort(f.gid)
        x, y, u, v, m = (a[order].copy() for a in (f.x, f.y, f.u, f.v, f.m))
        p = np.array([np.sum(m * u), np.sum(m * v)])
        budget = float(np.abs(p - self._prev[4]).max()) / float(m.sum())   # no external force
        self.steps.append([solver.t, solver.step, it, res, con, budget])
        prev, self._prev = self._prev, (x, y, u, v, p)
        if (solver.step - 1) % self.options.record_every:
            return
        # E at t_k = t - dt: positions q_k (held before this step), v_k = mean of v_{k -+ 1/2}
        ke, ie = self.energy(prev[0], prev[1], 0.5 * (prev[2] + u), 0.5 * (prev[3] + v), m)
        w = np.array(self.steps[-self.options.record_every:], dtype=float)
        pk = 0.5 * (prev[4] + p)
        self.history.append([solver.t - solver.last_dt, ke, ie, ke + ie, float(pk[0]), float(pk[1]),
                             float(w[:, 2].max()), float(np.nanmax(w[:, 3])) if np.isfinite(w[:, 3]).any() else 0.0])

    # ------------------------------------------------------------ results
    def post_process(self, outdir):
        hist, rows = io.read_history(outdir, allow_empty=True)
        results = {k: hist.get(k) for k in ("integrator", "alpha", "tol", "density", "nx", "U", "time_step")}
        results.update(iteration_statistics(outdir))
        if rows.size:
            t, E = rows[:, 0], rows[:, 3]
            rel = E / E[0] - 1.0
            half = t >= 0.5 * t[-1]
            results.update({"t": float(t[-1]), "E0": float(E[0]), "energy_error": float(np.abs(rel).max()),
                            "energy_final": float(rel[-1]),
                            "energy_mean_second_half": float(rel[half].mean()),
                            "momentum_max": float(np.abs(rows[:, 4:6]).max())})
        if self.options.reference_run:
            results.update(position_error(outdir, self.options.reference_run, period=self.L))
        io.write_json(os.path.join(outdir, "results.json"), results)
        print(f"lattice_variational: {results['integrator']} alpha={results['alpha']} dt={results['time_step']}: "
              f"energy error {results.get('energy_error')}, position error {results.get('position_error_max')}"
              f"\nresults: {os.path.join(outdir, 'results.json')}")
        return results
