"""Lid-driven cavity with SHTC-SPH in its fluid regime (Kincl, Peshkov, Pavelka & Klika (2023),
section 4.4; Kincl's thesis (2023), section 2.7), against Ghia, Ghia & Shin (1982).

Fluid in (0, 1)^2 on the isometric lattice fitted to the box (``filling_lattice``; dr =
1/``--nx``; paper: 1/200 at Re = 100),
DPRZ with rho0 = 1, c0 = cs = 20, nu = 1/Re, tau = 6 nu/cs^2 (eq. 29), c_p = 0.  Left,
right and bottom walls: ceil(2h/dr) = 3 layers of dummy particles at rest that carry their
own state and run the scheme's equations (with the corner blocks, also the two above the side
walls); the lid is the same kind of layer above y = 1 over 0 < x < 1 (``lid_mask``),
made of immobile particles whose prescribed velocity (1, 0), ramped linearly over
t = 0.4 (the ramp is not stated in the papers; the authors' code ramps linearly over
0.4), enters only the velocity gradient L; by default (``--wall-velocity extrapolated``) walls and lid
show, in L, 2 v_w minus the fluid's Shepard mean around them (Adami et al. 2012);
``--wall-velocity prescribed`` is the paper's text (they show v_w itself, which slips by about
1.2 dr; the choice is argued in docs/shtc.md).  dt from eq. 26 unless ``--dt`` (paper: 1.5e-5).

``results.json``: u on x = 0.5 and v on y = 0.5 at Ghia's points (Shepard interpolation
over fluid and walls) at the final time, and the largest deviation from Ghia's values
over the points more than 2 dr from the lid (``ghia_error``); the same for the centre lines
averaged over the samples (every 0.1) with t >= ``--average-from`` (default: half the end
time; ``ghia_error_averaged``, with the range of the instantaneous values over that window,
``ghia_error_window``), a choice of this application documented in docs/shtc.md, since the
particle velocities under a probe fluctuate from sample to sample; ``ghia_error_interior``:
the instantaneous error over the points more than 2 dr from every wall; ``viscosity_factor``: the
effective viscosity of the step over nu (steady shear, linearised: 0.73 at the paper's dt/tau
= 0.1, 1 at dt/tau = 1/3; see SHTCScheme's viscosity_factor).  Plots: centrelines.png,
speed.png (the velocity field), Axy.png (the distortion field).
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import layers_for_support, wall_layers_box
from sphgen.particles import ParticleArray
from sphgen.tools.probes import _prop as get, shepard
from sphgen.tools.reference import GHIA_RE, ghia_1982

from ..schemes.shtc import SHTCScheme, viscosity_factor
from ._perturbation import add_perturbation_options, check_perturbation, perturbed

RHO0, C0, CS, ULID, T_RAMP = 1.0, 20.0, 20.0, 1.0, 0.4
HDR = 1.5


def lid_motion(t_ramp=T_RAMP, speed=ULID):
    """The lid's prescribed velocity: linear ramp from 0 to ``speed`` over ``t_ramp``."""
    def motion(t, pa):
        return {"u": speed * min(t / t_ramp, 1.0)}
    return motion


def lid_mask(x, y):
    """The lid among the box's wall particles: the layers above y = 1 over 0 < x < 1 only, the
    moving surface of [P] sec. 4.4 (v_lid on the top boundary, v = 0 on the side walls).  The two
    corner blocks above the side walls stay with the walls at rest: as lid particles they widened
    the lid by ceil(2h/dr) dr on each side and drove a too-strong downflow along the right wall
    (docs/shtc.md, "The lid's corner particles")."""
    return (y > 1.0) & (x > 0.0) & (x < 1.0)


def add_wall_velocity_option(group, default="extrapolated"):
    """--wall-velocity: what the walls and the lid show in L (SHTCScheme's wall_velocity)."""
    group.add_argument("--wall-velocity", choices=("prescribed", "extrapolated"), default=default,
                       help="the velocity walls and lid show in L: their own (the paper) or 2 v_w minus "
                       "the Shepard mean of the fluid's around them (Adami et al. 2012) (default %(default)s)")


def all_columns(arrays):
    """Positions, h, m, rho and velocities of fluid and walls together (for Shepard probes)."""
    return {k: np.concatenate([get(pa, k) for pa in arrays.values()]) for k in ("x", "y", "h", "m", "rho", "u", "v")}


def filling_lattice(dr, side=1.0, width=None):
    """Isometric lattice that fills (0, width) x (0, side) (width = side unless given) with whole
    rows and columns: the paper's spacing
    (4/3)^(1/4) dr and rows (3/4)^(1/4) dr rounded so that round(side/spacing) points and rows
    fit exactly; rows at (j + 1/2) b, points at (i + 1/4) a or (i + 3/4) a in alternate rows.
    So the fluid stands half a row from the lid and the floor at every resolution (the plain
    ``hexagonal_lattice`` of the box left 1.38 dr under the lid at dr = 1/40)."""
    nr = max(int(round(side / (0.75 ** 0.25 * dr))), 1)
    width = side if width is None else width
    nc = max(int(round(width / ((4.0 / 3.0) ** 0.25 * dr))), 1)
    b, a = side / nr, width / nc
    j, i = np.meshgrid(np.arange(nr), np.arange(nc), indexing="ij")
    return ((i + 0.25 + 0.5 * (j % 2)) * a).ravel(), ((j + 0.5) * b).ravel()


class SHTCCavity(Application):
    """Lid-driven cavity, SHTC-SPH fluid (tau = 6 nu/cs^2), dummy walls, Ghia et al. (1982)."""

    tf = 20.0
    pfreq = 20000
    dim = 2
    history_columns = ("t", "kinetic_energy", "ghia_error")
    error_key = "ghia_error"
    sample_interval = 0.1

    def add_user_options(self, group):
        group.add_argument("--nx", type=int, default=200, help="particles per side: dr = 1/nx (paper: 200 at Re 100)")
        group.add_argument("--re", type=int, default=100, choices=GHIA_RE, help="Reynolds number (default %(default)s)")
        add_wall_velocity_option(group)
        group.add_argument("--average-from", type=float, default=None,
                           help="average the centre lines over the samples with t >= this (default: tf/2)")
        group.add_argument("--cs", type=float, default=CS, help="shear sound speed (paper: 20)")
        add_perturbation_options(group)

    def consume_user_options(self, o):
        if o.nx < 8:
            raise InputError(f"--nx must be at least 8, got {o.nx}")
        if not (math.isfinite(o.cs) and o.cs > 0):
            raise InputError(f"--cs must be positive, got {o.cs}")
        if o.average_from is not None and not (math.isfinite(o.average_from) and o.average_from >= 0):
            raise InputError(f"--average-from must be a non-negative number, got {o.average_from}")
        check_perturbation(o)
        self.dr = 1.0 / o.nx
        self.nu = ULID / o.re
        self.tau = 6.0 * self.nu / o.cs ** 2
        self.ghia = ghia_1982(o.re)
        self.t_average = 0.5 * o.tf if o.average_from is None else o.average_from
        self.window = []       # (t, u, v) at the samples with t >= t_average

    def create_particles(self):
        dr, h = self.dr, HDR * self.dr
        x, y = perturbed(filling_lattice(dr), dr, self.options)
        xw, yw, _, _ = wall_layers_box(0.0, 1.0, 0.0, 1.0, dr, layers_for_support(2.0, HDR), open_top=False)
        top = lid_mask(xw, yw)

        def array(name, px, py):
            n = px.size
            return ParticleArray(name, x=px, y=py, u=np.zeros(n), v=np.zeros(n), m=np.full(n, RHO0 * dr * dr),
                                 h=np.full(n, h), rho=np.full(n, RHO0))
        return [array("fluid", x, y), array("wall", xw[~top], yw[~top]), array("lid", xw[top], yw[top])]

    def create_scheme(self):
        return SHTCScheme(["fluid"], 2, rho0=RHO0, c0=C0, cs=self.options.cs, h=HDR * self.dr, dr=self.dr,
                          tau=self.tau, model="dprz", cp=0.0, walls=["wall", "lid"], moving_walls=["lid"],
                          motions={"lid": lid_motion()},
                          wall_velocity=self.options.wall_velocity)

    def post_step(self, solver):
        every = max(1, int(round(self.sample_interval / solver.dt)))
        if solver.step % every == 0 or solver.t >= solver.tf - 1e-12 * max(1.0, solver.tf):
            arrays = {pa.name: pa for pa in self.scene.arrays}
            f = arrays["fluid"]
            u, v, err = self.centrelines(arrays, self.scheme.kernel)
            self.history.append([solver.t, float(0.5 * np.sum(f.m * (f.u ** 2 + f.v ** 2))), err])
            if solver.t >= self.t_average - 1e-9 * max(1.0, solver.tf):
                self.window.append((solver.t, u, v))

    def centrelines(self, arrays, kernel):
        """(u at Ghia's y on x = 0.5, v at Ghia's x on y = 0.5, largest deviation from Ghia
        over the points more than 2 dr from the lid)."""
        cols = all_columns(arrays)
        g = self.ghia
        part = (cols["x"], cols["y"], cols["h"], cols["m"], cols["rho"])
        u = shepard((np.full(g["y"].size, 0.5), g["y"]), *part, cols["u"], kernel)
        v = shepard((g["x"], np.full(g["x"].size, 0.5)), *part, cols["v"], kernel)
        return u, v, self.deviation(u, v)

    def deviation(self, u, v, margin_walls=False):
        """Largest |u - u_Ghia|, |v - v_Ghia| over the points more than 2 dr from the lid (and,
        with ``margin_walls``, more than 2 dr from the other walls too)."""
        g, m = self.ghia, 2.0 * self.dr
        ku = g["y"] < 1.0 - m
        kv = np.ones(g["x"].size, bool)
        if margin_walls:
            ku &= g["y"] > m
            kv = (g["x"] > m) & (g["x"] < 1.0 - m)
        return float(max(np.abs(u - g["u"])[ku].max(), np.abs(v - g["v"])[kv].max()))

    def history_meta(self):
        o = self.options
        return {"nx": o.nx, "re": o.re, "nu": self.nu, "tau": self.tau, "dr": self.dr}

    def post_process(self, outdir):
        """results.json, centrelines.png, speed.png and Axy.png."""
        if self.solver is not None:
            arrays, t, kernel = {pa.name: pa for pa in self.scene.arrays}, self.solver.t, self.scheme.kernel
        else:
            last = io.load(io.output_files(outdir, self.name)[-1])
            arrays, t = last["arrays"], last["solver_data"]["t"]
            from sphgen.kernels import get_kernel
            kernel = get_kernel("wendland", 2)
        u, v, err = self.centrelines(arrays, kernel)
        g = self.ghia
        results = {"t": float(t), "re": self.options.re, "nx": self.options.nx, "dr": self.dr, "tau": self.tau,
                   "dt_over_tau": float(self.solver.dt / self.tau) if self.solver is not None else None,
                   "viscosity_factor": (viscosity_factor(self.solver.dt / self.tau)
                                        if self.solver is not None else None),
                   "ghia_error": err, "u_centre": u.tolist(), "v_centre": v.tolist(),
                   "ghia_error_interior": self.deviation(u, v, margin_walls=True),
                   "max_density_error": float(np.abs(np.asarray(get(arrays["fluid"], "rho")) / RHO0 - 1.0).max()),
                   "kinetic_energy": float(0.5 * np.sum(get(arrays["fluid"], "m") * (get(arrays["fluid"], "u") ** 2
                                                                                     + get(arrays["fluid"], "v") ** 2))),
                   "ghia_y": g["y"].tolist(), "ghia_u": g["u"].tolist(),
                   "ghia_x": g["x"].tolist(), "ghia_v": g["v"].tolist()}
        results.update(self.window_results())
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, arrays, kernel, t)
        avg = results.get("ghia_error_averaged")
        print(f"shtc_cavity: t={t:.4g}  Re={self.options.re}  max |deviation from Ghia et al. (1982)| = {err:.4f}"
              + (f"; centre lines averaged over {results['averaged_from']:.3g} <= t <= {t:.3g} "
                 f"({results['n_averaged']} samples): {avg:.4f}" if avg is not None else "")
              + f"\nresults: {os.path.join(outdir, 'results.json')}")
        return results

    def window_results(self):
        """The centre lines averaged over the samples with t >= t_average and their deviation
        from Ghia; the range of the instantaneous deviation over the same samples."""
        if not self.window:
            return {}
        u = np.mean([w[1] for w in self.window], axis=0)
        v = np.mean([w[2] for w in self.window], axis=0)
        inst = [self.deviation(w[1], w[2]) for w in self.window]
        return {"averaged_from": float(self.window[0][0]), "n_averaged": len(self.window),
                "ghia_error_averaged": self.deviation(u, v),
                "ghia_error_averaged_interior": self.deviation(u, v, margin_walls=True),
                "ghia_error_window": [float(min(inst)), float(max(inst))],
                "u_centre_averaged": u.tolist(), "v_centre_averaged": v.tolist()}

    def plot(self, outdir, arrays, kernel, t):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        g = self.ghia

        cols = all_columns(arrays)
        part = (cols["x"], cols["y"], cols["h"], cols["m"], cols["rho"])
        s = np.linspace(0.0, 1.0, 101)
        u = shepard((np.full(s.size, 0.5), s), *part, cols["u"], kernel)
        v = shepard((s, np.full(s.size, 0.5)), *part, cols["v"], kernel)
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
        win = self.window_results()
        if win:
            a.plot(win["u_centre_averaged"], g["y"], "b^", ms=4, label=f"mean over t >= {win['averaged_from']:.3g}")
            b.plot(g["x"], win["v_centre_averaged"], "b^", ms=4, label=f"mean over t >= {win['averaged_from']:.3g}")
        a.plot(u, s, "r-", label="SHTC-SPH")
        a.plot(g["u"], g["y"], "ks", mfc="none", label="Ghia et al. (1982)")
        a.set_xlabel("$v_x$ on x = 0.5")
        a.set_ylabel("y")
        a.legend()
        b.plot(s, v, "r-", label="SHTC-SPH")
        b.plot(g["x"], g["v"], "ks", mfc="none", label="Ghia et al. (1982)")
        b.set_xlabel("x")
        b.set_ylabel("$v_y$ on y = 0.5")
        b.legend()
        fig.suptitle(f"Re = {self.options.re}, t = {t:.3g}")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "centrelines.png"), dpi=100)
        plt.close(fig)
        f = arrays["fluid"]
        for name, val, cmap in (("speed", np.hypot(get(f, "u"), get(f, "v")), "viridis"),
                                ("Axy", get(f, "A").reshape(-1, 9)[:, 1], "RdBu_r")):
            fig, ax = plt.subplots(figsize=(5.5, 4.5))
            sc = ax.scatter(get(f, "x"), get(f, "y"), c=val, s=1, cmap=cmap)
            fig.colorbar(sc, ax=ax, label=name)
            ax.set_aspect("equal")
            fig.tight_layout()
            fig.savefig(os.path.join(outdir, f"{name}.png"), dpi=100)
            plt.close(fig)
