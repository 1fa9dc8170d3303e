"""Uniaxial compression of a sandstone bar (Das & Cleary 2015; Adepu & Ramachandran 2021, section 4.5).

A 82 x 140 mm specimen (E = 7.5 GPa, Poisson ratio 0.398, rho0 = 2300 kg/m^3, c0 = 2303
m/s) on a fixed base, compressed by a piston moving down at 1.5 mm/s; alpha = 1, h = dx,
square lattice, ``--dx`` 0.5, 1 or 2 mm (paper), CTVF + SPST (``--scheme gtvf`` for the
GTVF row of Fig. 23).  The base and the piston are ``--layers`` (3: the quintic support)
rows of the specimen's material below and above it, held at zero velocity and at the
piston's velocity by the integrator (the scheme's ``clamped`` and ``driven``); they keep
their own stress and pressure equations, so the specimen is glued to both (the paper does
not describe its contact, docs/ctvf.md).

``results.json``: the von Mises stress (eq. 68, with the principal stresses of the full
in-plane stress -p I + sigma', eqs. 69-70) at point A, the particle nearest the
specimen's centre, against time (``history.json``), and against the uniaxial plane-strain
estimate E V t / ((1 - nu^2) H) of a bar with free sides (the published curves of Das &
Cleary are not shipped: docs/ctvf.md).  Plots: von_mises.png, specimen.png (the final
state coloured by the von Mises stress).
"""
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import rectangle
from sphgen.particles import ParticleArray
from sphgen.tools.plots import particle_panels
from sphgen.tools.probes import MaterialPoints

from ..schemes.ctvf import SOLID_CORRECTIONS, CTVFSolidScheme, elastic_constants
from ..schemes.gtvf import GTVFSolidScheme
from ._solid_options import add_solid_scheme_options, check_solid_scheme_options

E, POISSON, RHO0 = 7.5e9, 0.398, 2300.0
WIDTH, HEIGHT, PISTON_SPEED = 0.082, 0.14, 1.5e-3


def von_mises(p, sd):
    """sqrt(s1^2 + s2^2 - s1 s2) of the in-plane principal stresses s1, s2 of sigma = -p I + sigma'
    (Adepu & Ramachandran 2021, eqs. 68-70; the square root of eqs. 69-70 holds
    ((sxx - syy)/2)^2 + sxy^2, the printed (sxx + syy)/2 would not give the principal
    stresses).  ``sd``: flat stride-9 deviatoric stress."""
    s = np.asarray(sd).reshape(-1, 9)
    sxx, syy, sxy = s[:, 0] - p, s[:, 4] - p, s[:, 1]
    mean, rad = 0.5 * (sxx + syy), np.sqrt((0.5 * (sxx - syy)) ** 2 + sxy ** 2)
    s1, s2 = mean + rad, mean - rad
    return np.sqrt(s1 * s1 + s2 * s2 - s1 * s2)


class UniaxialCompression(Application):
    """Sandstone bar between a fixed base and a moving piston: CTVF (default) or GTVF."""

    tf = 0.002
    pfreq = 5000
    dim = 2
    history_columns = ("t", "von_mises_A", "von_mises_estimate", "piston_y", "kinetic_energy")
    error_key = None

    def add_user_options(self, group):
        add_solid_scheme_options(group)
        group.add_argument("--dx", type=float, default=0.002, help="particle spacing (paper: 0.5, 1, 2 mm)")
        group.add_argument("--layers", type=int, default=3, help="rows of the base and of the piston")
        group.add_argument("--record-every", type=float, default=2e-5, help="time between samples (s)")

    def consume_user_options(self, o):
        self.shifting = check_solid_scheme_options(o, ("dx", "record_every"))
        if o.dx > WIDTH / 8:
            raise InputError(f"--dx {o.dx} leaves fewer than 8 particles across the specimen")
        if o.layers < 1:
            raise InputError(f"--layers must be at least 1, got {o.layers}")
        self.c0, self.G = elastic_constants(E, POISSON, RHO0)
        self._next_record = 0.0

    def create_particles(self):
        o, dx = self.options, self.options.dx
        x, y = rectangle(0.0, WIDTH, -o.layers * dx, HEIGHT + o.layers * dx, dx)
        n = x.size
        self.base = np.flatnonzero(y < 0)
        self.piston = np.flatnonzero(y > HEIGHT)
        pa = ParticleArray("solid", x=x, y=y, v=np.where(y > HEIGHT, -PISTON_SPEED, 0.0), rho=np.full(n, RHO0),
                           m=np.full(n, RHO0 * dx * dx), h=np.full(n, dx))
        self.a_gid = int(np.argmin((x - 0.5 * WIDTH) ** 2 + (y - 0.5 * HEIGHT) ** 2))   # gids: creation order
        self.piston_top = MaterialPoints("solid", gids=[int(self.piston[np.argmax(y[self.piston])])])
        self.y_top0 = float(y[self.piston].max())
        return [pa]

    def create_scheme(self):
        o = self.options
        common = dict(h=o.dx, dx=o.dx, umax=PISTON_SPEED, shifting=self.shifting, alpha=o.alpha,
                      clamped={"solid": self.base}, driven={"solid": (self.piston, (0.0, -PISTON_SPEED))})
        if o.scheme == "gtvf":
            return GTVFSolidScheme(["solid"], 2, RHO0, E, POISSON, **common)
        corrections = () if o.no_corrections else SOLID_CORRECTIONS
        return CTVFSolidScheme(["solid"], 2, RHO0, E, POISSON, corrections=corrections, **common)

    def history_meta(self):
        o = self.options
        return {"dx": o.dx, "scheme": o.scheme, "shifting": self.shifting, "c0": self.c0,
                "n_particles": int(self.scene.by_name["solid"].n), "corrections": not o.no_corrections,
                "layers": o.layers}

    @staticmethod
    def estimate(t):
        """E V t / ((1 - nu^2) H): von Mises (= |sigma_yy|) of a plane-strain bar with free sides
        under the uniform strain V t / H."""
        return E * PISTON_SPEED * t / ((1.0 - POISSON ** 2) * HEIGHT)

    def row(self, pa, t):
        a = int(np.flatnonzero(pa.gid == self.a_gid)[0])
        vm = float(von_mises(pa.p[a:a + 1], pa.sd[9 * a:9 * a + 9])[0])
        top = float(self.piston_top.positions({"solid": pa})[0, 1])
        ke = float(0.5 * np.sum(pa.m * (pa.u ** 2 + pa.v ** 2)))
        return [t, vm, self.estimate(t), top - self.y_top0, ke]

    def post_step(self, solver):
        pa = self.scene.by_name["solid"]
        if not self.history:
            self.history.append(self.row(pa, 0.0))
        if solver.t >= self._next_record - 0.5 * solver.dt or solver.t >= solver.tf - 0.5 * solver.dt:
            self.history.append(self.row(pa, solver.t))
            self._next_record = solver.t + self.options.record_every

    def post_process(self, outdir):
        hist, rows = io.read_history(outdir)
        t, vm, est, top = rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3]
        late = t >= 0.5 * t[-1]
        # the wave reflections oscillate about the ramp: compare the slopes over the second
        # half (None for a run too short to have two distinct samples there)
        slope = (float(np.polyfit(t[late], vm[late], 1)[0] / (E * PISTON_SPEED / ((1 - POISSON ** 2) * HEIGHT))
                       ) if np.unique(t[late]).size >= 2 else None)
        results = {
            "t": float(t[-1]), "reached_end": bool(t[-1] >= self.options.tf * (1 - 1e-6)),
            "scheme": hist["scheme"], "shifting": hist["shifting"], "dx": hist["dx"],
            "n_particles": hist["n_particles"], "finite": bool(np.all(np.isfinite(rows))),
            "von_mises_A_final": float(vm[-1]), "von_mises_estimate_final": float(est[-1]),
            "von_mises_slope_over_estimate": slope,
            "piston_displacement": float(top[-1]), "piston_displacement_expected": float(-PISTON_SPEED * t[-1]),
        }
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, rows, hist)
        print(f"uniaxial_compression: {hist['scheme']}+{hist['shifting']} dx={hist['dx']} t={t[-1]:.4g}  "
              f"von Mises at A {vm[-1]:.4g} Pa (plane-strain estimate {est[-1]:.4g}); slope over the second half "
              f"/ estimate {'n/a' if slope is None else format(slope, '.3f')}\n"
              f"results: {os.path.join(outdir, 'results.json')}")
        return results

    def plot(self, outdir, rows, hist):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = rows[:, 0] * 1e3
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(t, rows[:, 1] / 1e3, "r-", label=f"sphgen {hist['scheme'].upper()} + {hist['shifting'].upper()}, "
                f"dx = {hist['dx'] * 1e3:g} mm")
        ax.plot(t, rows[:, 2] / 1e3, "k--", label="E V t / ((1 - nu^2) H)")
        ax.set_xlabel("t [ms]")
        ax.set_ylabel("von Mises stress at A [kPa]")
        ax.set_title("Das & Cleary (2015) curves not shipped: not plotted", fontsize=8)
        ax.legend(fontsize=8)
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "von_mises.png"), dpi=100)
        plt.close(fig)
        if self.scene is not None:
            pa = self.scene.by_name["solid"]
            particle_panels(os.path.join(outdir, "specimen.png"),
                            [(f"von Mises [Pa], t = {rows[-1, 0] * 1e3:.3g} ms", pa.x, pa.y, von_mises(pa.p, pa.sd))],
                            size=(4.0, 6.0), marker=4)
