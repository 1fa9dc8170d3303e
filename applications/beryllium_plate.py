"""Vibrating beryllium plate: free elastic bending with SHTC-SPH (Kincl, Peshkov, Pavelka &
Klika (2023), section 4.1; Kincl's thesis (2023), section 2.6).

A plate (-L/2, L/2) x (-W/2, W/2), L = 0.06 m, W = 0.01 m (plane strain), DPRZ shear energy
(eq. 15) with c0 = cs = 9046.59 m/s, rho0 = 1850 kg/m^3 (thesis), tau = infinity (an
elastic solid), starts undeformed (A = I, rho = rho0) with the first free-free bending mode
as its velocity (Boscheri, Chiocchetti & Peshkov 2022, the paper's eq. in sec. 4.1):
v_y = A omega (a1 (sinh s + sin s) - a2 (cosh s + cos s)), s = alpha (x + L/2).
Particles on the paper's isometric lattice (spacing dr = W / ``--nw``, the origin a
lattice point), h = 1.5 dr, dt from eq. 26, tensile penalty c_p = ``--cp-factor`` c0
(paper: 10; 0 switches it off and the plate tears).

``results.json``: the largest relative drift of the total energy (kinetic + bulk + shear +
penalty, eqs. 13, 15, 19) over the run, the oscillation period of the centre point y_c(t)
(its zero crossings) beside the plane-strain Euler-Bernoulli and Timoshenko periods,
2 pi/omega and the linear plane-strain continuum period (finite elements, ``finite_element_period``), and
the tear indicators (``void_fraction``: particles whose summation density fell below
0.9 rho0; ``clump_fraction``: particles with a neighbour closer than dr/2; both zero for
an elastic plate, whose strains stay below 1%).  Plots: centre.png, energy.png,
pressure.png (the final state coloured by p).
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.particles import ParticleArray
from sphgen.tools.probes import pairs_within

from ..schemes.shtc import SHTC_INTEGRATORS, SHTCScheme
from ._solid_plots import plot_energy, plot_track
from ._perturbation import add_perturbation_options, check_perturbation, perturbed

L, W = 0.06, 0.01
RHO0, C0 = 1850.0, 9046.59
AMP, OMEGA, ALPHA, A1, A2 = 4.3369e-5, 2.3597e5, 78.834, 56.6368, 57.6455
HDR = 1.5
BETA_L = 4.730040745   # first root of cos(bL) cosh(bL) = 1 (free-free beam)
PERIOD_CONTINUUM = 2.786e-5
"""The linear plane-strain continuum period: finite_element_period at 60 x 10 and 96 x 16
elements (2.7782e-5, 2.7830e-5 s) extrapolated as (size)^2 (docs/shtc.md)."""
VOID_RHO = 0.9        # rho/rho0 below this: a particle that lost a tenth of its neighbourhood
CLUMP_DR = 0.5        # nearest neighbour closer than this times dr: particles clumping


def isometric_lattice(dr, length, width):
    """Isometric lattice centred on the origin (a lattice point), volume dr^2 per particle:
    spacing a = (4/3)^(1/4) dr, rows b = (3/4)^(1/4) dr, odd rows shifted by a/2; the points
    strictly inside (-length/2, length/2) x (-width/2, width/2)."""
    a, b = (4.0 / 3.0) ** 0.25 * dr, 0.75 ** 0.25 * dr
    nj, ni = int(width / 2 / b) + 1, int(length / 2 / a) + 2
    j, i = np.meshgrid(np.arange(-nj, nj + 1), np.arange(-ni, ni + 1), indexing="ij")
    x = (i + 0.5 * (j % 2)) * a
    y = j * b
    keep = (np.abs(x) < length / 2) & (np.abs(y) < width / 2)
    return x[keep].astype(float), y[keep].astype(float)


def bending_velocity(x):
    """v_y of the first free-free bending mode (Boscheri et al. 2022 via Kincl et al. 2023, sec. 4.1)."""
    s = ALPHA * (x + L / 2)
    return AMP * OMEGA * (A1 * (np.sinh(s) + np.sin(s)) - A2 * (np.cosh(s) + np.cos(s)))


def plane_strain_modulus(c0=C0, cs=C0):
    """E' = E/(1 - nu^2) per unit density of the linearised SHTC material (K = rho0 c0^2,
    mu = rho0 cs^2): the bending stiffness of a plane-strain beam (docs/shtc.md)."""
    K, mu = c0 ** 2, cs ** 2                     # per unit density
    E = 9.0 * K * mu / (3.0 * K + mu)
    nu = (3.0 * K - 2.0 * mu) / (2.0 * (3.0 * K + mu))
    return E / (1.0 - nu * nu)


def euler_bernoulli_period(c0=C0, cs=C0, length=L, width=W, beta_l=BETA_L):
    """First free-free bending period of a plane-strain Euler-Bernoulli beam of the linearised
    SHTC material (K = rho0 c0^2, mu = rho0 cs^2; derivation in docs/shtc.md)."""
    omega = beta_l ** 2 / length ** 2 * math.sqrt(plane_strain_modulus(c0, cs) * width ** 2 / 12.0)
    return 2.0 * math.pi / omega


def timoshenko_period(c0=C0, cs=C0, length=L, width=W, kappa=5.0 / 6.0):
    """First free-free bending period of a plane-strain Timoshenko beam (Timoshenko 1921: shear
    deformation with coefficient kappa and rotary inertia) of the linearised SHTC material: the
    lowest root of the symmetric-mode frequency equation derived in docs/shtc.md,
    P_a a^2 cosh(aL/2) sin(bL/2) + Q_b b^2 cos(bL/2) sinh(aL/2) = 0, found by bisection."""
    Ep, kg = plane_strain_modulus(c0, cs), kappa * cs ** 2     # E', kappa mu per unit density
    r2 = width ** 2 / 12.0                                     # I/A of the rectangular section

    def frequency_function(omega):
        w2 = omega * omega
        p = w2 * (1.0 / Ep + 1.0 / kg)
        q = w2 / (Ep * r2) * (1.0 - w2 * r2 / kg)            # > 0 below the shear cut-off
        s = math.sqrt(p * p + 4.0 * q)
        a, b = math.sqrt(0.5 * (s - p)), math.sqrt(0.5 * (s + p))
        pa, qb = a + w2 / (kg * a), b - w2 / (kg * b)          # phi/w amplitude ratios
        return (pa * a * a * math.cosh(0.5 * a * length) * math.sin(0.5 * b * length)
                + qb * b * b * math.cos(0.5 * b * length) * math.sinh(0.5 * a * length))

    omega_eb = 2.0 * math.pi / euler_bernoulli_period(c0, cs, length, width)
    lo, hi = 0.2 * omega_eb, 0.2 * omega_eb                    # shear and rotary inertia lower omega
    f_lo = frequency_function(lo)
    while True:                                                # first sign change above 0.2 omega_EB
        hi = lo + 0.0025 * omega_eb
        if hi > 1.2 * omega_eb:
            raise ValueError("no Timoshenko root below 1.2 omega_EB")
        f_hi = frequency_function(hi)
        if f_lo * f_hi <= 0.0:
            break
        lo, f_lo = hi, f_hi
    for _ in range(100):
        mid = 0.5 * (lo + hi)
        f_mid = frequency_function(mid)
        if f_lo * f_mid <= 0.0:
            hi = mid
        else:
            lo, f_lo = mid, f_mid
    return 4.0 * math.pi / (lo + hi)


def finite_element_period(nx, ny, c0=C0, cs=C0, length=L, width=W):
    """First bending period of the free plane-strain plate of the linearised SHTC material by
    bilinear finite elements (nx x ny elements, consistent mass, 2x2 Gauss; dense numpy
    eigenproblem, so keep 2 (nx+1)(ny+1) below a few thousand).  Full integration makes the
    elements too stiff in bending: the period converges from below, as (size/W)^2."""
    K, mu = c0 ** 2, cs ** 2                     # per unit density
    lam = K - 2.0 * mu / 3.0
    D = np.array([[lam + 2 * mu, lam, 0.0], [lam, lam + 2 * mu, 0.0], [0.0, 0.0, mu]])
    hx, hy = length / nx, width / ny
    xn, yn = np.array([-1, 1, 1, -1]), np.array([-1, -1, 1, 1])
    ke, me = np.zeros((8, 8)), np.zeros((8, 8))
    for xi in (-1 / math.sqrt(3), 1 / math.sqrt(3)):
        for eta in (-1 / math.sqrt(3), 1 / math.sqrt(3)):
            N = 0.25 * (1 + xi * xn) * (1 + eta * yn)
            B = np.zeros((3, 8))
            B[0, 0::2] = B[2, 1::2] = 0.5 * xn * (1 + eta * yn) / hx
            B[1, 1::2] = B[2, 0::2] = 0.5 * yn * (1 + xi * xn) / hy
            Nm = np.zeros((2, 8))
            Nm[0, 0::2] = Nm[1, 1::2] = N
            ke += B.T @ D @ B * hx * hy / 4
            me += Nm.T @ Nm * hx * hy / 4
    n = 2 * (nx + 1) * (ny + 1)
    Kg, Mg = np.zeros((n, n)), np.zeros((n, n))
    for i in range(nx):
        for j in range(ny):
            nodes = [j * (nx + 1) + i, j * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i + 1, (j + 1) * (nx + 1) + i]
            dofs = np.ravel([[2 * k, 2 * k + 1] for k in nodes])
            Kg[np.ix_(dofs, dofs)] += ke
            Mg[np.ix_(dofs, dofs)] += me
    Li = np.linalg.inv(np.linalg.cholesky(Mg))
    A = Li @ Kg @ Li.T
    ev = np.sort(np.abs(np.linalg.eigvalsh(0.5 * (A + A.T))))
    return 2.0 * math.pi / math.sqrt(ev[3])      # three rigid-body modes first


def zero_crossings(t, y):
    """Times where y changes sign (linear interpolation), and the sign of the slope there."""
    t, y = np.asarray(t), np.asarray(y)
    k = np.flatnonzero((y[:-1] != 0) & (np.sign(y[:-1]) != np.sign(y[1:])))
    tc = t[k] - y[k] * (t[k + 1] - t[k]) / (y[k + 1] - y[k])
    return tc, np.sign(y[k + 1] - y[k])


def measured_period(t, y):
    """Period from the centre's zero crossings after t = 0: the first upward crossing
    (one full period), else twice the first downward one (half a period); None if neither."""
    tc, up = zero_crossings(t, y)
    keep = tc > 0.05 * (t[-1] - t[0])       # the start at y = 0 is not a crossing
    tc, up = tc[keep], up[keep]
    if np.any(up > 0):
        return float(tc[up > 0][0]), "full"
    if tc.size:
        return float(2.0 * tc[0]), "half"
    return None, None


def tear_indicators(x, y, rho, dr, rho0=RHO0):
    """(void fraction, clump fraction): particles with rho < 0.9 rho0, and with a neighbour
    closer than dr/2."""
    i, j, r = pairs_within((x, y), (x, y), CLUMP_DR * dr)
    clumped = np.unique(i[i != j])
    return float(np.mean(rho < VOID_RHO * rho0)), float(clumped.size / x.size)


class BerylliumPlate(Application):
    """Beryllium plate in free bending vibration (SHTC-SPH, tau = infinity)."""

    tf = 3e-5
    pfreq = 5000
    dim = 2
    history_columns = ("t", "y_centre", "kinetic", "bulk", "shear", "penalty", "total")
    error_key = "energy_drift"

    def add_user_options(self, group):
        group.add_argument("--nw", type=int, default=40,
                           help="particles across the thickness: dr = W/nw (paper: 40)")
        group.add_argument("--cp-factor", type=float, default=10.0,
                           help="tensile penalty c_p / c0 (paper: 10; 0 switches the penalty off)")
        group.add_argument("--rho0", type=float, default=RHO0, help="density (thesis: 1850 kg/m^3)")
        group.add_argument("--samples-per-period", type=int, default=400,
                           help="history samples per linear period 2 pi/omega (default %(default)s)")
        group.add_argument("--integrator", choices=SHTC_INTEGRATORS, default="verlet",
                           help="time integrator (Kincl 2023, thesis sec. 1.4; the paper's eq. 25 is verlet; "
                                "default %(default)s)")
        add_perturbation_options(group)

    def consume_user_options(self, o):
        if o.nw < 4:
            raise InputError(f"--nw must be at least 4, got {o.nw}")
        if not (math.isfinite(o.cp_factor) and o.cp_factor >= 0):
            raise InputError(f"--cp-factor must be a non-negative number, got {o.cp_factor}")
        if not (math.isfinite(o.rho0) and o.rho0 > 0):
            raise InputError(f"--rho0 must be positive, got {o.rho0}")
        if o.samples_per_period < 10:
            raise InputError(f"--samples-per-period must be at least 10, got {o.samples_per_period}")
        check_perturbation(o)
        self.dr = W / o.nw
        self.rho0 = o.rho0

    def create_particles(self):
        x, y = isometric_lattice(self.dr, L, W)
        self.centre_gid = int(np.argmin(x * x + y * y))
        x, y = perturbed((x, y), self.dr, self.options)
        n = x.size
        self._v0 = bending_velocity(x)
        plate = ParticleArray("plate", x=x, y=y, u=np.zeros(n), v=self._v0.copy(),
                              m=np.full(n, self.rho0 * self.dr ** 2), h=np.full(n, HDR * self.dr),
                              rho=np.full(n, self.rho0))
        return [plate]

    def create_scheme(self):
        return SHTCScheme(["plate"], 2, rho0=self.rho0, c0=C0, cs=C0, h=HDR * self.dr, dr=self.dr,
                          tau=math.inf, model="dprz", cp=self.options.cp_factor * C0,
                          integrator=self.options.integrator)

    def post_step(self, solver):
        every = max(1, int(round(2 * math.pi / OMEGA / self.options.samples_per_period / solver.dt)))
        if not self.history:
            self.record(0.0, first=True)
        if solver.step % every == 0 or solver.t >= solver.tf - 1e-12 * solver.tf:
            self.record(solver.t)

    def record(self, t, first=False):
        pa = self.scene.by_name["plate"]
        if first:   # the state before the first step (energies of the initial condition)
            e = {"kinetic": 0.5 * float(np.sum(pa.m * self._v0[pa.gid] ** 2)),
                 "bulk": 0.0, "shear": 0.0, "penalty": 0.0}
            e["total"] = e["kinetic"]
            self.history.append([0.0, 0.0] + [e[k] for k in self.history_columns[2:]])
            return
        e = self.scheme.energies(self.scene.arrays)
        k = int(np.flatnonzero(pa.gid == self.centre_gid)[0])
        self.history.append([t, float(pa.y[k])] + [e[c] for c in self.history_columns[2:]])

    def history_meta(self):
        o = self.options
        return {"nw": o.nw, "cp_factor": o.cp_factor, "rho0": self.rho0, "dr": self.dr, "integrator": o.integrator,
                "perturb": o.perturb, "seed": o.seed}

    def post_process(self, outdir):
        """results.json, centre.png, energy.png and pressure.png from the run's files."""
        hist, rows = io.read_history(outdir)
        t, yc, ek, eb, es, ep, et = rows.T
        drift = np.abs(et / et[0] - 1.0)
        if self.solver is not None:
            pa = self.scene.by_name["plate"]
            state = {c: pa.get(c) for c in ("x", "y", "rho", "p")}
        else:
            last = io.load(io.output_files(outdir, self.name)[-1])
            state = last["arrays"]["plate"]
        dr = hist["dr"]
        void, clump = tear_indicators(state["x"], state["y"], state["rho"], dr, hist["rho0"])
        period, how = measured_period(t, yc)
        t_eb, t_omega, t_timo = euler_bernoulli_period(), 2 * math.pi / OMEGA, timoshenko_period()
        results = {
            "t": float(t[-1]), "nw": hist["nw"], "cp_factor": hist["cp_factor"], "dr": dr,
            "energy_drift": float(drift.max()), "energy_drift_final": float(drift[-1]),
            "energy_error": float(drift.max()),
            "max_density_error": float(np.abs(np.asarray(state["rho"]) / hist["rho0"] - 1.0).max()),
            "energy_initial": float(et[0]),
            "penalty_energy_max": float((ep / et[0]).max()),
            "period": period, "period_from": how,
            "period_euler_bernoulli": t_eb, "period_initial_omega": t_omega,
            "period_error_euler_bernoulli": None if period is None else period / t_eb - 1.0,
            "period_error_initial_omega": None if period is None else period / t_omega - 1.0,
            "period_timoshenko": t_timo,
            "period_error_timoshenko": None if period is None else period / t_timo - 1.0,
            "period_continuum": PERIOD_CONTINUUM,
            "period_error_continuum": None if period is None else period / PERIOD_CONTINUUM - 1.0,
            "centre_max": float(yc.max()), "t_centre_max": float(t[np.argmax(yc)]),
            "void_fraction": void, "clump_fraction": clump, "torn": bool(max(void, clump) > 0.01),
            "rho_min": float(np.min(state["rho"]) / hist["rho0"]),
        }
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, t, yc, rows[:, 2:], state, hist)
        p = "n/a" if period is None else f"{period:.4g} s ({how})"
        print(f"beryllium_plate: t={t[-1]:.4g}  energy drift {results['energy_drift']:.3g}  period {p} "
              f"(Euler-Bernoulli {t_eb:.4g}, Timoshenko {t_timo:.4g}, 2pi/omega {t_omega:.4g}, continuum {PERIOD_CONTINUUM:.4g})  void {void:.3g}  clump {clump:.3g}\n"
              f"results: {os.path.join(outdir, 'results.json')}")
        return results

    @staticmethod
    def plot(outdir, t, yc, energies, state, hist):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        plot_track(os.path.join(outdir, "centre.png"), plt, t, yc, "$y$ of the centre [m]",
                   "(the finite-volume curve of Boscheri et al. 2022 is not available)",
                   (AMP * 70.076 * np.sin(OMEGA * t), "linear theory $A\\phi(0)\\sin\\omega t$"))
        plot_energy(outdir, plt, t, energies)
        fig, ax = plt.subplots(figsize=(10, 2.6))
        sc = ax.scatter(state["x"], state["y"], c=state["p"], s=2, cmap="coolwarm")
        fig.colorbar(sc, ax=ax, label="p [Pa]")
        ax.set_aspect("equal")
        ax.set_title(f"c_p = {hist['cp_factor']:g} c0, t = {t[-1]:.3g} s")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "pressure.png"), dpi=100)
        plt.close(fig)
