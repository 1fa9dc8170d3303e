"""Second-sound standing wave in He II (Kincl 2023, thesis sec. 3.5, eqs. 3.45-3.51).

The square (0, L)^2, L = 1 cm, holds N x N helium particles on the cell-centred square
lattice (spacing dr = L/N, mass rho0 dr^2), surrounded by dummy walls (``--boundary``):

* ``mirror`` (default): 2 ceil(2h/dr) layers of dummies, each the mirror image of a fluid
  particle across the nearest face(s), refreshed before every evaluation (position, s,
  v and v_s with their normal components reversed): no heat and no normal flow across the
  wall (adiabatic, eq. 3.45); the fluid evolves as a quarter of the periodic box (0, 2L)^2;
* ``walls``: ceil(2h/dr) layers of ADIABATIC particles (v = v_s = 0, s = s0, no entropy
  flux, diffusion or s grad T across a pair with a wall; no-slip, eq. 3.46);
* ``periodic``: the periodic box (0, 2L)^2 with 2N x 2N particles, no walls.

At t = 0: v = v_s = 0, rho = rho0 (summation density with its constant, eq. 1.14) and s
from eq. 3.51,

    (s - s0)/s0 = A cos(pi x/L) cos(pi y/L) cos(sqrt(2) pi c2 t/L),

the linear standing wave.  The run lasts one period, t = sqrt(2) L/c2.
Helium at T0 = 1.9 K (:data:`~sphgen.equations.superfluid_energy.HELIUM_1_9K`), c1 = 40 m/s;
h = ``--hdx`` dr (default 1.5); dt = 2h/(M c1) with M the temporal resolution
(``--M``, default 50); beta = mu = 0 unless given.  The thesis prints none of these: the
choices and their sources are in docs/superfluid.md.

``post_process`` writes results.json:

* ``entropy_error``: max over the sampled times of the RMS over the fluid particles of
  (s_a - s_exact(x_a, t))/(A s0), eq. 3.51 at the particle's current position;
* ``energy_error``: max over the sampled times of |E(t) - E(0)|/E(0), E the total energy
  (eqs. 3.23 + 3.32) summed over the fluid (mirror) or over all particles (walls, periodic);
* ``frequency_ratio``: omega'/omega of the fit of the mode's amplitude to a0 cos(omega' t),
  against ``frequency_ratio_lattice``, the dispersion of the zero-order operators on the
  lattice (:func:`lattice_frequency_ratio`), and the entropy errors those frequencies alone
  would give;
* the entropy at (L/4, L/4) against eq. 3.51 (Shepard interpolation of the fluid), the
  largest |rho/rho0 - 1| and the drift of sum m s;

and second_sound.png (the probe against eq. 3.51, both errors over time).
"""
import json
import os
from math import cos, pi, sqrt

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import layers_for_support, perturb, square_lattice, wall_layers_box
from sphgen.nnps import Domain
from sphgen.particles import ParticleArray
from sphgen.tools.probes import shepard

from ..equations.superfluid import ADIABATIC, COOLER, FLUID
from ..equations.superfluid_energy import HELIUM_1_9K
from ..schemes.superfluid import SuperfluidScheme

L = 0.01
MODEL = HELIUM_1_9K
PERIOD = sqrt(2.0) * L / MODEL.c2
C1_WINDOW = sqrt(2.0) * L / MODEL.c1   # the end time of the authors' code (0.47 periods)
SAMPLES = 400   # history rows per period (the errors are maxima over these times)


def exact_entropy(x, y, t, A, model=MODEL):
    """s of the linear standing wave, eq. 3.51."""
    omega = sqrt(2.0) * pi * model.c2 / L
    return model.s0 * (1.0 + A * np.cos(pi * x / L) * np.cos(pi * y / L) * cos(omega * t))


def entropy_error(x, y, s, t, A, model=MODEL):
    """RMS over particles of (s - s_exact)/(A s0)."""
    d = (s - exact_entropy(x, y, t, A, model)) / (A * model.s0)
    return float(np.sqrt(np.mean(d * d)))


def mode_shape(x, y):
    """cos(pi x/L) cos(pi y/L), the spatial factor of eq. 3.51."""
    return np.cos(pi * np.asarray(x) / L) * np.cos(pi * np.asarray(y) / L)


def lattice_frequency_ratio(N, hdx, kernel):
    """omega_discrete/omega of eq. 3.51's mode for the zero-order operators of eq. 3.34 on the
    periodic cell-centred square lattice (dr = L/N, h = hdx dr), linearised about rest: both
    the gradient of T and the divergence of J act on a Fourier mode as i g(k), with
    g(k) = sum_b V_b sin(k . x_ab) grad W(x_ab) (a lattice sum), so omega_d/omega = |g|/|k|,
    k = (pi/L)(1, 1).  Tends to the lattice-sum factor of h/dr (not to 1) as N grows."""
    dr = L / N
    h = hdx * dr
    n = int(np.ceil(kernel.radius_scale * hdx)) + 1
    i = np.arange(-n, n + 1) * dr
    X, Y = (g.ravel() for g in np.meshgrid(i, i, indexing="ij"))
    r = np.hypot(X, Y)
    near = (r > 0) & (r < kernel.radius_scale * h)
    X, Y, r = X[near], Y[near], r[near]
    dw = np.vectorize(kernel.dwdr, otypes=[float])(r, h) / r
    k = pi / L
    sn = np.sin(k * X + k * Y)
    g = dr * dr * np.array([np.sum(sn * dw * X), np.sum(sn * dw * Y)])
    return float(np.hypot(*g) / (k * sqrt(2.0)))


def phase_error_bound(ratio, t_end, samples=20001):
    """max over t <= t_end of 1/2 |cos(ratio omega t) - cos(omega t)|: the entropy error of
    eq. 3.51's mode oscillating at ratio omega (1/2 is the RMS of the mode over the lattice)."""
    omega = sqrt(2.0) * pi * MODEL.c2 / L
    t = np.linspace(0.0, t_end, samples)
    return float(0.5 * np.abs(np.cos(ratio * omega * t) - np.cos(omega * t)).max())


def fitted_frequency_ratio(t, a):
    """omega'/omega of the least-squares fit a(t) ~ a0 cos(omega' t) (scan, then golden section)."""
    omega = sqrt(2.0) * pi * MODEL.c2 / L
    t, a = np.asarray(t), np.asarray(a)

    def misfit(q):
        c = np.cos(q * omega * t)
        return float(np.sum((a - (c @ a) / (c @ c) * c) ** 2))
    grid = np.linspace(0.8, 1.2, 801)
    k = int(np.argmin([misfit(q) for q in grid]))
    lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    g = (sqrt(5.0) - 1.0) / 2.0
    for _ in range(60):
        m1, m2 = hi - g * (hi - lo), lo + g * (hi - lo)
        if misfit(m1) < misfit(m2):
            hi = m2
        else:
            lo = m1
    return 0.5 * (lo + hi)


def mirror_partners(wx, wy, N, dr):
    """For wall particles around the N x N cell-centred lattice of (0, L)^2 (gid = i N + j
    of the fluid at ((i + 1/2) dr, (j + 1/2) dr), the order of ``square_lattice``): the gid
    of the mirror image across the nearest face(s), and per axis the sign (-1 across a face
    normal to it) and the shift (0, or 2L across x = L or y = L) of the reflection
    x -> sign x + shift."""
    def fold(c):
        k = np.rint(np.asarray(c) / dr - 0.5).astype(np.int64)   # lattice index, -n..N-1+n
        out = np.where(k < 0, -1 - k, np.where(k >= N, 2 * N - 1 - k, k))
        return out, np.where((k < 0) | (k >= N), -1.0, 1.0), np.where(k >= N, 2.0 * N * dr, 0.0)
    i, sx, ox = fold(wx)
    j, sy, oy = fold(wy)
    if np.any((i < 0) | (i >= N) | (j < 0) | (j >= N)):
        raise InputError(f"second_sound: the mirrored walls are deeper than the box (N = {N})")
    return i * N + j, (sx, sy), (ox, oy)


def loglog_slope(x, y):
    """Least-squares slope of log y against log x."""
    return float(np.polyfit(np.log(x), np.log(y), 1)[0])


class SecondSound(Application):
    """Second-sound standing wave in a 1 cm square of He II (Kincl 2023, sec. 3.5)."""

    tf = PERIOD
    pfreq = 100000
    dim = 2
    history_columns = ("t", "entropy_error", "energy", "kinetic", "compression", "heat", "entropy",
                       "s_probe", "s_probe_exact", "max_density_error", "mode")
    error_key = "entropy_error"   # what `sphgen precision` plots against run time
    diagnostics = ("linear_momentum", "density_range")
    diagnostics_every = 50

    def add_user_options(self, group):
        group.add_argument("--N", type=int, default=100, help="N x N fluid particles (default %(default)s)")
        group.add_argument("--M", type=float, default=50.0,
                           help="temporal resolution: dt = 2h/(M c1) (default %(default)s)")
        group.add_argument("--A", type=float, default=0.01,
                           help="amplitude (s - s0)/s0 of eq. 3.51 (default %(default)s)")
        group.add_argument("--hdx", type=float, default=1.5, help="h / dr (default %(default)s)")
        group.add_argument("--beta", type=float, default=0.0,
                           help="entropy diffusion beta of eq. 3.38 (default %(default)s)")
        group.add_argument("--mu", type=float, default=0.0,
                           help="normal viscosity mu of eq. 3.38 [Pa s] (default %(default)s)")
        group.add_argument("--renormalise", action="store_true",
                           help="divide the thermal operators by the first-moment normalisation of "
                           "each particle's support (not in the thesis; docs/superfluid.md)")
        group.add_argument("--samples", type=int, default=SAMPLES,
                           help="history rows per period (default %(default)s)")
        group.add_argument("--boundary", choices=("mirror", "walls", "periodic"), default="mirror",
                           help="mirror: dummy particles around (0, L)^2 at rest whose s and v_s are "
                           "mirrored from the fluid (adiabatic, eq. 3.45; no-slip, 3.46); walls: "
                           "ADIABATIC dummies at s0 that carry no heat across a pair; periodic: "
                           "the same wave in the periodic box (0, 2L)^2, 2N x 2N particles, no walls "
                           "(isolates the interior error) (default %(default)s)")
        group.add_argument("--perturb", type=float, default=0.0,
                           help="random displacement of the fluid particles in units of dr (default 0)")
        group.add_argument("--seed", type=int, default=1, help="seed of the perturbation (default 1)")

    def consume_user_options(self, o):
        if o.N < 8:
            raise InputError(f"--N must be at least 8, got {o.N}")
        for name in ("M", "A", "hdx"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name} must be a positive finite number, got {v}")
        for name in ("beta", "mu"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"--{name} must be a non-negative finite number, got {v}")
        if not (np.isfinite(o.perturb) and 0 <= o.perturb < 0.5):
            raise InputError(f"--perturb must be in [0, 0.5), got {o.perturb}")
        if o.samples < 2:
            raise InputError(f"--samples must be at least 2, got {o.samples}")
        self.N, self.M, self.A = o.N, o.M, o.A
        self.dr = L / o.N
        self.h = o.hdx * self.dr
        self.dt = 2.0 * self.h / (o.M * MODEL.c1)
        self.every = max(1, int(round(PERIOD / self.dt / o.samples)))
        # mirrored dummies within the fluid's reach need full supports: twice the layers
        self.n_layers = layers_for_support(2.0, o.hdx) * (2 if o.boundary == "mirror" else 1)
        self.side = 2.0 * L if o.boundary == "periodic" else L
        self.history = []

    def create_domain(self):
        if self.options.boundary == "periodic":
            return Domain(0.0, self.side, 0.0, self.side, periodic_in_x=True, periodic_in_y=True)
        return None

    def create_particles(self):
        dr, side = self.dr, self.side
        x, y = square_lattice(dr, 0.0, side, 0.0, side)
        if self.options.perturb > 0:
            x, y = perturb((x, y), self.options.perturb * dr, seed=self.options.seed)
            if self.options.boundary == "periodic":
                x, y = np.mod(x, side), np.mod(y, side)
        boundary = self.options.boundary
        if boundary != "periodic":
            wx, wy, _, _ = wall_layers_box(0.0, L, 0.0, L, dr, self.n_layers, open_top=False)
        else:
            wx = wy = np.empty(0)
        nf, nw = x.size, wx.size
        # mirrored dummies start at their partners' s: eq. 3.51 is even about x, y = 0 and L
        s_wall = exact_entropy(wx, wy, 0.0, self.A) if boundary == "mirror" else np.full(nw, MODEL.s0)
        s = np.concatenate([exact_entropy(x, y, 0.0, self.A), s_wall])
        n = nf + nw
        pa = ParticleArray("helium", x=np.concatenate([x, wx]), y=np.concatenate([y, wy]), s=s,
                           m=np.full(n, MODEL.rho0 * dr * dr), rho=np.full(n, MODEL.rho0),
                           h=np.full(n, self.h))
        wall_type = COOLER if boundary == "mirror" else ADIABATIC
        pa.add_property("ptype", dtype="int",
                        data=np.concatenate([np.full(nf, FLUID), np.full(nw, wall_type)]).astype(np.int32))
        if boundary == "mirror":
            partner, signs, shifts = mirror_partners(wx, wy, self.N, dr)
            pa.add_property("mirror", dtype="int", data=np.concatenate([np.full(nf, -1), partner]).astype(np.int32))
            for name, sign, shift in zip("xy", signs, shifts):
                pa.add_property(f"ms{name}", data=np.concatenate([np.ones(nf), sign]))
                pa.add_property(f"mo{name}", data=np.concatenate([np.zeros(nf), shift]))
        # the history row of t = 0 as created: rho = rho0 (calibrated), v = v_s = 0; the
        # sums over the degrees of freedom (mirrored dummies are copies: left out)
        own = slice(None) if boundary != "mirror" else slice(0, nf)
        heat = float(np.sum(pa.m[own] * MODEL.heat_energy(s[own])))
        probe = float(exact_entropy(np.array([L / 4]), np.array([L / 4]), 0.0, self.A)[0])
        self.initial = [0.0, 0.0, heat, 0.0, 0.0, heat, float(np.sum(pa.m[own] * s[own])), probe, probe, 0.0,
                        self.mode_amplitude(x, y, s[:nf], self.A)]
        return [pa]

    def create_scheme(self):
        o = self.options
        return SuperfluidScheme(arrays=("helium",), dim=2, model=MODEL, h=self.h, beta=o.beta, mu=o.mu,
                                dt=self.dt, renormalise=o.renormalise, mirror_walls=o.boundary == "mirror")

    # ------------------------------------------------------------ time series
    def post_step(self, solver):
        if not self.history:
            self.record(0.0, self.initial)
        if solver.step % self.every == 0 or solver.t >= solver.tf - 1e-12 * solver.tf:
            self.record(solver.t)

    def record(self, t, row=None):
        if row is None:
            row = self.history_row(self.scene.by_name["helium"], self.scheme, t, self.A)
        self.history.append(row)

    @staticmethod
    def history_row(pa, scheme, t, A):
        fluid = np.asarray(pa.ptype) == FLUID
        x, y, s = pa.x[fluid], pa.y[fluid], pa.s[fluid]
        e = scheme.energies([pa])
        probe = shepard((np.array([L / 4]), np.array([L / 4])), x, y, pa.h[fluid], pa.m[fluid],
                        pa.rho[fluid], s, scheme.kernel)
        return [t, entropy_error(x, y, s, t, A), e["total"], e["kinetic"], e["compression"], e["heat"],
                e["entropy"], float(probe[0]),
                float(exact_entropy(np.array([L / 4]), np.array([L / 4]), t, A)[0]),
                float(np.abs(pa.rho / MODEL.rho0 - 1.0).max()), SecondSound.mode_amplitude(x, y, s, A)]

    @staticmethod
    def mode_amplitude(x, y, s, A):
        """Projection of (s - s0)/(A s0) of the fluid on the mode of eq. 3.51 (1 at t = 0)."""
        phi = mode_shape(x, y)
        return float(phi @ (s - MODEL.s0) / (A * MODEL.s0 * (phi @ phi)))

    def history_meta(self):
        return {"N": self.N, "M": self.M, "A": self.A, "boundary": self.options.boundary, "h": self.h,
                "dt": self.dt, "period": PERIOD, "hdx": self.options.hdx}

    # ------------------------------------------------------------ results
    def post_process(self, outdir):
        """results.json and second_sound.png from history.json."""
        with open(os.path.join(outdir, "history.json")) as f:
            hist = json.load(f)
        if not hist["rows"]:
            raise InputError("second_sound: no time step was taken, nothing to post-process")
        rows = np.array(hist["rows"])
        cols = {c: rows[:, i] for i, c in enumerate(hist["columns"])}
        E, S = cols["energy"], cols["entropy"]
        energy_dev = np.abs(E - E[0]) / abs(E[0])
        results = {"t": float(cols["t"][-1]), "period": PERIOD, "N": hist["N"], "M": hist["M"],
                   "A": hist["A"], "boundary": hist.get("boundary", "walls"), "h": hist["h"], "dt": hist["dt"],
                   "entropy_error": float(cols["entropy_error"].max()),
                   "entropy_error_final": float(cols["entropy_error"][-1]),
                   # the window of the authors' code, t <= sqrt(2) L/c1 (docs/superfluid.md)
                   "entropy_error_c1_window": float(cols["entropy_error"][cols["t"] <= C1_WINDOW * (1 + 1e-12)].max()),
                   "energy_error": float(energy_dev.max()),
                   "energy_error_final": float(energy_dev[-1]),
                   "energy_initial": float(E[0]),
                   "total_entropy_drift": float(np.abs(S - S[0]).max() / abs(S[0])),
                   "probe_error": float(np.abs(cols["s_probe"] - cols["s_probe_exact"]).max()
                                        / (hist["A"] * MODEL.s0)),
                   "max_density_error": float(cols["max_density_error"].max()),
                   "samples": int(rows.shape[0])}
        # the error is a phase error: the measured frequency of the mode against the
        # lattice dispersion of the zero-order operators (docs/superfluid.md)
        if "mode" in cols and cols["t"][-1] >= 0.25 * PERIOD:
            ratio = fitted_frequency_ratio(cols["t"], cols["mode"])
            results["frequency_ratio"] = ratio
            results["entropy_error_of_frequency"] = phase_error_bound(ratio, float(cols["t"][-1]))
        if "hdx" in hist:
            lattice = lattice_frequency_ratio(hist["N"], hist["hdx"], self.scheme_kernel())
            results["frequency_ratio_lattice"] = lattice
            results["entropy_error_of_lattice_frequency"] = phase_error_bound(lattice, float(cols["t"][-1]))
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, cols, energy_dev, hist)
        print(f"second_sound: N={hist['N']} M={hist['M']:g} A={hist['A']:g}  t={results['t']:.4g} s "
              f"(period {PERIOD:.4g} s)\n  entropy error (max RMS / (A s0)) = {results['entropy_error']:.4g}"
              f"   energy error (max |E - E0|/E0) = {results['energy_error']:.3g}\n"
              f"results: {os.path.join(outdir, 'results.json')}\n"
              f"figure:  {os.path.join(outdir, 'second_sound.png')}")
        return results

    @staticmethod
    def scheme_kernel():
        from sphgen.kernels import get_kernel
        return get_kernel("wendland", 2)

    @staticmethod
    def plot(outdir, cols, energy_dev, hist):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = cols["t"] * 1e3
        fig, (a, b, c) = plt.subplots(1, 3, figsize=(14, 4))
        a.plot(t, cols["s_probe_exact"] - MODEL.s0, "k-", label="eq. 3.51")
        a.plot(t, cols["s_probe"] - MODEL.s0, "r.", ms=3, label="sphgen")
        a.set_xlabel("t [ms]")
        a.set_ylabel("s - s0 at (L/4, L/4) [J/(kg K)]")
        a.legend()
        b.plot(t, cols["entropy_error"], "b-")
        b.set_xlabel("t [ms]")
        b.set_ylabel("RMS (s - s_exact)/(A s0)")
        c.semilogy(t[1:], np.maximum(energy_dev[1:], 1e-18), "g-")
        c.set_xlabel("t [ms]")
        c.set_ylabel("|E - E0| / E0")
        fig.suptitle(f"second sound, N = {hist['N']}, M = {hist['M']:g}, A = {hist['A']:g}")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "second_sound.png"), dpi=100)
        plt.close(fig)
