"""Spherical ball of Ghavamian et al. (2021), sec. 7.6 (Figs. 23-24): a thin perforated shell
punched on its top and heated on its inner surface.

The paper gives v0 = [0, 0, -1.5] m/s "on its top surface" (eq. 95), theta = theta_R at
t = 0, Q_B = 470.871 kW/m^2 on the inner surface for t >= 0 (eq. 96), modified entropic
elasticity with E = 17 MPa, nu = 0.3, rho_R = 1100, k = 0.2, C_v = 1000, alpha = 2.223e-4,
theta_R = 293.15 K, and snapshots to t = 0.042 s; not the radii, the holes, which particles
move, the supports, the flux's sign or the resolution (Fig. 23 is a sketch).  Defaults (the
digest's; options): outer radius 0.1 m, wall 0.01 m (``--radius``, ``--wall``); six
circular holes of radius 0.025 m (``--hole-radius``) centred at (polar, azimuth) = (45, 0),
(60, 100), (90, 200), (110, 40), (135, 250), (80, 300) degrees (an asymmetric pattern; a
hole is the cylinder of that radius along the radial line through its centre); v0 on the
top cap Z >= 0.07 m only, the rest at rest (a uniform v0 would only translate the ball); a
roller (v_Z = 0) on the bottom cap Z <= -0.07 m; the heat flux *into* the shell (as for
the disk), shared by the particles whose vertex cells are cut by the inner sphere in
proportion to their volumes, so that the heat rate is exactly Q_B times the perforated
inner area; the outer surface insulated.  E-form, alpha_CFL = 0.3, raw jumps (the paper's),
no projection (the roller takes momentum); to 0.042 s.  Default scheme: the reduced
{p, F, H, E} (J = det F); the paper's full {p, F, H, J, E} (``--variant full``) stops on
this case as on the L-block and the gripper (docs/thermo.md).

Lattice: the vertices of spacing ``--dx`` through the centre inside the shell, volumes dx^3
times the fraction of the vertex cell inside (2^3 sub-cells).  ``results.json``: the
energy-budget residual (the heat input is the only external term: the roller does no work),
min J, the theta range, the mean temperature of the heated particles and the probe (the
top pole).
"""
import numpy as np

from sphgen.errors import InputError
from sphgen.geometry import vertex_fractions, vertex_lattice
from sphgen.particles import ParticleArray

from ..equations.thermo_materials import ModifiedEntropicElasticity
from ._thermo_solid import ThermoSolid, checks

PAPER = dict(E_young=17e6, nu=0.3, rho=1100.0, Cv=1000.0, alpha=2.223e-4, theta_R=293.15, k_th=0.2)
V_PUNCH, Q_B, CAP = -1.5, 470.871e3, 0.07
HOLES = ((45, 0), (60, 100), (90, 200), (110, 40), (135, 250), (80, 300))


def hole_axes():
    """Unit vectors of the holes' centres (rows)."""
    th, ph = np.radians(np.array(HOLES, dtype=float)).T
    return np.stack([np.sin(th) * np.cos(ph), np.sin(th) * np.sin(ph), np.cos(th)], 1)


def in_holes(x, y, z, r_hole):
    """Mask of the points inside any hole (within r_hole of a hole's radial half-line)."""
    p = np.stack([x, y, z], -1)
    out = np.zeros(np.shape(x), dtype=bool)
    for c in hole_axes():
        along = p @ c
        off = np.linalg.norm(p - along[..., None] * c, axis=-1)
        out |= (along > 0) & (off < r_hole)
    return out


def inside_ball(r_out, r_in, r_hole):
    """Shape function (x, y, z) -> mask of the perforated shell r_in <= r <= r_out."""
    def inside(x, y, z):
        r2 = x * x + y * y + z * z
        return (r2 <= r_out ** 2) & (r2 >= r_in ** 2) & ~in_holes(x, y, z, r_hole)
    return inside


def perforated_area_fraction(r_hole, radius, n=200000):
    """The fraction of the sphere of ``radius`` outside the holes (Fibonacci points)."""
    k = np.arange(n) + 0.5
    z = 1 - 2 * k / n
    phi = np.pi * (1 + 5 ** 0.5) * k
    s = np.sqrt(1 - z * z)
    return float(1 - in_holes(radius * s * np.cos(phi), radius * s * np.sin(phi), radius * z, r_hole).mean())


class ThermoBall(ThermoSolid):
    """Thin perforated thermo-elastic ball punched on top and heated inside (Ghavamian et al. 2021, sec. 7.6)."""

    tf = 0.042
    pfreq = 500
    default_variant = "reduced"
    default_jumps = "raw"
    default_projection = False
    probe_point = (0.0, 0.0, 0.1)

    def add_user_options(self, group):
        group.add_argument("--dx", type=float, default=0.0025,
                           help="vertex spacing (default %(default)s m: 5 layers across the wall)")
        group.add_argument("--radius", type=float, default=0.1, help="outer radius (default %(default)s m)")
        group.add_argument("--wall", type=float, default=0.01, help="wall thickness (default %(default)s m)")
        group.add_argument("--hole-radius", type=float, default=0.025, help="holes' radius (default %(default)s m)")
        group.add_argument("--heat", choices=("in", "out"), default="in",
                           help="Q_B enters the shell (default) or leaves it")
        self.add_scheme_options(group, "the paper's full scheme pulls J off det F and stops (J <= 0 at 0.0044 s "
                                       "at dx = 0.01; docs/thermo.md)")

    def consume_user_options(self, o):
        self.check_scheme_options(o)
        if not (np.isfinite(o.radius) and 0 < o.wall < o.radius and 0 <= o.hole_radius < 0.5 * o.radius):
            raise InputError(f"need 0 < --wall < --radius and 0 <= --hole-radius < radius/2, got "
                             f"{o.wall}, {o.radius}, {o.hole_radius}")
        if not (np.isfinite(o.dx) and 0 < o.dx <= o.wall):
            raise InputError(f"--dx must lie in (0, wall = {o.wall:g}], got {o.dx}")
        self.dx = o.dx
        self.material = ModifiedEntropicElasticity(**PAPER)

    def create_particles(self):
        o, dx = self.options, self.dx
        r_in = o.radius - o.wall
        n = int(np.ceil(o.radius / dx))
        x, y, z = vertex_lattice(dx, -n * dx, n * dx, -n * dx, n * dx, -n * dx, n * dx)
        V = dx ** 3 * vertex_fractions((x, y, z), inside_ball(o.radius, r_in, o.hole_radius), dx)
        keep = V > 0
        x, y, z, V = x[keep], y[keep], z[keep], V[keep]
        r = np.sqrt(x * x + y * y + z * z)
        inner = (r < r_in + dx) & (vertex_fractions((x, y, z), lambda a, b, c: a * a + b * b + c * c >= r_in ** 2,
                                                    dx) < 1.0)
        area_total = 4 * np.pi * r_in ** 2 * perforated_area_fraction(o.hole_radius, r_in)
        area = np.where(inner, V, 0.0)
        area *= area_total / area.sum()
        top, bottom = z >= CAP - 1e-12, z <= -CAP + 1e-12
        vfix = np.zeros((x.size, 3))
        vfix[bottom, 2] = 1.0
        self.set_probe(np.stack([x, y, z], 1))
        px, py, pz = self.perturbed(x, y, z, dx)
        pa = ParticleArray("body", x=px, y=py, z=pz, w=np.where(top, V_PUNCH, 0.0))
        pa.add_property("V", data=V)
        pa.add_property("area", data=area)
        pa.add_property("vfix", stride=3, data=vfix.ravel())
        print(f"thermo_ball: dx={dx:g} N={x.size} (paper: not given); volume {V.sum():.5g} m^3; heated inner "
              f"area {area_total:.5g} m^2 on {int(inner.sum())} particles; {int(top.sum())} punched, "
              f"{int(bottom.sum())} on the roller")
        return [pa]

    def create_scheme(self):
        s = self.make_scheme(self.material, self.dx)
        q = Q_B if self.options.heat == "in" else -Q_B

        def flux(t, pa):
            return None, q * pa.area / pa.V

        s.add_load("body", flux)
        return s

    def case_meta(self):
        o = self.options
        return {"radius": o.radius, "wall": o.wall, "hole_radius": o.hole_radius, "heat": o.heat}

    def post_process(self, outdir):
        """Energy budget (the heat input), J and theta ranges, the heated particles' mean theta."""
        pa = self.scene.by_name["body"]
        heated = pa.area > 0
        r = self.write_results(outdir, checks(self.history_columns, self.history, self.solver.t, 0.0),
                               {"heated_theta_mean": float(np.sum(pa.V[heated] * pa.theta[heated])
                                                           / np.sum(pa.V[heated]))})
        print(f"thermo_ball: N={r['n_particles']} t={self.solver.t:.4g} ({self.options.variant}, "
              f"{self.options.jumps} jumps): energy residual {r['energy_residual']:.2e}, Q_in {r['Q_in']:.4g} J, "
              f"J_min {r['J_min']:.3f}, theta {np.round(r['theta_range'], 2).tolist()}, heated mean theta "
              f"{r['heated_theta_mean']:.2f} K, top pole u {np.round(r['probe_u'], 4).tolist()}")
