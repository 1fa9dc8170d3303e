"""Free-flying L-shaped block of Ghavamian et al. (2021), sec. 7.2 (Figs. 4-9).

The block [0,3] x [0,10] x [0,3] U [3,6] x [0,3] x [0,3] m (``sphgen.geometry.l_block``, a
vertex lattice: particles on the faces, volumes dx^3 times the cell fraction inside) is
loaded by F1 = -F2 = [150, 300, 450] f(t), f = t up to 2.5 s, 5 - t to 5 s, 0 after, and
then flies freely to 40 s.  Insulated; theta = 300 K on the face Y = 10 and 250 K on the
face X = 6 at t = 0 (those face particles only), theta_R elsewhere.  Mie-Gruneisen,
E = 50.05 kPa, nu = 0.3, rho_R = 1000, k = 10, C_v = 1, alpha = 2.223e-4, theta_R = 293.15 K
(q = 1, neo-Hookean split), E-form, alpha_CFL = 0.3, angular-momentum projection on.

Default scheme: the reduced {p, F, H, E} (``--variant reduced``, J = det F), which runs to
40 s; the paper's full {p, F, H, J, E} (``--variant full``) drifts J away from det F through
D_J at the edges of the re-entrant corner and stops with J <= 0 or theta <= 0 near t = 5 s
on every lattice we tried (docs/thermo.md); ``--variant full-no-DJ`` also runs to 40 s.

Not given by the paper (options, defaults documented in docs/thermo.md): which face gets
which force (``F1`` on Y = 10, ``F2`` on X = 6), whether F is a traction in N/m^2 (default,
applied as A_R t_B with the vertices' tributary areas) or a total force in N spread
uniformly (``--load force``: t = F / 9 m^2); ``--load-time`` T stretches the load history
(f peaks at 2.5 at T/2 and ends at T; the paper's T = 5 s) so that a short run also has a
free flight.

``history.json`` holds, every step: L, A (about the origin, current positions), sum V |p|,
K, internal, total and ballistic energy, entropy S, the accumulated W_ext, Q_in, E_Dir,
min J, the theta range, and v, u = x - X, theta and P_11 at the material point X = [0, 10, 0].
``results.json``: the checks of the issue -- the linear-momentum drift over sum V |p|, the
angular-momentum drift after the load relative to |A|, the energy-budget residual
relative to max_t(K + |W_ext| + |Q_in| + |E_Dir|), the largest fall of S relative to
S(end) - S(0) and the largest rise of B after the load relative to its fall -- and the
final probe values.
"""
import os

import numpy as np

from sphgen.errors import InputError
from sphgen.geometry import inside_rectangle, l_block, vertex_fractions
from sphgen.particles import ParticleArray

from ..equations.thermo_materials import MieGruneisen
from ._thermo_solid import ThermoSolid, checks, columns_of, probe_error

PAPER = dict(E_young=50.05e3, nu=0.3, rho=1000.0, Cv=1.0, alpha=2.223e-4, theta_R=293.15, k_th=10.0)
FORCE = np.array([150.0, 300.0, 450.0])
HEIGHT, LENGTH, WIDTH, DEPTH = 10.0, 6.0, 3.0, 3.0
PROBE = np.array([0.0, 10.0, 0.0])


def load_history(t, T=5.0):
    """f(t): 2.5 * (t / (T/2)) rising, falling back to 0 at T, then 0 (the paper's f with T = 5 s)."""
    s = t / (0.5 * T)
    return 2.5 * (s if s < 1.0 else (2.0 - s if s < 2.0 else 0.0))


class LBlock(ThermoSolid):
    """Free-flying thermo-elastic L-shaped block (Ghavamian et al. 2021, sec. 7.2)."""

    tf = 40.0
    pfreq = 500
    default_variant = "reduced"
    probe_point = PROBE
    error_key = "probe_error"   # `sphgen precision l_block --dx ... --reference-run DIR`

    def add_user_options(self, group):
        group.add_argument("--dx", type=float, default=0.5,
                           help="vertex spacing; 10, 6, 3 must be multiples (default %(default)s: 1323 particles)")
        self.add_scheme_options(group, "the paper's full scheme drifts J away from det F through D_J and "
                                       "stops with J <= 0 or theta <= 0 near t = 5 s on this case (docs/thermo.md)")
        group.add_argument("--reference-run", default=None, metavar="DIR",
                           help="a finished l_block run (its history.json): results.json gets probe_error, "
                                "the relative L2-in-time distance of the probe's u from that run's "
                                "(`sphgen precision l_block`)")
        group.add_argument("--load", choices=("traction", "force"), default="traction",
                           help="F1, F2 as tractions in N/m^2 (default) or total forces in N")
        group.add_argument("--load-time", type=float, default=5.0,
                           help="end of the load history T (default %(default)s s, the paper's)")
        group.add_argument("--face-temperatures", type=float, nargs=2, default=(300.0, 250.0),
                           metavar=("Y10", "X6"), help="initial theta on the faces Y = 10 and X = 6 "
                           "(default %(default)s K, the paper's)")

    def consume_user_options(self, o):
        self.check_scheme_options(o)
        dx = o.dx
        if not (np.isfinite(dx) and 0 < dx <= 1.5):
            raise InputError(f"--dx must lie in (0, 1.5], got {dx}")
        for L in (HEIGHT, LENGTH, WIDTH):
            if abs(L / dx - round(L / dx)) > 1e-6:
                raise InputError(f"--dx {dx} must divide {L:g} (the block's dimensions 10, 6 and 3 m)")
        if not all(np.isfinite(th) and th > 0 for th in o.face_temperatures):
            raise InputError(f"--face-temperatures must be positive, got {o.face_temperatures}")
        if not (np.isfinite(o.load_time) and o.load_time > 0):
            raise InputError(f"--load-time must be positive, got {o.load_time}")
        if o.reference_run is not None and not os.path.isfile(os.path.join(o.reference_run, "history.json")):
            raise InputError(f"--reference-run {o.reference_run}: no history.json there")
        self.dx = dx
        self.material = MieGruneisen(**PAPER)

    def create_particles(self):
        o, dx = self.options, self.dx
        x, y, z, V = l_block(dx, HEIGHT, LENGTH, WIDTH, DEPTH)
        tol = 1e-9
        top = np.abs(y - HEIGHT) < tol             # face of F1 (3 x 3 m^2 at Y = 10)
        end = np.abs(x - LENGTH) < tol             # face of F2 (3 x 3 m^2 at X = 6)
        area = np.zeros(x.size)
        area[top] = dx * dx * vertex_fractions((x[top], z[top]), inside_rectangle(0, WIDTH, 0, DEPTH), dx)
        area[end] = dx * dx * vertex_fractions((y[end], z[end]), inside_rectangle(0, WIDTH, 0, DEPTH), dx)
        theta = np.full(x.size, self.material.theta_R)
        theta[top], theta[end] = o.face_temperatures
        self.set_probe(np.stack([x, y, z], 1))
        px, py, pz = self.perturbed(x, y, z, dx)
        pa = ParticleArray("body", x=px, y=py, z=pz)
        pa.add_property("V", data=V)
        pa.add_property("theta", data=theta)
        pa.add_property("area", data=area)
        pa.add_property("face", data=np.where(top, 1.0, np.where(end, 2.0, 0.0)))
        print(f"l_block: dx={dx:g} N={x.size} (paper: 680/1900/5400/17600); loaded faces "
              f"{area[top].sum():.6g} and {area[end].sum():.6g} m^2")
        return [pa]

    def create_scheme(self):
        o = self.options
        s = self.make_scheme(self.material, self.dx)
        scale = 1.0 / (WIDTH * DEPTH) if o.load == "force" else 1.0
        T = o.load_time

        def tractions(t, pa):
            f = load_history(t, T)
            if f == 0.0:
                return None, None
            sign = np.where(pa.face == 1.0, 1.0, np.where(pa.face == 2.0, -1.0, 0.0))
            w = sign * pa.area / pa.V * scale * f
            return w[:, None] * FORCE[None, :], None

        s.add_load("body", tractions)
        return s

    def _signature(self, arrays):
        """The scene's identity for restarts: --reference-run only changes the analysis."""
        sig = super()._signature(arrays)
        sig["options"].pop("reference_run", None)
        return sig

    def case_meta(self):
        o = self.options
        return {"load": o.load, "load_time": o.load_time, "face_temperatures": list(o.face_temperatures)}

    def post_process(self, outdir):
        """The checks: A and E_tot from the end of the load, S (insulated) from t = 0 and B from
        the end of the load."""
        T = self.options.load_time
        b = checks(self.history_columns, self.history, T, T)
        extra = {"ballistic_rise": b["ballistic_rise"], "ballistic_drop": b["ballistic_drop"]}
        if self.options.reference_run:
            extra.update(probe_error(columns_of(self.history_columns, self.history), self.options.reference_run))
        r = self.write_results(outdir, checks(self.history_columns, self.history, T, 0.0), extra)
        print(f"l_block: N={r['n_particles']} t={self.solver.t:.4g} ({self.options.variant}): |dL|/sum V|p| "
              f"{r['L_drift']:.2e}, |dA|/|A| after the load {r['A_drift']}, energy residual "
              f"{r['energy_residual']:.2e}, S fall {r['entropy_fall']}, B rise {r['ballistic_rise']} "
              f"(None: the run ended before the load did)")
