"""Twisting column: a large elastic deformation in 3D with SHTC-SPH (Kincl, Peshkov, Pavelka &
Klika (2023), section 4.2, after Haider et al. (2018)).

A column (-W/2, W/2)^2 x (0, H), W = 1 m, H = 6 m, neo-Hookean shear energy (eq. 17) with
tau = infinity, rho0 = 1100 kg/m^3, Young's modulus Y = 17 MPa, Poisson's ratio 0.495,
starts undeformed (A = I) with v = omega sin(pi z/(2H)) (y, -x, 0), omega = 105 1/s (eq. 27).
Material: rho0 c0^2 = nu Y/((1 + nu)(1 - 2 nu)) (the Lame constant; c0 = 715.3 m/s) and
rho0 cs^2 = Y/(2 (1 + nu)) (the shear modulus; cs = 71.89 m/s, the paper's Table 1; its text
prints Y/(1 + nu), which would give 101.7 m/s: docs/shtc.md).  Particles on the BCC lattice of
cube edge W/``--n`` (paper: 16, dr = edge/2^(1/3) = 0.0496, 49152 particles), h = 1.5 dr,
dt from eq. 26, tensile penalty c_p = ``--cp-factor`` c0 (paper: 10).  The base (the paper's
Dirichlet condition) is a layer of the same lattice below z = 0, at least 2h deep, made of
dummy particles at rest that run the scheme's equations (a wall of SHTCScheme).

``results.json``: z(t)/H of the material point initially nearest to (0, 0, H) (z0 = H - a/4
on this lattice), its lowest value before the rotation reverses and the rise after it
("bounce"), the first sign change of the mean angular
velocity of the top layer (the rotation reversing), the largest relative drift of the
column's total energy (kinetic + bulk + shear + penalty, eqs. 13, 17, 19), the smallest
det A.  Plots: ztop.png ([P] Fig. 7), energy.png (Fig. 6), pressure.png (Fig. 5: side
views coloured by p at the stored output times).
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import bcc_lattice, layers_for_support
from sphgen.particles import ParticleArray
from sphgen.tools.probes import _prop

from ..schemes.shtc import SHTCScheme
from ._solid_plots import plot_energy, plot_track
from ._perturbation import add_perturbation_options, check_perturbation, perturbed

W, H = 1.0, 6.0
RHO0, YOUNG, POISSON, OMEGA = 1100.0, 17e6, 0.495, 105.0
HDR = 1.5
TOP_LAYER = 0.05
"""The top layer whose mean angular velocity is followed: z > (1 - TOP_LAYER) H at t = 0."""


def sound_speeds(young=YOUNG, poisson=POISSON, rho0=RHO0):
    """(c0, cs): rho0 c0^2 = Lame's lambda, rho0 cs^2 = the shear modulus Y/(2(1 + nu))
    (Kincl et al. (2023), sec. 4.2 and Table 1; the text's Y/(1 + nu) is twice the modulus)."""
    lam = poisson * young / ((1.0 + poisson) * (1.0 - 2.0 * poisson))
    mu = young / (2.0 * (1.0 + poisson))
    return math.sqrt(lam / rho0), math.sqrt(mu / rho0)


def twist_velocity(x, y, z, omega=OMEGA, height=H):
    """v = omega sin(pi z/(2H)) (y, -x, 0) (Kincl et al. (2023), after eq. 27)."""
    s = omega * np.sin(np.pi * z / (2.0 * height))
    return s * y, -s * x, np.zeros_like(z)


def column_and_base(n, base_depth):
    """BCC points of the column (edge W/n) and of the base below z = 0: whole cubes, at least
    ``base_depth`` deep, on the same lattice (so the two join without a gap)."""
    a = W / n
    dr = a / 2.0 ** (1.0 / 3.0)
    k = int(math.ceil(base_depth / a - 1e-9))
    x, y, z = bcc_lattice(dr, -W / 2, W / 2, -W / 2, W / 2, -k * a, H)
    top = z > 0
    return (x[top], y[top], z[top]), (x[~top], y[~top], z[~top]), dr


class TwistingColumn(Application):
    """Twisting column (3D, neo-Hookean, tau = infinity, clamped base)."""

    tf = 0.2
    pfreq = 5000
    dim = 3
    history_columns = ("t", "z_top", "omega_top", "kinetic", "bulk", "shear", "penalty", "total", "detA_min")
    error_key = "energy_error"

    def add_user_options(self, group):
        group.add_argument("--n", type=int, default=16, help="BCC cubes across W (paper: 16)")
        group.add_argument("--cp-factor", type=float, default=10.0,
                           help="tensile penalty c_p / c0 (paper: 10; 0 switches it off)")
        group.add_argument("--samples", type=int, default=400, help="history samples over the run (default %(default)s)")
        add_perturbation_options(group)

    def consume_user_options(self, o):
        if o.n < 2:
            raise InputError(f"--n must be at least 2, got {o.n}")
        if not (math.isfinite(o.cp_factor) and o.cp_factor >= 0):
            raise InputError(f"--cp-factor must be a non-negative number, got {o.cp_factor}")
        if o.samples < 10:
            raise InputError(f"--samples must be at least 10, got {o.samples}")
        check_perturbation(o)
        self.c0, self.cs = sound_speeds()
        self.dr = W / o.n / 2.0 ** (1.0 / 3.0)

    def create_particles(self):
        h = HDR * self.dr
        col, base, _ = column_and_base(self.options.n, layers_for_support(2.0, HDR) * self.dr)
        self.top_gid = int(np.argmin(col[0] ** 2 + col[1] ** 2 + (col[2] - H) ** 2))
        self.z0 = col[2]
        x, y, z = perturbed(col, self.dr, self.options)
        u, v, w = twist_velocity(x, y, z)

        def array(name, px, py, pz, pu, pv, pw):
            n = px.size
            return ParticleArray(name, x=px, y=py, z=pz, u=pu, v=pv, w=pw, m=np.full(n, RHO0 * self.dr ** 3),
                                 h=np.full(n, h), rho=np.full(n, RHO0))
        zero = np.zeros(base[0].size)
        return [array("column", x, y, z, u, v, w), array("base", *base, zero, zero, zero)]

    def create_scheme(self):
        return SHTCScheme(["column"], 3, rho0=RHO0, c0=self.c0, cs=self.cs, h=HDR * self.dr, dr=self.dr,
                          tau=math.inf, model="neo-hookean", cp=self.options.cp_factor * self.c0,
                          walls=["base"])

    def post_step(self, solver):
        every = max(1, int(round(solver.tf / self.options.samples / solver.dt)))
        if not self.history:
            self.record(0.0)
        if solver.step % every == 0 or solver.t >= solver.tf - 1e-12 * solver.tf:
            self.record(solver.t)

    def record(self, t):
        """One history row; the first (t = 0) uses the initial velocities (the state before the
        first kick), with only kinetic energy since A = I, rho = rho0 and lambda = 0 there."""
        pa = self.scene.by_name["column"]
        top = self.z0[pa.gid] > (1.0 - TOP_LAYER) * H
        r2 = pa.x ** 2 + pa.y ** 2
        if t == 0.0:
            u, v, w = twist_velocity(pa.x, pa.y, pa.z)
            e = {"kinetic": 0.5 * float(np.sum(pa.m * (u * u + v * v + w * w))), "bulk": 0.0, "shear": 0.0, "penalty": 0.0}
            e["total"] = e["kinetic"]
        else:
            u, v = pa.u, pa.v
            e = self.scheme.energies(self.scene.arrays, include_walls=True)
        omega = float(np.sum((pa.x * v - pa.y * u)[top]) / np.sum(r2[top]))
        k = int(np.flatnonzero(pa.gid == self.top_gid)[0])
        det = np.linalg.det(pa.A.reshape(-1, 3, 3)).min()
        self.history.append([t, float(pa.z[k]), omega] + [e[c] for c in ("kinetic", "bulk", "shear", "penalty", "total")]
                            + [float(det)])

    def history_meta(self):
        o = self.options
        return {"n": o.n, "cp_factor": o.cp_factor, "dr": self.dr, "c0": self.c0, "cs": self.cs,
                "perturb": o.perturb, "seed": o.seed}

    def post_process(self, outdir):
        """results.json, ztop.png, energy.png and pressure.png from the run's files."""
        hist, rows = io.read_history(outdir)
        t, zt, om = rows[:, 0], rows[:, 1] / H, rows[:, 2]
        energies, det = rows[:, 3:8], rows[:, 8]
        drift = np.abs(energies[:, -1] / energies[0, -1] - 1.0)
        flip = np.flatnonzero(np.sign(om[1:]) != np.sign(om[:-1]))
        # the shrinking while the column twists: the lowest z before the rotation reverses
        i_min = int(np.argmin(zt[:flip[0] + 2])) if flip.size else None
        results = {
            "t": float(t[-1]), "n": hist["n"], "dr": hist["dr"], "c0": hist["c0"], "cs": hist["cs"],
            "cp_factor": hist["cp_factor"],
            "energy_error": float(drift.max()), "energy_error_final": float(drift[-1]),
            "energy_initial": float(energies[0, -1]),
            "z_top_min": float(zt.min()), "t_z_top_min": float(t[np.argmin(zt)]),
            "z_top_twisted_min": None if i_min is None else float(zt[i_min]),
            "t_z_top_twisted_min": None if i_min is None else float(t[i_min]),
            "bounce": None if i_min is None else float(zt[i_min:].max() - zt[i_min]),
            "z_top_final": float(zt[-1]),
            "t_rotation_reverses": float(t[flip[0] + 1]) if flip.size else None,
            "detA_min": float(det[1:].min()) if det.size > 1 else float(det[0]),
            "max_density_error": self._density_error(),
        }
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, t, zt, energies)
        print(f"twisting_column: t={t[-1]:.4g}  energy drift {results['energy_error']:.3g}  z_top/H min "
              f"{results['z_top_min']:.4f} at t={results['t_z_top_min']:.3g}  rotation reverses at "
              f"{results['t_rotation_reverses']}  min det A {results['detA_min']:.3g}\n"
              f"results: {os.path.join(outdir, 'results.json')}")
        return results

    def _density_error(self):
        if self.solver is None:
            return None
        pa = self.scene.by_name["column"]
        return float(np.abs(pa.rho / RHO0 - 1.0).max())

    def plot(self, outdir, t, zt, energies):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        plot_track(os.path.join(outdir, "ztop.png"), plt, t, zt, "z / H of the top point",
                   "(the finite-element curve of the paper is not available)")
        plot_energy(outdir, plt, t, energies)
        snaps = self._snapshots(outdir)
        fig, axes = plt.subplots(1, len(snaps), figsize=(2.2 * len(snaps) + 1, 6), squeeze=False)
        for ax, (ts, s) in zip(axes[0], snaps):
            sc = ax.scatter(s["x"], s["z"], c=s["p"], s=2, cmap="coolwarm")
            ax.set_aspect("equal")
            ax.set_title(f"t = {ts:.3g} s", fontsize=9)
            fig.colorbar(sc, ax=ax, shrink=0.6)
        fig.suptitle("pressure [Pa], side view (x, z)")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "pressure.png"), dpi=100)
        plt.close(fig)

    def _snapshots(self, outdir, most=4):
        """[(t, {x, z, p})] at up to ``most`` stored outputs (the final state if none)."""
        files = io.output_files(outdir, self.name)
        if len(files) > 1:
            pick = [files[int(round(i))] for i in np.linspace(1, len(files) - 1, min(most, len(files) - 1))]
            out = []
            for f in pick:
                d = io.load(f)
                out.append((d["solver_data"]["t"], {k: _prop(d["arrays"]["column"], k) for k in ("x", "z", "p")}))
            return out
        pa = self.scene.by_name["column"]
        return [(self.solver.t, {k: _prop(pa, k) for k in ("x", "z", "p")})]

