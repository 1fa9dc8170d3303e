"""The superfluid fountain (Kincl 2023, thesis sec. 3.6, eqs. 3.52-3.59, Figs. 3.4-3.8).

A cell of He II at T0 = 1.65 K, closed at the bottom by a superleak and on the sides and
top by adiabatic walls, opens into a capillary; a heater of power W_dot [W/m] in the cell
drives superflow in through the superleak (the fountain effect) and a jet out of the
capillary.  2D (translational symmetry), gravity on v and v_s, COOLER walls (T = T0) around
the cryostat.  The thesis' Fig. 3.4 is an image without numbers: the apparatus below is the
authors' code's (lengths in mm; docs/superfluid.md, "The fountain"):

* two solids, mirror images about x = 0 (:func:`inside_profile`, the profile of the
  authors' code), leaving the cell |x| < 7.975, 0 < y < 16.7, and the capillary
  |x| < r_cap = 0.775 from the cell roof to its exit at y = 33.7;
* the cryostat box (-25, 25) x (-10, 120) with COOLER walls, helium up to y = 23 at t = 0,
  hydrostatic;
* the superleak band y = 1 +- 2 across |x| <= 15 (:mod:`sphgen.equations.superfluid_fountain`),
  the heater at (0, 8) with H = 2 (support radius 4), ramped over 0.02 s;
* the walls' density constants calibrated as if wet, their pressure floored at 0.

Presets: ``paper`` (dr = r_cap/8, about 200 000 particles, t = 0.3 s; the thesis' run) and
``quick`` (dr = r_cap, 2 particles across the capillary, ``--tf`` 0.12 s).  ``post_process`` writes results.json: the mass
flux Q through the flux counter (the exit segment |x| < r_cap, y = 33.7) over time and its
mean over the last ``--window`` seconds against eq. 3.56, Q = W_dot/(s_cell T_cell), with
s_cell and T_cell measured at the heater (kernel W_H, fluid particles); the jet speed of
eq. 3.57; the jet height against v_jet^2/(2g); T_cell - T0; and fountain.png.
"""
import json
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import hexagonal_lattice, inside_disk, inside_rectangle, layers_for_support, perturb
from sphgen.particles import ParticleArray
from sphgen.tools.probes import pairs_within, shepard

from ..equations.superfluid import ADIABATIC, COOLER, FLUID
from ..equations.superfluid_energy import HELIUM_1_65K
from ..schemes.superfluid_fountain import FountainScheme

MM = 1e-3
MODEL = HELIUM_1_65K
R_CAP = 0.775 * MM            # half width of the capillary
Y_EXIT = 33.7 * MM            # capillary exit: the flux counter
LEVEL = 23.0 * MM             # helium level at t = 0
BOX = (-25.0 * MM, 25.0 * MM, -10.0 * MM, 120.0 * MM)   # cryostat (COOLER walls outside)
HEATER = dict(x_heat=0.0, y_heat=8.0 * MM, H=2.0 * MM, t_ramp=0.02)
SUPERLEAK = dict(k0=1.0e6, y_sl=1.0 * MM, d_sl=2.0 * MM, r_sl=15.0 * MM)
G = 9.8
HDX = 1.4                     # h / dr (the authors' support 2.8 dr)
MU = 1.0e-4                   # normal viscosity [Pa s]
BETA = 1.0e-2 * R_CAP * MODEL.rho0 * MODEL.s0 ** 2 / MODEL.c2   # = 6.20, the authors' code
PRESETS = {"paper": dict(ratio=8.0, tf=0.3, window=0.1),
           "quick": dict(ratio=1.0, tf=0.12, window=0.04)}
OUTPUTS = 200                 # history rows per run (the authors' code: t_end/200)


def inside_profile(u, y):
    """The solid profile of one side in its own frame (mm): u = 0 outside, u = 17.1 at the capillary."""
    body = (inside_rectangle(0.0, 9.9, 0.0, 23.7)(u, y) | inside_rectangle(9.9, 17.1, 16.7, 23.7)(u, y))
    rounded = (u < 10.7) & (y > 13.0) & ~inside_disk(10.7, 13.0, 10.7)(u, y)
    fillet = inside_rectangle(9.9, 11.9, 14.7, 16.7)(u, y) & ~inside_disk(11.9, 14.7, 2.0)(u, y)
    corner = (u > 15.1) & (y < 18.7) & ~inside_disk(15.1, 18.7, 2.0)(u, y)
    return ((body & ~rounded & ~corner) | fillet | inside_disk(4.95, 0.0, 4.95)(u, y)
            | inside_rectangle(15.6, 17.1, 23.7, 33.7)(u, y))


def inside_solid(x, y):
    """The two solids (x, y in m), mirror images about x = 0, the capillary 2 r_cap between them."""
    u = (R_CAP / MM + 17.1) - np.abs(np.asarray(x)) / MM
    return inside_profile(u, np.asarray(y) / MM)


def apparatus(dr, n_layers):
    """(x, y, ptype) of the hexagonal lattice: fluid below the level, the solids' ADIABATIC
    particles within n_layers dr of their surface, COOLER layers around the box."""
    x0, x1, y0, y1 = BOX
    pad = n_layers * dr
    x, y = hexagonal_lattice(dr, x0 - pad, x1 + pad, y0 - pad, y1)
    in_box = (x > x0) & (x < x1) & (y > y0)
    solid = inside_solid(x, y)
    near = np.zeros_like(solid)
    for k in range(12):   # a solid point whose n-dr disc reaches out of the solid
        a = 2 * np.pi * k / 12
        for r in np.arange(1, n_layers + 1) * dr:
            near |= ~inside_solid(x + r * np.cos(a), y + r * np.sin(a))
    wall = in_box & solid & near
    fluid = in_box & ~solid & (y < LEVEL)
    cooler = ~in_box & (y < y1 - pad)   # the box is open at the top
    keep = wall | fluid | cooler
    ptype = np.where(fluid, FLUID, np.where(wall, ADIABATIC, COOLER))[keep]
    dry = in_box & ~solid & (y >= LEVEL)   # where fluid may come: the walls' calibration
    return x[keep], y[keep], ptype.astype(np.int32), (x[dry], y[dry])


def entropy_flux_across(pa, kernel, y_c, half_width):
    """The pair entropy flux of eq. 3.34 from below y = y_c to above it, within |x| < half_width:
    sum over pairs (a above, b below) of -m_a m_b (J_a/rho_a^2 + J_b/rho_b^2) . grad W_ab
    [W/(m K)] (ADIABATIC pairs carry none); the part of the entropy transport relative to v."""
    x, y, h = pa.x, pa.y, pa.h
    near = np.flatnonzero((np.abs(y - y_c) < kernel.radius_scale * h) & (np.abs(x) < half_width))
    i, j, r = pairs_within((x[near], y[near]), (x[near], y[near]), kernel.radius_scale * h.max())
    i, j, r = near[i], near[j], r
    keep = (y[i] > y_c) & (y[j] < y_c) & (r > 0) & (pa.ptype[i] != ADIABATIC) & (pa.ptype[j] != ADIABATIC)
    i, j, r = i[keep], j[keep], r[keep]
    dw = np.vectorize(kernel.dwdr, otypes=[float])(r, h[i]) / r
    f = (pa.jx[i] + pa.jx[j]) * (x[i] - x[j]) + (pa.jy[i] + pa.jy[j]) * (y[i] - y[j])
    return float(-(pa.m[i] * pa.m[j] * dw * f).sum())


class FluxCounter:
    """Net count of fluid particles crossing y = y_c upwards within |x| < half_width, tracked by gid."""

    def __init__(self, y_c, half_width):
        self.y_c, self.half_width = y_c, half_width
        self.prev = None
        self.count = 0

    def update(self, gid, x, y):
        """Add the crossings since the last call (positions of the fluid particles by gid)."""
        below = np.full(int(gid.max()) + 1 if gid.size else 0, False)
        below[gid] = y < self.y_c
        if self.prev is not None:
            inside = np.abs(x) < self.half_width
            was = self.prev[gid]
            up = was & ~below[gid] & inside
            down = ~was & below[gid] & inside
            self.count += int(up.sum()) - int(down.sum())
        self.prev = below
        return self.count


class Fountain(Application):
    """Superfluid fountain: heater, superleak, capillary jet (Kincl 2023, sec. 3.6)."""

    tf = None
    pfreq = 100000
    dim = 2
    history_columns = ("t", "crossed", "s_cell", "T_cell", "jet_top", "heater_power", "mass", "energy",
                       "entropy")
    error_key = "flux_error"
    diagnostics = ("density_range",)
    diagnostics_every = 200

    def add_user_options(self, group):
        group.add_argument("--preset", choices=sorted(PRESETS), default="paper",
                           help="paper: dr = r_cap/8 (149 195 particles), t = 0.3 s; quick: "
                           "dr = r_cap (4 049 particles), t = 0.12 s (default %(default)s)")
        group.add_argument("--power", type=float, default=80.0,
                           help="heater power W_dot [W/m] (the thesis: 60, 80, 100; default %(default)s)")
        group.add_argument("--ratio", type=float, default=None, help="r_cap/dr (default: the preset's)")
        group.add_argument("--window", type=float, default=None,
                           help="the flux is averaged over the last WINDOW seconds (default: the "
                           "preset's, 0.1 s paper, 0.04 s quick)")
        group.add_argument("--beta", type=float, default=BETA,
                           help="entropy diffusion beta of eq. 3.38 (default %(default).4g, the authors' code)")
        group.add_argument("--mu", type=float, default=MU,
                           help="normal viscosity mu [Pa s] (default %(default)s)")
        group.add_argument("--perturb", type=float, default=0.0,
                           help="random displacement of the fluid particles in units of dr (default 0)")
        group.add_argument("--seed", type=int, default=1, help="seed of the perturbation (default 1)")

    def consume_user_options(self, o):
        preset = PRESETS[o.preset]
        o.ratio = preset["ratio"] if o.ratio is None else o.ratio
        o.tf = preset["tf"] if o.tf is None else o.tf
        o.window = preset["window"] if o.window is None else o.window
        if not (np.isfinite(o.ratio) and 1.0 <= o.ratio <= 32.0):
            raise InputError(f"--ratio must be in [1, 32], got {o.ratio}")
        if not (np.isfinite(o.power) and o.power >= 0):
            raise InputError(f"--power must be a non-negative number, got {o.power}")
        for name in ("beta", "mu", "window"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"--{name} must be a non-negative finite number, got {v}")
        if not (np.isfinite(o.perturb) and 0 <= o.perturb < 0.5):
            raise InputError(f"--perturb must be in [0, 0.5), got {o.perturb}")
        self.dr = R_CAP / o.ratio
        self.h = HDX * self.dr
        self.n_layers = layers_for_support(2.0, HDX)
        self.every = None
        self.counter = FluxCounter(Y_EXIT, R_CAP)

    def create_particles(self):
        dr = self.dr
        x, y, ptype, self.dry = apparatus(dr, self.n_layers)
        fluid = ptype == FLUID
        if self.options.perturb > 0:
            px, py = perturb((x[fluid], y[fluid]), self.options.perturb * dr, seed=self.options.seed)
            x, y = x.copy(), y.copy()
            x[fluid], y[fluid] = px, py
        n = x.size
        self.mass = MODEL.rho0 * dr * dr * np.sqrt(3.0) / 2.0
        rho = MODEL.rho0 * (1.0 + G * np.maximum(LEVEL - y, 0.0) / MODEL.c1 ** 2)   # hydrostatic
        pa = ParticleArray("helium", x=x, y=y, m=np.full(n, self.mass),
                           rho=rho, h=np.full(n, self.h), s=np.full(n, MODEL.s0))
        pa.add_property("ptype", dtype="int", data=ptype)
        return [pa]

    def create_scheme(self):
        o = self.options
        return FountainScheme(arrays=("helium",), model=MODEL, h=self.h, beta=o.beta, mu=o.mu,
                              gravity=(0.0, -G, 0.0), heater=dict(HEATER, power=o.power),
                              superleak=SUPERLEAK, wet={"helium": self.dry + (self.mass,)})

    # ------------------------------------------------------------ time series
    def post_step(self, solver):
        pa = self.scene.by_name["helium"]
        fluid = np.asarray(pa.ptype) == FLUID
        self.counter.update(np.asarray(pa.gid)[fluid], pa.x[fluid], pa.y[fluid])
        if self.every is None:
            self.every = max(1, int(round(self.options.tf / OUTPUTS / solver.dt)))
        if solver.step % self.every == 0 or solver.t >= solver.tf - 1e-12 * solver.tf:
            self.history.append(self.history_row(pa, solver.t))

    def history_row(self, pa, t):
        fluid = np.asarray(pa.ptype) == FLUID
        x, y = pa.x[fluid], pa.y[fluid]
        cell = np.array([[HEATER["x_heat"]], [HEATER["y_heat"]]])
        s_cell, T_cell = shepard((cell[0], cell[1]), x, y, HEATER["H"], pa.m[fluid], pa.rho[fluid],
                                 np.column_stack([pa.s[fluid], pa.T[fluid]]), self.scheme.kernel)[0]
        column = np.abs(x) < 4 * R_CAP
        top = float(y[column].max()) if column.any() else float("nan")
        e = self.scheme.energies([pa])
        return [t, self.counter.count, float(s_cell), float(T_cell), top,
                self.scheme.heater_power([pa]), float(pa.m.sum()), e["total"], e["entropy"]]

    def history_meta(self):
        o = self.options
        return {"preset": o.preset, "power": o.power, "ratio": o.ratio, "dr": self.dr, "h": self.h,
                "tf": o.tf, "window": o.window, "particle_mass": MODEL.rho0 * self.dr ** 2 * np.sqrt(3.0) / 2.0}

    # ------------------------------------------------------------ results
    def post_process(self, outdir):
        """results.json and fountain.png from history.json."""
        with open(os.path.join(outdir, "history.json")) as f:
            hist = json.load(f)
        if len(hist["rows"]) < 2:   # a run cut short (--max-steps, as the benchmark's) is not an error
            print(f"fountain: {len(hist['rows'])} history row(s) (one every tf/{OUTPUTS}): no results")
            return None
        results = summarise(hist)
        if self.scene is not None:   # the pair entropy flux J at the end (docs/superfluid.md)
            pa, k = self.scene.by_name["helium"], self.scheme.kernel
            results["entropy_flux_J_superleak"] = entropy_flux_across(pa, k, SUPERLEAK["y_sl"], 7.9 * MM)
            results["entropy_flux_J_capillary"] = entropy_flux_across(pa, k, 25.0 * MM, R_CAP + 0.5 * self.dr)
        io.write_json(os.path.join(outdir, "results.json"), results)
        plot(outdir, hist, results)
        print(f"fountain: W = {hist['power']:g} W/m, {hist['preset']} (r_cap/dr = {hist['ratio']:g}), "
              f"t = {results['t']:.4g} s\n  Q = {results['flux']:.4g} kg/(m s) over the last "
              f"{results['window']:g} s; eq. 3.56: {results['flux_theory']:.4g} "
              f"(error {results['flux_error']:+.2%})\n  T_cell - T0 = {results['dT_cell'] * 1e3:.3g} mK, "
              f"jet height {results['jet_height'] * 1e3:.3g} mm (v_jet^2/2g = {results['jet_height_theory'] * 1e3:.3g} mm)\n"
              f"results: {os.path.join(outdir, 'results.json')}")
        return results


def summarise(hist):
    """The flux over time and its mean over the last window against eqs. 3.56-3.57."""
    rows = np.array(hist["rows"], dtype=float)
    c = {k: rows[:, i] for i, k in enumerate(hist["columns"])}
    t, m = c["t"], hist["particle_mass"]
    flux = np.diff(c["crossed"]) * m / np.diff(t)       # Q over each output interval
    window = t >= t[-1] - hist["window"] * (1 + 1e-9)
    i0 = int(np.argmax(window))
    span = t[-1] - t[i0]
    q = (c["crossed"][-1] - c["crossed"][i0]) * m / span if span > 0 else float("nan")
    s_cell, T_cell = float(c["s_cell"][window].mean()), float(c["T_cell"][window].mean())
    q_theory = hist["power"] / (s_cell * T_cell)
    v_jet = q / (MODEL.rho0 * 2 * R_CAP)
    return {"t": float(t[-1]), "power": hist["power"], "preset": hist["preset"], "ratio": hist["ratio"],
            "window": float(span), "flux": float(q), "flux_theory": float(q_theory),
            "flux_error": float(q / q_theory - 1.0) if q_theory > 0 else float("nan"),
            "flux_series": [[float(a), float(b)] for a, b in zip(0.5 * (t[1:] + t[:-1]), flux)],
            "s_cell": s_cell, "T_cell": T_cell, "dT_cell": T_cell - MODEL.T0,
            "v_jet": float(v_jet), "v_jet_theory": float(q_theory / (MODEL.rho0 * 2 * R_CAP)),
            "jet_height": float(np.nanmean(c["jet_top"][window]) - Y_EXIT),
            "jet_height_max": float(np.nanmax(c["jet_top"]) - Y_EXIT),
            "jet_height_theory": float(v_jet ** 2 / (2 * G)),
            "heater_power": float(c["heater_power"][-1]),
            "mass_drift": float(np.abs(c["mass"] - c["mass"][0]).max() / c["mass"][0])}


def plot(outdir, hist, res):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    rows = np.array(hist["rows"], dtype=float)
    c = {k: rows[:, i] for i, k in enumerate(hist["columns"])}
    fs = np.array(res["flux_series"])
    fig, (a, b, d) = plt.subplots(1, 3, figsize=(14, 4))
    a.plot(fs[:, 0], fs[:, 1], "b-", lw=0.5, alpha=0.5, label="flux counter")
    k = min(10, len(fs))
    a.plot(fs[:, 0], np.convolve(fs[:, 1], np.ones(k) / k, "same"), "b-", lw=1.5, label=f"moving mean of {k}")
    a.axhline(res["flux_theory"], color="k", ls="--", label="eq. 3.56")
    a.set_xlabel("t [s]")
    a.set_ylabel("Q [kg/(m s)]")
    a.legend()
    b.plot(c["t"], (c["T_cell"] - MODEL.T0) * 1e3, "r-")
    b.set_xlabel("t [s]")
    b.set_ylabel("T_cell - T0 [mK]")
    d.plot(c["t"], (c["jet_top"] - Y_EXIT) * 1e3, "g-", label="jet top")
    d.axhline(res["jet_height_theory"] * 1e3, color="k", ls="--", label="v_jet^2/2g")
    d.set_xlabel("t [s]")
    d.set_ylabel("height above the exit [mm]")
    d.legend()
    fig.suptitle(f"fountain, W = {hist['power']:g} W/m, r_cap/dr = {hist['ratio']:g}")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, "fountain.png"), dpi=100)
    plt.close(fig)
