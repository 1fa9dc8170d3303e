"""Colliding rubber rings (Gray, Monaghan & Swift 2001; Adepu & Ramachandran 2021, section 4.6).

Two equal rings, inner radius 0.03 m, outer 0.04 m, centres at x = -/+0.041 m (2 mm gap),
E = 10 MPa, rho0 = 1200 kg/m^3, Poisson ratio ``--poisson`` (paper: 0.3975 and 0.47),
each moving toward the other at ``--v0`` c0 (0.059: the "0.12 c0" of the paper read as
the approach speed, as Gray et al. run it), Monaghan artificial viscosity alpha = 1,
h = dx (paper: dx = 1 mm), end time 0.016 s.  ``--scheme`` ctvf (default; ``--shifting``
spst or ipst) or gtvf.  Particles on the square lattice through each ring's centre,
r_in <= r < r_out (``--lattice vertex``; this is the lattice of PySPH's
``solid_mech.rings`` example, so ``--dx 0.0005`` gives 17 584 particles against that example's 17 592: its float grid
keeps 8 of the points that lie exactly on the outer circles by round-off, the integer
test here none) or on the
cell-centred lattice (``--lattice centred``, :func:`sphgen.geometry.annulus`).

Each ring is a body of its own (arrays ``left`` and ``right``): its SPH sums run over its
own particles, and the rings touch only through a contact force that pushes and never
pulls (:class:`~sphgen.equations.contact.ContactForce`, the scheme's ``contact``), so
they part freely after the rebound.  ``--one-body`` puts both rings in one array whose
sums run over both (PySPH's ``solid_mech.rings``): the contact then carries tension and
the rings stay joined.

``results.json``: whether the run reached the end, the largest speed over the run (a
blow-up shows as a speed of order c0), the energies (kinetic, elastic: s':s'/(4G) +
p^2/(2K) per unit volume) at the start and the end, the x velocity of each ring's centre
of mass at the end (reversed: the rings bounced), the gap between the rings (smallest
distance between a particle of one and one of the other, in dx) against time and at the
end, and the trajectory of the material points A (outer left) and B (outer top) of the
left ring.  The energy includes the contact springs' k (d0 - r)^2 / 2.  Plots: energy.png,
points.png (A and B against t), rings.png (the final state coloured by p).
"""
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import annulus, vertex_lattice
from sphgen.particles import ParticleArray
from sphgen.tools.plots import particle_panels
from sphgen.tools.probes import MaterialPoints

from ..equations.contact import contact_energy
from ..schemes.ctvf import SOLID_CORRECTIONS, CTVFSolidScheme, elastic_constants
from ..schemes.gtvf import GTVFSolidScheme
from ._solid_options import add_solid_scheme_options, check_solid_scheme_options

E, RHO0 = 1.0e7, 1200.0
R_IN, R_OUT, CENTRE = 0.03, 0.04, 0.041
LATTICES = ("vertex", "centred")


def ring_lattice(cx, dx, lattice):
    """One ring centred at (cx, 0) on the chosen lattice."""
    if lattice == "centred":
        return annulus(cx, 0.0, R_IN, R_OUT, dx)
    x, y = vertex_lattice(dx, -R_OUT, R_OUT, -R_OUT, R_OUT)
    r2 = (np.rint(x / dx) ** 2 + np.rint(y / dx) ** 2) * dx * dx     # exact on the circles
    keep = (r2 >= R_IN ** 2 * (1 - 1e-9)) & (r2 < R_OUT ** 2 * (1 - 1e-9))
    return x[keep] + cx, y[keep]


def energies(pa, G, K):
    """(kinetic, elastic): sum m |u|^2 / 2 and sum V (s':s' / (4G) + p^2 / (2K))."""
    kinetic = 0.5 * float(np.sum(pa.m * (pa.u ** 2 + pa.v ** 2)))
    s = pa.sd.reshape(-1, 9)
    vol = pa.m / pa.rho
    elastic = float(np.sum(vol * (np.sum(s * s, axis=1) / (4.0 * G) + pa.p ** 2 / (2.0 * K))))
    return kinetic, elastic


class Rings(Application):
    """Two elastic rings colliding head on: CTVF (SPST or IPST) or GTVF."""

    tf = 0.016
    pfreq = 1000
    dim = 2
    history_columns = ("t", "kinetic", "elastic", "max_speed", "xA", "yA", "xB", "yB", "u_left", "u_right",
                       "contact", "gap")
    bodies = ("left", "right")
    error_key = None

    def add_user_options(self, group):
        add_solid_scheme_options(group)
        group.add_argument("--poisson", type=float, default=0.3975, help="Poisson ratio (paper: 0.3975, 0.47)")
        group.add_argument("--v0", type=float, default=0.059, help="speed of each ring / c0 (default %(default)s)")
        group.add_argument("--dx", type=float, default=0.001, help="particle spacing (paper: 0.001 m)")
        group.add_argument("--hdx", type=float, default=1.0, help="h / dx (default %(default)s)")
        group.add_argument("--lattice", choices=LATTICES, default="vertex",
                           help="vertex: points centre + i dx (PySPH's rings); centred: cell centres")
        group.add_argument("--record-every", type=float, default=1e-4, help="time between samples (s)")
        group.add_argument("--one-body", action="store_true",
                           help="both rings in one array (the contact carries tension; PySPH's rings)")

    def consume_user_options(self, o):
        self.shifting = check_solid_scheme_options(o, ("dx", "hdx", "v0", "record_every"))
        if not 0 < o.poisson < 0.5:
            raise InputError(f"--poisson must be in (0, 0.5), got {o.poisson}")
        if o.dx > 0.005:
            raise InputError(f"--dx {o.dx} leaves fewer than 2 particles across the rings")
        self.c0, self.G = elastic_constants(E, o.poisson, RHO0)
        self.K = RHO0 * self.c0 ** 2
        self._next_record = 0.0

    def _array(self, name, x, y, sign):
        o, n = self.options, x.size
        return ParticleArray(name, x=x, y=y, u=np.full(n, sign * o.v0 * self.c0), rho=np.full(n, RHO0),
                             m=np.full(n, RHO0 * o.dx * o.dx), h=np.full(n, o.hdx * o.dx))

    def create_particles(self):
        o, dx = self.options, self.options.dx
        xl, yl = ring_lattice(-CENTRE, dx, o.lattice)
        xr, yr = ring_lattice(CENTRE, dx, o.lattice)
        near = [int(np.argmin((xl - px) ** 2 + (yl - py) ** 2)) for px, py in ((-CENTRE - R_OUT, 0.0), (-CENTRE, R_OUT))]
        if o.one_body:
            self.media = ["rings"]
            self.n_left = xl.size
            arrays = [self._array("rings", np.concatenate([xl, xr]), np.concatenate([yl, yr]), 1.0)]
            arrays[0].u[xl.size:] *= -1.0
        else:
            self.media = list(self.bodies)
            arrays = [self._array("left", xl, yl, 1.0), self._array("right", xr, yr, -1.0)]
        self.points = MaterialPoints(self.media[0], gids=near)     # A (outer left), B (outer top)
        return arrays

    def create_scheme(self):
        o = self.options
        common = dict(h=o.hdx * o.dx, dx=o.dx, umax=o.v0 * self.c0, shifting=self.shifting, alpha=o.alpha,
                      contact=not o.one_body)
        media = ["rings"] if o.one_body else list(self.bodies)
        if o.scheme == "gtvf":
            return GTVFSolidScheme(media, 2, RHO0, E, o.poisson, **common)
        corrections = () if o.no_corrections else SOLID_CORRECTIONS
        return CTVFSolidScheme(media, 2, RHO0, E, o.poisson, corrections=corrections, **common)

    def history_meta(self):
        o = self.options
        return {"dx": o.dx, "scheme": o.scheme, "shifting": self.shifting, "poisson": o.poisson, "v0": o.v0,
                "c0": self.c0, "G": self.G, "K": self.K,
                "n_particles": int(sum(self.scene.by_name[m].n for m in self.media)),
                "lattice": o.lattice, "corrections": not o.no_corrections, "contact": not o.one_body,
                "contact_stiffness": self.contact_k()}

    def contact_k(self):
        return None if self.options.one_body else self.scheme.contact_stiffness()

    def bodies_of(self, arrays):
        """[(x, y, u, v, m) of the left ring, ... of the right ring] from the arrays."""
        props = ("x", "y", "u", "v", "m")
        if not self.options.one_body:
            return [tuple(getattr(arrays[b], p) for p in props) for b in self.bodies]
        pa = arrays["rings"]
        left = pa.gid < self.n_left
        return [tuple(getattr(pa, p)[sel] for p in props) for sel in (left, ~left)]

    def row(self, arrays, t):
        kinetic = elastic = 0.0
        for m in self.media:
            k, e = energies(arrays[m], self.G, self.K)
            kinetic, elastic = kinetic + k, elastic + e
        (xa, ya), (xb, yb) = self.points.positions(arrays)
        (xl, yl, ul, vl, ml), (xr, yr, ur, vr, mr) = self.bodies_of(arrays)
        k = self.contact_k()
        spring, gap = contact_energy(np.column_stack([xl, yl]), np.column_stack([xr, yr]), k or 0.0,
                                     self.options.dx)
        vmax = max(float(np.sqrt((arrays[m].u ** 2 + arrays[m].v ** 2).max())) for m in self.media)
        return [t, kinetic, elastic, vmax, float(xa), float(ya), float(xb), float(yb),
                float(np.sum(ml * ul) / np.sum(ml)), float(np.sum(mr * ur) / np.sum(mr)), spring,
                gap / self.options.dx]

    def post_step(self, solver):
        arrays = self.scene.by_name
        if not self.history:
            self.history.append(self.row(arrays, 0.0))
        if solver.t >= self._next_record - 0.5 * solver.dt or solver.t >= solver.tf - 0.5 * solver.dt:
            self.history.append(self.row(arrays, solver.t))
            self._next_record = solver.t + self.options.record_every

    def post_process(self, outdir):
        hist, rows = io.read_history(outdir)
        t, ek, ee, vmax, ec, gap = rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3], rows[:, 10], rows[:, 11]
        total = ek + ee + ec
        touching = np.flatnonzero(gap < 1.0)
        results = {
            "t": float(t[-1]), "reached_end": bool(t[-1] >= self.options.tf * (1 - 1e-6)),
            "scheme": hist["scheme"], "shifting": hist["shifting"], "poisson": hist["poisson"],
            "n_particles": hist["n_particles"], "dx": hist["dx"],
            "max_speed_over_c0": float(vmax.max() / hist["c0"]),
            "energy_initial": float(total[0]), "energy_final": float(total[-1]),
            "energy_final_over_initial": float(total[-1] / total[0]),
            "energy_max_over_initial": float(total.max() / total[0]),
            "contact": hist["contact"], "gap_final_over_dx": float(gap[-1]), "gap_min_over_dx": float(gap.min()),
            "contact_start": float(t[touching[0]]) if touching.size else None,
            "contact_end": float(t[touching[-1]]) if touching.size else None,
            "separated": bool(touching.size and gap[-1] > 1.0),
            "kinetic_min_over_initial": float(ek.min() / ek[0]),
            "elastic_max_over_initial": float(ee.max() / total[0]),
            "u_left_final": float(rows[-1, 8]), "u_right_final": float(rows[-1, 9]),
            "bounced": bool(rows[-1, 8] < 0 < rows[-1, 9]),
            "point_A": rows[:, 4:6].tolist()[-1], "point_B": rows[:, 6:8].tolist()[-1],
        }
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, rows, hist)
        print(f"rings: {hist['scheme']}+{hist['shifting']} nu={hist['poisson']} n={hist['n_particles']} t={t[-1]:.4g}  "
              f"E_end/E_0 {results['energy_final_over_initial']:.3f}  max|u|/c0 {results['max_speed_over_c0']:.3f}  "
              f"u_cm left/right {results['u_left_final']:.3g}/{results['u_right_final']:.3g}  "
              f"gap at the end {results['gap_final_over_dx']:.3g} dx\n"
              f"results: {os.path.join(outdir, 'results.json')}")
        return results

    def plot(self, outdir, rows, hist):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        t = rows[:, 0] * 1e3
        e0 = rows[0, 1] + rows[0, 2] + rows[0, 10]
        fig, ax = plt.subplots(figsize=(6, 4))
        for k, name in ((1, "kinetic"), (2, "elastic"), (10, "contact")):
            ax.plot(t, rows[:, k] / e0, label=name)
        ax.plot(t, (rows[:, 1] + rows[:, 2] + rows[:, 10]) / e0, "k-", label="total")
        ax.set_xlabel("t [ms]")
        ax.set_ylabel("E / E(0)")
        ax.set_title(f"{hist['scheme'].upper()} + {hist['shifting'].upper()}, nu = {hist['poisson']}", fontsize=9)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "energy.png"), dpi=100)
        plt.close(fig)
        fig, ax = plt.subplots(figsize=(6, 4))
        for c, lab in ((4, "x_A"), (5, "y_A"), (6, "x_B"), (7, "y_B")):
            ax.plot(t, rows[:, c], label=lab)
        ax.set_xlabel("t [ms]")
        ax.set_ylabel("position [m]")
        ax.set_title("points A (outer left) and B (outer top) of the left ring", fontsize=9)
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "points.png"), dpi=100)
        plt.close(fig)
        fig, ax = plt.subplots(figsize=(6, 4))
        ax.plot(t, rows[:, 11])
        ax.axhline(1.0, color="k", lw=0.5)
        ax.set_xlabel("t [ms]")
        ax.set_ylabel("gap between the rings / dx")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "gap.png"), dpi=100)
        plt.close(fig)
        if self.scene is not None:
            arrays = [self.scene.by_name[m] for m in self.media]
            x, y, p = (np.concatenate([getattr(pa, c) for pa in arrays]) for c in "xyp")
            particle_panels(os.path.join(outdir, "rings.png"),
                            [(f"t = {rows[-1, 0] * 1e3:.3g} ms", x, y, p)], size=(8.0, 4.0), marker=1)
