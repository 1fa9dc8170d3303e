"""Oscillating plate: a clamped elastic cantilever in free bending (Adepu & Ramachandran 2021,
section 4.4; Gray, Monaghan & Swift 2001).

A plate of length L = 0.2 m and thickness H = 0.02 m (plane strain), E = 2 MPa,
nu = 0.3975, rho0 = 1000 kg/m^3 (c0 = 57.03 m/s), h = dx = H / ``--nh`` (paper: 2 mm, 10
across), Monaghan artificial viscosity alpha = 1, starts straight with the velocity of
eq. 67: v_y = V_f c0 F(x) / F(L), kL = 1.875.  The clamp: the plate continues
``--clamp-layers`` columns to the left of x = 0, held at u = u~ = 0 by the integrator
(its particles keep their stress and pressure equations, so the plate sees a full
kernel support at x = 0); ``--clamp wall`` (gtvf) leaves those columns free inside fixed
wall particles above, below and behind them.  ``--scheme`` ctvf (default, SPST; the
paper's Figs. 19-21) or gtvf (its homogenisation, Fig. 18a; ``--shifting spst`` for Fig.
18b).  ``--kernel``, ``--hdx`` (default the quintic at h = dx; the GTVF plate stays whole
only at h = 1.3 dx, docs/ctvf.md "Fig. 18a"), ``--p-ref`` (gtvf: the cap of p0, a
pressure or 'body', the body's largest |p|).

``results.json``: the period of the tip (the midpoint of the two end particles on the
centre line, followed by id: :class:`sphgen.tools.probes.MaterialPoints`) from its zero
crossings, beside the paper's CTVF value 0.284 s (Table 1, V_f = 0.05) and the thin-plate
value; and the separation measures over the run and up to ``--separation-time``
(0.22 s, Figs. 18-19): the bond gap, the largest empty disc centred at the midpoint of
an initial nearest-neighbour pair (in dx: 0.5 on the lattice, 1 with a particle missing;
the plate counts as separated from 1 dx on), the number of pieces (particles joined
when closer than 1.5 dx), the largest stretch of an initial bond (in dx) and the
particles with fewer than half the bulk's neighbours within 2.5 dx, beyond the initial
count (the lattice's corners).  Plots: tip.png (y_tip(t)), plate.png (the particles at the
separation time and at the end, coloured by the pressure).
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.kernels import KERNELS, get_kernel
from sphgen.geometry import rectangle
from sphgen.particles import ParticleArray
from sphgen.tools.plots import particle_panels
from sphgen.tools.probes import MaterialPoints, count_neighbours, nearest_distance, pairs_within

from ..equations.shifting import SHIFTINGS
from ..schemes.ctvf import SOLID_CORRECTIONS, CTVFSolidScheme, elastic_constants
from ..schemes.gtvf import GTVFSolidScheme
from .beryllium_plate import measured_period

E, POISSON, RHO0 = 2.0e6, 0.3975, 1000.0
KL = 1.875
PERIOD_PAPER = {0.001: 0.284, 0.01: 0.283, 0.03: 0.283, 0.05: 0.284}
"""T_CTVF of Adepu & Ramachandran (2021), Table 1 (L = 0.2, H = 0.02)."""
PERIOD_PAPER_GTVF = {0.001: 0.284, 0.01: 0.283, 0.03: 0.284, 0.05: 0.285}
"""T_GTVF of the same Table 1."""
SCHEMES = ("ctvf", "gtvf")
BOND = 1.5            # bond / piece radius, in dx
NEIGHBOUR_RADIUS = 2.5
CLAMPS = ("held", "wall")
GAP_CRACK = 1.0       # bond gap (in dx) of a separation: a hole a whole particle fits into


def mode_shape(x, length, kl=KL):
    """F(x) of eq. 67 (Adepu & Ramachandran 2021): the first clamped-free bending mode."""
    k = kl / length
    return ((math.cos(kl) + math.cosh(kl)) * (np.cosh(k * x) - np.cos(k * x))
            + (math.sin(kl) - math.sinh(kl)) * (np.sinh(k * x) - np.sin(k * x)))


def thin_plate_period(length, height, E=E, poisson=POISSON, rho0=RHO0, kl=KL):
    """2 pi / omega, omega^2 = E H^2 k^4 / (12 rho (1 - nu^2)) (Landau & Lifshitz; the
    analytical row of Adepu & Ramachandran 2021, Table 1)."""
    k = kl / length
    return 2.0 * math.pi / math.sqrt(E * height ** 2 * k ** 4 / (12.0 * rho0 * (1.0 - poisson ** 2)))


def pieces(x, y, radius):
    """Number of connected pieces of the graph joining particles closer than radius."""
    i, j, _ = pairs_within((x, y), (x, y), radius)
    label = np.arange(x.size)
    while True:
        new = label.copy()
        np.minimum.at(new, i, label[j])
        new = new[new]          # pointer jumping
        if np.array_equal(new, label):
            return int(np.unique(label).size)
        label = new


def sparse_particles(x, y, dx):
    """Particles with fewer than half the bulk's (the median's) neighbours within 2.5 dx."""
    counts = count_neighbours((x, y), NEIGHBOUR_RADIUS * dx)
    return int(np.sum(counts < 0.5 * 21))   # 21: a square lattice's bulk count, itself included


def parse_p_ref(text):
    """--p-ref: None, 'body' or a positive pressure."""
    if text is None or text == "body":
        return text
    try:
        value = float(text)
    except ValueError:
        value = float("nan")
    if not (math.isfinite(value) and value > 0):
        raise InputError(f"--p-ref must be a positive pressure or 'body', got {text!r}")
    return value


class OscillatingPlate(Application):
    """Clamped elastic plate in bending: CTVF (default) or GTVF, SPST/IPST/GTVF shifting."""

    tf = 0.3
    pfreq = 5000
    dim = 2
    history_columns = ("t", "y_tip", "pieces", "bond_stretch", "bond_gap", "sparse", "kinetic_energy")
    error_key = "period_error"

    def add_user_options(self, group):
        group.add_argument("--scheme", choices=SCHEMES, default="ctvf",
                           help="CTVF (Adepu & Ramachandran 2021) or GTVF (Zhang, Hu & Adams 2017)")
        group.add_argument("--shifting", choices=SHIFTINGS, default=None,
                           help="homogenisation (default: spst for ctvf, gtvf for gtvf)")
        group.add_argument("--no-corrections", action="store_true",
                           help="ctvf: switch off the correction terms (EDAC, continuity, Jaumann)")
        group.add_argument("--free-surface", dest="free_surface", action="store_true", default=None,
                           help="the free-surface treatment of the shifting (sections 3.4-3.5; "
                           "default on for ctvf, off for gtvf)")
        group.add_argument("--no-free-surface", dest="free_surface", action="store_false")
        group.add_argument("--surface-pressure", action="store_true",
                           help="hold p = 0 on free-surface particles (not in the paper; the first "
                           "author's later code does it)")
        group.add_argument("--edac-damping", choices=("paper", "consistent"), default="paper",
                           help="ctvf: EDAC damping as printed in eq. 26 (default) or dimensionally consistent")
        group.add_argument("--vf", type=float, default=0.05, help="V_f: tip speed / c0 (default %(default)s)")
        group.add_argument("--length", type=float, default=0.2, help="L (default %(default)s m)")
        group.add_argument("--height", type=float, default=0.02, help="H (default %(default)s m)")
        group.add_argument("--nh", type=int, default=10, help="particles across H (paper: 10, dx = 2 mm)")
        group.add_argument("--clamp-layers", type=int, default=3, help="clamped columns left of x = 0 (default 3)")
        group.add_argument("--clamp", choices=CLAMPS, default="held",
                           help="held: the clamp columns are held at u = u~ = 0 (default); wall (gtvf): "
                           "they are free, inside fixed wall particles above, below and behind them")
        group.add_argument("--alpha", type=float, default=1.0, help="artificial viscosity (paper: 1)")
        group.add_argument("--kernel", choices=KERNELS, default="quintic",
                           help="smoothing kernel of every equation (default %(default)s)")
        group.add_argument("--hdx", type=float, default=1.0, help="h / dx (default %(default)s)")
        group.add_argument("--p-ref", default=None,
                           help="gtvf shifting: the cap of p0 = min(10|p|, p_ref), a pressure in Pa or "
                           "'body' (the body's largest |p| each step); default rho0 c0^2")
        group.add_argument("--separation-time", type=float, default=0.22,
                           help="report separation up to this time too (paper, Figs. 18-19: 0.22 s)")
        group.add_argument("--record-every", type=float, default=5e-4, help="time between samples (s)")
        group.add_argument("--perturb", type=float, default=0.0, help="random lattice perturbation / dx")
        group.add_argument("--seed", type=int, default=1)

    def consume_user_options(self, o):
        for name in ("vf", "length", "height", "record_every", "separation_time"):
            v = getattr(o, name)
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive number, got {v}")
        if o.nh < 4 or o.clamp_layers < 1:
            raise InputError("--nh must be at least 4 and --clamp-layers at least 1")
        if o.clamp == "wall" and o.scheme != "gtvf":
            raise InputError("--clamp wall applies to --scheme gtvf only")
        if o.p_ref is not None and o.scheme != "gtvf":
            raise InputError("--p-ref applies to --scheme gtvf only")
        if o.no_corrections and o.scheme != "ctvf":
            raise InputError("--no-corrections applies to --scheme ctvf only")
        if not (0 <= o.perturb < 0.5):
            raise InputError(f"--perturb must be in [0, 0.5), got {o.perturb}")
        if not (math.isfinite(o.hdx) and o.hdx > 0):
            raise InputError(f"--hdx must be a positive number, got {o.hdx}")
        self.p_ref = parse_p_ref(o.p_ref)
        self.dx = o.height / o.nh
        self.c0, _ = elastic_constants(E, POISSON, RHO0)
        self.shifting = o.shifting or ("spst" if o.scheme == "ctvf" else "gtvf")
        self.free_surface = (o.scheme == "ctvf") if o.free_surface is None else o.free_surface
        if o.surface_pressure and not self.free_surface:
            raise InputError("--surface-pressure needs the free-surface treatment")
        self._next_record = 0.0
        self._snap = None

    def create_particles(self):
        o, dx = self.options, self.dx
        x0, y0 = rectangle(-o.clamp_layers * dx, o.length, -0.5 * o.height, 0.5 * o.height, dx)
        x, y = x0, y0
        if o.perturb > 0:      # the plate only; clamp, tip and bonds from the lattice
            rng = np.random.default_rng(o.seed)
            x = x0 + o.perturb * dx * rng.uniform(-1, 1, x0.size) * (x0 > 0)
            y = y0 + o.perturb * dx * rng.uniform(-1, 1, y0.size) * (x0 > 0)
        v = np.where(x > 0, o.vf * self.c0 * mode_shape(np.maximum(x, 0.0), o.length)
                     / mode_shape(o.length, o.length), 0.0)
        n = x.size
        plate = ParticleArray("plate", x=x, y=y, v=v, rho=np.full(n, RHO0), m=np.full(n, RHO0 * dx * dx),
                              h=np.full(n, o.hdx * dx))
        self.clamp_gids = np.flatnonzero(x0 < 0) if o.clamp == "held" else np.array([], dtype=int)
        xt = x0.max()
        self.tip = MaterialPoints("plate", gids=np.flatnonzero((x0 == xt) & (np.abs(y0) < 0.6 * dx)))
        i, j, _ = pairs_within((x0, y0), (x0, y0), 1.01 * dx)
        keep = i < j
        self.bonds = np.column_stack([i[keep], j[keep]])        # gids = initial indices
        self.sparse0 = sparse_particles(x, y, dx)
        if o.clamp == "wall":
            return [plate, self.clamp_wall(x0.min(), y0.min(), y0.max())]
        return [plate]

    def clamp_wall(self, xmin, ymin, ymax):
        """Fixed particles, as many layers as the kernel's support (in dx), above and below
        the clamp columns (x < 0) and behind them over the whole height (the public GTVF
        plate script's clamp, there around L/4 of the plate)."""
        o, dx = self.options, self.dx
        n = math.ceil(get_kernel(o.kernel, 2).radius_scale * o.hdx - 1e-9)
        cols = np.arange(xmin, 0.0, dx)
        rows = np.concatenate([ymax + dx * np.arange(1, n + 1), ymin - dx * np.arange(1, n + 1)])
        xa, ya = (a.ravel() for a in np.meshgrid(cols, rows, indexing="ij"))
        xb, yb = (a.ravel() for a in np.meshgrid(xmin - dx * np.arange(1, n + 1),
                                                 np.arange(ymin - n * dx, ymax + (n + 0.5) * dx, dx), indexing="ij"))
        x, y = np.concatenate([xa, xb]), np.concatenate([ya, yb])
        k = x.size
        return ParticleArray("wall", x=x, y=y, rho=np.full(k, RHO0), m=np.full(k, RHO0 * dx * dx),
                             h=np.full(k, o.hdx * dx))

    def create_scheme(self):
        o = self.options
        common = dict(h=o.hdx * self.dx, dx=self.dx, kernel=o.kernel, p_ref=self.p_ref, umax=o.vf * self.c0,
                      shifting=self.shifting, alpha=o.alpha,
                      clamped={"plate": self.clamp_gids}, free_surface=self.free_surface,
                      surface_pressure=o.surface_pressure)
        if o.scheme == "gtvf":
            fixed = ("wall",) if o.clamp == "wall" else ()
            return GTVFSolidScheme(["plate"], 2, RHO0, E, POISSON, fixed=fixed, **common)
        corrections = () if o.no_corrections else SOLID_CORRECTIONS
        return CTVFSolidScheme(["plate"], 2, RHO0, E, POISSON, corrections=corrections,
                               edac_damping=o.edac_damping, **common)

    def history_meta(self):
        o = self.options
        return {"dx": self.dx, "scheme": o.scheme, "shifting": self.shifting, "vf": o.vf, "length": o.length,
                "height": o.height, "nh": o.nh, "c0": self.c0, "free_surface": self.free_surface,
                "corrections": not o.no_corrections, "sparse_initial": self.sparse0,
                "surface_pressure": o.surface_pressure, "edac_damping": o.edac_damping, "kernel": o.kernel,
                "hdx": o.hdx, "p_ref": self.p_ref, "clamp": o.clamp, "clamp_layers": o.clamp_layers}

    # ------------------------------------------------------------ samples
    def separation(self, pa):
        """(pieces, largest bond stretch / dx, bond gap / dx, sparse particles beyond the
        initial count).  The bond gap is the largest empty disc centred at the midpoint of
        an initial nearest-neighbour pair: 0.5 dx on the lattice, 1 dx where a particle is
        missing; a crack opens it wider."""
        order = np.argsort(pa.gid)
        x, y = pa.x[order], pa.y[order]
        a, b = self.bonds.T
        stretch = float(np.hypot(x[a] - x[b], y[a] - y[b]).max() / self.dx)
        gap = float(nearest_distance((0.5 * (x[a] + x[b]), 0.5 * (y[a] + y[b])), (x, y), 4 * self.dx).max())
        return (pieces(x, y, BOND * self.dx), stretch, gap / self.dx,
                sparse_particles(x, y, self.dx) - self.sparse0)

    def post_step(self, solver):
        pa = self.scene.by_name["plate"]
        if not self.history:
            self.history.append([0.0, 0.0, *self.separation(pa), float(0.5 * np.sum(pa.m * (pa.u ** 2 + pa.v ** 2)))])
        if solver.t >= self._next_record - 0.5 * solver.dt or solver.t >= solver.tf - 0.5 * solver.dt:
            y_tip = float(self.tip.positions({"plate": pa})[:, 1].mean())
            ke = float(0.5 * np.sum(pa.m * (pa.u ** 2 + pa.v ** 2)))
            self.history.append([solver.t, y_tip, *self.separation(pa), ke])
            self._next_record = solver.t + self.options.record_every
        if self._snap is None and solver.t >= self.options.separation_time - 0.5 * solver.dt:
            self._snap = (solver.t, pa.x.copy(), pa.y.copy(), pa.p.copy())
            np.savez(os.path.join(self.outdir, "snapshot.npz"), t=solver.t, x=pa.x, y=pa.y, p=pa.p)

    # ------------------------------------------------------------ results
    def post_process(self, outdir):
        hist, rows = io.read_history(outdir)
        t, y_tip, npieces, stretch, gap, sparse, ke = rows.T
        period, how = measured_period(t, y_tip)
        vf, length, height = hist["vf"], hist["length"], hist["height"]
        table = PERIOD_PAPER_GTVF if hist["scheme"] == "gtvf" else PERIOD_PAPER
        paper = table.get(vf) if abs(length - 0.2) < 1e-12 and abs(height - 0.02) < 1e-12 else None
        upto = t <= self.options.separation_time + 1e-9
        sep = dict(pieces_max=int(npieces.max()), bond_stretch_max=float(stretch.max()),
                   bond_gap_max=float(gap.max()), sparse_max=int(sparse.max()))
        sep_t = dict(pieces_max=int(npieces[upto].max()), bond_stretch_max=float(stretch[upto].max()),
                     bond_gap_max=float(gap[upto].max()), sparse_max=int(sparse[upto].max()))
        results = {
            "t": float(t[-1]), "scheme": hist["scheme"], "shifting": hist["shifting"], "vf": vf,
            "dx": hist["dx"], "free_surface": hist["free_surface"], "corrections": hist["corrections"],
            "period": period, "period_from": how, "period_paper": paper,
            "period_error": None if (period is None or paper is None) else period / paper - 1.0,
            "period_thin_plate": thin_plate_period(length, height),
            "tip_max": float(y_tip.max()), "tip_min": float(y_tip.min()),
            "separation": sep, "separation_time": self.options.separation_time,
            "separation_upto": sep_t,
            "separated_upto": bool(sep_t["pieces_max"] > 1 or sep_t["bond_gap_max"] >= GAP_CRACK),
            "separated": bool(sep["pieces_max"] > 1 or sep["bond_gap_max"] >= GAP_CRACK),
            "kinetic_energy_final_over_initial": float(ke[-1] / ke[0]) if ke[0] > 0 else None,
        }
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, t, y_tip, hist)
        p = "n/a" if period is None else f"{period:.4g} s ({how})"
        print(f"oscillating_plate: {hist['scheme']}+{hist['shifting']} t={t[-1]:.4g}  period {p} (paper {paper}, "
              f"thin plate {results['period_thin_plate']:.4g})  up to t={self.options.separation_time:g}: "
              f"pieces {sep_t['pieces_max']}, bond gap {sep_t['bond_gap_max']:.3g} dx, bond stretch "
              f"{sep_t['bond_stretch_max']:.3g} dx, sparse {sep_t['sparse_max']}\nresults: {os.path.join(outdir, 'results.json')}")
        return results

    def plot(self, outdir, t, y_tip, hist):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(t, y_tip, "r-", label=f"sphgen {hist['scheme'].upper()} + {hist['shifting'].upper()}")
        ax.set_xlabel("t [s]")
        ax.set_ylabel("tip y [m]")
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "tip.png"), dpi=100)
        plt.close(fig)
        snaps = []
        path = os.path.join(outdir, "snapshot.npz")
        if os.path.exists(path):
            d = np.load(path)
            snaps.append((float(d["t"]), d["x"], d["y"], d["p"]))
        if self.scene is not None:
            pa = self.scene.by_name["plate"]
            snaps.append((float(t[-1]), pa.x, pa.y, pa.p))
        if snaps:
            name = f"{hist['scheme'].upper()} + {hist['shifting'].upper()}"
            particle_panels(os.path.join(outdir, "plate.png"),
                            [(f"{name}, t = {ts:.3g} s", x, y, p) for ts, x, y, p in snaps])
