"""Two-dimensional dam break over a dry bed (Martin & Moyce 1952; Koshizuka & Oka 1996).

The set-up of PySPH's ``dam_break_2d`` example: a water column of width L = 1 and height
2L at the left of a tank 4L wide and 4L high (open top), rho0 = 1000, g = 9.81,
c0 = 10 sqrt(2 g H) with H = 2L (62.6 m/s), artificial viscosity alpha = 0.1, beta = 0.
Differences from PySPH, chosen and documented: sphgen's kernel is the quintic spline
(support 3h) with h = dx (PySPH: Wendland quintic, support 2h, h = 1.3 dx: 3 dx against
2.6 dx of support); three layers of Adami walls (PySPH: dummy particles with the
continuity equation); the column starts in hydrostatic equilibrium (rho from the Tait
equation with p = rho0 g (2L - y), m = rho dx^2), PySPH starts at rho0 and p = 0
(``--initial-state uniform``); delta-SPH
(delta = 0.1) is on by default (``--delta 0`` gives plain WCSPH).

The default ``--dx 0.03`` is PySPH's (h = 0.039 = 1.3 dx), rounded so that L/dx is a whole
number (dx = 1/33, 33 x 66 = 2178 fluid particles).  The default final time 0.7 s reaches
T = t sqrt(2 g / L) = 3.1.

``--scheme ctvf`` runs the corrected transport-velocity formulation of Adepu &
Ramachandran (2021, section 4.3) on the same geometry and walls: continuity density
(eq. 25) and EDAC pressure (eq. 26), SPST shifting with the free-surface treatment of
sections 3.4-3.5, free-slip ghost velocities in the divergence terms, alpha = 0.05
(``--alpha``), nu = 0, p = 0 held on the free-surface particles (``--no-surface-pressure``
leaves it to the EDAC equation), hydrostatic initial pressure; its energy budget has
no internal term (EDAC has no equation of state).

``--scheme variational`` runs the time integrators of da Silva & Giraldi (2024) on the same
geometry (:class:`~schemes.variational.VariationalScheme`): ``--integrator variational``
(generalised midpoint, ``--midpoint-alpha`` 0.5, fixed-point tolerance ``--tol``, default
1e-6 dx) or ``explicit`` (leapfrog, eqs. 59-62); K3 Gaussian kernel (lam = 1.3 dx), continuity
density (eq. 67), AV of eq. 55 with a = ``--alpha`` (0.1) and b = 0, the walls' first layers as
the repulsive boundary particles of eq. 58 (D = 2 g H, r0 = dx); delta-SPH is not used.

``--scheme symplectic`` runs the method of Kincl's thesis (2023, §1.6, the "SYM" curve of its
Fig. 1.3; :class:`~schemes.symplectic.SymplecticSPHScheme`): summation density with the
constant that makes rho = rho0 at t = 0 (eq. 1.14), Tait (eq. 1.15), physical viscosity
nu = 1e-6 (eq. 1.81, ``--nu``), the viscous Verlet step (eq. 1.82), dummy no-slip walls that
are fluid particles at rest (ceil(2h/dx) layers, eq. 1.83); the thesis' tank (4L x 3L, open
top), g = 9.8, column at rho0 and p = 0; Wendland kernel with h = 1.5 dx, c0 = 50 m/s
(``--c0``) and dt = 0.2 h/c0 from the authors' code (the thesis gives none of them; docs/shtc.md,
"Thesis §1.6 dam break").  Its toe is also compared with Violeau's (2012) curve and Kincl's
digitisation of Koshizuka & Oka, both from the authors' repository
(:func:`sphgen.tools.reference.violeau_2012_dam_break_front`); :func:`thesis_figure_1_3`
draws the thesis' Fig. 1.3 from a finished run.

``post_process`` writes ``results.json``: the toe position Z = x_toe/L against T (largest x
of the fluid within 2 dx of the floor, ejected particles ignored,
:func:`sphgen.tools.probes.front_position`), its largest relative deviation from Martin &
Moyce (1952, a = 2.25 in and 1.125 in) and Koshizuka & Oka's (1996) experiment over
0.8 <= T <= 3 and from their MPS curve (the reference of Adepu & Ramachandran's Fig. 16)
over its whole data range T <= 2.943 (our curve interpolated at their times), the mass drift, the particles that left the
tank, and the energy balance (kinetic + potential + Tait internal energy); ``toe.png``
and ``energy.png`` plot them.
"""
import os
from math import sqrt

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.kernels import get_kernel
from sphgen.geometry import layers_for_support, rectangle, wall_layers_box
from sphgen.particles import ParticleArray
from sphgen.tools.probes import front_position
from sphgen.tools import reference

from ..schemes.ctvf import CTVFScheme
from ..schemes.symplectic import SymplecticSPHScheme
from ..schemes.variational import VariationalScheme
from ..schemes.wcsph import WCSPHScheme

try:
    from sphgen.errors import InputError
except ImportError:  # pragma: no cover
    InputError = ValueError

L = 1.0            # column width
H = 2.0 * L        # column height
TANK_W = 4.0 * L   # tank width
TANK_H = 4.0 * L   # tank height (PySPH's container_height)
RHO0 = 1000.0
G = 9.81
G_THESIS = 9.8     # Kincl (2023), §1.6
TANK_H_THESIS = 3.0 * L   # Kincl (2023), §1.6: container (0, 4a) x (0, 3a)
C0_THESIS = 50.0   # the authors' code (SmoothedParticles.jl, collapse_symplectic.jl); not in the thesis
T_RANGE = (0.8, 3.0)  # where the toe is compared with the experiments
VIOLEAU_RANGE = (0.0, 3.01)  # Violeau's curve: its whole data range (T <= 3.005)
MPS_RANGE = (0.0, 2.95)  # Koshizuka & Oka's MPS curve: its whole data range (T <= 2.943)


def toe_scale(g=G):
    """T = t * toe_scale() = t sqrt(2 g / L)."""
    return sqrt(2.0 * g / L)


def max_rel_deviation(T, Z, T_ref, Z_ref, lo=T_RANGE[0], hi=T_RANGE[1]):
    """max |Z(T_ref) - Z_ref| / Z_ref over the reference points with lo <= T_ref <= hi (our
    curve interpolated linearly at their times); also the signed value at that point."""
    sel = (T_ref >= lo) & (T_ref <= hi) & (T_ref <= T.max())
    if not sel.any():
        return None, None
    ours = np.interp(T_ref[sel], T, Z)
    rel = (ours - Z_ref[sel]) / Z_ref[sel]
    k = int(np.argmax(np.abs(rel)))
    return float(abs(rel[k])), float(rel[k])


def _pct(v):
    return "n/a (run to T >= 0.8)" if v is None else f"{100 * v:.1f}%"


class DamBreak2D(Application):
    """2D dam break (Martin & Moyce 1952 / Koshizuka & Oka 1996), WCSPH with Adami walls."""

    tf = 0.7
    pfreq = 500
    dim = 2
    history_columns = ("t", "T", "toe", "kinetic", "potential", "internal", "total",
                       "mass_inside", "n_outside", "rho_mean")
    diagnostics = ("mass", "energies", "density_range", "pressure_range")
    diagnostics_every = 50

    def add_user_options(self, group):
        group.add_argument("--dx", type=float, default=0.03,
                           help="particle spacing, rounded so that L/dx is whole (default %(default)s)")
        group.add_argument("--hdx", type=float, default=None,
                           help="h / dx (default 1, 1.5 for --scheme symplectic)")
        group.add_argument("--kernel", choices=("quintic", "wendland"), default=None,
                           help="kernel: quintic spline (support 3h) or Wendland C2 (support 2h; PySPH's "
                                "dam_break_2d uses it with --hdx 1.3) (default quintic; wendland for "
                                "--scheme symplectic, Kincl 2023 eq. 1.6)")
        group.add_argument("--scheme", choices=("wcsph", "ctvf", "variational", "symplectic"), default="wcsph",
                           help="scheme (default %(default)s)")
        group.add_argument("--integrator", choices=("variational", "explicit"), default="variational",
                           help="--scheme variational: midpoint (eqs. 37, 63-65) or leapfrog (59-62)")
        group.add_argument("--midpoint-alpha", type=float, default=0.5,
                           help="--scheme variational: generalised-midpoint alpha (default %(default)s)")
        group.add_argument("--tol", type=float, default=None,
                           help="--scheme variational: fixed-point tolerance, metres (default 1e-6 dx)")
        group.add_argument("--alpha", type=float, default=None,
                           help="artificial viscosity (default 0.1 for wcsph and variational (a of "
                                "eq. 55), 0.05 for ctvf)")
        group.add_argument("--no-surface-pressure", dest="surface_pressure", action="store_false",
                           help="ctvf: do not hold p = 0 on the free-surface particles")
        group.add_argument("--nu", type=float, default=None,
                           help="ctvf: kinematic viscosity, m^2/s, with the no-slip wall ghost velocity "
                                "(default 0; water 1e-6); symplectic: eq. 1.81 viscosity (default 1e-6, "
                                "Kincl 2023 §1.6)")
        group.add_argument("--c0", type=float, default=None,
                           help="sound speed, m/s, instead of --c0-factor (default for --scheme "
                                f"symplectic: {C0_THESIS:g}, the authors' code)")
        group.add_argument("--edac-damping", choices=("consistent", "paper"), default="consistent",
                           help="ctvf: the pressure damping of eq. 26 as a Laplacian (default) or as printed "
                                "(an extra 1/rho: 1000 times weaker for water)")
        group.add_argument("--delta", type=float, default=0.1,
                           help="delta-SPH coefficient, 0 turns it off (default %(default)s)")
        group.add_argument("--no-delta-correction", dest="delta_correction", action="store_false",
                           help="Molteni-Colagrossi 2009 diffusion instead of Antuono et al. 2010")
        group.add_argument("--c0-factor", type=float, default=10.0,
                           help="c0 = factor * sqrt(2 g H) (default %(default)s)")
        group.add_argument("--wall-alpha", type=int, choices=(0, 1), default=1,
                           help="artificial viscosity against the walls too (default 1)")
        group.add_argument("--initial-state", choices=("hydrostatic", "uniform"), default="hydrostatic",
                           help="column at hydrostatic density and pressure (default), or at rho0 and "
                                "p = 0 everywhere as in PySPH's example")
        group.add_argument("--record-every", type=float, default=0.005,
                           help="time between toe/energy samples (default %(default)s s)")

    def consume_user_options(self, o):
        thesis = o.scheme == "symplectic"
        if o.kernel is None:
            o.kernel = "wendland" if thesis else "quintic"   # Kincl 2023 eq. 1.6
        if o.hdx is None:
            o.hdx = 1.5 if thesis else 1.0                    # the authors' code: support 3 dx
        for name in ("dx", "hdx", "c0_factor", "record_every"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive finite number, got {v}")
        if o.scheme == "ctvf" and o.kernel != "quintic":
            raise InputError("--scheme ctvf uses the quintic spline (its near-surface treatment is tied "
                             "to it, Adepu & Ramachandran 2021 sec. 3.5); drop --kernel")
        if o.scheme == "variational" and o.kernel != "quintic":
            raise InputError("--scheme variational uses its own kernel (da Silva & Giraldi 2024, eq. 69 "
                             "variants); drop --kernel")
        if o.nu is None:
            o.nu = 1e-6 if o.scheme == "symplectic" else 0.0
        if o.c0 is None and o.scheme == "symplectic":
            o.c0 = C0_THESIS
        if o.c0 is not None and not (np.isfinite(o.c0) and o.c0 > 0):
            raise InputError(f"--c0 must be a positive finite number, got {o.c0}")
        if not (np.isfinite(o.nu) and o.nu >= 0):
            raise InputError(f"--nu must be a non-negative finite number, got {o.nu}")
        # the thesis' tank and g for its method; PySPH's for the others
        self.g, self.tank_h = (G_THESIS, TANK_H_THESIS) if o.scheme == "symplectic" else (G, TANK_H)
        if o.alpha is None:
            o.alpha = 0.05 if o.scheme == "ctvf" else 0.1
        if o.scheme == "ctvf":   # no equation of state: no internal energy to sample
            self.diagnostics = tuple(d for d in type(self).diagnostics if d != "energies")
        for name in ("alpha", "delta"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v >= 0):
                raise InputError(f"--{name} must be a non-negative finite number, got {v}")
        if not 0.0 <= o.midpoint_alpha <= 1.0:
            raise InputError(f"--midpoint-alpha must be in [0, 1], got {o.midpoint_alpha}")
        if o.tol is not None and not (np.isfinite(o.tol) and o.tol > 0):
            raise InputError(f"--tol must be a positive finite number, got {o.tol}")
        n = max(int(round(L / o.dx)), 4)
        self.dx = L / n
        self.h = o.hdx * self.dx
        if o.scheme == "variational":   # the Gaussian's neighbour radius sets h (rc = 3h)
            self.h = VariationalScheme(["fluid"], [], dx=self.dx).h
        self.c0 = o.c0 if o.c0 is not None else o.c0_factor * sqrt(2.0 * G * H)
        self.n_layers = layers_for_support(get_kernel(o.kernel, 2), o.hdx)
        self.history = []
        self._next_record = 0.0

    def create_particles(self):
        dx, h = self.dx, self.h
        x, y = rectangle(0.0, L, 0.0, H, dx)
        b = RHO0 * self.c0 ** 2 / 7.0
        p = RHO0 * G * (H - y)
        if self.options.initial_state == "uniform" or self.options.scheme == "symplectic":
            p = 0.0 * y    # the symplectic scheme's density constant makes rho = rho0 at t = 0
        rho = RHO0 * (1.0 + p / b) ** (1.0 / 7.0)
        fluid = ParticleArray("fluid", x=x, y=y, rho=rho, m=rho * dx * dx, h=np.full(x.size, h))
        fluid.add_property("p", data=p)
        xw, yw, nx, ny = wall_layers_box(0.0, TANK_W, 0.0, self.tank_h, dx, self.n_layers, open_top=True)
        wall = ParticleArray("wall", x=xw, y=yw, rho=np.full(xw.size, RHO0),
                             m=np.full(xw.size, RHO0 * dx * dx), h=np.full(xw.size, h))
        wall.add_property("normal", stride=3, data=np.column_stack([nx, ny, 0 * nx]).ravel())
        self.m0 = float(fluid.m.sum())
        return [fluid, wall]

    def create_scheme(self):
        o = self.options
        if o.scheme == "symplectic":
            return SymplecticSPHScheme(["fluid"], ["wall"], dim=2, rho0=RHO0, c0=self.c0, h=self.h, nu=o.nu,
                                       gy=-self.g, kernel=o.kernel)
        if o.scheme == "ctvf":
            return CTVFScheme(["fluid"], dim=2, rho0=RHO0, c0=self.c0, nu=o.nu, h=self.h, dx=self.dx,
                              umax=sqrt(2.0 * G * H), density="continuity", alpha=o.alpha, gy=-G,
                              walls=["wall"], free_surface=True, surface_pressure=o.surface_pressure,
                              edac_damping=o.edac_damping, wall_alpha=bool(o.wall_alpha))
        if o.scheme == "variational":
            return VariationalScheme(["fluid"], ["wall"], dim=2, rho0=RHO0, c0=self.c0, gy=-G, kernel="K3",
                                     dx=self.dx, av_a=o.alpha, av_b=0.0, D=2.0 * G * H, r0=self.dx,
                                     integrator=o.integrator, alpha=o.midpoint_alpha,
                                     tol=o.tol if o.tol is not None else 1e-6 * self.dx)
        return WCSPHScheme(["fluid"], ["wall"], dim=2, rho0=RHO0, c0=self.c0, h=self.h, gy=-G,
                           alpha=o.alpha, beta=0.0, delta=o.delta, delta_correction=o.delta_correction,
                           umax=sqrt(2.0 * G * H), wall_alpha=bool(o.wall_alpha), kernel=o.kernel)

    def history_meta(self):
        return {"dx": self.dx, "h": self.h, "c0": self.c0, "L": L, "m0": self.m0, "scheme": self.options.scheme,
                "g": self.g}

    # ------------------------------------------------------------ diagnostics
    def post_step(self, solver):
        if solver.t + 1e-12 >= self._next_record or solver.t >= solver.tf - 1e-12:
            self.record(solver.t)
            self._next_record = solver.t + self.options.record_every

    def record(self, t):
        f = self.scene.by_name["fluid"]
        e = self.energies(f)
        self.history.append([t, t * toe_scale(self.g), *self.row(f, self.dx), e["kinetic"], e["potential"],
                             e["internal"], e["total"], *self.mass_row(f)])

    def energies(self, f):
        """The scheme's energies; kinetic and potential only for a scheme without them (EDAC)."""
        if isinstance(self.scheme, SymplecticSPHScheme):   # its walls hold internal energy
            return self.scheme.energies([f, self.scene.by_name["wall"]])
        if hasattr(self.scheme, "energies"):
            return self.scheme.energies([f])
        ke = 0.5 * float(np.sum(f.m * (f.u ** 2 + f.v ** 2)))
        pe = float(np.sum(f.m * self.g * f.y))
        return {"kinetic": ke, "potential": pe, "internal": 0.0, "total": ke + pe}

    @staticmethod
    def row(f, dx):
        """[toe / L] of the fluid array f."""
        return [front_position(f.x, f.y, 0.0, dx) / L]

    @staticmethod
    def outside(f, dx):
        """Mask of fluid particles that went through a wall: beyond its first layer of wall
        particles, which sits dx/2 behind the wall surface (x < -dx/2, x > 4L + dx/2,
        y < -dx/2).  A particle between the surface and that layer is still held by it."""
        return (f.x < -0.5 * dx) | (f.x > TANK_W + 0.5 * dx) | (f.y < -0.5 * dx)

    def mass_row(self, f):
        out = self.outside(f, self.dx)
        return [float(f.m[~out].sum()), int(out.sum()), float(f.rho.mean())]

    # ------------------------------------------------------------ results
    def post_process(self, outdir):
        hist, rows = io.read_history(outdir)
        cols = {c: rows[:, i] for i, c in enumerate(hist["columns"])}
        T, Z = cols["T"], cols["toe"]
        ok = np.isfinite(Z)
        results = {"t": float(cols["t"][-1]), "T": float(T[-1]), "dx": hist.get("dx"),
                   "h": hist.get("h"), "c0": hist.get("c0"), "n_samples": int(rows.shape[0])}
        refs = {"martin_moyce_a2.25in": reference.martin_moyce_1952(2.25),
                "martin_moyce_a1.125in": reference.martin_moyce_1952(1.125),
                "koshizuka_oka": reference.koshizuka_oka_1996(),
                "koshizuka_oka_mps": reference.koshizuka_oka_1996_mps(),
                "violeau": reference.violeau_2012_dam_break_front(),
                "koshizuka_oka_kincl": reference.koshizuka_oka_1996_kincl()}
        ranges = {"koshizuka_oka_mps": MPS_RANGE, "violeau": VIOLEAU_RANGE}
        for name, (Tr, Zr) in refs.items():
            lo, hi = ranges.get(name, T_RANGE)
            dev, signed = max_rel_deviation(T[ok], Z[ok], np.asarray(Tr), np.asarray(Zr), lo, hi)
            results[f"toe_max_rel_dev_{name}"] = dev
            results[f"toe_signed_dev_at_max_{name}"] = signed
        m0 = hist.get("m0", cols["mass_inside"][0])
        e0 = cols["total"][0]
        results.update({
            "toe_at_T3": float(np.interp(3.0, T[ok], Z[ok])) if T[ok].max() >= 3.0 else None,
            "mass_drift": float(cols["mass_inside"][-1] / m0 - 1.0),
            "n_outside_final": int(cols["n_outside"][-1]), "n_outside_max": int(cols["n_outside"].max()),
            "rho_mean_drift": float(cols["rho_mean"][-1] / cols["rho_mean"][0] - 1.0),
            "energy_initial": float(e0), "energy_final": float(cols["total"][-1]),
            # relative to the potential energy available: m g (H/2 - h_final) ~ half the PE
            "energy_change_rel": float((cols["total"][-1] - e0) / abs(cols["potential"][0])),
        })
        results["scheme"] = hist.get("scheme", "wcsph")
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, T, Z, refs, cols, label=f"sphgen {results['scheme'].upper()}")
        print(f"dam_break_2d: T={results['T']:.3g}  toe max deviation over {T_RANGE[0]} <= T <= {T_RANGE[1]}: "
              f"Martin-Moyce (a=2.25in) {_pct(results['toe_max_rel_dev_martin_moyce_a2.25in'])}, "
              f"Koshizuka-Oka (experiment) {_pct(results['toe_max_rel_dev_koshizuka_oka'])}; over "
              f"T <= {MPS_RANGE[1]}: Koshizuka-Oka MPS {_pct(results['toe_max_rel_dev_koshizuka_oka_mps'])}; "
              f"T <= {VIOLEAU_RANGE[1]}: Violeau {_pct(results['toe_max_rel_dev_violeau'])}; "
              f"mass drift {results['mass_drift']:.2e}, outside {results['n_outside_final']}\n"
              f"results: {os.path.join(outdir, 'results.json')}\nfigures: {os.path.join(outdir, 'toe.png')}, "
              f"{os.path.join(outdir, 'energy.png')}")
        return results

    @staticmethod
    def plot(outdir, T, Z, refs, cols, label="sphgen WCSPH"):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(6, 4.5))
        ax.plot(T, Z, "k-", label=label)
        marks = {"martin_moyce_a2.25in": ("bo", "Martin & Moyce 1952 (a = 2.25 in)"),
                 "martin_moyce_a1.125in": ("bs", "Martin & Moyce 1952 (a = 1.125 in)"),
                 "koshizuka_oka": ("r^", "Koshizuka & Oka 1996 (experiment)"),
                 "koshizuka_oka_mps": ("gv", "Koshizuka & Oka 1996 (MPS)"),
                 "violeau": ("mD", "Violeau 2012 (SPH; Kincl's digitisation)"),
                 "koshizuka_oka_kincl": ("c<", "Koshizuka & Oka 1996 (Kincl's digitisation)")}
        for name, (Tr, Zr) in refs.items():
            ax.plot(Tr, Zr, marks[name][0], mfc="none", label=marks[name][1])
        ax.axvspan(*T_RANGE, color="0.93", zorder=0)
        ax.set_xlim(0, max(3.5, float(T.max())))
        ax.set_ylim(0.8, 4.2)
        ax.set_xlabel("$T = t\\sqrt{2g/L}$")
        ax.set_ylabel("toe $x/L$")
        ax.legend(loc="upper left")
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "toe.png"), dpi=100)
        plt.close(fig)
        fig, ax = plt.subplots(figsize=(6, 4.5))
        e0 = cols["total"][0]
        for k, style in (("kinetic", "r-"), ("potential", "b-"), ("internal", "g-"), ("total", "k-")):
            ax.plot(cols["T"], cols[k] - (cols[k][0] if k in ("potential", "total") else 0.0), style,
                    label=k + (" - initial" if k in ("potential", "total") else ""))
        ax.set_xlabel("$T = t\\sqrt{2g/L}$")
        ax.set_ylabel("energy per unit depth (J/m)")
        ax.set_title(f"total at start {e0:.4g} J/m")
        ax.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "energy.png"), dpi=100)
        plt.close(fig)


def thesis_figure_1_3(outdir, path=None):
    """Kincl's thesis (2023), Fig. 1.3 from a finished ``dam_break_2d`` run in ``outdir``: the
    toe X = x_wave/a against T = t sqrt(2g/a) (the thesis prints t/sqrt(2ga)) of the run ("SYM"
    for ``--scheme symplectic``), Violeau's (2012) curve ("VIO") and Koshizuka & Oka's (1996)
    experiment ("EXP"), both as Kincl digitised them.  Writes ``path`` (default
    ``outdir/thesis_fig_1_3.png``) and returns it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    hist, rows = io.read_history(outdir)
    cols = {c: rows[:, i] for i, c in enumerate(hist["columns"])}
    path = path or os.path.join(outdir, "thesis_fig_1_3.png")
    label = {"symplectic": "SYM (sphgen)"}.get(hist.get("scheme"), f"sphgen {hist.get('scheme', 'wcsph')}")
    fig, ax = plt.subplots(figsize=(6, 4.5))
    ax.plot(cols["T"], cols["toe"], "k-", label=label)
    Tv, Zv = reference.violeau_2012_dam_break_front()
    Tk, Zk = reference.koshizuka_oka_1996_kincl()
    ax.plot(Tv, Zv, "bo", mfc="none", label="VIO (Violeau 2012)")
    ax.plot(Tk, Zk, "r^", mfc="none", label="EXP (Koshizuka & Oka 1996)")
    ax.set_xlim(0, 3.2)
    ax.set_ylim(0.9, 4.1)
    ax.set_xlabel("$T = t\\sqrt{2g/a}$")
    ax.set_ylabel("$X = x_{wave}/a$")
    ax.set_title(f"dam break, dx = a/{int(round(L / hist['dx']))}")
    ax.legend(loc="upper left")
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def thesis_figure_1_2(outdir, path=None, times=(0.0, 0.2, 0.4, 0.6), walls=True):
    """Kincl's thesis (2023), Fig. 1.2 from the output files of a finished ``dam_break_2d`` run in
    ``outdir`` (run without ``--disable-output``): snapshots of the particles coloured by the
    velocity magnitude, at the output times nearest ``times`` (s).  Writes ``path`` (default
    ``outdir/thesis_fig_1_2.png``) and returns it."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    from sphgen.tools.probes import output_series
    series = list(output_series(outdir))
    if not series:
        raise InputError(f"thesis_figure_1_2: no output files in {outdir} (run without --disable-output)")
    ts = np.array([t for t, _ in series])
    picks = [series[int(np.argmin(np.abs(ts - t)))] for t in times]
    vmax = max(float(np.hypot(a["fluid"].get("u"), a["fluid"].get("v")).max()) for _, a in picks) or 1.0
    fig, axes = plt.subplots(1, len(picks), figsize=(3.2 * len(picks), 2.8), squeeze=False)
    for ax, (t, arrays) in zip(axes[0], picks):
        f = arrays["fluid"]
        x, y = np.asarray(f.get("x")), np.asarray(f.get("y"))
        speed = np.hypot(f.get("u"), f.get("v"))
        sc = ax.scatter(x, y, c=speed, s=1.0, cmap="jet", vmin=0.0, vmax=vmax, linewidths=0)
        if walls and "wall" in arrays:
            ax.scatter(arrays["wall"].get("x"), arrays["wall"].get("y"), c="0.6", s=0.5, linewidths=0)
        ax.set_aspect("equal")
        ax.set_xlim(-0.1, TANK_W + 0.1)
        ax.set_ylim(-0.1, 3.1)
        ax.set_title(f"t = {t:.2f} s")
        ax.set_xticks([])
        ax.set_yticks([])
    fig.colorbar(sc, ax=list(axes[0]), label="|v| (m/s)", shrink=0.8)
    path = path or os.path.join(outdir, "thesis_fig_1_2.png")
    fig.savefig(path, dpi=150, bbox_inches="tight")
    plt.close(fig)
    return path
