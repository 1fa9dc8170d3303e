"""Lid-driven cavity (Ghia, Ghia & Shin 1982; Adepu & Ramachandran 2021, section 4.2).

A unit square of fluid (rho0 = 1) closed by three layers of wall particles on each side
(Adami et al. 2012 ghost particles); the lid (the top layers, corner columns included)
slides at U = 1.  nu = U L / Re (the paper prints "Re/U", a typo), c0 = 10 U, summation
density, no artificial viscosity, h = dx, default final time 25 (the run the paper
times).  ``--scheme`` picks CTVF (the default, with SPST; ``--shifting`` and
``--no-corrections`` as in taylor_green), the uncorrected EDAC baseline (walls with the
prescribed velocity in the divergence, Sun et al. shifting) or GTVF.

``post_process`` writes ``results.json``: the centre-line profiles u(y) on x = 0.5 and
v(x) on y = 0.5 at Ghia's points (linear-corrected SPH interpolation of the fluid,
:func:`sphgen.tools.probes.shepard`, order 1), averaged over the samples of the last
``--average`` time units, their largest deviations from Ghia et al. (1982) at the points
more than 2 dx from the lid, the kinetic energy and its change over that window (is the
flow steady?), the fluid particles that left the cavity and the largest empty disc in
the fluid (:func:`sphgen.tools.probes.largest_empty_disc`, in units of dx: the void of
the paper's Fig. 13); ``profiles.png`` plots the profiles against Ghia's points.
"""
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import layers_for_support, rectangle, wall_layers_box
from sphgen.particles import ParticleArray
from sphgen.tools import reference
from sphgen.tools.probes import shepard

from ..equations.shifting import SHIFTINGS
from ..schemes.ctvf import CTVFScheme
from ..schemes.edac import EDACScheme
from ..schemes.gtvf import GTVFScheme

L = 1.0        # cavity side
U = 1.0        # lid speed
RHO0 = 1.0
SCHEMES = ("ctvf", "edac", "gtvf")
EDAC_SHIFTING = {"spst": "sun2019", "tvf": "tvf", "none": "none"}
GHIA = {re: reference.ghia_1982(re) for re in reference.GHIA_RE}
N_GHIA = (len(GHIA[100]["y"]), len(GHIA[100]["x"]))


def centre_lines(f, kernel, ys, xs):
    """u at (0.5, ys) and v at (xs, 0.5) of the fluid array ``f`` (order-1 Shepard)."""
    u = shepard((np.full(ys.size, 0.5 * L), ys), f.x, f.y, f.h, f.m, f.rho, f.u, kernel, order=1)
    v = shepard((xs, np.full(xs.size, 0.5 * L)), f.x, f.y, f.h, f.m, f.rho, f.v, kernel, order=1)
    return u, v


def compared_points(ys, dx, lid_gap=2.0):
    """Mask of Ghia's u(y) points more than lid_gap * dx below the lid."""
    return (L - ys) > lid_gap * dx


class Cavity(Application):
    """Lid-driven cavity at Re = 100 or 1000: CTVF (default), EDAC or GTVF, Adami walls."""

    tf = 25.0
    pfreq = 2000
    dim = 2
    error_key = "max_dev"   # what `sphgen precision cavity` plots against run time
    diagnostics = ("mass", "kinetic_energy")
    diagnostics_every = 100

    def add_user_options(self, group):
        group.add_argument("--nx", type=int, default=50, help="particles per side (default %(default)s)")
        group.add_argument("--re", type=float, default=100.0, help="Reynolds number U L / nu (default %(default)s)")
        group.add_argument("--scheme", choices=SCHEMES, default="ctvf",
                           help="CTVF (Adepu & Ramachandran 2021), the uncorrected EDAC baseline, or GTVF "
                           "(Zhang, Hu & Adams 2017) (default %(default)s)")
        group.add_argument("--shifting", choices=SHIFTINGS, default=None,
                           help="homogenisation (default: spst for ctvf and edac, gtvf for gtvf)")
        group.add_argument("--no-corrections", action="store_true",
                           help="ctvf: switch off every correction term (EDAC, stress, divergence)")
        group.add_argument("--c0-factor", type=float, default=10.0, help="c0 = factor * U (default %(default)s)")
        group.add_argument("--hdx", type=float, default=1.0, help="h / dx (default %(default)s)")
        group.add_argument("--bql", action="store_true",
                           help="ctvf/edac: subtract the local mean pressure (Basa et al. 2009; not in the paper)")
        group.add_argument("--perturb", type=float, default=0.0,
                           help="random perturbation of the fluid lattice in units of dx (default 0; "
                           "`sphgen stress` sets it)")
        group.add_argument("--seed", type=int, default=1, help="seed of the perturbation (default 1)")
        group.add_argument("--record-every", type=float, default=0.1,
                           help="time between profile samples (default %(default)s)")
        group.add_argument("--average", type=float, default=1.0,
                           help="average the profiles over the samples of the last AVERAGE time units "
                           "(default %(default)s; 0: the last sample)")

    def consume_user_options(self, o):
        if o.nx < 8:
            raise InputError(f"--nx must be at least 8, got {o.nx}")
        for name in ("re", "c0_factor", "hdx", "record_every"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive finite number, got {v}")
        if not (np.isfinite(o.perturb) and 0 <= o.perturb < 0.5):
            raise InputError(f"--perturb must be in [0, 0.5), got {o.perturb}")
        if not (np.isfinite(o.average) and o.average >= 0):
            raise InputError(f"--average must be a non-negative finite number, got {o.average}")
        if o.scheme == "edac" and o.shifting is not None and o.shifting not in EDAC_SHIFTING:
            raise InputError(f"--shifting {o.shifting} is not available with --scheme edac "
                             f"(choose from {', '.join(EDAC_SHIFTING)})")
        if o.scheme == "gtvf" and o.bql:
            raise InputError("--bql is not part of the GTVF scheme")
        if o.no_corrections and o.scheme != "ctvf":
            raise InputError("--no-corrections applies to --scheme ctvf only")
        if o.re not in GHIA:
            print(f"cavity: Ghia et al. (1982) data exist for Re in {tuple(GHIA)}: no comparison at Re = {o.re:g}")
        self.nx, self.re = o.nx, o.re
        self.dx = L / o.nx
        self.h = o.hdx * self.dx
        self.nu = U * L / o.re
        self.c0 = o.c0_factor * U
        self.n_layers = layers_for_support(3.0, o.hdx)
        ghia = GHIA.get(o.re, GHIA[100])
        self.ys, self.xs = ghia["y"], ghia["x"]
        self.history_columns = (("t", "kinetic_energy", "max_speed", "n_outside")
                                + tuple(f"u_y{y:.4f}" for y in self.ys)
                                + tuple(f"v_x{x:.4f}" for x in self.xs))
        self._next_record = 0.0

    def create_particles(self):
        dx = self.dx
        x, y = rectangle(0.0, L, 0.0, L, dx)
        if self.options.perturb > 0:
            rng = np.random.default_rng(self.options.seed)
            x = x + self.options.perturb * dx * rng.uniform(-1, 1, x.size)
            y = y + self.options.perturb * dx * rng.uniform(-1, 1, y.size)
        fluid = ParticleArray("fluid", x=x, y=y, rho=np.full(x.size, RHO0), m=np.full(x.size, RHO0 * dx * dx),
                              h=np.full(x.size, self.h))
        xw, yw, nx, ny = wall_layers_box(0.0, L, 0.0, L, dx, self.n_layers, open_top=False)
        top = yw > L
        # the lid is a plate: its corner columns slide with it and share its normal
        nx, ny = np.where(top, 0.0, nx), np.where(top, -1.0, ny)
        arrays = [fluid]
        for name, sel in (("wall", ~top), ("lid", top)):
            n = int(sel.sum())
            w = ParticleArray(name, x=xw[sel], y=yw[sel], rho=np.full(n, RHO0), m=np.full(n, RHO0 * dx * dx),
                              h=np.full(n, self.h))
            w.add_property("normal", stride=3, data=np.column_stack([nx[sel], ny[sel], np.zeros(n)]).ravel())
            if name == "lid":
                w.add_property("uw", data=np.full(n, U))
                w.add_property("vw", data=np.zeros(n))
            arrays.append(w)
        return arrays

    def create_scheme(self):
        o = self.options
        common = dict(dim=2, rho0=RHO0, c0=self.c0, nu=self.nu, h=self.h, dx=self.dx, umax=U,
                      walls=["wall", "lid"], moving_walls=["lid"])
        if o.scheme == "edac":
            pst = EDAC_SHIFTING[o.shifting or "spst"]
            return EDACScheme(["fluid"], pst=pst, bql=o.bql, **common)
        if o.scheme == "gtvf":
            return GTVFScheme(["fluid"], shifting=o.shifting or "gtvf", density="summation", **common)
        corrections = ("continuity",) if o.no_corrections else ("edac", "stress", "divergence", "continuity")
        return CTVFScheme(["fluid"], shifting=o.shifting or "spst", corrections=corrections, bql=o.bql, **common)

    def history_meta(self):
        return {"dx": self.dx, "re": self.re, "nx": self.nx, "nu": self.nu, "c0": self.c0,
                "scheme": self.options.scheme, "ghia_y": list(map(float, self.ys)),
                "ghia_x": list(map(float, self.xs))}

    # ------------------------------------------------------------ samples
    def post_step(self, solver):
        # half a step of slack: t accumulates round-off (44000 steps of dt end at 10 - 1e-11)
        if solver.t >= self._next_record - 0.5 * solver.dt or solver.t >= solver.tf - 0.5 * solver.dt:
            self.history.append(self.history_row(self.scene.by_name["fluid"], solver.t))
            self._next_record = solver.t + self.options.record_every

    def history_row(self, f, t):
        u, v = centre_lines(f, self.scheme.kernel, self.ys, self.xs)
        speed2 = f.u ** 2 + f.v ** 2
        return [t, float(0.5 * np.sum(f.m * speed2)), float(np.sqrt(speed2.max())), int(self.outside(f).sum())] \
            + [float(a) for a in u] + [float(a) for a in v]

    @staticmethod
    def outside(f, tol=0.0):
        """Fluid particles that went through a wall (beyond the cavity by more than tol)."""
        return (f.x < -tol) | (f.x > L + tol) | (f.y < -tol) | (f.y > L + tol)

    # ------------------------------------------------------------ results
    def post_process(self, outdir):
        from sphgen.tools.probes import largest_empty_disc
        hist, rows = io.read_history(outdir)
        t, ke = rows[:, 0], rows[:, 1]
        ys, xs = np.array(hist["ghia_y"]), np.array(hist["ghia_x"])
        nu_, nv_ = ys.size, xs.size
        window = t >= t[-1] - self.options.average - 1e-12 if self.options.average > 0 else t >= t[-1]
        u = rows[window, 4:4 + nu_].mean(axis=0)
        v = rows[window, 4 + nu_:4 + nu_ + nv_].mean(axis=0)
        dx = hist["dx"]
        if self.scene is not None:
            f = self.scene.by_name["fluid"]
        else:
            f = io.load(io.output_files(outdir, self.name)[-1])["arrays"]["fluid"]
        inside = ~self.outside(f)
        void = largest_empty_disc((f.x[inside], f.y[inside]), (0.0, L, 0.0, L)) / dx
        results = {"t": float(t[-1]), "nx": hist["nx"], "re": hist["re"], "scheme": hist["scheme"],
                   "averaged_over": [float(t[window][0]), float(t[-1])], "n_samples_averaged": int(window.sum()),
                   "y": ys.tolist(), "u": u.tolist(), "x": xs.tolist(), "v": v.tolist(),
                   "kinetic_energy": float(ke[-1]), "max_speed": float(rows[-1, 2]),
                   "n_outside_max": int(rows[:, 3].max()), "n_outside_final": int(np.sum(self.outside(f))),
                   "largest_empty_disc_over_dx": float(void)}
        i0 = int(np.searchsorted(t, t[-1] - 1.0 - 1e-12))
        results["kinetic_energy_change_last_unit"] = float((ke[-1] - ke[i0]) / ke[-1]) if ke[-1] > 0 else None
        re = hist["re"]
        if re in GHIA:
            g = GHIA[re]
            keep = compared_points(ys, dx)
            du, dv = np.abs(u - g["u"])[keep], np.abs(v - g["v"])
            results.update({"ghia_re": re, "n_points_u": int(keep.sum()), "n_points_v": int(nv_),
                            "max_dev_u": float(du.max()), "max_dev_v": float(dv.max()),
                            "max_dev": float(max(du.max(), dv.max())),
                            "rms_dev": float(np.sqrt(np.mean(np.concatenate([du, dv]) ** 2))),
                            "y_max_dev_u": float(ys[keep][np.argmax(du)]), "x_max_dev_v": float(xs[np.argmax(dv)])})
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, ys, u, xs, v, re, f"sphgen {hist['scheme'].upper()} {hist['nx']}x{hist['nx']}")
        dev = (f"max |u - Ghia| {results['max_dev_u']:.4f}, max |v - Ghia| {results['max_dev_v']:.4f}"
               if "max_dev" in results else "no Ghia data at this Re")
        print(f"cavity: t={results['t']:.4g}  Re={re:g}  {dev}; largest empty disc {void:.2f} dx; "
              f"outside {results['n_outside_final']}\nresults: {os.path.join(outdir, 'results.json')}\n"
              f"figure:  {os.path.join(outdir, 'profiles.png')}")
        return results

    @staticmethod
    def plot(outdir, ys, u, xs, v, re, label):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4.5))
        a.plot(u, ys, "r.-", label=label)
        b.plot(xs, v, "r.-", label=label)
        if re in GHIA:
            a.plot(GHIA[re]["u"], GHIA[re]["y"], "ko", mfc="none", label="Ghia et al. (1982)")
            b.plot(GHIA[re]["x"], GHIA[re]["v"], "ko", mfc="none", label="Ghia et al. (1982)")
        a.set_xlabel("u on x = 0.5")
        a.set_ylabel("y")
        b.set_xlabel("x")
        b.set_ylabel("v on y = 0.5")
        for ax in (a, b):
            ax.legend()
            ax.grid(alpha=0.3)
        fig.suptitle(f"Lid-driven cavity, Re = {re:g}")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "profiles.png"), dpi=100)
        plt.close(fig)
