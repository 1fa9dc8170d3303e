"""The figures of Ghavamian et al. (2021), CMAME 379, 113736: entropy-stable upwind TLSPH
thermo-elasticity (docs/thermo.md).  One Problem per section of its sec. 7:

* ``ThermoMMSFigures`` (sec. 7.1): Fig. 1 (the particle approximation: a lattice slice and
  one particle's support), Fig. 2 (the cube: particles with exact data, initial |v| and
  theta), Fig. 3 (L2 errors of p, P, theta against dx, reconstructed and raw jumps, the
  chosen buffer and the literal surface data);
* ``LBlockFigures`` (sec. 7.2): Fig. 4 (the block's particles, loaded and heated faces),
  5 (p at 7.7 s, every level), 6 (p, theta at 11 s), 7 (probe v, u at X = [0, 10, 0]),
  8 (L, A, energies, S), 9 (theta at 0/10/20/25/30 s, p at 0/8/18/28/38 s);
* ``DiskFigures`` (sec. 7.3): Figs. 10-14 (E and eta forms);
* ``PunchFigures`` (sec. 7.4): Figs. 15-19 (full and reduced schemes, E and eta forms);
* ``GripperFigures`` (sec. 7.5): Figs. 20-22;
* ``BallFigures`` (sec. 7.6): Figs. 23-24.

Each figure goes to a folder named after its number (``fig5/fig5.png``).  The paper's Figs.
3, 6, 7 and 17 also show the authors' in-house vertex-centred finite-volume code: those
curves are not available, so ours alone are drawn (the titles say so).  Sketches (Figs. 1,
4, 10, 15, 20, 23) are drawn from the applications' own particles, coloured by their role.
The ablations (``ablation_<section>``: raw vs reconstructed jumps, the projection off, S^E of
eq. 76 on the disk) plot K, S and the angular-momentum drift of each variant beside the
default; the disk's also gives the E-vs-eta probe gap with and without S^E.

Snapshots are written at the figures' times (``--output-at``), so each panel is at its time.
``python automate.py thermo`` runs the paper preset (levels as close to the paper's counts
as the lattices allow; docs/thermo.md), ``python automate.py thermo_quick`` the quick one
(coarsest levels; meant for under 30 minutes on 2 cores, docs/thermo.md says how this was
estimated).  A figure whose runs are missing is drawn with "not run" panels.  A run the
blow-up guard stopped is drawn up to its stop, labelled "stopped at t = ..." (its panels after
the stop say so); what only its results.json would give is None or left out, with a printed
note, and the convergence and E-vs-eta measures that use its curves name it under ``stopped``
(they compare over the common interval).
``python -m automation.thermo [outputs] [quick]`` redraws from finished runs.
"""
import os
import sys

import numpy as np

from .superfluid import _json, _plt, _save
from .tasks import (SphgenProblem, Simulation, paper_and_quick, pick, reached, read_results, run_info, run_state,
                    state_suffix, state_text, stopped_marks)

THIRD = repr(1.0 / 3.0)
SIXTH = repr(1.0 / 6.0)
# per section: the levels (coarsest first) and end times; None = the application's own tf.
# The paper preset's punch levels are the paper's dx = 1/10, 1/13, 1/16 (2728, 5488, 10268
# particles on our lattice; the paper's 2500/5000/10000).
CONFIG = {
    "paper": dict(mms_n=(20, 24, 32, 40), mms_cases=(("limited", "buffer"), ("raw", "buffer"),
                                                     ("limited", "surface"), ("raw", "surface")),
                  lblock_dx=("1", "0.5", THIRD, "0.2"), disk_dx=("0.5", "0.25", "0.2", SIXTH),
                  punch_dx=("0.1", repr(1 / 13), "0.0625"), gripper_dx=("0.02", "0.01"),
                  ball_dx=("0.01", "0.005"), tf={}),
    "quick": dict(mms_n=(20, 24, 28, 32), mms_cases=(("limited", "buffer"), ("raw", "buffer"),
                                                     ("limited", "surface"), ("raw", "surface")),
                  lblock_dx=("1", "0.5", THIRD), disk_dx=("1", "0.5", THIRD),
                  punch_dx=("0.25", SIXTH, "0.125"), gripper_dx=("0.02",), ball_dx=("0.01",), tf={}),
}

# the figures' times (the paper's captions)
LBLOCK_TIMES = dict(fig5=(7.7,), fig6=(11.0,), fig9_theta=(0.0, 10.0, 20.0, 25.0, 30.0),
                    fig9_p=(0.0, 8.0, 18.0, 28.0, 38.0))
DISK_TIMES = dict(fig11=(1.35,), fig14_theta=(0.0, 2.0, 4.5, 7.0), fig14_p=(0.0, 3.3, 6.6, 9.9))
PUNCH_TIMES = dict(fig16=(0.07, 0.14, 0.21, 0.28, 0.35), fig17=(0.38,),
                   fig19=(0.0, 0.07, 0.14, 0.21, 0.28, 0.35))
GRIPPER_TIMES = dict(fig21=(0.47,))
BALL_TIMES = dict(fig24=(0.0, 0.01, 0.02, 0.03, 0.04, 0.042))


def _times(table):
    return sorted({t for ts in table.values() for t in ts if t > 0})


def _dx_label(dx):
    return f"{float(dx):.4g}"


# ------------------------------------------------------------------ case lists
def mms_cases(cfg):
    """{name: (application, [args])} of Fig. 3."""
    return {f"mms_{j}_{bc}_n{n}": ("thermo_mms", ["--n", str(n), "--jumps", j, "--bc", bc])
            for j, bc in cfg["mms_cases"] for n in cfg["mms_n"]}


def lblock_cases(cfg):
    """Every level with the default scheme; ablations at the second level: raw jumps, no
    projection."""
    out_at = ["--output-at", *map(str, _times(LBLOCK_TIMES))]
    out = {f"lblock_dx{_dx_label(dx)}": ("l_block", ["--dx", dx, *out_at]) for dx in cfg["lblock_dx"]}
    dx = cfg["lblock_dx"][min(1, len(cfg["lblock_dx"]) - 1)]
    out["lblock_ablation_raw"] = ("l_block", ["--dx", dx, "--jumps", "raw", "--disable-output"])
    out["lblock_ablation_noproj"] = ("l_block", ["--dx", dx, "--no-projection", "--disable-output"])
    return out


def disk_cases(cfg):
    """Every level in the E and eta forms; ablations at the coarsest: raw jumps, no projection,
    S^E of eq. 76 (``--SE matched``); all at the disk's default alpha_CFL = 0.25 (not the
    paper's 0.3: docs/thermo.md, "Decision (disk time step)")."""
    out_at = ["--output-at", *map(str, _times(DISK_TIMES))]
    out = {f"disk_{form}_dx{_dx_label(dx)}": ("thermo_disk", ["--dx", dx, "--form", form, *out_at])
           for dx in cfg["disk_dx"] for form in ("E", "eta")}
    dx = cfg["disk_dx"][0]
    out["disk_ablation_raw"] = ("thermo_disk", ["--dx", dx, "--jumps", "raw", "--disable-output"])
    out["disk_ablation_noproj"] = ("thermo_disk", ["--dx", dx, "--no-projection", "--disable-output"])
    out["disk_ablation_SE"] = ("thermo_disk", ["--dx", dx, "--SE", "matched", "--disable-output"])
    return out


def punch_middle(cfg):
    """The level of Figs. 16 and 19 (the paper's 5000 particles: the middle one)."""
    return cfg["punch_dx"][len(cfg["punch_dx"]) // 2]


def punch_cases(cfg):
    """Full scheme, E and eta, every level; the reduced scheme at the middle level (Fig. 16);
    ablation: limited jumps at the middle level (the default is the paper's raw jumps)."""
    out_at = ["--output-at", *map(str, _times(PUNCH_TIMES))]
    out = {f"punch_full_{form}_dx{_dx_label(dx)}": ("thermo_punch", ["--dx", dx, "--form", form, *out_at])
           for dx in cfg["punch_dx"] for form in ("E", "eta")}
    mid = punch_middle(cfg)
    out[f"punch_reduced_E_dx{_dx_label(mid)}"] = ("thermo_punch", ["--dx", mid, "--variant", "reduced", *out_at])
    out["punch_ablation_limited"] = ("thermo_punch", ["--dx", mid, "--jumps", "limited", "--disable-output"])
    return out


def gripper_cases(cfg):
    out_at = ["--output-at", *map(str, _times(GRIPPER_TIMES))]
    return {f"gripper_dx{_dx_label(dx)}": ("thermo_gripper", ["--dx", dx, *out_at]) for dx in cfg["gripper_dx"]}


def ball_cases(cfg):
    out_at = ["--output-at", *map(str, _times(BALL_TIMES))]
    return {f"ball_dx{_dx_label(dx)}": ("thermo_ball", ["--dx", dx, *out_at]) for dx in cfg["ball_dx"]}


# ------------------------------------------------------------------ reading runs
def history(folder):
    """{column: array} of a run's history.json, or None."""
    h = _json(folder, "history.json")
    if h is None or not h.get("rows"):
        return None
    rows = np.array(h["rows"], dtype=float)
    return {k: rows[:, i] for i, k in enumerate(h["columns"])}


def probe_convergence(folders, columns):
    """Relative L2-in-time differences of probe curves between successive levels (folders
    coarsest first; missing runs skipped): {column: [d(level k, level k+1) ...]} and
    ``converging`` = the two finest closer than the two coarsest for every column."""
    from sphgen.applications._thermo_solid import relative_l2_in_time
    hs = [h for h in map(history, folders) if h is not None]
    out = {"levels": len(hs), **_stopped(folders)}
    if len(hs) < 3:
        return out
    for col in columns:
        out[col] = [relative_l2_in_time(f["t"], f[col], c["t"], c[col]) for c, f in zip(hs, hs[1:])]
    out["converging"] = all(out[col][-1] < out[col][0] for col in columns)
    return out


def forms_gap(folder_E, folder_eta, columns):
    """Relative L2-in-time gap of probe curves between the E and eta forms (None if missing)."""
    from sphgen.applications._thermo_solid import relative_l2_in_time
    hE, hn = history(folder_E), history(folder_eta)
    if hE is None or hn is None:
        return None
    return {**{col: relative_l2_in_time(hE["t"], hE[col], hn["t"], hn[col]) for col in columns},
            **_stopped((folder_E, folder_eta))}


def _stopped(folders):
    """{"stopped": {run: t}} of the runs among ``folders`` the guard stopped, {} if none."""
    got = {os.path.basename(os.path.normpath(f)): run_info(f).get("t") for f in folders
           if run_state(f) == "stopped"}
    return {"stopped": got} if got else {}


def snapshots(folder, prefix, times):
    """{time: (ParticleArray 'body', its time) or None}: the output file nearest each time."""
    from sphgen import io
    try:
        files = io.output_files(folder, prefix)
    except OSError:
        files = []
    if not files:
        return {t: None for t in times}
    have = np.array([io.read_solver_data(p)["t"] for p in files])
    out = {}
    for t in times:
        k = int(np.argmin(np.abs(have - t)))
        out[t] = (io.load(files[k])["arrays"]["body"], float(have[k]))
    return out


def _not_run(ax, title="", run=None):
    """An empty panel: "not run", or "stopped at t = ..." for a run the guard stopped."""
    text = "not run" if run is None else state_text(run)
    ax.text2D(0.5, 0.5, text, ha="center", transform=ax.transAxes) if hasattr(ax, "text2D") else \
        ax.text(0.5, 0.5, text, ha="center", transform=ax.transAxes)
    ax.set_title(title, fontsize=8)


def _field(pa, name):
    return {"p": pa.p, "theta": pa.theta}[name]


LABELS = {"p": "p [Pa]", "theta": "theta [K]"}


def scatter3d(fig, ax, pa, field, title, view=(25, -60), cmap=None):
    """The particles at their current positions coloured by ``field``."""
    c = _field(pa, field)
    size = float(np.clip(4000.0 / max(pa.n, 1), 0.3, 20.0))
    lo, hi = np.percentile(c, [1, 99])        # a few held or edge particles do not set the scale
    sc = ax.scatter(pa.x, pa.y, pa.z, c=c, s=size, vmin=lo, vmax=hi,
                    cmap=cmap or ("coolwarm" if field == "p" else "inferno"))
    ax.view_init(*view)
    ax.set_box_aspect((np.ptp(pa.x) or 1.0, np.ptp(pa.y) or 1.0, np.ptp(pa.z) or 1.0))
    ax.set_title(title, fontsize=8)
    ax.tick_params(labelsize=6)
    fig.colorbar(sc, ax=ax, shrink=0.6, label=LABELS[field] + " (1-99 %)", extend="both")


def snapshot_figure(out_dir, name, rows, suptitle, view=(25, -60)):
    """A grid of 3-D panels: ``rows`` = [(folder, prefix, field, times, label)]."""
    plt = _plt()
    ncol = max(len(r[3]) for r in rows)
    fig = plt.figure(figsize=(3.6 * ncol, 3.4 * len(rows)))
    shown = {}
    for i, (folder, prefix, field, times, label) in enumerate(rows):
        shots = snapshots(folder, prefix, times)
        for j, t in enumerate(times):
            ax = fig.add_subplot(len(rows), ncol, i * ncol + j + 1, projection="3d")
            hit = shots[t]
            if hit is None or not reached(folder, t, hit[1]):
                _not_run(ax, f"{label}, t = {t:g} s", folder)      # none, or after the stop
                continue
            pa, t_file = hit
            scatter3d(fig, ax, pa, field, f"{label}, t = {t_file:.4g} s{state_suffix(folder)}", view)
            shown[f"{label} {field} {t:g}"] = {"t": t_file, "min": float(_field(pa, field).min()),
                                               "max": float(_field(pa, field).max())}
    fig.suptitle(suptitle, fontsize=10)
    _save(fig, out_dir, name)
    _dump(out_dir, name, shown)
    return shown


def series_figure(out_dir, name, runs, panels, suptitle):
    """Time series of several runs: ``runs`` = [(label, folder, style)], ``panels`` =
    [(title, [(column, component label)], y label)]."""
    plt = _plt()
    fig, axes = plt.subplots(1, len(panels), figsize=(4.6 * len(panels), 3.8), squeeze=False)
    for ax, (title, cols, ylabel) in zip(axes[0], panels):
        for label, folder, style in runs:
            h = history(folder)
            if h is None:
                continue
            for col, comp in cols:
                ax.plot(h["t"], h[col], style, lw=1, label=f"{comp} {label}".strip() + state_suffix(folder))
        if ax.lines:
            ax.legend(fontsize=6)
        else:
            ax.text(0.5, 0.5, "not run", ha="center", transform=ax.transAxes)
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        ax.set_title(title, fontsize=8)
    fig.suptitle(suptitle, fontsize=9)
    _save(fig, out_dir, name)


def sketch(out_dir, name, app_name, args, roles, suptitle, view=(25, -60)):
    """The application's particles (no run) coloured by role: ``roles`` =
    [(label, function(pa) -> mask)]; the rest are drawn grey."""
    from sphgen.app import load_application
    plt = _plt()
    app = load_application(app_name)()
    app.options = app.parser().parse_args(list(args))
    app.consume_user_options(app.options)
    pa = app.create_particles()[0]
    fig = plt.figure(figsize=(6, 5))
    ax = fig.add_subplot(projection="3d")
    rest = np.ones(pa.n, bool)
    size = float(np.clip(3000.0 / pa.n, 0.5, 20.0))
    marks = []
    for label, sel in roles:
        m = np.asarray(sel(pa), bool) & rest
        rest &= ~m
        marks.append((label, m))
    ax.scatter(pa.x[rest], pa.y[rest], pa.z[rest], s=size, color="0.75", label=f"body ({rest.sum()})")
    for (label, m), color in zip(marks, ("tab:red", "tab:blue", "tab:green", "tab:orange")):
        if m.any():
            ax.scatter(pa.x[m], pa.y[m], pa.z[m], s=2 * size, color=color, label=f"{label} ({m.sum()})")
    ax.view_init(*view)
    ax.set_box_aspect((np.ptp(pa.x) or 1.0, np.ptp(pa.y) or 1.0, np.ptp(pa.z) or 1.0))
    ax.set_xlabel("X [m]")
    ax.set_ylabel("Y [m]")
    ax.set_zlabel("Z [m]")
    ax.legend(fontsize=7, markerscale=3, loc="upper left")
    ax.set_title(f"{suptitle}\n{' '.join(args)}: {pa.n} particles", fontsize=8)
    _save(fig, out_dir, name)
    return pa.n


def _dump(out_dir, name, data):
    from sphgen import io
    os.makedirs(os.path.join(out_dir, name), exist_ok=True)
    io.write_json(os.path.join(out_dir, name, name + ".json"), data)


def _has(pa, prop):
    return pa.has(prop) if hasattr(pa, "has") else prop in pa.data


def _flag(prop, k=None, stride=1):
    def sel(pa):
        if not _has(pa, prop):
            return np.zeros(pa.n, bool)
        v = np.asarray(pa.get(prop)).reshape(pa.n, stride)
        return (v[:, k] if k is not None else v.max(axis=1)) > 0.5 if stride > 1 else v[:, 0] > 0.5
    return sel


def _positive(prop):
    return lambda pa: np.asarray(pa.get(prop)) > 0 if _has(pa, prop) else np.zeros(pa.n, bool)


def ablation_figure(out_dir, name, runs, suptitle, free_from=0.0):
    """K, S and |A - A(free_from)| / |A(free_from)| of the default run and each ablation;
    with the runs' checks in ``name.json``."""
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(14, 3.8))
    data = {}
    for label, folder in runs:
        h = history(folder)
        if h is None:
            continue
        A = np.stack([h["A_x"], h["A_y"], h["A_z"]], 1)
        k = min(int(np.searchsorted(h["t"], free_from - 1e-12)), len(h["t"]) - 1)
        drift = np.linalg.norm(A - A[k], axis=1) / max(np.linalg.norm(A[k]), 1e-300)
        shown = label + state_suffix(folder)
        axes[0].plot(h["t"], h["kinetic"], lw=1, label=shown)
        axes[1].plot(h["t"], h["entropy"] - h["entropy"][0], lw=1, label=shown)
        axes[2].semilogy(h["t"][k:], np.maximum(drift[k:], 1e-17), lw=1, label=shown)
        data[label] = pick(folder, read_results(folder, "its checks (ablation)"),
                           ("t", "n_particles", "J_min", "energy_residual", "L_drift", "A_drift", "entropy_fall",
                            "entropy_rise", "theta_range"))
        data[label]["A_drift_end"] = float(drift[-1])
    for ax, ylabel in zip(axes, ("K [J]", "S - S(0) [J/K]", f"|A - A({free_from:g})| / |A({free_from:g})|")):
        ax.set_xlabel("t [s]")
        ax.set_ylabel(ylabel)
        if ax.lines:
            ax.legend(fontsize=7)
        else:
            ax.text(0.5, 0.5, "not run", ha="center", transform=ax.transAxes)
    fig.suptitle(suptitle, fontsize=9)
    _save(fig, out_dir, name)
    _dump(out_dir, name, data)
    return data


# ------------------------------------------------------------------ sec. 7.1
def fig1(out_dir):
    """The particle approximation: the mid-plane of the MMS vertex lattice (n = 10) and the
    support 2h = 2.4 dx of one particle (Wendland C2, h = 1.2 dx)."""
    from sphgen.applications.thermo_mms import vertex_cube
    plt = _plt()
    n, hdx = 10, 1.2
    X, V = vertex_cube(n)
    dx = 1.0 / n
    mid = np.abs(X[:, 2] - 0.5) < 1e-9
    a = np.array([0.5, 0.5])
    fig, ax = plt.subplots(figsize=(5, 5))
    ax.scatter(X[mid, 0], X[mid, 1], s=2e4 * V[mid], color="0.6", label="particles X_b (area ~ V_b)")
    inside = mid & (np.linalg.norm(X[:, :2] - a, axis=1) < 2 * hdx * dx)
    ax.scatter(X[inside, 0], X[inside, 1], s=2e4 * V[inside], color="tab:blue",
               label=f"neighbours Lambda_a ({inside.sum() - 1} in this plane)")
    ax.scatter(*a, s=60, color="tab:red", label="particle a")
    ax.add_patch(plt.Circle(a, 2 * hdx * dx, fill=False, color="tab:red", ls="--"))
    ax.set_aspect("equal")
    ax.set_xlabel("X_1 [m]")
    ax.set_ylabel("X_2 [m]")
    ax.legend(fontsize=7, loc="upper right")
    ax.set_title(f"Fig. 1: particle approximation (our vertex lattice, n = {n}; support 2h = {2 * hdx:g} dx)",
                 fontsize=8)
    _save(fig, out_dir, "fig1")


def fig2(out_dir, n=10, n_data=20):
    """(a) the plane X_3 = 1/2 of the coarsest level (n_data): particles with exact data (the
    4h buffer), the interior, the inner cube where errors are measured; (b) |v| and (c)
    theta at t = 0 from the exact fields (eqs. 84-88) on an n^3 lattice."""
    from sphgen.applications.thermo_mms import PAPER, Manufactured, vertex_cube
    from sphgen.equations.thermo_materials import LinearThermoElastic
    plt = _plt()
    ex = Manufactured(LinearThermoElastic(**PAPER))
    fig = plt.figure(figsize=(14, 4.2))
    Xd, _ = vertex_cube(n_data)
    Xd = Xd[np.abs(Xd[:, 2] - 0.5) < 1e-9]
    buffer = np.minimum(Xd, 1.0 - Xd).min(axis=1) < 4.0 * 1.2 / n_data
    inner = np.all((Xd >= 0.25 - 1e-9) & (Xd <= 0.75 + 1e-9), axis=1)
    ax = fig.add_subplot(1, 3, 1)
    for mask, color, label in ((buffer, "tab:red", "exact p, theta (4h buffer)"), (~buffer & ~inner, "0.6", "free"),
                               (inner, "tab:blue", "free, errors measured (inner cube)")):
        ax.scatter(Xd[mask, 0], Xd[mask, 1], s=8, color=color, label=f"{label} ({mask.sum()})")
    ax.set_aspect("equal")
    ax.legend(fontsize=6, loc="upper right")
    ax.set_title(f"(a) plane X_3 = 1/2, n = {n_data} (--bc buffer)", fontsize=8)
    X, _ = vertex_cube(n)
    for k, (c, title, cmap) in enumerate(((np.linalg.norm(ex.velocity(X), axis=1), "(b) |v| at t = 0 [m/s]", "viridis"),
                                          (ex.temperature(X, 0.0), "(c) theta at t = 0 [K]", "inferno"))):
        ax = fig.add_subplot(1, 3, k + 2, projection="3d")
        sc = ax.scatter(X[:, 0], X[:, 1], X[:, 2], c=c, s=6, cmap=cmap)
        ax.set_title(title, fontsize=8)
        fig.colorbar(sc, ax=ax, shrink=0.6)
    fig.suptitle("Fig. 2: manufactured solution on the unit cube (our lattices)", fontsize=9)
    _save(fig, out_dir, "fig2")


def fig3(sim_dir, out_dir, cfg):
    """L2 errors of p, P, theta at t = 0.001 s against dx (inner cube), one line style per
    (jumps, BCs); least-squares orders over the three finest levels in fig3.json."""
    from sphgen.applications.thermo_mms import orders
    plt = _plt()
    fig, axes = plt.subplots(1, 3, figsize=(15, 4.5))
    comps = (("p_x", "p_y", "p_z"), ("P_11", "P_12", "P_22", "P_23", "P_33"), ("theta",))
    data = {}
    for (jumps, bc), style in zip(cfg["mms_cases"], ("o-", "s--", "^-.", "v:")):
        runs = {f"n = {n}": os.path.join(sim_dir, f"mms_{jumps}_{bc}_n{n}") for n in cfg["mms_n"]}
        rows = [r for run in runs.values() if (r := read_results(run, "its L2 errors (Fig. 3)"))]
        if not rows:
            continue
        key = f"{jumps}, {bc}"
        data[key] = {"dx": [r["dx"] for r in rows], "orders": orders(rows, "inner") if len(rows) >= 3 else {},
                     "errors": {c: [r.get(f"inner_{c}") for r in rows] for group in comps for c in group},
                     **_stopped(runs.values())}          # a stopped level has no errors: left out
        for ax, group in zip(axes, comps):
            for c in group:
                e = data[key]["errors"][c]
                ax.loglog(data[key]["dx"], e, style, ms=4, lw=1, label=f"{c} ({key}){stopped_marks(runs)}")
    for ax, what in zip(axes, ("(a) linear momentum", "(b) first Piola-Kirchhoff stress", "(c) temperature")):
        if ax.lines:
            dx = np.array(sorted({d for v in data.values() for d in v["dx"]}))
            y0 = min(min(ln.get_ydata()) for ln in ax.lines)
            ax.loglog(dx, y0 * (dx / dx[0]) ** 2, "k-", lw=0.8, label="slope 2")
            ax.legend(fontsize=5, ncol=2)
        else:
            ax.text(0.5, 0.5, "not run", ha="center", transform=ax.transAxes)
        ax.set_xlabel("dx [m]")
        ax.set_ylabel("L2 error (inner cube)")
        ax.set_title(what, fontsize=8)
    fig.suptitle("Fig. 3: sphgen only (the paper's Upwind-VCFVM curves are not available); t = 0.001 s", fontsize=9)
    _save(fig, out_dir, "fig3")
    _dump(out_dir, "fig3", data)
    return data


def mms_figures(sim_dir, out_dir, cfg):
    fig1(out_dir)
    fig2(out_dir)
    return {"fig3": fig3(sim_dir, out_dir, cfg)}


# ------------------------------------------------------------------ sec. 7.2
MOMENTA_PANELS = [("(a) linear momentum", [("L_x", "L_x"), ("L_y", "L_y"), ("L_z", "L_z")], "L [kg m/s]"),
                  ("(b) angular momentum", [("A_x", "A_x"), ("A_y", "A_y"), ("A_z", "A_z")], "A [kg m^2/s]"),
                  ("(c) energies", [("kinetic", "K"), ("internal", "internal"), ("total", "total"),
                                    ("ballistic", "ballistic")], "[J]"),
                  ("(d) entropy", [("entropy", "S")], "S [J/K]")]


def lblock_figures(sim_dir, out_dir, cfg):
    from sphgen.applications.l_block import PAPER
    levels = cfg["lblock_dx"]
    fine = os.path.join(sim_dir, f"lblock_dx{_dx_label(levels[-1])}")
    theta_R = PAPER["theta_R"]
    n = {"fig4": sketch(out_dir, "fig4", "l_block", ["--dx", levels[0]],
                        [("F1 on Y = 10, 300 K", lambda pa: pa.face == 1.0),
                         ("F2 on X = 6, 250 K", lambda pa: pa.face == 2.0)],
                        "Fig. 4: L-shaped block (our vertex lattice)", view=(20, -50))}
    snapshot_figure(out_dir, "fig5", [(os.path.join(sim_dir, f"lblock_dx{_dx_label(dx)}"), "l_block", "p", (7.7,),
                                       f"dx = {_dx_label(dx)}") for dx in levels],
                    "Fig. 5: p at 7.7 s, every level (rows)")
    snapshot_figure(out_dir, "fig6", [(fine, "l_block", f, (11.0,), f"sphgen dx = {_dx_label(levels[-1])}")
                                      for f in ("p", "theta")],
                    "Fig. 6: p and theta at 11 s, sphgen only (the paper's Upwind-VCFVM shapes are not available)")
    runs = [(f"dx={_dx_label(dx)}", os.path.join(sim_dir, f"lblock_dx{_dx_label(dx)}"), style)
            for dx, style in zip(levels[-3:], ("--", "-.", "-"))]
    series_figure(out_dir, "fig7", runs,
                  [("(a) v at X = [0, 10, 0]", [(f"probe_v{c}", f"v_{c}") for c in "xyz"], "v [m/s]"),
                   ("(b) u at X = [0, 10, 0]", [(f"probe_u{c}", f"u_{c}") for c in "xyz"], "u [m]")],
                  "Fig. 7: probe, the three finest levels, sphgen only (no Upwind-VCFVM curves available)")
    n["fig7"] = probe_convergence([os.path.join(sim_dir, f"lblock_dx{_dx_label(dx)}") for dx in levels],
                                  [f"probe_{q}{c}" for q in "vu" for c in "xyz"])
    _dump(out_dir, "fig7", n["fig7"])
    series_figure(out_dir, "fig8", [(f"dx={_dx_label(levels[-1])}", fine, "-")], MOMENTA_PANELS,
                  "Fig. 8: momenta, energies, entropy (finest level)")
    snapshot_figure(out_dir, "fig9", [(fine, "l_block", "theta", LBLOCK_TIMES["fig9_theta"], "theta"),
                                      (fine, "l_block", "p", LBLOCK_TIMES["fig9_p"], "p")],
                    f"Fig. 9: theta and p sequences, dx = {_dx_label(levels[-1])} (theta_R = {theta_R} K)")
    base = os.path.join(sim_dir, f"lblock_dx{_dx_label(levels[min(1, len(levels) - 1)])}")
    n["ablation"] = ablation_figure(out_dir, "ablation_lblock",
                                    [("default (limited jumps, projection)", base),
                                     ("raw jumps", os.path.join(sim_dir, "lblock_ablation_raw")),
                                     ("no projection", os.path.join(sim_dir, "lblock_ablation_noproj"))],
                                    "L-block ablations (second level)", free_from=5.0)
    return n


# ------------------------------------------------------------------ sec. 7.3
def disk_figures(sim_dir, out_dir, cfg):
    levels = cfg["disk_dx"]

    def run(form, dx):
        return os.path.join(sim_dir, f"disk_{form}_dx{_dx_label(dx)}")

    fine = run("E", levels[-1])
    out = {"fig10": sketch(out_dir, "fig10", "thermo_disk", ["--dx", levels[0]],
                           [("heated quarter of the rim", _positive("area"))],
                           "Fig. 10: rotating disk (our lattice), heat flux on a quarter of the rim",
                           view=(35, -60))}
    snapshot_figure(out_dir, "fig11", [(run("E", dx), "thermo_disk", "p", (1.35,), f"dx = {_dx_label(dx)}")
                                       for dx in levels], "Fig. 11: p at 1.35 s, every level (rows)")
    runs = [(f"{form} dx={_dx_label(dx)}", run(form, dx), "-" if form == "E" else "--")
            for dx in levels for form in ("E", "eta")]
    series_figure(out_dir, "fig12", runs,
                  [("(a) v_Z at X = [2, 4, 0]", [("probe_vz", "")], "v_Z [m/s]"),
                   ("(b) theta at X = [2, 4, 0]", [("probe_theta", "")], "theta [K]")],
                  "Fig. 12: E-form (solid) and eta-form (dashed), every level")
    out["fig12"] = {"convergence": {form: probe_convergence([run(form, dx) for dx in levels],
                                                            ["probe_vz", "probe_theta"]) for form in ("E", "eta")},
                    "E_vs_eta": {_dx_label(dx): forms_gap(run("E", dx), run("eta", dx), ["probe_vz", "probe_theta"])
                                 for dx in levels}}
    _dump(out_dir, "fig12", out["fig12"])
    series_figure(out_dir, "fig13", [(f"dx={_dx_label(levels[-1])}", fine, "-")], MOMENTA_PANELS,
                  "Fig. 13: momenta, energies, entropy (finest level, E-form)")
    snapshot_figure(out_dir, "fig14", [(fine, "thermo_disk", "theta", DISK_TIMES["fig14_theta"], "theta"),
                                       (fine, "thermo_disk", "p", DISK_TIMES["fig14_p"], "p")],
                    f"Fig. 14: theta and p sequences, dx = {_dx_label(levels[-1])}", view=(35, -60))
    out["ablation"] = ablation_figure(out_dir, "ablation_disk",
                                      [("default (limited jumps, projection)", run("E", levels[0])),
                                       ("raw jumps", os.path.join(sim_dir, "disk_ablation_raw")),
                                       ("no projection", os.path.join(sim_dir, "disk_ablation_noproj")),
                                       ("S^E of eq. 76", os.path.join(sim_dir, "disk_ablation_SE"))],
                                      "Disk ablations (coarsest level)")
    out["ablation_SE_vs_eta"] = {"S^E = 0": forms_gap(run("E", levels[0]), run("eta", levels[0]),
                                                      ["probe_vz", "probe_theta"]),
                                 "S^E eq. 76": forms_gap(os.path.join(sim_dir, "disk_ablation_SE"),
                                                         run("eta", levels[0]), ["probe_vz", "probe_theta"])}
    return out


# ------------------------------------------------------------------ sec. 7.4
def punch_figures(sim_dir, out_dir, cfg):
    levels, mid = cfg["punch_dx"], punch_middle(cfg)

    def run(variant, form, dx):
        return os.path.join(sim_dir, f"punch_{variant}_{form}_dx{_dx_label(dx)}")

    out = {"fig15": sketch(out_dir, "fig15", "thermo_punch", ["--dx", levels[0]],
                           [("roller v_Z = 0", _flag("vfix", 2, 3))],
                           "Fig. 15: punch (hollow cylinder, our lattice), v0 = -10 Z/H e_Z")}
    times = PUNCH_TIMES["fig16"]
    snapshot_figure(out_dir, "fig16", [(run(v, "E", mid), "thermo_punch", f, times, f"{v} {f}")
                                       for v in ("reduced", "full") for f in ("theta", "p")],
                    f"Fig. 16: reduced {{p, F, H, E}} vs full {{p, F, H, J, E}}, dx = {_dx_label(mid)}")
    snapshot_figure(out_dir, "fig17", [(run("full", "E", levels[-1]), "thermo_punch", f, (0.38,),
                                        f"sphgen dx = {_dx_label(levels[-1])}") for f in ("p", "theta")],
                    "Fig. 17: at 0.38 s, sphgen only (the paper's Upwind-VCFVM shapes are not available)")
    runs = [(f"{form} dx={_dx_label(dx)}", run("full", form, dx), "-" if form == "E" else "--")
            for dx in levels for form in ("E", "eta")]
    series_figure(out_dir, "fig18", runs,
                  [("(a) v_Z at X = [0, 1, 1]", [("probe_vz", "")], "v_Z [m/s]"),
                   ("(b) P_11 at X = [0, 1, 1]", [("probe_P11", "")], "P_11 [Pa]")],
                  "Fig. 18: E-form (solid) and eta-form (dashed), every level")
    out["fig18"] = {"convergence": {form: probe_convergence([run("full", form, dx) for dx in levels],
                                                            ["probe_vz", "probe_P11"]) for form in ("E", "eta")},
                    "E_vs_eta": {_dx_label(dx): forms_gap(run("full", "E", dx), run("full", "eta", dx),
                                                          ["probe_vz", "probe_P11"]) for dx in levels}}
    _dump(out_dir, "fig18", out["fig18"])
    snapshot_figure(out_dir, "fig19", [(run("full", "E", mid), "thermo_punch", "theta", PUNCH_TIMES["fig19"],
                                        "theta (top view)"),
                                       (run("full", "E", mid), "thermo_punch", "p", PUNCH_TIMES["fig19"], "p")],
                    f"Fig. 19: full scheme, dx = {_dx_label(mid)}")
    res = {v: read_results(run(v, "E", mid), "its R_p") for v in ("full", "reduced")}
    out["R_p"] = {v: {k: s["R_p"] for k, s in r.get("snapshots", {}).items()} for v, r in res.items() if r}
    out["ablation"] = ablation_figure(out_dir, "ablation_punch",
                                      [("default (raw jumps)", run("full", "E", mid)),
                                       ("limited jumps", os.path.join(sim_dir, "punch_ablation_limited"))],
                                      f"Punch ablation (dx = {_dx_label(mid)})")
    return out


# ------------------------------------------------------------------ secs. 7.5, 7.6
def gripper_figures(sim_dir, out_dir, cfg):
    levels = cfg["gripper_dx"]
    fine = os.path.join(sim_dir, f"gripper_dx{_dx_label(levels[-1])}")
    out = {"fig20": sketch(out_dir, "fig20", "thermo_gripper", ["--dx", levels[0]],
                           [("core held, 280 K", _flag("tfix")), ("loaded ends, 300 K", _positive("area"))],
                           "Fig. 20: gripper (our lattice)", view=(40, -60))}
    plt = _plt()
    shots = snapshots(fine, "thermo_gripper", (0.47,))
    fig = plt.figure(figsize=(13, 7))
    for i, f in enumerate(("p", "theta")):
        for j, (view, name) in enumerate((((25, -60), "isometric"), ((0, -90), "front"), ((90, -90), "top"))):
            ax = fig.add_subplot(2, 3, 3 * i + j + 1, projection="3d")
            if shots[0.47] is None:
                _not_run(ax, name, fine)
            else:
                scatter3d(fig, ax, shots[0.47][0], f, f"{name}, t = {shots[0.47][1]:.4g} s{state_suffix(fine)}", view)
    fig.suptitle(f"Fig. 21: gripper at 0.47 s, dx = {_dx_label(levels[-1])}", fontsize=9)
    _save(fig, out_dir, "fig21")
    series_figure(out_dir, "fig22", [(f"dx={_dx_label(dx)}", os.path.join(sim_dir, f"gripper_dx{_dx_label(dx)}"),
                                      "-" if dx == levels[-1] else "--") for dx in levels],
                  [("u at X = [0.4, 0, -0.03]", [(f"probe_u{c}", f"u_{c}") for c in "xyz"], "u [m]")],
                  "Fig. 22: gripper probe")
    return out


def ball_figures(sim_dir, out_dir, cfg):
    levels = cfg["ball_dx"]
    fine = os.path.join(sim_dir, f"ball_dx{_dx_label(levels[-1])}")
    out = {"fig23": sketch(out_dir, "fig23", "thermo_ball", ["--dx", levels[0]],
                           [("punched top cap (v0 = -1.5 e_Z)", lambda pa: pa.w < 0),
                            ("roller bottom cap", _flag("vfix", 2, 3)), ("heated inner surface", _positive("area"))],
                           "Fig. 23: perforated ball (our lattice)")}
    times = BALL_TIMES["fig24"]
    snapshot_figure(out_dir, "fig24", [(fine, "thermo_ball", f, times, f) for f in ("theta", "p")],
                    f"Fig. 24: ball, dx = {_dx_label(levels[-1])}")
    return out


SECTIONS = {"mms": (mms_cases, mms_figures), "lblock": (lblock_cases, lblock_figures),
            "disk": (disk_cases, disk_figures), "punch": (punch_cases, punch_figures),
            "gripper": (gripper_cases, gripper_figures), "ball": (ball_cases, ball_figures)}


def all_cases(cfg):
    return {name: case for cases, _ in SECTIONS.values() for name, case in cases(cfg).items()}


# ------------------------------------------------------------------ automan
class _ThermoSection(SphgenProblem):
    """One section of Ghavamian et al. (2021) sec. 7: its runs and figures."""

    section = None
    preset = "paper"

    def get_name(self):
        return f"thermo_{self.section}" + ("" if self.preset == "paper" else f"_{self.preset}")

    def setup(self):
        cfg = CONFIG[self.preset]
        job = dict(n_core=1, n_thread=1)
        cases = SECTIONS[self.section][0](cfg)
        self.cases = [Simulation(self.input_path(name), f"{self.sphgen(app)} {' '.join(args)}", job_info=job,
                                 threads=1, **({"tf": cfg["tf"][self.section]} if self.section in cfg["tf"] else {}))
                      for name, (app, args) in cases.items()]

    def run(self):
        self.make_output_dir()
        SECTIONS[self.section][1](self.input_path(), self.output_path(), CONFIG[self.preset])


def _section(name, section, doc):
    return paper_and_quick(_ThermoSection, name, doc, __name__, section=section)


ThermoMMSFigures, ThermoMMSFiguresQuick = _section("ThermoMMSFigures", "mms", "Sec. 7.1: Figs. 1-3")
LBlockFigures, LBlockFiguresQuick = _section("LBlockFigures", "lblock", "Sec. 7.2: Figs. 4-9, ablations")
DiskFigures, DiskFiguresQuick = _section("DiskFigures", "disk", "Sec. 7.3: Figs. 10-14, ablations")
PunchFigures, PunchFiguresQuick = _section("PunchFigures", "punch", "Sec. 7.4: Figs. 15-19, ablation")
GripperFigures, GripperFiguresQuick = _section("GripperFigures", "gripper", "Sec. 7.5: Figs. 20-22")
BallFigures, BallFiguresQuick = _section("BallFigures", "ball", "Sec. 7.6: Figs. 23-24")

PAPER_PROBLEMS = [ThermoMMSFigures, LBlockFigures, DiskFigures, PunchFigures, GripperFigures, BallFigures]
QUICK_PROBLEMS = [ThermoMMSFiguresQuick, LBlockFiguresQuick, DiskFiguresQuick, PunchFiguresQuick,
                  GripperFiguresQuick, BallFiguresQuick]


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "outputs"
    preset = "quick" if "quick" in sys.argv[2:] else "paper"
    for cls in PAPER_PROBLEMS:
        prob = cls.__new__(cls)
        prob.preset = preset
        name = prob.get_name()
        print(name, SECTIONS[cls.section][1](os.path.join(root, name), os.path.join("manuscript", "figures", name),
                                             CONFIG[preset]))
