"""Entropy-stable upwind Total Lagrangian SPH for large-strain thermo-elasticity,
Ghavamian, Lee, Gil, Bonet, Heuze & Stainier (2021), CMAME 379, 113736.

Unknowns per particle: velocity v = p / rho_R (``u, v, w``), F, H, J and the total
energy density E (E-form, the default) or the entropy density eta (eta-form); positions
x.  Pair loops run on the reference configuration with neighbours fixed at t = 0.
Time stepping is the two-stage TVD Runge-Kutta scheme of eq. 77 (Algorithm 1):

    U* = U^n + dt dU/dt(U^n, t^n)          (essential BCs imposed on U*)
    U^{n+1} = (U^n + U* + dt dU/dt(U*, t^{n+1})) / 2   (essential BCs imposed again)

on U and on the positions, with dt = alpha_CFL h_min / c_p,max (eq. 78; the wave speeds
are evaluated once per step, at t^n, and used in both stages' upwinding).  The
angular-momentum projection of eqs. 79-82 is a switch.  External data enter as loads
(body force f_R, heat source s_R, tractions A_R t_B, boundary heat fluxes A_R Q_B, all per
unit reference volume) and essential conditions (velocity components, temperature), both
evaluated in Python at the stage times; their work and heat are accumulated per body in
the array constant ``budget`` = [W_ext, Q_in, E_Dir] (energy put in by temperature
resets), so that E_tot(t) - E_tot(0) = W_ext + Q_in + E_Dir to round-off in the E-form.
"""
import numpy as np

from sphgen.equation import Group, declare
from sphgen.errors import BlowUpError, InputError
from sphgen.integrators import Integrator, IntegratorStep
from sphgen.kernels import get_kernel
from sphgen.linalg import det3
from sphgen.scheme import Bound, Scheme

from ..equations.thermo_materials import (ThermoElasticMaterial, energy_from_temperature,
                                          entropy_from_temperature)
from ..equations.thermo_upwind import (AngularMomentumProjection, CorrectionMatrix,
                                       EntropyVariableGradients, ThermoState, UpwindFluxes,
                                       WaveSpeeds, load_tensor)

FORMS = {"E": 0, "eta": 1}
JUMPS = ("raw", "limited")

STATE_9 = ("F", "H")
FILLED = ("fb", "sb", "vB", "thB", "vfix", "tfix", "dEbc")    # set from Python (zero by default)
VECTORS = ("gradT", "Q", "gs", "tint", "fb", "xc", "vB", "vfix")
TENSORS = ("F", "H", "P", "L", "gw", "aF", "aH", "Fn", "Hn")
SCALARS = ("J", "E", "eta", "theta", "p", "SJ", "SD", "cp", "cs", "dt_cfl", "aJ", "aE", "aeta", "sb",
           "un", "vn", "wn", "xn", "yn", "zn", "Jn", "En", "etan", "tfix", "thB", "dEbc",
           "x0", "y0", "z0", "V")


class ThermoRK2Step(IntegratorStep):
    """Per-particle stages of the TVD Runge-Kutta scheme, Ghavamian et al. (2021) eq. 77."""

    switches = ("model", "form", "reduced", "projection", "external", "vel_bc", "th_bc")

    def __init__(self, model, form, reduced, projection, external, vel_bc, th_bc):
        self.model, self.form, self.reduced = int(model), int(form), int(reduced)
        self.projection, self.external = int(projection), int(external)
        self.vel_bc, self.th_bc = int(vel_bc), int(th_bc)

    def stage1(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_F, d_H, d_J, d_E, d_eta, d_xn, d_yn,
               d_zn, d_un, d_vn, d_wn, d_Fn, d_Hn, d_Jn, d_En, d_etan, d_xc):
        """Keep U^n and x^n; the projection point of the first stage is x^n (eq. 79)."""
        d_xn[d_idx] = d_x[d_idx]
        d_yn[d_idx] = d_y[d_idx]
        d_zn[d_idx] = d_z[d_idx]
        d_un[d_idx] = d_u[d_idx]
        d_vn[d_idx] = d_v[d_idx]
        d_wn[d_idx] = d_w[d_idx]
        for k in range(9):
            d_Fn[9 * d_idx + k] = d_F[9 * d_idx + k]
            d_Hn[9 * d_idx + k] = d_H[9 * d_idx + k]
        if not self.reduced:
            d_Jn[d_idx] = d_J[d_idx]
        if self.form == 0:
            d_En[d_idx] = d_E[d_idx]
        else:
            d_etan[d_idx] = d_eta[d_idx]
        if self.projection:
            d_xc[3 * d_idx] = d_x[d_idx]
            d_xc[3 * d_idx + 1] = d_y[d_idx]
            d_xc[3 * d_idx + 2] = d_z[d_idx]

    def stage2(self, d_idx, d_x, d_y, d_z, d_u, d_v, d_w, d_F, d_H, d_J, d_E, d_eta, d_xn, d_yn,
               d_zn, d_un, d_vn, d_wn, d_Fn, d_Hn, d_Jn, d_En, d_etan, d_rho, d_tint, d_fb, d_aF,
               d_aH, d_aJ, d_aE, d_aeta, d_rk, dt):
        """A stage of eq. 77: U <- c U^n + (1 - c)(U + dt dU/dt(U)), x <- c x^n + (1 - c)(x + dt v)
        with c = rk[0]: 0 in the first stage (where U = U^n: U* = U^n + dt dU/dt(U^n)), 1/2 in
        the second (U^{n+1} = (U^n + U* + dt dU/dt(U*)) / 2)."""
        c = d_rk[0]
        b = 1.0 - c
        d_x[d_idx] = c * d_xn[d_idx] + b * (d_x[d_idx] + dt * d_u[d_idx])
        d_y[d_idx] = c * d_yn[d_idx] + b * (d_y[d_idx] + dt * d_v[d_idx])
        d_z[d_idx] = c * d_zn[d_idx] + b * (d_z[d_idx] + dt * d_w[d_idx])
        ri = dt / d_rho[d_idx]
        fx = d_tint[3 * d_idx]
        fy = d_tint[3 * d_idx + 1]
        fz = d_tint[3 * d_idx + 2]
        if self.external:
            fx += d_fb[3 * d_idx]
            fy += d_fb[3 * d_idx + 1]
            fz += d_fb[3 * d_idx + 2]
        d_u[d_idx] = c * d_un[d_idx] + b * (d_u[d_idx] + ri * fx)
        d_v[d_idx] = c * d_vn[d_idx] + b * (d_v[d_idx] + ri * fy)
        d_w[d_idx] = c * d_wn[d_idx] + b * (d_w[d_idx] + ri * fz)
        for k in range(9):
            d_F[9 * d_idx + k] = c * d_Fn[9 * d_idx + k] + b * (d_F[9 * d_idx + k] + dt * d_aF[9 * d_idx + k])
            d_H[9 * d_idx + k] = c * d_Hn[9 * d_idx + k] + b * (d_H[9 * d_idx + k] + dt * d_aH[9 * d_idx + k])
        if not self.reduced:
            d_J[d_idx] = c * d_Jn[d_idx] + b * (d_J[d_idx] + dt * d_aJ[d_idx])
        if self.form == 0:
            d_E[d_idx] = c * d_En[d_idx] + b * (d_E[d_idx] + dt * d_aE[d_idx])
        else:
            d_eta[d_idx] = c * d_etan[d_idx] + b * (d_eta[d_idx] + dt * d_aeta[d_idx])

    def stage3(self, d_idx, d_u, d_v, d_w, d_vfix, d_vB, d_tfix, d_thB, d_F, d_H, d_J, d_E, d_eta,
               d_dEbc, d_rho, d_mat):
        """Essential conditions on p and on E (or eta), Algorithm 1 step 7: a velocity
        component is overwritten (E is not: the kinetic change becomes heat); a temperature
        sets E = |p|^2/(2 rho_R) + E_R + c_v (theta_B - theta_R) or eta = eta_R +
        c_v ln(theta_B / theta_R); ``dEbc`` records the change of E."""
        F = declare("matrix(9)")
        H = declare("matrix(9)")
        if self.vel_bc:
            if d_vfix[3 * d_idx] > 0.5:
                d_u[d_idx] = d_vB[3 * d_idx]
            if d_vfix[3 * d_idx + 1] > 0.5:
                d_v[d_idx] = d_vB[3 * d_idx + 1]
            if d_vfix[3 * d_idx + 2] > 0.5:
                d_w[d_idx] = d_vB[3 * d_idx + 2]
        if self.th_bc:
            d_dEbc[d_idx] = 0.0
            if d_tfix[d_idx] > 0.5:
                load_tensor(d_F, d_idx, F)
                load_tensor(d_H, d_idx, H)
                J = d_J[d_idx]
                if self.reduced:
                    J = det3(F)
                if self.form == 0:
                    kin = 0.5 * d_rho[d_idx] * (d_u[d_idx] * d_u[d_idx] + d_v[d_idx] * d_v[d_idx]
                                                + d_w[d_idx] * d_w[d_idx])
                    e = energy_from_temperature(self.model, d_thB[d_idx], kin, F, H, J, d_mat)
                    d_dEbc[d_idx] = e - d_E[d_idx]
                    d_E[d_idx] = e
                else:
                    d_eta[d_idx] = entropy_from_temperature(self.model, d_thB[d_idx], F, H, J, d_mat)

    def stage4(self, d_idx, d_xn, d_yn, d_zn, d_un, d_vn, d_wn, d_u, d_v, d_w, d_xc, dt):
        """Projection point of the second stage: x^n + dt (v^n + v*)/2 (eq. 79)."""
        if self.projection:
            d_xc[3 * d_idx] = d_xn[d_idx] + 0.5 * dt * (d_un[d_idx] + d_u[d_idx])
            d_xc[3 * d_idx + 1] = d_yn[d_idx] + 0.5 * dt * (d_vn[d_idx] + d_v[d_idx])
            d_xc[3 * d_idx + 2] = d_zn[d_idx] + 0.5 * dt * (d_wn[d_idx] + d_w[d_idx])

    def stage5(self, d_idx, d_u, d_v, d_w, d_F, d_H, d_J, d_E, d_eta, d_theta, d_rho, d_mat):
        """Initial state: E (eq. 23 inverted) or eta (eq. 19) from the given temperature."""
        F = declare("matrix(9)")
        H = declare("matrix(9)")
        load_tensor(d_F, d_idx, F)
        load_tensor(d_H, d_idx, H)
        J = d_J[d_idx]
        if self.reduced:
            J = det3(F)
        if self.form == 0:
            kin = 0.5 * d_rho[d_idx] * (d_u[d_idx] * d_u[d_idx] + d_v[d_idx] * d_v[d_idx]
                                        + d_w[d_idx] * d_w[d_idx])
            d_E[d_idx] = energy_from_temperature(self.model, d_theta[d_idx], kin, F, H, J, d_mat)
        else:
            d_eta[d_idx] = entropy_from_temperature(self.model, d_theta[d_idx], F, H, J, d_mat)


class ThermoRK2(Integrator):
    """Algorithm 1 of Ghavamian et al. (2021): the TVD Runge-Kutta step of eq. 77 with the
    essential conditions, loads and the state update (P, theta) after every stage.

    Equation sets: 0 the rates (with the projection if on), 1 the state (theta, P,
    Sigma_J), 2 the state and the wave speeds (end of step: c_p, c_s stay frozen for the
    next step's two stages), 3 the correction matrices (once, before the first step).
    ``loads``: [(body, f(t, pa) -> (fb (n, 3) or None, sb (n,) or None))]; ``velocity`` /
    ``temperature``: {body: f(t, pa) -> targets}; the guard stops on J <= 0 or theta <= 0.
    """

    n_evaluations = 4

    def __init__(self, bodies, loads=(), velocity=None, temperature=None, thermal_bc=(), **steppers):
        super().__init__(**steppers)
        self.bodies = list(bodies)
        self.loads = list(loads)
        self.velocity = dict(velocity or {})
        self.temperature = dict(temperature or {})
        self.thermal_bc = set(thermal_bc)
        self.step_count = 0

    def _arrays(self):
        return [self.scene.by_name[b] for b in self.bodies]

    def apply_loads(self, t):
        """fb, sb at time t; returns (sum V fb . v, sum V sb) per body."""
        if not self.loads:
            return {}
        for pa in self._arrays():
            pa.fb[:] = 0.0
            pa.sb[:] = 0.0
        for body, load in self.loads:
            pa = self.scene.by_name[body]
            fb, sb = load(t, pa)
            if fb is not None:
                pa.fb.reshape(-1, 3)[:] += fb
            if sb is not None:
                pa.sb[:] += sb
        out = {}
        for pa in self._arrays():
            vel = np.stack([pa.u, pa.v, pa.w], axis=1)
            out[pa.name] = (float(np.sum(pa.V * np.einsum("ai,ai->a", pa.fb.reshape(-1, 3), vel))),
                            float(np.sum(pa.V * pa.sb)))
        return out

    def impose(self, t):
        """Essential conditions at time t; returns {body: sum V (E_new - E_old)}."""
        for body, f in self.velocity.items():
            pa = self.scene.by_name[body]
            pa.vB.reshape(-1, 3)[:] = f(t, pa)
        for body, f in self.temperature.items():
            pa = self.scene.by_name[body]
            pa.thB[:] = f(t, pa)
        self.scene.stage("stage3", t, 0.0)
        return {b: float(np.sum(self.scene.by_name[b].V * self.scene.by_name[b].dEbc))
                for b in self.thermal_bc}

    def state(self, index, t, dt, where):
        """Equation set ``index`` (the state), then the guard: J > 0 and theta > 0."""
        self.compute_accelerations(index, t, dt)
        for pa in self._arrays():
            for prop, name in (("J", "J"), ("theta", "temperature")):
                a = pa.get(prop)
                i = int(np.argmin(a)) if a.size else 0
                if a.size and not a[i] > 0.0:
                    raise BlowUpError(
                        f"{name} {prop} = {a[i]:.4g} <= 0 at particle gid {int(pa.gid[i])} of "
                        f"'{pa.name}' {where} (t={t:.6g}): the state left the material's range")

    def attach(self, scene):
        """Complete the initial state as soon as the scene exists (so that what the
        application samples at t = 0 is it): correction matrices, E or eta from the given
        temperature, essential conditions at t = 0, theta, P and the wave speeds.  A restart
        then overwrites it with the file's state."""
        super().attach(scene)
        self.compute_accelerations(3, 0.0, 0.0)
        self.scene.stage("stage5", 0.0, 0.0)
        self.impose(0.0)
        self.state(2, 0.0, 0.0, "in the initial state")

    def initial_accelerations(self, t, dt):
        self.state(2, t, dt, "in the initial state")

    def _budget(self, name, dw, dq, de):
        b = self.scene.by_name[name].budget
        b[0] += dw
        b[1] += dq
        b[2] += de

    def _rk(self, c):
        for pa in self._arrays():
            pa.rk[0] = c

    def one_timestep(self, t, dt):
        self.scene.stage("stage1", t, dt)
        p1 = self.apply_loads(t)
        self.compute_accelerations(0, t, dt)
        q1 = self._projection_rates()
        self._rk(0.0)
        self.scene.stage("stage2", t, dt)
        r1 = self.impose(t + dt)
        self.scene.stage("stage4", t, dt)
        self.state(1, t + dt, dt, f"after the first stage of step {self.step_count + 1}")
        p2 = self.apply_loads(t + dt)
        self.compute_accelerations(0, t + dt, dt)
        q2 = self._projection_rates()
        self._rk(0.5)
        self.scene.stage("stage2", t, dt)
        r3 = self.impose(t + dt)
        self.state(2, t + dt, dt, f"at the end of step {self.step_count + 1}")
        for name in self.bodies:
            w = 0.5 * dt * (p1.get(name, (0.0, 0.0))[0] + p2.get(name, (0.0, 0.0))[0])
            q = 0.5 * dt * (p1.get(name, (0.0, 0.0))[1] + p2.get(name, (0.0, 0.0))[1])
            self._budget(name, w, q, 0.5 * r1.get(name, 0.0) + r3.get(name, 0.0))
        for pa in self._arrays():     # the projection's work and entropy, RK2-consistently
            pa.proj[2:] += 0.5 * dt * (q1[pa.name] + q2[pa.name])
        self.step_count += 1

    def _projection_rates(self):
        """(power, entropy rate) of the angular-momentum projection in the stage just
        evaluated (zero without it)."""
        out = {}
        for pa in self._arrays():
            out[pa.name] = pa.proj[:2].copy()
            pa.proj[:2] = 0.0
        return out


class ThermoUpwindScheme(Scheme):
    """Upwind TL-SPH for thermo-elasticity, Ghavamian et al. (2021): E-form {p, F, H, J, E}
    (default), eta-form {p, F, H, J, eta}, or with ``reduced`` the {p, F, H, E} scheme of
    their Fig. 16 (J = det F, no J equation) or its eta-form {p, F, H, eta} (ours, not the
    paper's: the same J = det F with the entropy equation 57; docs/thermo.md).

    ``bodies``: array names (3-D; each needs the reference volume ``V``; ``rho`` defaults to
    the material's; ``theta`` to theta_R; ``F``, ``H`` to I and ``J`` to 1; reference
    positions ``x0, y0, z0`` are the positions at set-up).  ``dx``: the smallest particle
    spacing h_min of eq. 78; ``hdx``: smoothing length h / dx (one constant h: the paper's
    "0.6 x the largest spacing in the support" fixes no kernel; see docs/thermo.md);
    ``jumps``: 'raw' (the paper's eqs. 66, 72) or 'limited' (limited linear
    reconstruction); ``projection``: the angular-momentum projection of eqs. 79-82;
    ``dt``: a fixed step instead of eq. 78 every step (it must respect eq. 78 at t = 0);
    ``dissipation`` False drops the upwinding (for tests), ``"p"`` keeps D_p but drops
    D_J (an ablation, docs/thermo.md); ``dj``: 'paper' (D_J on the jump of Sigma_J, moving
    J only, eqs. 54d, 66), 'volumetric' (on the jump of the mean stress, moving J, F and
    H together so that J stays det F; docs/thermo.md) or 'pressure' (on the jump of the
    volumetric part of Sigma_J, moving J only: a diagnostic whose pair dissipation has no
    sign; docs/thermo.md, round 10).  Essential conditions: a body
    with a ``vfix`` property (3 flags per particle) gets its velocity components reset to
    ``vB`` (zero, or ``velocity(t, pa)``); one with ``tfix`` gets its temperature reset to
    ``thB`` (or ``temperature(t, pa)``).  ``add_load(body, f)`` adds a body force / heat
    supply per unit reference volume, ``f(t, pa) -> (fb (n, 3) or None, sb (n,) or None)``.
    """

    output_props = ("x", "y", "z", "u", "v", "w", "theta", "p", "J", "E", "eta", "P", "F",
                    "V", "rho", "m", "h")
    dim = 3

    def __init__(self, bodies, material, dx, hdx=1.2, kernel="wendland", form="E", reduced=False,
                 jumps="raw", projection=False, dissipation=True, cfl=0.3, dt=None, dj="paper", se="zero"):
        if not isinstance(material, ThermoElasticMaterial):
            raise InputError(f"ThermoUpwindScheme: material must be a ThermoElasticMaterial, got {material!r}")
        if form not in FORMS:
            raise InputError(f"ThermoUpwindScheme: form {form!r} must be one of {', '.join(FORMS)}")
        if dissipation not in (True, False, "p"):
            raise InputError(f"ThermoUpwindScheme: dissipation {dissipation!r} must be True, False or 'p'")
        if dj not in ("paper", "volumetric", "pressure"):
            raise InputError(f"ThermoUpwindScheme: dj {dj!r} must be 'paper', 'volumetric' or 'pressure'")
        if dj != "paper" and reduced:
            raise InputError(f"ThermoUpwindScheme: dj={dj!r} needs the J equation (reduced=False)")
        if se not in ("zero", "matched"):
            raise InputError(f"ThermoUpwindScheme: se {se!r} must be 'zero' or 'matched'")
        if se == "matched" and form != "E":
            raise InputError("ThermoUpwindScheme: S^E (se='matched', eq. 76) belongs to the E-form")
        if jumps not in JUMPS:
            raise InputError(f"ThermoUpwindScheme: jumps {jumps!r} must be one of {', '.join(JUMPS)}")
        for name, v in (("dx", dx), ("hdx", hdx), ("cfl", cfl), ("dt", 1.0 if dt is None else dt)):
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"ThermoUpwindScheme: {name}={v!r} must be a positive number")
        self.bodies = list(bodies)
        self.material = material
        self.dx, self.hdx, self.h = float(dx), float(hdx), float(hdx) * float(dx)
        self.kernel_name = kernel
        self.kernel = get_kernel(kernel, 3)
        self.form, self.reduced, self.jumps = form, bool(reduced), jumps
        self.projection, self.cfl = bool(projection), float(cfl)
        self.dissipation = 2 if dissipation == "p" else int(bool(dissipation))
        self.volumetric = int(dj == "volumetric")
        self.sd_mode = {"paper": 0, "volumetric": 1, "pressure": 2}[dj]
        self.se = int(se == "matched")
        self.dt = None if dt is None else float(dt)
        self.adaptive_dt = (("dt_cfl",), self.cfl) if dt is None else None
        self.loads = []
        self.velocity, self.temperature = {}, {}
        self.arrays = {}

    # ------------------------------------------------------------------ set-up
    def add_load(self, body, load):
        """Add ``load(t, pa) -> (fb, sb)``: body force and heat supply per unit reference volume."""
        if body not in self.bodies:
            raise InputError(f"ThermoUpwindScheme.add_load: unknown body {body!r}")
        self.loads.append((body, load))

    def set_dirichlet(self, body, velocity=None, temperature=None):
        """Time-dependent targets of the essential conditions of ``body`` (see the class)."""
        if velocity is not None:
            self.velocity[body] = velocity
        if temperature is not None:
            self.temperature[body] = temperature

    def setup_properties(self, arrays):
        mat = self.material
        for pa in arrays:
            if pa.name not in self.bodies:
                continue
            self.arrays[pa.name] = pa
            if "V" not in pa.data:
                raise InputError(f"ThermoUpwindScheme: body '{pa.name}' needs the reference volume 'V'")
            if np.any(pa.V <= 0):
                raise InputError(f"ThermoUpwindScheme: body '{pa.name}' has a non-positive volume V")
            for p in SCALARS:
                if not pa.has(p):
                    pa.add_property(p, default=0.0 if p in FILLED else None)
            for p in VECTORS:
                if not pa.has(p):
                    pa.add_property(p, stride=3, default=0.0 if p in FILLED else None)
            for p in TENSORS:
                if not pa.has(p):
                    pa.add_property(p, stride=9)
            n = pa.n
            for c in "xyz":
                if f"{c}0" not in pa.data:
                    pa.set(f"{c}0", pa.get(c).copy())
            if "rho" not in pa.data:
                pa.set("rho", np.full(n, mat.rho))
            pa.set("m", pa.rho * pa.V)
            pa.set("h", np.full(n, self.h))
            for p in STATE_9:
                if p not in pa.data:
                    pa.set(p, np.tile(np.eye(3).ravel(), n))
            if "J" not in pa.data:
                pa.set("J", np.ones(n))
            if "theta" not in pa.data:
                pa.set("theta", np.full(n, mat.theta_R))
            if np.any(pa.theta <= 0):
                raise InputError(f"ThermoUpwindScheme: body '{pa.name}' has a non-positive temperature")
            for c in "uvw":
                if c not in pa.data:
                    pa.set(c, np.zeros(n))
            pa.add_constant("mat", mat.constants())
            if "budget" not in pa.constants:
                pa.add_constant("budget", np.zeros(3))
            if "proj" not in pa.constants:
                pa.add_constant("proj", np.zeros(4))     # the projection: stage power, entropy rate; W, S
            if "rk" not in pa.constants:
                pa.add_constant("rk", np.zeros(1))       # the weight of U^n in a stage of eq. 77
        missing = [b for b in self.bodies if b not in self.arrays]
        if missing:
            raise InputError(f"ThermoUpwindScheme: no particle array named {missing[0]!r}")

    def _has_flags(self, name, prop):
        pa = self.arrays[name]
        return prop in pa.data and bool(np.any(pa.get(prop) > 0.5))

    # ------------------------------------------------------------------ pieces
    def get_equations(self):
        form, rec, red = FORMS[self.form], int(self.jumps != "raw"), int(self.reduced)
        model = self.material.model
        rates, state, state_speeds, once = [], [], [], []
        for b in self.bodies:
            ext = int(any(name == b for name, _ in self.loads))
            rates += [Group([EntropyVariableGradients(b, [b], form=form, reconstruct=rec)], reference=True),
                      Group([UpwindFluxes(b, [b], form=form, reconstruct=rec, reduced=red,
                                          dissipation=self.dissipation, external=ext,
                                          volumetric=self.volumetric, se=self.se)], reference=True)]
            if self.projection:
                rates.append(Group([AngularMomentumProjection(b, form=form)]))
            vol = self.sd_mode
            state.append(Group([ThermoState(b, model=model, form=form, reduced=red, volumetric=vol)]))
            state_speeds.append(Group([ThermoState(b, model=model, form=form, reduced=red, volumetric=vol),
                                       WaveSpeeds(b, model=model, hmin=self.dx)]))
            once.append(Group([CorrectionMatrix(b, [b])], reference=True))
        return [rates, state, state_speeds, once]

    def get_integrator(self):
        steppers = {}
        for b in self.bodies:
            ext = any(name == b for name, _ in self.loads)
            steppers[b] = ThermoRK2Step(self.material.model, FORMS[self.form], self.reduced, self.projection,
                                        ext, self._has_flags(b, "vfix"), self._has_flags(b, "tfix"))
        thermal = [b for b in self.bodies if self._has_flags(b, "tfix") and self.form == "E"]
        return ThermoRK2(self.bodies, self.loads, self.velocity, self.temperature, thermal, **steppers)

    def output_properties(self, pa):
        """The output properties, and the per-particle step limit ``dt_cfl`` that the solver
        reads when the step follows eq. 78."""
        props = super().output_properties(pa)
        return props + ["dt_cfl"] if self.adaptive_dt and pa.name in self.bodies else props

    def max_wave_speed(self):
        """c_p,max at the bodies' current temperatures."""
        return max(float(np.max(self.material.wave_speeds(pa.theta))) for pa in self.arrays.values())

    def get_timestep(self):
        """The fixed ``dt`` if given, else alpha_CFL h_min / c_p,max (eq. 78) at the initial
        temperatures (the run then recomputes it every step from the particles' c_p)."""
        return self.dt if self.dt is not None else self.cfl_timestep()

    def cfl_timestep(self):
        return self.cfl * self.dx / self.max_wave_speed()

    def stability_bounds(self, dt):
        return [Bound("--dt", dt, self.cfl_timestep(), True,
                      f"dt <= {self.cfl:g} h_min / c_p,max, Ghavamian et al. (2021) eq. 78")]

    def energies(self, arrays):
        """Kinetic K, internal U, total E_tot = sum V E, entropy S = sum V eta, ballistic
        B = E_tot - theta_R S (eqs. 33, 41), and the accumulated external work W_ext, heat
        input Q_in and energy injected by temperature resets E_Dir; W_proj and S_proj: the
        kinetic energy given and the entropy taken (E-form) by the angular-momentum
        projection (eqs. 79-82; outside the entropy proof of eqs. 61-65)."""
        out = dict.fromkeys(("kinetic", "internal", "total", "entropy", "ballistic",
                             "W_ext", "Q_in", "E_Dir", "W_proj", "S_proj"), 0.0)
        for pa in arrays:
            if pa.name not in self.bodies:
                continue
            V = pa.V
            kin = float(np.sum(0.5 * pa.m * (pa.u ** 2 + pa.v ** 2 + pa.w ** 2)))
            tot = float(np.sum(V * pa.E))
            S = float(np.sum(V * pa.eta))
            out["kinetic"] += kin
            out["internal"] += tot - kin
            out["total"] += tot
            out["entropy"] += S
            out["ballistic"] += tot - self.material.theta_R * S
            b = pa.budget
            out["W_ext"] += float(b[0])
            out["Q_in"] += float(b[1])
            out["E_Dir"] += float(b[2])
            out["W_proj"] += float(pa.proj[2])
            out["S_proj"] += float(pa.proj[3])
        return out
