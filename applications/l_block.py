"""Free-flying L-shaped block of Ghavamian et al. (2021), sec. 7.2 (Figs. 4-9).

The block [0,3] x [0,10] x [0,3] U [3,6] x [0,3] x [0,3] m (``sphgen.geometry.l_block``, a
vertex lattice: particles on the faces, volumes dx^3 times the cell fraction inside) is
loaded by F1 = -F2 = [150, 300, 450] f(t), f = t up to 2.5 s, 5 - t to 5 s, 0 after, and
then flies freely to 40 s.  Insulated; theta = 300 K on the face Y = 10 and 250 K on the
face X = 6 at t = 0 (those face particles only), theta_R elsewhere.  Mie-Gruneisen,
E = 50.05 kPa, nu = 0.3, rho_R = 1000, k = 10, C_v = 1, alpha = 2.223e-4, theta_R = 293.15 K
(q = 1, neo-Hookean split), E-form, alpha_CFL = 0.3, angular-momentum projection on.

Not given by the paper (options, defaults documented in docs/thermo.md): which face gets
which force (``F1`` on Y = 10, ``F2`` on X = 6), whether F is a traction in N/m^2 (default,
applied as A_R t_B with the vertices' tributary areas) or a total force in N spread
uniformly (``--load force``: t = F / 9 m^2); ``--load-time`` T stretches the load history
(f peaks at 2.5 at T/2 and ends at T; the paper's T = 5 s) so that a short run also has a
free flight.

``history.json`` holds, every step: L, A (about the origin, current positions), sum V |p|,
K, internal, total and ballistic energy, entropy S, the accumulated W_ext, Q_in, E_Dir,
min J, the theta range, and v and u = x - X at the material point X = [0, 10, 0].
``results.json``: the checks of the issue -- the linear-momentum drift over sum V |p|, the
angular-momentum drift after the load relative to |A|, the energy-budget residual
relative to max_t(K + |W_ext| + |Q_in| + |E_Dir|) and the largest fall of S relative to
S(end) - S(0) -- and the final probe values.
"""
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import inside_rectangle, l_block, vertex_fractions
from sphgen.particles import ParticleArray

from ..equations.thermo_materials import MieGruneisen
from ..schemes.thermo_upwind import ThermoUpwindScheme

PAPER = dict(E_young=50.05e3, nu=0.3, rho=1000.0, Cv=1.0, alpha=2.223e-4, theta_R=293.15, k_th=10.0)
FORCE = np.array([150.0, 300.0, 450.0])
HEIGHT, LENGTH, WIDTH, DEPTH = 10.0, 6.0, 3.0, 3.0
PROBE = np.array([0.0, 10.0, 0.0])


def load_history(t, T=5.0):
    """f(t): 2.5 * (t / (T/2)) rising, falling back to 0 at T, then 0 (the paper's f with T = 5 s)."""
    s = t / (0.5 * T)
    return 2.5 * (s if s < 1.0 else (2.0 - s if s < 2.0 else 0.0))


class LBlock(Application):
    """Free-flying thermo-elastic L-shaped block (Ghavamian et al. 2021, sec. 7.2)."""

    tf = 40.0
    pfreq = 500
    dim = 3
    history_columns = ("t", "L_x", "L_y", "L_z", "A_x", "A_y", "A_z", "sum_V_abs_p", "kinetic", "internal",
                       "total", "ballistic", "entropy", "W_ext", "Q_in", "E_Dir", "J_min", "theta_min",
                       "theta_max", "probe_vx", "probe_vy", "probe_vz", "probe_ux", "probe_uy", "probe_uz")

    def add_user_options(self, group):
        group.add_argument("--dx", type=float, default=0.5,
                           help="vertex spacing; 10, 6, 3 must be multiples (default %(default)s: 1323 particles)")
        group.add_argument("--hdx", type=float, default=1.2, help="h / dx (default %(default)s)")
        group.add_argument("--kernel", choices=("wendland", "quintic"), default="wendland",
                           help="smoothing kernel (default %(default)s)")
        group.add_argument("--jumps", choices=("limited", "raw"), default="limited",
                           help="dissipation on limited reconstructed jumps or the paper's raw jumps")
        group.add_argument("--form", choices=("E", "eta"), default="E", help="total energy or entropy")
        group.add_argument("--reduced", action="store_true",
                           help="the reduced {p, F, H, E} scheme (J = det F, no J equation)")
        group.add_argument("--no-DJ", dest="dj", action="store_false",
                           help="drop the J dissipation D_J (an ablation, docs/thermo.md)")
        group.add_argument("--no-projection", dest="projection", action="store_false",
                           help="switch the angular-momentum projection (eqs. 79-82) off")
        group.add_argument("--load", choices=("traction", "force"), default="traction",
                           help="F1, F2 as tractions in N/m^2 (default) or total forces in N")
        group.add_argument("--load-time", type=float, default=5.0,
                           help="end of the load history T (default %(default)s s, the paper's)")
        group.add_argument("--face-temperatures", type=float, nargs=2, default=(300.0, 250.0),
                           metavar=("Y10", "X6"), help="initial theta on the faces Y = 10 and X = 6 "
                           "(default %(default)s K, the paper's)")
        group.add_argument("--cfl", type=float, default=0.3, help="alpha_CFL of eq. 78 (default %(default)s)")

    def consume_user_options(self, o):
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
        self.dx = dx
        self.material = MieGruneisen(**PAPER)
        self.probe = None

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
        pa = ParticleArray("body", x=x, y=y, z=z)
        pa.add_property("V", data=V)
        pa.add_property("theta", data=theta)
        pa.add_property("area", data=area)
        pa.add_property("face", data=np.where(top, 1.0, np.where(end, 2.0, 0.0)))
        print(f"l_block: dx={dx:g} N={x.size} (paper: 680/1900/5400/17600); loaded faces "
              f"{area[top].sum():.6g} and {area[end].sum():.6g} m^2")
        return [pa]

    def create_scheme(self):
        o = self.options
        s = ThermoUpwindScheme(["body"], self.material, self.dx, hdx=o.hdx, kernel=o.kernel, form=o.form,
                               jumps=o.jumps, projection=o.projection, cfl=o.cfl, reduced=o.reduced,
                               dissipation=True if o.dj else "p")
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

    # ------------------------------------------------------------------ time series
    def _execute(self):
        if not self.solver.restarted:
            self.post_step(self.solver)       # the row at t = 0
        return super()._execute()

    def post_step(self, solver):
        pa = self.scene.by_name["body"]
        if self.probe is None or pa.x0[self.probe] != PROBE[0] or pa.y0[self.probe] != PROBE[1]:
            X = np.stack([pa.x0, pa.y0, pa.z0], 1)
            self.probe = int(np.argmin(np.linalg.norm(X - PROBE, axis=1)))
        x = np.stack([pa.x, pa.y, pa.z], 1)
        p = pa.rho[:, None] * np.stack([pa.u, pa.v, pa.w], 1)
        L = (pa.V[:, None] * p).sum(0)
        A = (pa.V[:, None] * np.cross(x, p)).sum(0)
        e = self.scheme.energies([pa])
        i = self.probe
        u = [pa.x[i] - pa.x0[i], pa.y[i] - pa.y0[i], pa.z[i] - pa.z0[i]]
        self.history.append([solver.t, *L, *A, float(np.sum(pa.V * np.linalg.norm(p, axis=1))),
                             e["kinetic"], e["internal"], e["total"], e["ballistic"], e["entropy"],
                             e["W_ext"], e["Q_in"], e["E_Dir"], float(pa.J.min()), float(pa.theta.min()),
                             float(pa.theta.max()), pa.u[i], pa.v[i], pa.w[i], *u])

    def history_meta(self):
        o = self.options
        return {"dx": self.dx, "jumps": o.jumps, "form": o.form, "projection": o.projection, "load": o.load,
                "load_time": o.load_time, "reduced": o.reduced, "D_J": o.dj, "hdx": o.hdx, "kernel": o.kernel, "cfl": o.cfl,
                "face_temperatures": list(o.face_temperatures)}

    def post_process(self, outdir):
        o = self.options
        pa = self.scene.by_name["body"]
        if not self.history:
            raise InputError("l_block: no steps were taken (--tf too small)")
        results = {"t": self.solver.t, "dx": self.dx, "n_particles": pa.n, "steps": self.solver.step,
                   **self.history_meta(), **checks(self.history_columns, self.history, o.load_time),
                   "material": self.material.parameters()}
        io.write_json(os.path.join(outdir, "results.json"), results)
        io.write_json(os.path.join(outdir, "history.json"),
                      {"columns": list(self.history_columns), "rows": self.history, **self.history_meta()})
        from sphgen.tools.plots import plot_series
        plot_series(os.path.join(outdir, "history.json"), os.path.join(outdir, "history.png"))
        print(f"l_block: N={pa.n} t={self.solver.t:.4g}: |dL|/sum V|p| {results['L_drift']:.2e}, "
              f"|dA|/|A| after the load {results['A_drift']}, energy residual {results['energy_residual']:.2e}, "
              f"S fall {results['entropy_fall']:.2e}")


def checks(columns, rows, load_time):
    """The conservation and second-law checks of the issue from the time series (its first
    row, at t = 0, is the reference)."""
    h = np.array(rows, dtype=float)
    c = {k: h[:, i] for i, k in enumerate(columns)}
    L = np.stack([c["L_x"], c["L_y"], c["L_z"]], 1)
    A = np.stack([c["A_x"], c["A_y"], c["A_z"]], 1)
    out = {"L_drift": float(np.abs(L - L[0]).max() / max(c["sum_V_abs_p"].max(), 1e-300))}
    free = c["t"] >= load_time - 1e-12
    if free.sum() >= 2:
        Af = A[free]
        out["A_drift"] = float(np.abs(Af - Af[0]).max() / np.linalg.norm(Af[0]))
        out["A_free"] = Af[0].tolist()
    else:
        out["A_drift"] = None
    res = (c["total"] - c["total"][0]) - sum(c[k] - c[k][0] for k in ("W_ext", "Q_in", "E_Dir"))
    scale = np.max(c["kinetic"] + np.abs(c["W_ext"]) + np.abs(c["Q_in"]) + np.abs(c["E_Dir"]))
    out["energy_residual"] = float(np.abs(res).max() / scale)
    dS = np.diff(c["entropy"])
    rise = c["entropy"][-1] - c["entropy"][0]
    out["entropy_rise"] = float(rise)
    out["entropy_fall"] = float(max(0.0, -dS.min()) / abs(rise)) if dS.size and rise != 0 else 0.0
    out["W_ext"] = float(c["W_ext"][-1])
    out["J_min"] = float(c["J_min"].min())
    out["theta_range"] = [float(c["theta_min"].min()), float(c["theta_max"].max())]
    out["probe_v"] = [float(c[f"probe_v{k}"][-1]) for k in "xyz"]
    out["probe_u"] = [float(c[f"probe_u{k}"][-1]) for k in "xyz"]
    return out
