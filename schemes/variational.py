"""Variational time integration for SPH (da Silva & Giraldi 2024): the generalised-midpoint
discrete Euler-Lagrange scheme solved by fixed-point iteration, and the explicit leapfrog.

:class:`VariationalMidpoint` (eqs. 37, 40-42, 63-65, Algorithm 1), in velocity form
(the project's digest of the paper, section 2.4): with q_k, v_{k-1,k} = (q_k - q_{k-1})/dt and rho_{k-1,k} known,

* a_2 = A_int at xbar_old = (1-alpha) q_{k-1} + alpha q_k = q_k - (1-alpha) dt v_{k-1,k},
  velocity v_{k-1,k}, density rho_{k-1,k} (evaluation 0, once per step),
* Gamma_k = wall force at q_k (evaluation 2, once per step; eq. 58),
* predictor (Verlet): v^(0) = v_{k-1,k} + dt (a_2 + Gamma_k + g), q^(0) = q_k + dt v^(0),
* iteration j: at xbar = (1-alpha) q_k + alpha q^(j-1) with velocity v^(j-1),
  rho = rho_{k-1,k} + dt Cont (eq. 67, sign fixed), p = Tait, a_1 = A_int (evaluation 1);
  v^(j) = v_{k-1,k} + dt ((1-alpha)(a_1 + Gamma_k + g) + alpha (a_2 + Gamma_k + g)),
  q^(j) = q_k + dt v^(j); residual r_j = max_i |q^(j)_i - q^(j-1)_i| (metres); stop when r_j <= eps,
* finalise: rho_{k,k+1} from the accepted q_{k+1} (evaluation 1 once more), shift the levels.

Step 0 is one explicit leapfrog step (the start rule v(-dt/2) = v(0) - dt g/2 of eq. 60)
followed by the density finalisation at xbar(q_0, q_1), so alpha = 1 is the explicit
leapfrog to round-off (digest A14, A27).

:class:`ExplicitLeapfrog` (eqs. 59-62): rho_k = rho_{k-1} + dt Cont(q_k, v_{k-1/2}), a_k at q_k,
v_{k+1/2} = v_{k-1/2} + dt (a_k + Gamma_k + g), q_{k+1} = q_k + dt v_{k+1/2}.

Between steps the arrays hold x = q_k, u = v_{k-1/2} (the last half-step velocity),
rho = rho_{k-1,k}: what is written to the output files.  Two dimensions only.
"""
import numpy as np

from sphgen.equation import Group
from sphgen.errors import BlowUpError
from sphgen.integrators import Integrator, IntegratorStep
from sphgen.kernels import get_kernel
from sphgen.scheme import Scheme

try:
    from sphgen.scheme import Bound
except ImportError:  # pragma: no cover
    Bound = None

from ..equations.variational import (GaussianContinuityDensity, GaussianPressureGradient,
                                     GaussianSummationDensity, PaperArtificialViscosity,
                                     ZeroAcceleration, kernel_parameters)
from ..equations.walls import LennardJonesWallForce
from ..equations.wcsph import TaitEOS

DENSITIES = ("continuity", "summation", "centred")
"""continuity: eq. 67 as printed (rho_{k,k+1} used at beta_{k,k+1}: first order in dt); summation:
eq. 20 at the interpolated configuration; centred (ours, variational integrator only): rhok holds
rho_k, the forces at beta_{k,k+1} use rho_k + alpha dt Cont(beta_{k,k+1}, v_{k,k+1}), those at
beta_{k-1,k} use rho_k - (1 - alpha) dt Cont(beta_{k-1,k}, v_{k-1,k}), and the accepted step sets
rho_{k+1} = rho_k + dt Cont(beta_{k,k+1}, v_{k,k+1}): the density interpolated like q."""

PREDICTORS = {"verlet": 0, "linear": 1, "previous": 2}
"""Initial guess q^(0) of the iteration (digest A15): verlet q_k + dt (v_{k-1,k} + dt (a_2 +
Gamma_k + g)) (default), linear 2 q_k - q_{k-1}, previous q_k."""

FLUID_PROPS = ("xk", "yk", "uh", "vh", "ui", "vi", "xi", "yi", "a2x", "a2y", "gwx", "gwy",
               "rhok", "res", "p", "arho", "au", "av", "aw")


class VariationalStep(IntegratorStep):
    """Per-particle stages of both integrators (2-D; da Silva & Giraldi 2024, eqs. 60-65).

    stage1 start rule (eq. 60); stage2-4 explicit leapfrog (eqs. 59-62); stage5 the
    startup finalisation; stage6-9 the fixed-point iteration (eqs. 40, 63); stage10 accept;
    stage11 back to the start of the step (after a non-converged iteration).
    """

    switches = ("predictor", "centred")

    def __init__(self, alpha=0.5, gx=0.0, gy=0.0, predictor=0, centred=0):
        self.alpha = float(alpha)
        self.gx, self.gy = float(gx), float(gy)
        self.predictor = int(predictor)   # PREDICTORS: 0 verlet, 1 linear, 2 previous
        self.centred = int(centred)       # 1: rhok holds rho_k, advanced by dt Cont at acceptance

    def stage1(self, d_idx, d_u, d_v, d_uh, d_vh, d_rho, d_rhok, dt):
        d_uh[d_idx] = d_u[d_idx] - 0.5 * dt * self.gx
        d_vh[d_idx] = d_v[d_idx] - 0.5 * dt * self.gy
        d_rhok[d_idx] = d_rho[d_idx]

    def stage2(self, d_idx, d_x, d_y, d_xk, d_yk, d_u, d_v, d_uh, d_vh):
        d_xk[d_idx] = d_x[d_idx]
        d_yk[d_idx] = d_y[d_idx]
        d_u[d_idx] = d_uh[d_idx]
        d_v[d_idx] = d_vh[d_idx]

    def stage3(self, d_idx, d_au, d_av, d_a2x, d_a2y):
        d_a2x[d_idx] = d_au[d_idx]
        d_a2y[d_idx] = d_av[d_idx]

    def stage4(self, d_idx, d_x, d_y, d_xk, d_yk, d_u, d_v, d_uh, d_vh, d_au, d_av, d_a2x, d_a2y,
               d_gwx, d_gwy, d_rho, d_rhok, dt):
        d_gwx[d_idx] = d_au[d_idx]
        d_gwy[d_idx] = d_av[d_idx]
        d_uh[d_idx] = d_uh[d_idx] + dt * ((d_a2x[d_idx] + d_au[d_idx]) + self.gx)
        d_vh[d_idx] = d_vh[d_idx] + dt * ((d_a2y[d_idx] + d_av[d_idx]) + self.gy)
        d_x[d_idx] = d_xk[d_idx] + dt * d_uh[d_idx]
        d_y[d_idx] = d_yk[d_idx] + dt * d_vh[d_idx]
        d_u[d_idx] = d_uh[d_idx]
        d_v[d_idx] = d_vh[d_idx]
        if self.centred == 0:
            d_rhok[d_idx] = d_rho[d_idx]

    def stage5(self, d_idx, d_x, d_y, d_xk, d_yk, d_xi, d_yi, d_u, d_v, d_ui, d_vi, d_uh, d_vh):
        d_xi[d_idx] = d_x[d_idx]
        d_yi[d_idx] = d_y[d_idx]
        d_ui[d_idx] = d_uh[d_idx]
        d_vi[d_idx] = d_vh[d_idx]
        d_x[d_idx] = (1.0 - self.alpha) * d_xk[d_idx] + self.alpha * d_xi[d_idx]
        d_y[d_idx] = (1.0 - self.alpha) * d_yk[d_idx] + self.alpha * d_yi[d_idx]
        d_u[d_idx] = d_ui[d_idx]
        d_v[d_idx] = d_vi[d_idx]

    def stage6(self, d_idx, d_x, d_y, d_xk, d_yk, d_u, d_v, d_uh, d_vh, d_rho, d_rhok, dt):
        d_xk[d_idx] = d_x[d_idx]
        d_yk[d_idx] = d_y[d_idx]
        d_x[d_idx] = d_xk[d_idx] - (1.0 - self.alpha) * dt * d_uh[d_idx]
        d_y[d_idx] = d_yk[d_idx] - (1.0 - self.alpha) * dt * d_vh[d_idx]
        d_u[d_idx] = d_uh[d_idx]
        d_v[d_idx] = d_vh[d_idx]
        d_rho[d_idx] = d_rhok[d_idx]

    def stage7(self, d_idx, d_x, d_y, d_xk, d_yk, d_au, d_av, d_a2x, d_a2y):
        d_a2x[d_idx] = d_au[d_idx]
        d_a2y[d_idx] = d_av[d_idx]
        d_x[d_idx] = d_xk[d_idx]
        d_y[d_idx] = d_yk[d_idx]

    def stage8(self, d_idx, d_x, d_y, d_xk, d_yk, d_xi, d_yi, d_u, d_v, d_ui, d_vi, d_uh, d_vh,
               d_au, d_av, d_a2x, d_a2y, d_gwx, d_gwy, dt):
        d_gwx[d_idx] = d_au[d_idx]
        d_gwy[d_idx] = d_av[d_idx]
        if self.predictor == 0:
            d_ui[d_idx] = d_uh[d_idx] + dt * ((d_a2x[d_idx] + d_gwx[d_idx]) + self.gx)
            d_vi[d_idx] = d_vh[d_idx] + dt * ((d_a2y[d_idx] + d_gwy[d_idx]) + self.gy)
        elif self.predictor == 1:
            d_ui[d_idx] = d_uh[d_idx]
            d_vi[d_idx] = d_vh[d_idx]
        else:
            d_ui[d_idx] = 0.0
            d_vi[d_idx] = 0.0
        d_xi[d_idx] = d_xk[d_idx] + dt * d_ui[d_idx]
        d_yi[d_idx] = d_yk[d_idx] + dt * d_vi[d_idx]
        d_x[d_idx] = (1.0 - self.alpha) * d_xk[d_idx] + self.alpha * d_xi[d_idx]
        d_y[d_idx] = (1.0 - self.alpha) * d_yk[d_idx] + self.alpha * d_yi[d_idx]
        d_u[d_idx] = d_ui[d_idx]
        d_v[d_idx] = d_vi[d_idx]

    def stage9(self, d_idx, d_x, d_y, d_xk, d_yk, d_xi, d_yi, d_u, d_v, d_ui, d_vi, d_uh, d_vh,
               d_au, d_av, d_a2x, d_a2y, d_gwx, d_gwy, d_res, dt):
        a = self.alpha
        ax = (1.0 - a) * ((d_au[d_idx] + d_gwx[d_idx]) + self.gx) + a * ((d_a2x[d_idx] + d_gwx[d_idx]) + self.gx)
        ay = (1.0 - a) * ((d_av[d_idx] + d_gwy[d_idx]) + self.gy) + a * ((d_a2y[d_idx] + d_gwy[d_idx]) + self.gy)
        d_ui[d_idx] = d_uh[d_idx] + dt * ax
        d_vi[d_idx] = d_vh[d_idx] + dt * ay
        xn = d_xk[d_idx] + dt * d_ui[d_idx]
        yn = d_yk[d_idx] + dt * d_vi[d_idx]
        dx = xn - d_xi[d_idx]
        dy = yn - d_yi[d_idx]
        d_res[d_idx] = dx * dx + dy * dy
        d_xi[d_idx] = xn
        d_yi[d_idx] = yn
        d_x[d_idx] = (1.0 - a) * d_xk[d_idx] + a * xn
        d_y[d_idx] = (1.0 - a) * d_yk[d_idx] + a * yn
        d_u[d_idx] = d_ui[d_idx]
        d_v[d_idx] = d_vi[d_idx]

    def stage10(self, d_idx, d_x, d_y, d_xi, d_yi, d_u, d_v, d_ui, d_vi, d_uh, d_vh, d_rho, d_rhok,
                d_arho, dt):
        if self.centred == 0:
            d_rhok[d_idx] = d_rho[d_idx]
        else:
            d_rhok[d_idx] = d_rhok[d_idx] + dt * d_arho[d_idx]
            d_rho[d_idx] = d_rhok[d_idx]
        d_uh[d_idx] = d_ui[d_idx]
        d_vh[d_idx] = d_vi[d_idx]
        d_x[d_idx] = d_xi[d_idx]
        d_y[d_idx] = d_yi[d_idx]
        d_u[d_idx] = d_ui[d_idx]
        d_v[d_idx] = d_vi[d_idx]


    def stage11(self, d_idx, d_x, d_y, d_xk, d_yk, d_u, d_v, d_uh, d_vh, d_rho, d_rhok):
        d_x[d_idx] = d_xk[d_idx]
        d_y[d_idx] = d_yk[d_idx]
        d_u[d_idx] = d_uh[d_idx]
        d_v[d_idx] = d_vh[d_idx]
        d_rho[d_idx] = d_rhok[d_idx]


class ExplicitLeapfrog(Integrator):
    """Explicit leapfrog of da Silva & Giraldi (2024), eqs. 59-62 (alpha in {0, 1} of eq. 38).

    Equation sets: 0 unused, 1 continuity -> EOS -> internal forces at the current x, 2 the
    wall force.  The first step applies the start rule v(-dt/2) = v(0) - dt g/2 (eq. 60).
    """

    n_evaluations = 3

    def __init__(self, **steppers):
        super().__init__(**steppers)
        self.k = 0
        self.evaluations = 0     # equation-set evaluations (each with its neighbour search)

    def evaluate(self, index, t, dt):
        self.update_nnps()
        self.compute_accelerations(index, t, dt)
        self.evaluations += 1

    def restarted(self, step, t):
        """Continue a run from its output of step ``step``: no second start-up step.  The
        file holds x = q_k, u = v_{k-1/2}, rho = rho_{k-1,k}; the levels the next step reads
        (uh, vh, rhok) are set from them (they are equal in a file this integrator wrote)."""
        self.k = int(step)
        for name in self.steppers:
            pa = self.scene.by_name[name]
            for level, value in (("uh", "u"), ("vh", "v"), ("rhok", "rho")):
                if level in pa.data and value in pa.data:
                    np.copyto(pa.data[level], pa.data[value])

    def explicit_step(self, t, dt):
        if self.k == 0:
            self.stage("stage1", t, dt)
        self.stage("stage2", t, dt)
        self.evaluate(1, t, dt)
        self.stage("stage3", t, dt)
        self.evaluate(2, t, dt)
        self.stage("stage4", t, dt)

    def one_timestep(self, t, dt):
        self.explicit_step(t, dt)
        self.update_nnps()
        self.k += 1


class VariationalMidpoint(ExplicitLeapfrog):
    """Generalised-midpoint variational integrator of da Silva & Giraldi (2024), eqs. 37, 40-42,
    63-65 and Algorithm 1, as a fixed-point iteration on q_{k+1} (module docstring).

    ``tol`` (eps, metres, on max_i |q^(j) - q^(j-1)|), ``max_iter`` (the cap: a step not
    converged puts the arrays back to the start of the step and raises BlowUpError naming
    the step, 1-based as the solver counts, and the residual).  The contraction is
    monitored while iterating: a residual that has not fallen over ``diverge_after``
    iterations (r_j >= r_{j-n}: the map is no contraction at this dt, the bound of eq. 54 is
    violated) stops the run the same way at once.
    Per step it records ``iterations``, ``residual`` (last r_j), ``residuals`` (all r_j) and
    ``contraction`` (max r_j/r_{j-1}, nan for one iteration); ``history`` keeps (step,
    iterations, residual, contraction) of every step.
    """

    def __init__(self, alpha=0.5, tol=1e-3, max_iter=50, diverge_after=3, **steppers):
        super().__init__(**steppers)
        if not 0.0 <= alpha <= 1.0:
            raise ValueError(f"VariationalMidpoint: alpha={alpha!r} must be in [0, 1]")
        if not tol > 0 or int(max_iter) < 1:
            raise ValueError(f"VariationalMidpoint: tol={tol!r} must be > 0, max_iter={max_iter!r} >= 1")
        if int(diverge_after) < 1:
            raise ValueError(f"VariationalMidpoint: diverge_after={diverge_after!r} must be >= 1")
        self.alpha, self.tol, self.max_iter = float(alpha), float(tol), int(max_iter)
        self.diverge_after = int(diverge_after)
        self.iterations, self.residual, self.contraction = 0, 0.0, float("nan")
        self.residuals = []
        self.history = []

    def _max_residual(self):
        r2 = 0.0
        for name in self.steppers:
            res = self.scene.by_name[name].data["res"]
            if res.size:
                r2 = max(r2, float(res.max()))
        return float(np.sqrt(r2))

    def one_timestep(self, t, dt):
        if self.k == 0:
            # q_1 by one explicit leapfrog step, then rho_{0,1} at xbar(q_0, q_1)
            self.explicit_step(t, dt)
            self.stage("stage5", t, dt)
            self.evaluate(1, t, dt)
            self.stage("stage10", t, dt)
            self.iterations, self.residual, self.residuals, self.contraction = 0, 0.0, [], float("nan")
        else:
            self.stage("stage6", t, dt)
            self.evaluate(0, t, dt)          # a_2 at xbar(q_{k-1}, q_k)
            self.stage("stage7", t, dt)
            self.evaluate(2, t, dt)          # Gamma_k at q_k
            self.stage("stage8", t, dt)      # predictor
            res = []
            while True:
                self.evaluate(1, t, dt)      # a_1 at xbar(q_k, q^(j-1))
                self.stage("stage9", t, dt)
                res.append(self._max_residual())
                if res[-1] <= self.tol:
                    break
                if not np.isfinite(res[-1]) or len(res) >= self.max_iter:
                    self._fail("did not converge", t, dt, res)
                n = self.diverge_after
                if len(res) > n and res[-1] >= res[-1 - n]:
                    self._fail("diverges", t, dt, res,
                               f"; the residual did not fall over {n} iterations: the map is no "
                               "contraction at this dt (reduce it)")
            self.evaluate(1, t, dt)          # rho_{k,k+1} at the accepted q_{k+1}
            self.stage("stage10", t, dt)
            ratios = [b / a for a, b in zip(res, res[1:]) if a > 0]
            self.iterations, self.residual, self.residuals = len(res), res[-1], res
            self.contraction = max(ratios) if ratios else float("nan")
        self.history.append((self.k, self.iterations, self.residual, self.contraction))
        self.update_nnps()
        self.k += 1

    def _fail(self, what, t, dt, res, why=""):
        """Arrays back to the start of the step; a BlowUpError naming step and residual."""
        self.stage("stage11", t, dt)
        self.update_nnps()
        ratios = [f"{b / a:.3g}" for a, b in zip(res, res[1:]) if a > 0]
        shown = ", ".join(ratios[-6:]) if ratios else "n/a"
        if len(ratios) > 6:
            shown = "last: " + shown
        raise BlowUpError(
            f"variational fixed-point iteration {what} at step {self.k + 1} (t={t:.6g} -> {t + dt:.6g}): "
            f"residual {res[-1]:.3e} m > tol {self.tol:.3e} m after {len(res)} iteration(s) "
            f"(contraction ratios {shown}){why}")


class VariationalScheme(Scheme):
    """da Silva & Giraldi (2024): Tait EOS, Gaussian kernel (K1/K2/K3), continuity density
    (eq. 67), artificial viscosity (eq. 55), Lennard-Jones wall force (eq. 58), gravity;
    ``integrator`` 'variational' (alpha, tol, max_iter) or 'explicit' (eqs. 59-62).

    ``density='summation'`` replaces the continuity density by the summation density at the
    interpolated configuration (eq. 20): with ``av_a = av_b = 0`` and no walls this is the
    "pure" variational scheme of eq. 37, and alpha in {0, 1} is Stormer-Verlet (eq. 38).

    Fluids need ``h = rc/3`` (the quintic spline's support 3h is the neighbour radius);
    boundary arrays (``walls``) only need positions and that ``h``.
    """

    output_props = ("x", "y", "u", "v", "p", "rho", "m", "h")

    def __init__(self, fluids, walls, dim=2, rho0=1000.0, c0=23.841, gx=0.0, gy=0.0,
                 kernel="K3", dx=0.005, h_cut=0.072, av_a=1.0, av_b=1.0, D=5.684, r0=0.005,
                 wall_power=1, integrator="variational", alpha=0.5, tol=1e-3, max_iter=50,
                 gamma=7.0, predictor="verlet", dt=None, density="continuity", diverge_after=3):
        if dim != 2:
            raise ValueError("VariationalScheme: only dim = 2 is implemented")
        if integrator not in ("variational", "explicit"):
            raise ValueError(f"VariationalScheme: integrator {integrator!r}: variational or explicit")
        for name, v in (("rho0", rho0), ("c0", c0), ("dx", dx), ("h_cut", h_cut)):
            if not v > 0:
                raise ValueError(f"VariationalScheme: {name}={v!r} must be > 0")
        self.fluids, self.walls, self.dim = list(fluids), list(walls), dim
        self.rho0, self.c0, self.gamma, self.gx, self.gy = rho0, c0, gamma, gx, gy
        self.kernel_name, self.dx, self.h_cut = kernel, dx, h_cut
        self.ell, self.lam, self.rc, self.shift = kernel_parameters(kernel, dx, h_cut)
        self.h = self.rc / 3.0           # particle h: the quintic's 3h support = rc
        self.hphi = h_cut if kernel in ("K1", "K2") else self.lam   # digest A34
        self.av_a, self.av_b, self.D, self.r0, self.wall_power = av_a, av_b, D, r0, wall_power
        self.integrator, self.alpha, self.tol, self.max_iter = integrator, alpha, tol, max_iter
        if density not in DENSITIES:
            raise ValueError(f"VariationalScheme: density {density!r}: {', '.join(DENSITIES)}")
        if density == "centred" and integrator != "variational":
            raise ValueError("VariationalScheme: density 'centred' needs integrator='variational'")
        self.density = density
        if predictor not in PREDICTORS:
            raise ValueError(f"VariationalScheme: predictor {predictor!r}: {', '.join(PREDICTORS)}")
        self.predictor, self.dt, self.diverge_after = predictor, dt, diverge_after
        self.B = rho0 * c0 * c0 / gamma
        self.kernel = get_kernel("quintic", dim)
        self.speed_limit = c0

    def setup_properties(self, arrays):
        for pa in arrays:
            if pa.name in self.fluids:
                for p in FLUID_PROPS:
                    if not pa.has(p):
                        pa.add_property(p)

    def _kw(self):
        return dict(ell=self.ell, lam=self.lam, rc=self.rc, shift=self.shift)

    def _forces(self, d):
        f = self.fluids
        return [GaussianPressureGradient(d, f, **self._kw()),
                PaperArtificialViscosity(d, f, a=self.av_a, b=self.av_b, c=self.c0, hphi=self.hphi,
                                         **self._kw())]

    def get_equations(self):
        f, w = self.fluids, self.walls
        summation = self.density == "summation"
        centred = self.density == "centred"

        def eos():
            return Group([TaitEOS(d, None, rho0=self.rho0, c0=self.c0, gamma=self.gamma) for d in f])

        def density(weight=1.0):
            if summation:
                return Group([GaussianSummationDensity(d, f, **self._kw()) for d in f])
            return Group([GaussianContinuityDensity(d, f, weight=weight, **self._kw()) for d in f])

        # set 0 at xbar(q_{k-1}, q_k): the continuity density rho_{k-1,k} is the stored one,
        # the summation density is recomputed there (eq. 20), the centred one interpolated
        a = self.alpha
        old = ([density(-(1.0 - a))] if summation or centred else []) + [
            eos(), Group([e for d in f for e in self._forces(d)])]
        new = [density(a if centred else 1.0), eos(), Group([e for d in f for e in self._forces(d)])]
        walls = [ZeroAcceleration(d) for d in f]
        if w:
            walls += [LennardJonesWallForce(d, w, D=self.D, r0=self.r0, power=self.wall_power) for d in f]
        return [old, new, [Group(walls)]]

    def get_integrator(self):
        step = VariationalStep(alpha=self.alpha if self.integrator == "variational" else 1.0,
                               gx=self.gx, gy=self.gy, predictor=PREDICTORS[self.predictor],
                               centred=int(self.density == "centred"))
        steppers = {name: step for name in self.fluids}
        if self.integrator == "explicit":
            return ExplicitLeapfrog(**steppers)
        return VariationalMidpoint(alpha=self.alpha, tol=self.tol, max_iter=self.max_iter,
                                   diverge_after=self.diverge_after, **steppers)

    def get_timestep(self):
        """``dt`` if given (the paper's 1e-4 s), else 0.25 lam / c0 (acoustic CFL on the kernel width)."""
        if self.dt is not None:
            return self.dt
        return 0.25 * self.lam / self.c0 if self.kernel_name != "K1" else 0.25 * self.dx / self.c0

    def stability_bounds(self, dt):
        """Acoustic CFL only as a documented bound; the contraction of the fixed point is
        monitored at run time (eq. 54 is not reliable: digest A20)."""
        if Bound is None:
            return []
        cfl = 0.25 * self.lam / self.c0 if self.kernel_name != "K1" else 0.25 * self.dx / self.c0
        return [Bound("--dt", dt, 2.0 * cfl, True,
                      "dt <= 0.5 lam/c0 (acoustic CFL; da Silva & Giraldi 2024 use dt = 1e-4 s)")]

    def density_bounds(self):
        return {f: (0.5 * self.rho0, 2.0 * self.rho0) for f in self.fluids}

    def energies(self, arrays):
        """Kinetic (with u = v_{k-1/2}), gravity potential -sum m g.x and Tait internal energy."""
        ke = pe = ie = 0.0
        for pa in arrays:
            if pa.name not in self.fluids:
                continue
            m, rho = pa.m, pa.rho
            ke += 0.5 * float(np.sum(m * (pa.u ** 2 + pa.v ** 2)))
            pe -= float(np.sum(m * (self.gx * pa.x + self.gy * pa.y)))
            r = rho / self.rho0
            e = (self.B / ((self.gamma - 1.0) * self.rho0) * (r ** (self.gamma - 1.0) - 1.0)
                 + self.B * (1.0 / rho - 1.0 / self.rho0))
            ie += float(np.sum(m * e))
        return {"kinetic": ke, "potential": pe, "internal": ie, "total": ke + pe + ie}
