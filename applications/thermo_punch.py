"""Punch test of Ghavamian et al. (2021), sec. 7.4 (Figs. 15-19): a nearly incompressible
thermo-elastic perforated cylinder.

The paper gives H = 1 m and no other dimension: the default body (the digest's choice) is
a hollow cylinder, outer radius 1 m, inner radius 0.5 m (``--r-out``, ``--r-in``), Z in
[0, H], axis Z.  Initial velocity v0 = -10 (Z / H) e_Z m/s (eq. 94), theta = theta_R; a
roller on the base Z = 0 (v_Z = 0), every other face traction-free; insulated.
Mie-Gruneisen, E = 50.05 kPa, nu = 0.499, rho_R = 1000, k = 10, C_v = 1, alpha = 2.223e-4,
theta_R = 293.15 K; E-form, alpha_CFL = 0.3 (with the adiabatic c_p, 132 m/s), no
angular-momentum projection; to 0.4 s.  Default scheme: the paper's full {p, F, H, J, E}
with the paper's raw jumps (``--variant reduced`` is the {p, F, H, E} scheme of its Fig.
16; with ``--jumps limited`` the full scheme stops near 0.27 s at dx = 0.1, docs/thermo.md).

Probe X = [0, 1, 1] (on the outer top edge).  The checkerboard indicator R[p]
(``_thermo_solid.checkerboard``) is taken at the first step at or after 0.07 k s, k = 1..5
(the times of Fig. 19): the paper shows the reduced scheme's spurious pressure modes in
Fig. 16 by eye and defines no measure.  ``results.json``: the energy-budget residual (the
roller does no work, so E_tot is constant), S never falling, min J, the theta range and
R[p], R[theta] at those times.
"""
import numpy as np

from sphgen.errors import InputError
from sphgen.particles import ParticleArray

from ..equations.thermo_materials import MieGruneisen
from ._thermo_solid import ThermoSolid, checkerboard, checks, cylinder_lattice

PAPER = dict(E_young=50.05e3, nu=0.499, rho=1000.0, Cv=1.0, alpha=2.223e-4, theta_R=293.15, k_th=10.0)
HEIGHT, V_TOP = 1.0, 10.0
SNAPSHOTS = (0.07, 0.14, 0.21, 0.28, 0.35)


class ThermoPunch(ThermoSolid):
    """Nearly incompressible perforated cylinder punched by an initial velocity (Ghavamian et al. 2021, sec. 7.4)."""

    tf = 0.4
    pfreq = 500
    default_variant = "full"
    default_jumps = "raw"
    default_projection = False
    probe_point = (0.0, 1.0, 1.0)

    def add_user_options(self, group):
        group.add_argument("--dx", type=float, default=0.1,
                           help="vertex spacing; H/dx whole (default %(default)s: 2728 particles)")
        group.add_argument("--r-out", type=float, default=1.0, help="outer radius (default %(default)s m)")
        group.add_argument("--r-in", type=float, default=0.5, help="inner radius (default %(default)s m)")
        self.add_scheme_options(group, "the paper's")

    def consume_user_options(self, o):
        self.check_scheme_options(o)
        if not (np.isfinite(o.dx) and 0 < o.dx <= 0.5) or abs(HEIGHT / o.dx - round(HEIGHT / o.dx)) > 1e-6:
            raise InputError(f"--dx must divide H = {HEIGHT:g} m and be at most 0.5, got {o.dx}")
        if not (0 <= o.r_in < o.r_out) or not np.isfinite(o.r_out):
            raise InputError(f"need 0 <= --r-in < --r-out, got {o.r_in}, {o.r_out}")
        self.dx = o.dx
        self.material = MieGruneisen(**PAPER)
        self.snapshots = {}

    def create_particles(self):
        o, dx = self.options, self.dx
        x, y, z, V, _ = cylinder_lattice(dx, o.r_out, 0.0, HEIGHT, o.r_in)
        self.set_probe(np.stack([x, y, z], 1))
        px, py, pz = self.perturbed(x, y, z, dx)
        base = np.abs(z) < 1e-9
        pz = np.where(base, 0.0, pz)           # the roller's particles stay on Z = 0
        vfix = np.zeros((x.size, 3))
        vfix[base, 2] = 1.0
        pa = ParticleArray("body", x=px, y=py, z=pz, w=-V_TOP * z / HEIGHT)
        pa.add_property("V", data=V)
        pa.add_property("vfix", stride=3, data=vfix.ravel())
        print(f"thermo_punch: dx={dx:g} N={x.size} (paper: 2500/5000/10000); volume {V.sum():.5g} m^3 "
              f"(exact {np.pi * (o.r_out ** 2 - o.r_in ** 2) * HEIGHT:.5g}); {int(base.sum())} roller particles")
        return [pa]

    def create_scheme(self):
        return self.make_scheme(self.material, self.dx)

    def post_step(self, solver):
        super().post_step(solver)
        for ts in SNAPSHOTS:
            if solver.t >= ts - 1e-12 and ts not in self.snapshots:
                pa = self.scene.by_name["body"]
                X = np.stack([pa.x0, pa.y0, pa.z0], 1)
                self.snapshots[ts] = {"t": solver.t, "R_p": checkerboard(X, pa.V, pa.p.copy(), self.scheme.h,
                                                                         self.options.kernel),
                                      "R_theta": checkerboard(X, pa.V, pa.theta.copy(), self.scheme.h,
                                                              self.options.kernel)}

    def case_meta(self):
        """(with the snapshots' R[p], so that a run that stops early keeps them in history.json)"""
        return {"r_out": self.options.r_out, "r_in": self.options.r_in,
                "snapshots": {f"{ts:g}": v for ts, v in sorted(self.snapshots.items())}}

    def post_process(self, outdir):
        """Insulated and the roller does no work: E_tot constant and S never falls, from t = 0."""
        r = self.write_results(outdir, checks(self.history_columns, self.history, 0.0, 0.0))
        snaps = r["snapshots"]
        R = ", ".join(f"{k} s: {v['R_p']:.3g}" for k, v in snaps.items())
        print(f"thermo_punch: N={r['n_particles']} t={self.solver.t:.4g} ({self.options.variant}, "
              f"{self.options.form}-form): energy residual {r['energy_residual']:.2e}, S fall {r['entropy_fall']}, "
              f"J_min {r['J_min']:.3f}, theta {r['theta_range']}; R[p] {R}")
