"""What the thermo-elastic solid applications of Ghavamian et al. (2021), sec. 7, share: the
scheme's options (variant, form, jumps, kernel, projection, CFL, lattice perturbation), the
per-step time series (momenta, energies, entropy, budget, J and theta ranges, a probe), the
checks of issue 12 on it, and the checkerboard indicator R[p].

Variants (``--variant``): ``full`` is the paper's {p, F, H, J, E} scheme with D_J (eqs.
54d, 66, 73), ``reduced`` the {p, F, H, E} scheme of its Fig. 16 (J = det F, no D_J;
with ``--form eta`` the {p, F, H, eta} scheme, ours, not the paper's),
``full-no-DJ`` the full scheme without D_J (an ablation), ``full-vol`` the full scheme
with D_J acting on the mean stress and on J, F, H together (not the paper's; docs/thermo.md),
``full-pJ`` the full scheme with D_J on the jump of the volumetric part of Sigma_J only (a
diagnostic of round 10, docs/thermo.md: its dissipation has no sign).
"""
import json
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import perturb, vertex_fractions, vertex_lattice
from sphgen.kernels import get_kernel

from ..schemes.thermo_upwind import ThermoUpwindScheme

VARIANTS = {"full": dict(reduced=False, dissipation=True), "reduced": dict(reduced=True, dissipation=True),
            "full-no-DJ": dict(reduced=False, dissipation="p"),
            "full-vol": dict(reduced=False, dissipation=True, dj="volumetric"),
            "full-pJ": dict(reduced=False, dissipation=True, dj="pressure")}

PAPER_CFL = 0.3     # alpha_CFL of eq. 78, the paper's


class ThermoSolid(Application):
    """Base of the sec. 7 applications of Ghavamian et al. (2021): subclasses set
    ``default_variant``, ``default_jumps``, ``default_projection``, ``default_cfl``,
    ``probe_point`` and build particles and loads."""

    dim = 3
    default_variant = "full"
    default_jumps = "limited"
    default_cfl = PAPER_CFL
    default_projection = True
    probe_point = (0.0, 0.0, 0.0)
    history_columns = ("t", "L_x", "L_y", "L_z", "A_x", "A_y", "A_z", "sum_V_abs_p", "kinetic", "internal",
                       "total", "ballistic", "entropy", "W_ext", "Q_in", "E_Dir", "J_min", "theta_min",
                       "theta_max", "probe_vx", "probe_vy", "probe_vz", "probe_ux", "probe_uy", "probe_uz",
                       "probe_theta", "probe_P11", "W_proj", "S_proj")

    def add_scheme_options(self, group, variant_help):
        """The scheme's options; ``variant_help`` says why the default variant is the default."""
        group.add_argument("--variant", choices=tuple(VARIANTS), default=self.default_variant,
                           help=f"full {{p, F, H, J, E}} (the paper's), reduced {{p, F, H, E}} (J = det F; "
                                f"with --form eta {{p, F, H, eta}}, ours), "
                                f"full-no-DJ (D_J dropped), full-vol (D_J on the mean stress, moving J, F, H "
                                f"together) or full-pJ (D_J on the volumetric part of Sigma_J; a diagnostic); default %(default)s: {variant_help}")
        group.add_argument("--hdx", type=float, default=1.2, help="h / dx (default %(default)s)")
        group.add_argument("--kernel", choices=("wendland", "quintic"), default="wendland",
                           help="smoothing kernel (default %(default)s)")
        group.add_argument("--jumps", choices=("limited", "raw"), default=self.default_jumps,
                           help="dissipation on limited reconstructed jumps or the paper's raw jumps "
                                "(default %(default)s)")
        group.add_argument("--form", choices=("E", "eta"), default="E", help="total energy or entropy")
        if self.default_projection:
            group.add_argument("--no-projection", dest="projection", action="store_false",
                               help="switch the angular-momentum projection (eqs. 79-82) off")
        else:
            group.add_argument("--projection", dest="projection", action="store_true",
                               help="switch the angular-momentum projection (eqs. 79-82) on")
        group.add_argument("--SE", dest="se", choices=("zero", "matched"), default="zero",
                           help="E-form temperature dissipation S^E: zero (default; S^E = 0) or matched "
                                "(eq. 76, guarded: 0 at equal temperatures and for a negative bracket, "
                                "capped at the pair's conductance; docs/thermo.md)")
        papers = "" if self.default_cfl == PAPER_CFL else f"; the paper's {PAPER_CFL}"
        group.add_argument("--cfl", type=float, default=self.default_cfl,
                           help=f"alpha_CFL of eq. 78 (default %(default)s{papers})")
        group.add_argument("--perturb", type=float, default=0.0,
                           help="random perturbation of the reference lattice in units of dx (default 0)")
        group.add_argument("--seed", type=int, default=1, help="seed of the perturbation (default 1)")
        group.add_argument("--output-at", type=float, nargs="+", default=(), metavar="T",
                           help="also write the particles at these times (the step is shortened to hit "
                                "each; for the figures' snapshots)")

    def check_scheme_options(self, o):
        if not (np.isfinite(o.perturb) and 0 <= o.perturb < 0.5):
            raise InputError(f"--perturb must be in [0, 0.5), got {o.perturb}")
        if not all(np.isfinite(t) and t >= 0 for t in o.output_at):
            raise InputError(f"--output-at times must be finite and >= 0, got {o.output_at}")
        if o.se == "matched" and o.form != "E":
            raise InputError("--SE matched belongs to the E-form (--form E)")

    def _solver(self, integrator, dt):
        solver = super()._solver(integrator, dt)
        solver.output_at_times = sorted(t for t in self.options.output_at if 0 < t <= self.options.tf)
        return solver

    def perturbed(self, x, y, z, dx):
        """The lattice moved by --perturb dx at random (the volumes stay)."""
        o = self.options
        if o.perturb <= 0:
            return x, y, z
        return perturb((x, y, z), o.perturb * dx, o.seed)

    def make_scheme(self, material, dx):
        o = self.options
        return ThermoUpwindScheme(["body"], material, dx, hdx=o.hdx, kernel=o.kernel, form=o.form,
                                  jumps=o.jumps, projection=o.projection, cfl=o.cfl, se=o.se,
                                  **VARIANTS[o.variant])

    def set_probe(self, X):
        """The particle (its gid: the creation index; sorting moves particles in memory) nearest
        to ``probe_point`` among the (unperturbed) lattice points X (n, 3)."""
        self.probe = int(np.argmin(np.linalg.norm(X - np.asarray(self.probe_point), axis=1)))
        return self.probe

    # ------------------------------------------------------------------ time series
    def _execute(self):
        if not self.solver.restarted:
            self.post_step(self.solver)       # the row at t = 0
        return super()._execute()

    def post_step(self, solver):
        pa = self.scene.by_name["body"]
        x = np.stack([pa.x, pa.y, pa.z], 1)
        p = pa.rho[:, None] * np.stack([pa.u, pa.v, pa.w], 1)
        L = (pa.V[:, None] * p).sum(0)
        A = (pa.V[:, None] * np.cross(x, p)).sum(0)
        e = self.scheme.energies([pa])
        i = int(np.flatnonzero(pa.gid == self.probe)[0])
        u = [pa.x[i] - pa.x0[i], pa.y[i] - pa.y0[i], pa.z[i] - pa.z0[i]]
        self.history.append([solver.t, *L, *A, float(np.sum(pa.V * np.linalg.norm(p, axis=1))),
                             e["kinetic"], e["internal"], e["total"], e["ballistic"], e["entropy"],
                             e["W_ext"], e["Q_in"], e["E_Dir"], float(pa.J.min()), float(pa.theta.min()),
                             float(pa.theta.max()), pa.u[i], pa.v[i], pa.w[i], *u, pa.theta[i], pa.P[9 * i],
                             e["W_proj"], e["S_proj"]])

    def history_meta(self):
        o = self.options
        return {"dx": self.dx, "variant": o.variant, "jumps": o.jumps, "form": o.form, "se": o.se,
                "projection": o.projection,
                "hdx": o.hdx, "kernel": o.kernel, "cfl": o.cfl, "perturb": o.perturb, "seed": o.seed,
                "probe_X": list(self.probe_point), **self.case_meta()}

    def case_meta(self):
        return {}

    def write_results(self, outdir, checks_, extra=None):
        """results.json (the checks and the case), history.json and its plot."""
        pa = self.scene.by_name["body"]
        if not self.history:
            raise InputError(f"{self.name}: no steps were taken (--tf too small)")
        results = {"t": self.solver.t, "n_particles": pa.n, "steps": self.solver.step, **self.history_meta(),
                   **checks_, **(extra or {}), "material": self.material.parameters()}
        io.write_json(os.path.join(outdir, "results.json"), results)
        io.write_json(os.path.join(outdir, "history.json"),
                      {"columns": list(self.history_columns), "rows": self.history, **self.history_meta()})
        from sphgen.tools.plots import plot_series
        plot_series(os.path.join(outdir, "history.json"), os.path.join(outdir, "history.png"))
        return results


def cylinder_lattice(dx, r_out, z0, z1, r_in=0.0):
    """Vertices of spacing dx (a lattice through the origin) in the hollow cylinder r_in <= r
    <= r_out, z0 <= z <= z1 (axis Z): (x, y, z, V, f) with V = dx^3 times the fraction of the
    vertex cell inside (2^3 sub-cells) and f the fraction of its cell inside radially (< 1
    on the curved surfaces)."""
    x, y, z = vertex_lattice(dx, -r_out, r_out, -r_out, r_out, z0, z1)
    tol = 1e-9 * r_out

    def ring(a, b, *c):
        r2 = a * a + b * b
        return (r2 <= r_out * r_out) & (r2 >= r_in * r_in)

    V = dx ** 3 * vertex_fractions((x, y, z), lambda a, b, c: ring(a, b) & (c >= z0 - tol) & (c <= z1 + tol), dx)
    keep = (V > 0) & (x * x + y * y <= (r_out + tol) ** 2) & (x * x + y * y >= (r_in - tol) ** 2)
    x, y, z, V = x[keep], y[keep], z[keep], V[keep]
    return x, y, z, V, vertex_fractions((x, y), ring, dx)


def surface_tributary_areas(X, samples, sample_area, radius):
    """Tributary areas of a boundary surface on the particles X (n, 3): each surface sample
    point (m, 3), of area ``sample_area`` (scalar or (m,)), goes to the particle nearest to it
    (within ``radius``), so a particle carries the part of the surface closest to it and the
    areas sum to the surface's (the boundary flux A_R Q_B of Ghavamian et al. 2021, eq. 54e)."""
    from sphgen.tools.probes import pairs_within
    i, j, r = pairs_within(samples.T, X.T, radius)
    order = np.lexsort((r, i))
    first = order[np.r_[True, i[order][1:] != i[order][:-1]]]
    if first.size != samples.shape[0]:
        raise InputError(f"{samples.shape[0] - first.size} surface points have no particle within {radius:g}")
    return np.bincount(j[first], weights=np.broadcast_to(sample_area, (samples.shape[0],))[i[first]],
                       minlength=X.shape[0])


def columns_of(columns, rows):
    h = np.array(rows, dtype=float)
    return {k: h[:, i] for i, k in enumerate(columns)}


def run_quietly(app, outdir, *args):
    """Run the application class ``app`` into ``outdir`` (one thread, no particle files) and
    read back (results.json, {column: array} of history.json) — for tests and scripts."""
    app().run(["-d", str(outdir), "--no-progress", "--disable-output", "--threads", "1", *args])
    with open(os.path.join(outdir, "results.json")) as f:
        r = json.load(f)
    with open(os.path.join(outdir, "history.json")) as f:
        h = json.load(f)
    return r, columns_of(h["columns"], h["rows"])


def checks(columns, rows, free_from, law_from=0.0):
    """The conservation and second-law checks of issue 12 from the time series (first row
    at t = 0): L drift over max sum V|p|; A drift from ``free_from`` relative to |A|; the
    energy-budget residual over max_t(K + |W_ext| + |Q_in| + |E_Dir|) and the spread of
    E_tot from ``free_from`` on the same scale; from ``law_from``, the largest fall of S and
    the largest rise of B between rows, each over |its change| in that phase; the entropy the
    angular-momentum projection took in that phase (``entropy_projection``, E-form) and the
    largest fall of S - S_proj (``entropy_fall_without_projection``: what the paper's proof,
    eqs. 61-65, covers; it has no projection term)."""
    c = columns_of(columns, rows)
    L = np.stack([c["L_x"], c["L_y"], c["L_z"]], 1)
    A = np.stack([c["A_x"], c["A_y"], c["A_z"]], 1)
    out = {"L_drift": float(np.abs(L - L[0]).max() / max(c["sum_V_abs_p"].max(), 1e-300))}
    res = (c["total"] - c["total"][0]) - sum(c[k] - c[k][0] for k in ("W_ext", "Q_in", "E_Dir"))
    scale = np.max(c["kinetic"] + np.abs(c["W_ext"]) + np.abs(c["Q_in"]) + np.abs(c["E_Dir"]))
    out["energy_residual"] = float(np.abs(res).max() / scale)
    free = c["t"] >= free_from - 1e-12
    out["A_drift"] = out["A_free"] = out["total_spread"] = None
    if free.sum() >= 2:
        Af = A[free]
        out["A_drift"] = float(np.abs(Af - Af[0]).max() / max(np.linalg.norm(Af[0]), 1e-300))
        out["A_free"] = Af[0].tolist()
        out["total_spread"] = float(np.ptp(c["total"][free]) / scale)
    law = c["t"] >= law_from - 1e-12
    S, B = c["entropy"][law], c["ballistic"][law]
    out.update(dict.fromkeys(("entropy_rise", "entropy_fall", "ballistic_drop", "ballistic_rise",
                              "entropy_projection", "entropy_fall_without_projection")))
    if S.size > 1:
        out["entropy_rise"] = float(S[-1] - S[0])
        out["entropy_fall"] = largest_fall(S)
        if "S_proj" in c:
            Sp = c["S_proj"][law]
            out["entropy_projection"] = float(Sp[-1] - Sp[0])
            out["entropy_fall_without_projection"] = largest_fall(S - Sp)
        out["ballistic_drop"] = float(B[0] - B[-1])
        out["ballistic_rise"] = float(max(0.0, np.diff(B).max()) / abs(B[-1] - B[0])) if B[-1] != B[0] else 0.0
    out["W_ext"] = float(c["W_ext"][-1])
    out["Q_in"] = float(c["Q_in"][-1])
    out["J_min"] = float(c["J_min"].min())
    out["theta_range"] = [float(c["theta_min"].min()), float(c["theta_max"].max())]
    out["probe_v"] = [float(c[f"probe_v{k}"][-1]) for k in "xyz"]
    out["probe_u"] = [float(c[f"probe_u{k}"][-1]) for k in "xyz"]
    return out


def largest_fall(S):
    """The largest fall of S between successive rows over |S(end) - S(start)| (0 if S never falls)."""
    return float(max(0.0, -np.diff(S).min()) / abs(S[-1] - S[0])) if S[-1] != S[0] else 0.0


def relative_l2_in_time(t1, f1, t2, f2):
    """||f1 - f2||_L2(t) / ||f1||_L2(t), f2 interpolated on t1 (over the common interval)."""
    t1, f1, t2, f2 = map(np.asarray, (t1, f1, t2, f2))
    keep = t1 <= t2[-1] + 1e-12
    d = f1[keep] - np.interp(t1[keep], t2, f2)
    return float(np.sqrt(np.trapezoid(d * d, t1[keep]) / np.trapezoid(f1[keep] ** 2, t1[keep])))


def probe_error(history, reference_dir, prefix="probe_u"):
    """The probe's vector curve (columns ``prefix`` x, y, z of ``history``, {column: array})
    against a finished run's (``reference_dir``/history.json), relative L2 in time over the
    common interval: ||f - f_ref|| / ||f_ref|| with the reference interpolated on our times."""
    with open(os.path.join(reference_dir, "history.json")) as f:
        h = json.load(f)
    ref = columns_of(h["columns"], h["rows"])
    t, tr = history["t"], ref["t"]
    keep = t <= tr[-1] + 1e-12
    d2 = sum((history[prefix + k][keep] - np.interp(t[keep], tr, ref[prefix + k])) ** 2 for k in "xyz")
    r2 = sum(np.interp(t[keep], tr, ref[prefix + k]) ** 2 for k in "xyz")
    return {"probe_error": float(np.sqrt(np.trapezoid(d2, t[keep]) / np.trapezoid(r2, t[keep]))),
            "probe_error_interval": [0.0, float(t[keep][-1])], "reference_run": os.path.abspath(reference_dir)}


def checkerboard(X, V, f, h, kernel="wendland"):
    """R[f] = ||f - S f||_V / ||f - mean f||_V with the Shepard average S f_a =
    sum_b V_b f_b W_ab / sum_b V_b W_ab on the reference positions X (n, 3): the spurious
    (particle-to-particle) part of f relative to its variation (digest's indicator; the paper
    judges the oscillations of its Fig. 16 by eye)."""
    k = get_kernel(kernel, 3)
    w = np.vectorize(k.w)
    rad = k.radius_scale * h
    Sf = np.empty_like(f)
    for lo in range(0, len(f), 256):
        d = np.linalg.norm(X[lo:lo + 256, None, :] - X[None, :, :], axis=2)
        near = d < rad
        W = np.zeros_like(d)
        W[near] = w(d[near], h)
        Sf[lo:lo + 256] = (W * (V * f)[None, :]).sum(1) / (W * V[None, :]).sum(1)
    mean = np.sum(V * f) / np.sum(V)
    den = np.sqrt(np.sum(V * (f - mean) ** 2))
    return float(np.sqrt(np.sum(V * (f - Sf) ** 2)) / den) if den > 0 else 0.0
