"""Soft gripper of Ghavamian et al. (2021), sec. 7.5 (Figs. 20-22): bending of four arms on a
hollow cylinder, with a cold core.

The paper gives the arms' length L = 0.4 m and the cylinder's radius R = 0.1 m, and no
section, support or resolution (its Fig. 20 is a sketch).  Defaults (the digest's, options
``--thickness``, ``--width``, ``--r-in``): a hub r_in = 0.05 <= r <= R = 0.1 m and four arms
along +-X, +-Y reaching |X| = L (or |Y| = L), section 0.06 x 0.06 m (|Y| <= 0.03 for the X
arms), all Z in [-0.06, 0] so that the paper's probe X = [0.4, 0, -0.03] is the centre of the
+X arm's end face.  Supports: the paper states none, and a free body under four equal
vertical tractions only accelerates, so the particles of the hub's inner surface (the
"central interior") are held (v = 0), a gripper on its shaft (``--free`` drops this).
Thermal: theta = 280 K held on the same inner-surface particles, theta = 300 K initially on
the four end faces' particles, theta_R = 293.15 K elsewhere, every other face insulated.
Load: a constant traction t_B = 1000 N/m^2 on the four end faces, vertical; the paper gives
no sign: -Z (``--traction`` for another value), applied through the vertices' tributary
areas.  Mie-Gruneisen, E = 50.05 kPa, nu = 0.45, rho_R = 1000, k = 10, C_v = 1,
alpha = 2.223e-4, theta_R = 293.15 K; E-form, alpha_CFL = 0.3, raw jumps (the paper's), no
projection (the body is held); to 0.5 s (Fig. 21 at 0.47 s).  Default scheme: the reduced
{p, F, H, E} (``--variant reduced``, J = det F): the paper's full {p, F, H, J, E}
(``--variant full``) stops on this case as on the L-block, D_J pulling J off det F at the
arms' ends (docs/thermo.md).

Lattice: vertices of spacing ``--dx`` through the origin (4-fold symmetric about Z), with
volumes dx^3 times the fraction of the vertex cell inside (2^3 sub-cells); dx must divide
the thickness and L.  ``results.json``: the energy-budget residual (the tractions' work
and the heat drawn by the 280 K core included), min J, the theta range, the probe's
displacement, and the four arm tips' vertical displacements (equal by symmetry).
"""
import numpy as np

from sphgen.errors import InputError
from sphgen.geometry import inside_rectangle, vertex_fractions, vertex_lattice
from sphgen.particles import ParticleArray

from ..equations.thermo_materials import MieGruneisen
from ._thermo_solid import ThermoSolid, checks

PAPER = dict(E_young=50.05e3, nu=0.45, rho=1000.0, Cv=1.0, alpha=2.223e-4, theta_R=293.15, k_th=10.0)
ARM, R_HUB = 0.4, 0.1
THETA_CORE, THETA_ENDS = 280.0, 300.0


def inside_gripper(r_in, width, thickness):
    """Shape function (x, y, z) -> mask of the closed gripper (hub and four arms)."""
    tol = 1e-9

    def inside(x, y, z):
        r2 = x * x + y * y
        hub = (r2 <= R_HUB ** 2 + tol) & (r2 >= r_in ** 2 - tol)
        arms = (((np.abs(x) <= ARM + tol) & (np.abs(y) <= 0.5 * width + tol))
                | ((np.abs(y) <= ARM + tol) & (np.abs(x) <= 0.5 * width + tol))) & (r2 >= R_HUB ** 2 - tol)
        return (hub | arms) & (z >= -thickness - tol) & (z <= tol)
    return inside


class ThermoGripper(ThermoSolid):
    """Four-armed thermo-elastic gripper under end tractions with a cold core (Ghavamian et al. 2021, sec. 7.5)."""

    tf = 0.5
    pfreq = 500
    default_variant = "reduced"
    default_jumps = "raw"
    default_projection = False
    probe_point = (ARM, 0.0, -0.03)

    def add_user_options(self, group):
        group.add_argument("--dx", type=float, default=0.01,
                           help="vertex spacing; must divide the thickness and L = 0.4 m (default %(default)s)")
        group.add_argument("--thickness", type=float, default=0.06, help="Z extent (default %(default)s m)")
        group.add_argument("--width", type=float, default=0.06, help="arm width (default %(default)s m)")
        group.add_argument("--r-in", type=float, default=0.05, help="hub's inner radius (default %(default)s m)")
        group.add_argument("--traction", type=float, default=-1000.0,
                           help="vertical traction on the end faces (default %(default)s N/m^2: downwards)")
        group.add_argument("--free", action="store_true", help="do not hold the hub's inner surface")
        self.add_scheme_options(group, "the paper's full scheme pulls J off det F at the arms' ends and stops "
                                       "with theta <= 0 or J <= 0 (0.26 s raw, 0.48 s limited at dx = 0.02; docs/thermo.md)")

    def consume_user_options(self, o):
        self.check_scheme_options(o)
        for name, L in (("--thickness", o.thickness), ("L", ARM)):
            if not (np.isfinite(o.dx) and 0 < o.dx <= 0.5 * L) or abs(L / o.dx - round(L / o.dx)) > 1e-6:
                raise InputError(f"--dx {o.dx} must divide {name} = {L:g} m (at least two cells)")
        if not (0 < o.r_in < R_HUB and 0 < o.width < 2 * R_HUB):
            raise InputError(f"need 0 < --r-in < {R_HUB} and 0 < --width < {2 * R_HUB}, got {o.r_in}, {o.width}")
        self.dx = o.dx
        self.material = MieGruneisen(**PAPER)

    def create_particles(self):
        o, dx = self.options, self.dx
        inside = inside_gripper(o.r_in, o.width, o.thickness)
        x, y, z = vertex_lattice(dx, -ARM, ARM, -ARM, ARM, -o.thickness, 0.0)
        V = dx ** 3 * vertex_fractions((x, y, z), inside, dx)
        keep = V > 0
        x, y, z, V = x[keep], y[keep], z[keep], V[keep]
        tol = 1e-9
        r = np.hypot(x, y)
        # inner surface: the vertex cells cut by r = r_in
        core = (r < o.r_in + dx) & (vertex_fractions((x, y), lambda a, b: a * a + b * b >= o.r_in ** 2, dx) < 1.0)
        ends = (np.abs(np.abs(x) - ARM) < tol) | (np.abs(np.abs(y) - ARM) < tol)
        # tributary areas of the end faces (the section in its own coordinates)
        lateral = np.where(np.abs(np.abs(x) - ARM) < tol, y, x)
        area = np.where(ends, dx * dx * vertex_fractions((lateral, z), inside_rectangle(
            -0.5 * o.width, 0.5 * o.width, -o.thickness, 0.0), dx), 0.0)
        theta = np.where(ends, THETA_ENDS, self.material.theta_R)
        self.set_probe(np.stack([x, y, z], 1))
        self.tips = [int(np.argmin(np.linalg.norm(np.stack([x, y, z], 1) - p, axis=1)))
                     for p in ([ARM, 0, -0.5 * o.thickness], [0, ARM, -0.5 * o.thickness],
                               [-ARM, 0, -0.5 * o.thickness], [0, -ARM, -0.5 * o.thickness])]
        px, py, pz = self.perturbed(x, y, z, dx)
        pa = ParticleArray("body", x=px, y=py, z=pz)
        pa.add_property("V", data=V)
        pa.add_property("theta", data=theta)
        pa.add_property("area", data=area)
        pa.add_property("tfix", data=core.astype(float))
        pa.add_property("thB", data=np.where(core, THETA_CORE, 0.0))
        if not o.free:
            pa.add_property("vfix", stride=3, data=np.repeat(core.astype(float), 3))
        print(f"thermo_gripper: dx={dx:g} N={x.size} (paper: not given); volume {V.sum():.5g} m^3; "
              f"{int(core.sum())} core particles (280 K{'' if o.free else ', held'}); end faces "
              f"{area.sum():.5g} m^2 on {int(ends.sum())} particles")
        return [pa]

    def create_scheme(self):
        s = self.make_scheme(self.material, self.dx)
        tz = self.options.traction

        def traction(t, pa):
            fb = np.zeros((pa.n, 3))
            fb[:, 2] = tz * pa.area / pa.V
            return fb, None

        s.add_load("body", traction)
        return s

    def case_meta(self):
        o = self.options
        return {"thickness": o.thickness, "width": o.width, "r_in": o.r_in, "traction": o.traction, "free": o.free}

    def post_process(self, outdir):
        """Energy budget (tractions and the core's heat), J and theta ranges, the arm tips."""
        pa = self.scene.by_name["body"]
        tips = []
        for g in self.tips:
            i = int(np.flatnonzero(pa.gid == g)[0])
            tips.append(float(pa.z[i] - pa.z0[i]))
        r = self.write_results(outdir, checks(self.history_columns, self.history, self.solver.t, 0.0),
                               {"tip_uz": tips, "tip_uz_spread": float(np.ptp(tips) / max(np.abs(tips).max(), 1e-300))})
        print(f"thermo_gripper: N={r['n_particles']} t={self.solver.t:.4g} ({self.options.variant}, "
              f"{self.options.jumps} jumps): energy residual {r['energy_residual']:.2e}, J_min {r['J_min']:.3f}, "
              f"theta {r['theta_range']}, probe u {np.round(r['probe_u'], 4).tolist()}, tip u_z {np.round(tips, 4).tolist()}")
