"""The figures of Kincl, Peshkov, Pavelka & Klika (2023), "Unified description of fluids and
solids in Smoothed Particle Hydrodynamics" ([P]), and of chapters 1-2 of Kincl's thesis (2023)
([T]) (docs/shtc.md, "Figures: python automate.py shtc").

Each figure goes to a folder named after its number: ``P_fig1`` ... ``P_fig12`` for [P],
``T_fig1_1`` ... ``T_fig2_6`` for [T].  [P] Fig. 1 (the kernel's h-derivatives) and [T] Fig. 1.1
(the SPH sketch) need no run.  The beryllium plate gives [P] Figs. 2-4 and [T] Figs. 2.1-2.3,
the twisting column [P] Figs. 5-7, Taylor-Couette [P] Figs. 8-9, the lid-driven cavity [P]
Figs. 10-12 and [T] Figs. 2.4-2.6.  Curves the papers compare with and we do not have (the
finite-volume plate of Boscheri et al. 2022, the column's finite-element z(t)) are left out and
the titles say so.  The captions of [P] Figs. 10-11 / [T] Figs. 2.4-2.5 give no times: the
cavity's evolution is shown at ``CAVITY_TIMES`` (our choice, up to [T]'s t = 20).  Three
figures of ours go beside them: ``T_thm1_convergence`` ([T] Theorem 1, the kernel-interpolation
study), ``T_sec2_2_impulse_of_shear`` and ``P_sec3_6_reversibility`` (the applications' plots).
[T] sec. 1.6's dam break (Figs. 1.2-1.3) is ``dam_break_2d --scheme symplectic``, drawn by the
application's ``thesis_figure_1_2`` and ``thesis_figure_1_3``.

``python automate.py shtc`` runs the paper preset (the papers' resolutions and steps; the
cavity at Re 400 and 1000 with delta t = tau/3, below the relaxation guard's 0.464 tau),
``python automate.py shtc_quick`` the quick one (coarse levels; the cavity at Re 100 with cs = 10
and delta t = tau/3 as docs/shtc.md's row 7, at Re 400 and 1000 with cs = 5 so that delta t = tau/3
is four times larger; meant for under 30 minutes on 2 cores).  A figure whose
runs are missing is drawn with "not run" panels; a run the blow-up guard stopped is drawn up to
its stop and labelled "stopped at t = ...", and what only its results.json would hold is left
out (None in the figure's json, named in a printed note).  ``python -m automation.shtc [outputs] [quick]``
redraws from finished runs.
"""
import os
import shutil
import sys

import numpy as np

from .superfluid import _plt, _save
from .tasks import SphgenProblem, Simulation, pick, reached, read_results, run_state, state_suffix, state_text
from .thermo import _dump, history

# the cavity's snapshots ([P] Figs. 10-11, [T] Figs. 2.4-2.5): the captions give no times
CAVITY_TIMES = (2.5, 5.0, 10.0, 20.0)
# [T] Fig. 2.1: "three different time-steps" (not given): a quarter, half and the whole run
PLATE_FRACTIONS = (0.25, 0.5, 1.0)
# [P] Fig. 5: the column at four times (not given) over our documented end time 0.2 s
COLUMN_TIMES = (0.05, 0.1, 0.15, 0.2)
CAVITY_RE = (100, 400, 1000)

CONFIG = {
    # the papers' parameters: plate W/40, column n = 16, Taylor-Couette 1/30 ([P] Table 1), the
    # cavity (re, nx, cs, delta t) at nx = 200, cs = 20 (Table 1), delta t = 1.5e-5 at Re 100 (Table 1);
    # at Re 400 and 1000 delta t = tau/3 (Table 1's step is 0.4 tau at Re 400 and refused at Re 1000);
    # the dam break at dr = a/100 (the authors' code), an output every 1667 steps of 6e-5 s (0.1 s)
    "paper": dict(plate_nw=40, plate_pfreq=2764, column_n=16, column_pfreq=4840, couette_nr=30,
                  cavity=((100, 200, "20", "1.5e-05"), (400, 200, "20", "1.25e-05"), (1000, 200, "20", "5e-06")),
                  kernel_args=[], impulse_args=["--nx", "80"],
                  reversibility_args=["--amplitude", "5", "--perturb", "0.1", "--steps", "1000"],
                  dam_break_dx="0.01", dam_break_pfreq=1667),
    # coarse levels; the cavity at Re 100 as docs/shtc.md row 7 (cs = 10, delta t = tau/3 = 2e-4), at
    # Re 400 and 1000 with cs = 5 (tau = 6 nu / cs^2 four times larger, delta t = tau/3: 100 k and 250 k
    # steps instead of 400 k and 1 M; the Navier-Stokes limit does not depend on cs while tau << 1);
    # the kernel study on 512^2 with h >= 8 lattice spacings (the test's h); the dam break at a/50
    "quick": dict(plate_nw=10, plate_pfreq=692, column_n=4, column_pfreq=1210, couette_nr=10,
                  cavity=((100, 40, "10", "0.0002"), (400, 40, "5", "0.0002"), (1000, 30, "5", "8e-05")),
                  kernel_args=["--n", "512", "--h", "0.016", "0.022", "0.032", "0.045"], impulse_args=[],
                  reversibility_args=[], dam_break_dx="0.02", dam_break_pfreq=833),
}


def cavity_name(re, nx):
    return f"cavity_re{re}_nx{nx}"


def cavity_pfreq(dt):
    """Steps between outputs so that the files fall on CAVITY_TIMES (every 2.5 time units)."""
    return int(round(CAVITY_TIMES[0] / float(dt)))


# ------------------------------------------------------------------ case lists
def plate_cases(cfg):
    """The plate with the penalty (c_p = 10 c0) and without (c_p = 0), [P] Figs. 2-4, [T] 2.1-2.3."""
    base = ["--nw", str(cfg["plate_nw"]), "--pfreq", str(cfg["plate_pfreq"])]
    return {"plate_cp10": ("beryllium_plate", base), "plate_cp0": ("beryllium_plate", base + ["--cp-factor", "0"])}


def column_cases(cfg):
    return {"column": ("twisting_column", ["--n", str(cfg["column_n"]), "--pfreq", str(cfg["column_pfreq"])])}


def couette_cases(cfg):
    return {"couette": ("taylor_couette", ["--nr", str(cfg["couette_nr"])])}


def cavity_cases(cfg):
    """Re 100 (with the snapshots of Figs. 10-11), 400 and 1000, all to t = 20."""
    out = {}
    for re, nx, cs, dt in cfg["cavity"]:
        args = ["--nx", str(nx), "--re", str(re), "--cs", cs, "--dt", dt]
        if re == 100:
            args += ["--pfreq", str(cavity_pfreq(dt))]
        out[cavity_name(re, nx)] = ("shtc_cavity", args)
    return out


def thesis_cases(cfg):
    """[T] Theorem 1's kernel-interpolation study, sec. 2.2's impulse of shear, reversibility."""
    return {"kernel_convergence": ("shtc_kernel_convergence", list(cfg["kernel_args"])),
            "impulse_of_shear": ("shtc_impulse_of_shear", ["--disable-output", *cfg["impulse_args"]]),
            "reversibility": ("shtc_reversibility", ["--disable-output", *cfg["reversibility_args"]])}


def dam_break_cases(cfg):
    """[T] sec. 1.6's dam break (Figs. 1.2-1.3) with the thesis' method, to t = 0.7 s (T = 3.1)."""
    return {"dam_break": ("dam_break_2d", ["--scheme", "symplectic", "--dx", cfg["dam_break_dx"],
                                           "--pfreq", str(cfg["dam_break_pfreq"])])}


SECTIONS = (plate_cases, column_cases, couette_cases, cavity_cases, thesis_cases, dam_break_cases)


def all_cases(cfg):
    return {name: case for cases in SECTIONS for name, case in cases(cfg).items()}


# ------------------------------------------------------------------ reading runs
def outputs(folder, prefix):
    """[(t, path)] of a run's particle files (empty if none)."""
    from sphgen import io
    try:
        files = io.output_files(folder, prefix)
    except OSError:
        return []
    return [(float(io.read_solver_data(p)["t"]), p) for p in files]


def nearest(files, times):
    """{time: (arrays, file time) or None}: the file nearest each time."""
    from sphgen import io
    if not files:
        return {t: None for t in times}
    have = np.array([t for t, _ in files])
    out = {}
    for t in times:
        k = int(np.argmin(np.abs(have - t)))
        out[t] = (io.load(files[k][1])["arrays"], float(have[k]))
    return out


def snapshots_upto_stop(folder, prefix, times):
    """:func:`nearest` of the run's files, with None for the times a stopped run did not reach."""
    files = outputs(folder, prefix)
    return {t: hit if files and reached(folder, t, files[-1][0]) else None
            for t, hit in nearest(files, times).items()}


def _prop(pa, name):
    return np.asarray(pa.get(name))


def _not_run(ax, title="", run=None):
    """An empty panel: "not run", or "stopped at t = ..." for a run the guard stopped."""
    ax.text(0.5, 0.5, "not run" if run is None else state_text(run), ha="center", va="center",
            transform=ax.transAxes)
    ax.set_title(title, fontsize=8)


def _summary(run, keys, what):
    """{key: value} of the run's results.json (the ``keys`` it has, all if None); None if it
    has none; ``stopped_at`` only (and a note naming ``what``) if the guard stopped it."""
    res = read_results(run, what)
    if res is not None:
        return {k: res[k] for k in keys if k in res} if keys else res
    return pick(run, None, ()) if run_state(run) == "stopped" else None


def _mark_stopped(png, run):
    """Redraw the figure file ``png`` of a stopped run with "stopped at t = ..." above it."""
    if run_state(run) != "stopped":
        return
    plt = _plt()
    image = plt.imread(png)
    fig = plt.figure(figsize=(image.shape[1] / 100, image.shape[0] / 100 + 0.4))
    ax = fig.add_axes((0, 0, 1, image.shape[0] / (image.shape[0] + 40)))
    ax.imshow(image)
    ax.axis("off")
    fig.suptitle(f"{os.path.basename(os.path.normpath(run))}{state_suffix(run)}", fontsize=9)
    fig.savefig(png, dpi=100)
    plt.close(fig)


def _copy_plot(src_folder, png, out_dir, name, title):
    """A figure of ours that the application already draws: its png, or a "not run" panel."""
    src = os.path.join(src_folder, png)
    if os.path.exists(src):
        os.makedirs(os.path.join(out_dir, name), exist_ok=True)
        shutil.copy(src, os.path.join(out_dir, name, name + ".png"))
        return True
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5, 3))
    _not_run(ax, title, src_folder)
    _save(fig, out_dir, name)
    return False


# ------------------------------------------------------------------ [P] Fig. 1, [T] Fig. 1.1
def kernel_h_derivatives(dim, r, h=1.0):
    """(h dW/dh, (h/r) d2W/(dr dh)) of the scheme's Wendland kernel, and their central
    finite differences in h of W and of dW/dr (the check of [P] Fig. 1's curves)."""
    from sphgen.kernels import WendlandQuinticC2
    k = WendlandQuinticC2(dim)
    gradh = np.array([k.gradh(x, h) for x in r])
    mixed = np.array([k.mixed(x, h) for x in r])
    e = 1e-5 * h
    fd_gradh = np.array([h * (k.w(x, h + e) - k.w(x, h - e)) / (2 * e) for x in r])
    fd_mixed = np.array([h / x * (k.dwdr(x, h + e) - k.dwdr(x, h - e)) / (2 * e) if x > 0 else np.nan for x in r])
    return gradh, mixed, fd_gradh, fd_mixed


def p_fig1(out_dir):
    """[P] Fig. 1: h dW/dh (left) and (h/r) d2W/(dr dh) (right), 2D and 3D, h = 1."""
    plt = _plt()
    r = np.linspace(1e-3, 2.0, 400)
    fig, (a, b) = plt.subplots(1, 2, figsize=(9, 3.6))
    data = {}
    for dim, style in ((2, "-"), (3, "--")):
        g, m, fg, fm = kernel_h_derivatives(dim, r)
        a.plot(r, g, style, label=f"{dim}D")
        b.plot(r, m, style, label=f"{dim}D")
        scale_g, scale_m = np.abs(g).max(), np.abs(m).max()
        data[f"{dim}D"] = {"gradh_vs_finite_difference": float(np.nanmax(np.abs(g - fg)) / scale_g),
                           "mixed_vs_finite_difference": float(np.nanmax(np.abs(m - fm)) / scale_m)}
    a.set_xlabel("r")
    a.set_title("$h\\,\\partial w/\\partial h$", fontsize=9)
    b.set_xlabel("r")
    b.set_title("$(h/r)\\,\\partial^2 w/\\partial r\\partial h$ (2D: the corrected factor 35/(8 pi))", fontsize=9)
    for ax in (a, b):
        ax.axhline(0.0, color="0.6", lw=0.5)
        ax.legend()
    fig.suptitle("[P] Fig. 1: Wendland kernel (sphgen/kernels.py), h = 1", fontsize=9)
    _save(fig, out_dir, "P_fig1")
    _dump(out_dir, "P_fig1", data)
    return data


def t_fig1_1(out_dir):
    """[T] Fig. 1.1, the SPH sketch: particles on the scheme's lattice, one particle's support
    (radius 2h, h = 1.5 dr) and the kernel weights it gives its neighbours."""
    from sphgen.applications.beryllium_plate import isometric_lattice
    from sphgen.kernels import WendlandQuinticC2
    plt = _plt()
    dr, h = 1.0, 1.5
    x, y = isometric_lattice(dr, 12.0, 12.0)
    r = np.hypot(x, y)
    k = WendlandQuinticC2(2)
    w = np.array([k.w(q, h) for q in r])
    fig, ax = plt.subplots(figsize=(5, 5))
    inside = r < 2 * h
    ax.scatter(x[~inside], y[~inside], s=18, color="0.75")
    sc = ax.scatter(x[inside], y[inside], s=40, c=w[inside], cmap="viridis")
    ax.add_patch(plt.Circle((0, 0), 2 * h, fill=False, ls="--"))
    ax.annotate("a", (0, 0), xytext=(0.25, 0.3))
    ax.set_aspect("equal")
    fig.colorbar(sc, ax=ax, shrink=0.7, label="$w(|x_a - x_b|, h)$")
    ax.set_title(f"[T] Fig. 1.1 (sketch): support 2h of particle a, h = 1.5 dr, {int(inside.sum()) - 1} "
                 "neighbours", fontsize=8)
    _save(fig, out_dir, "T_fig1_1")


# ------------------------------------------------------------------ plate
ENERGY_PARTS = ("kinetic", "bulk", "shear", "penalty", "total")


def plate_figures(sim_dir, out_dir, cfg):
    plt = _plt()
    run = {k: os.path.join(sim_dir, k) for k in ("plate_cp10", "plate_cp0")}
    h = history(run["plate_cp10"])
    for name, title in (("P_fig2", "[P] Fig. 2"), ("T_fig2_3", "[T] Fig. 2.3")):
        fig, ax = plt.subplots(figsize=(6, 3.6))
        if h is None:
            _not_run(ax)
        else:
            ax.plot(h["t"], h["y_centre"], "C1-", label="SHTC-SPH (sphgen)" + state_suffix(run["plate_cp10"]))
            ax.legend(fontsize=7)
        ax.set_xlabel("t [s]")
        ax.set_ylabel("y of the centre point [m]")
        ax.set_title(f"{title}: ours only (the finite-volume reference of Boscheri et al. 2022 is not "
                     "available)", fontsize=7)
        _save(fig, out_dir, name)
    for name, title, norm in (("P_fig3", "[P] Fig. 3: energy contributions / initial total", True),
                              ("T_fig2_2", "[T] Fig. 2.2: energy contributions", False)):
        fig, ax = plt.subplots(figsize=(6, 3.6))
        if h is None:
            _not_run(ax)
        else:
            e0 = h["total"][0] if norm else 1.0
            for part in ENERGY_PARTS:
                ax.plot(h["t"], h[part] / e0, label=part)
            drift = float(np.abs(h["total"] / h["total"][0] - 1.0).max())
            ax.legend(fontsize=7)
            title += f"; largest relative drift of the total {drift:.2g}" + state_suffix(run["plate_cp10"])
        ax.set_xlabel("t [s]")
        ax.set_ylabel("E / E(0)" if norm else "E [J/m]")
        ax.set_title(title, fontsize=8)
        _save(fig, out_dir, name)
    # [P] Fig. 4: the end state with and without the penalty
    fig, axes = plt.subplots(2, 1, figsize=(8, 4.4))
    for ax, key, label in zip(axes, ("plate_cp10", "plate_cp0"), ("c_p = 10 c0", "c_p = 0")):
        files = outputs(run[key], "beryllium_plate")
        if not files:
            _not_run(ax, label)
            continue
        shot = nearest(files, (files[-1][0],))[files[-1][0]]
        _pressure(fig, ax, shot[0]["plate"], f"{label}, t = {shot[1]:.3g} s{state_suffix(run[key])}")
    fig.suptitle("[P] Fig. 4: pressure with the tensile penalty (top) and without (bottom)", fontsize=9)
    _save(fig, out_dir, "P_fig4")
    # [T] Fig. 2.1: three times of the run with the penalty
    files = outputs(run["plate_cp10"], "beryllium_plate")
    times = [f * files[-1][0] for f in PLATE_FRACTIONS] if files else list(PLATE_FRACTIONS)
    shots = nearest(files, times)
    fig, axes = plt.subplots(len(times), 1, figsize=(8, 2.0 * len(times)))
    for ax, t in zip(axes, times):
        if shots[t] is None:
            _not_run(ax, "c_p = 10 c0")
        else:
            _pressure(fig, ax, shots[t][0]["plate"], f"t = {shots[t][1]:.3g} s")
    fig.suptitle("[T] Fig. 2.1: the plate at three times (c_p = 10 c0), pressure" + state_suffix(run["plate_cp10"]),
                 fontsize=9)
    _save(fig, out_dir, "T_fig2_1")
    keep = ("energy_drift", "period", "period_error_euler_bernoulli", "period_error_timoshenko",
            "period_error_initial_omega", "void_fraction", "clump_fraction", "torn", "nw", "t")
    out = {k: _summary(v, keep, "its period, drift and tearing numbers") for k, v in run.items()}
    _dump(out_dir, "P_fig4", out)
    return out


def _pressure(fig, ax, pa, title):
    x, y, p = _prop(pa, "x"), _prop(pa, "y"), _prop(pa, "p")
    size = float(np.clip(8000.0 / max(pa.n, 1), 0.5, 20.0))
    lo, hi = np.percentile(p, [1, 99])          # a few clumped particles do not set the scale
    sc = ax.scatter(x, y, c=p, s=size, cmap="coolwarm", vmin=lo, vmax=hi)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=8)
    fig.colorbar(sc, ax=ax, label="p [Pa] (1-99 %)", shrink=0.8)


# ------------------------------------------------------------------ column
def column_figures(sim_dir, out_dir, cfg):
    from sphgen.applications.twisting_column import H
    plt = _plt()
    run = os.path.join(sim_dir, "column")
    shots = snapshots_upto_stop(run, "twisting_column", COLUMN_TIMES)
    fig, axes = plt.subplots(1, len(COLUMN_TIMES), figsize=(2.6 * len(COLUMN_TIMES) + 1, 6))
    for ax, t in zip(axes, COLUMN_TIMES):
        if shots[t] is None:
            _not_run(ax, f"t = {t:g} s", run)
            continue
        pa = shots[t][0]["column"]
        size = float(np.clip(12000.0 / max(pa.n, 1), 0.3, 20.0))
        p = _prop(pa, "p")
        lo, hi = np.percentile(p, [1, 99])
        sc = ax.scatter(_prop(pa, "x"), _prop(pa, "z"), c=p, s=size, cmap="coolwarm", vmin=lo, vmax=hi)
        ax.set_aspect("equal")
        ax.set_title(f"t = {shots[t][1]:.3g} s", fontsize=8)
        fig.colorbar(sc, ax=ax, shrink=0.6)
    fig.suptitle("[P] Fig. 5: twisting column, pressure [Pa] (1-99 % range), side view (x, z)" + state_suffix(run),
                 fontsize=9)
    _save(fig, out_dir, "P_fig5")
    h = history(run)
    fig, ax = plt.subplots(figsize=(6, 3.6))
    if h is None:
        _not_run(ax)
    else:
        for part in ENERGY_PARTS:
            ax.plot(h["t"], h[part], label=part)
        ax.legend(fontsize=7)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("E [J]")
    ax.set_title("[P] Fig. 6: energy of the twisting column" + state_suffix(run), fontsize=8)
    _save(fig, out_dir, "P_fig6")
    fig, ax = plt.subplots(figsize=(6, 3.6))
    if h is None:
        _not_run(ax)
    else:
        ax.plot(h["t"], h["z_top"] / H, "C1-", label="SHTC-SPH (sphgen)" + state_suffix(run))
        ax.legend(fontsize=7)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("z / H of the point initially at (0, 0, H)")
    ax.set_title("[P] Fig. 7: ours only (the paper's FEniCS curve is not available)", fontsize=8)
    _save(fig, out_dir, "P_fig7")
    res = _summary(run, None, "its results")
    _dump(out_dir, "P_fig7", res or {})
    return res


# ------------------------------------------------------------------ Taylor-Couette
def couette_figures(sim_dir, out_dir, cfg):
    plt = _plt()
    run = os.path.join(sim_dir, "couette")
    out = _summary(run, None, "its velocity profile ([P] Fig. 8)")
    res = None if out is None or "stopped_at" in out else out
    fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
    if res is None:
        _not_run(a, run=run)
        _not_run(b, run=run)
    else:
        x, v, ve = (np.array(res[k]) for k in ("profile_x", "profile_v", "profile_exact"))
        for ax, shift in ((a, 0.0), (b, 1.0)):
            ax.plot(x, v - shift * x, "C1-", label="SHTC-SPH")
            ax.plot(x[::5], ve[::5] - shift * x[::5], "bs", label="exact (eq. 28)")
            ax.set_xlabel("x (y = 0)")
            ax.legend(fontsize=7)
        a.set_ylabel("$v_y$")
        b.set_ylabel("$v_y - \\omega r$")
        a.set_title(f"t = {res['t']:.3g}, mean error / (omega R2) = {res['profile_error']:.3g}", fontsize=8)
    fig.suptitle("[P] Fig. 8: tangential velocity along y = 0 (right: minus omega r)", fontsize=9)
    _save(fig, out_dir, "P_fig8")
    files = outputs(run, "taylor_couette")
    fig, ax = plt.subplots(figsize=(5.5, 4.6))
    if not files:
        _not_run(ax)
    else:
        shot = nearest(files, (files[-1][0],))[files[-1][0]]
        _field(fig, ax, shot[0], ("fluid",), "Axy", f"t = {shot[1]:.3g}{state_suffix(run)}")
    fig.suptitle("[P] Fig. 9: $A_{xy}$ (Taylor-Couette)", fontsize=9)
    _save(fig, out_dir, "P_fig9")
    return out


def _value(pa, what):
    if what == "speed":
        return np.hypot(_prop(pa, "u"), _prop(pa, "v"))
    return _prop(pa, "A").reshape(-1, 9)[:, 1]


def _field(fig, ax, arrays, names, what, title, lim=None):
    pas = [arrays[n] for n in names if n in arrays]
    x = np.concatenate([_prop(pa, "x") for pa in pas])
    y = np.concatenate([_prop(pa, "y") for pa in pas])
    c = np.concatenate([_value(pa, what) for pa in pas])
    size = float(np.clip(30000.0 / max(x.size, 1), 0.3, 30.0))   # about one marker per particle spacing
    if lim is None and what == "Axy":
        m = float(np.percentile(np.abs(c), 99)) or 1.0
        lim = (-m, m)
    if lim is None and what == "speed":
        lim = (0.0, 1.0)           # up to the lid's speed, the same scale in every panel
    sc = ax.scatter(x, y, c=c, s=size, cmap="viridis" if what == "speed" else "RdBu_r", vmin=lim[0], vmax=lim[1],
                    linewidths=0)
    ax.set_aspect("equal")
    ax.set_title(title, fontsize=8)
    fig.colorbar(sc, ax=ax, shrink=0.7, extend="max" if what == "speed" else "neither",
                 label="|v| (lid: 1)" if what == "speed" else "$A_{xy}$")
    return {"min": float(c.min()), "max": float(c.max())}


# ------------------------------------------------------------------ cavity
def cavity_evolution(out_dir, name, folder, what, suptitle):
    """One field of the Re = 100 cavity at CAVITY_TIMES (one panel each)."""
    plt = _plt()
    shots = snapshots_upto_stop(folder, "shtc_cavity", CAVITY_TIMES)
    fig, axes = plt.subplots(1, len(CAVITY_TIMES), figsize=(3.6 * len(CAVITY_TIMES), 3.4))
    shown = {}
    for ax, t in zip(axes, CAVITY_TIMES):
        if shots[t] is None:
            _not_run(ax, f"t = {t:g}", folder)
            continue
        shown[f"{t:g}"] = dict(t=shots[t][1], **_field(fig, ax, shots[t][0], ("fluid",), what,
                                                        f"t = {shots[t][1]:.4g}"))
    fig.suptitle(suptitle + state_suffix(folder), fontsize=9)
    _save(fig, out_dir, name)
    _dump(out_dir, name, shown)
    return shown


def _centrelines(ax_u, ax_v, res, ghia, re, cs, run):
    """v_x on x = 1/2 against y and v_y on y = 1/2 against x: the run's (at the end, and averaged
    over the second half of the run) and Ghia et al. (1982)."""
    ax_u.plot(ghia["u"], ghia["y"], "ks", mfc="none", ms=4, label="Ghia et al. (1982)")
    ax_v.plot(ghia["x"], ghia["v"], "ks", mfc="none", ms=4, label="Ghia et al. (1982)")
    if res is None:
        _not_run(ax_u, f"Re = {re}", run)
        _not_run(ax_v, f"Re = {re}", run)
        return
    ax_u.plot(res["u_centre"], ghia["y"], "C1-", label=f"SHTC-SPH, t = {res['t']:.3g}")
    ax_v.plot(ghia["x"], res["v_centre"], "C1-", label=f"SHTC-SPH, t = {res['t']:.3g}")
    if "u_centre_averaged" in res:
        lab = f"mean over t >= {res['averaged_from']:.3g}"
        ax_u.plot(res["u_centre_averaged"], ghia["y"], "b^", ms=3, label=lab)
        ax_v.plot(ghia["x"], res["v_centre_averaged"], "b^", ms=3, label=lab)
    err = f"max dev. {res['ghia_error']:.3f}" + (f", mean {res['ghia_error_averaged']:.3f}"
                                                 if "ghia_error_averaged" in res else "")
    ax_u.set_title(f"Re = {re}, nx = {res.get('nx')}: {err}", fontsize=7)
    ax_v.set_title(f"Re = {re}, nx = {res.get('nx')}, cs = {cs}, dt/tau = {res.get('dt_over_tau') or 0:.3g}",
                   fontsize=7)


def centreline_figure(out_dir, name, sim_dir, cfg, res_list, suptitle):
    from sphgen.tools.reference import ghia_1982
    plt = _plt()
    runs = {re: os.path.join(sim_dir, cavity_name(re, nx)) for re, nx, _, _ in cfg["cavity"]}
    speeds = {re: cs for re, _, cs, _ in cfg["cavity"]}
    fig, axes = plt.subplots(2, len(res_list), figsize=(4.2 * len(res_list), 7.2), squeeze=False)
    out = {}
    for k, re in enumerate(res_list):
        res = read_results(runs[re], "its centre-line velocities")
        _centrelines(axes[0][k], axes[1][k], res, ghia_1982(re), re, speeds[re], runs[re])
        axes[0][k].set_xlabel("$v_x$ on x = 1/2")
        axes[0][k].set_ylabel("y")
        axes[1][k].set_xlabel("x")
        axes[1][k].set_ylabel("$v_y$ on y = 1/2")
        axes[0][k].legend(fontsize=6)
        if res is not None or run_state(runs[re]) == "stopped":
            out[f"Re{re}"] = pick(runs[re], res, ("nx", "t", "ghia_error", "ghia_error_averaged", "ghia_error_window",
                                                  "ghia_error_interior", "dt_over_tau", "viscosity_factor",
                                                  "max_density_error"))
    fig.suptitle(suptitle, fontsize=9)
    _save(fig, out_dir, name)
    _dump(out_dir, name, out)
    return out


def cavity_figures(sim_dir, out_dir, cfg):
    re100 = os.path.join(sim_dir, cavity_name(*cfg["cavity"][0][:2]))
    for names, what, title in ((("P_fig10", "T_fig2_4"), "speed", "velocity field |v|"),
                               (("P_fig11", "T_fig2_5"), "Axy", "distortion $A_{xy}$")):
        for name in names:
            paper = "[P] Fig. " + name[5:] if name.startswith("P") else "[T] Fig. " + name[6:].replace("_", ".")
            cavity_evolution(out_dir, name, re100, what,
                             f"{paper}: cavity Re = 100, {title} (the caption gives no times: ours)")
    return {"P_fig12": centreline_figure(out_dir, "P_fig12", sim_dir, cfg, (100, 400),
                                         "[P] Fig. 12: centre-line velocities, Re = 100 and 400"),
            "T_fig2_6": centreline_figure(out_dir, "T_fig2_6", sim_dir, cfg, CAVITY_RE,
                                          "[T] Fig. 2.6: centre-line velocities, Re = 100, 400, 1000 at t = 20")}


# ------------------------------------------------------------------ thesis extras, dam break
def thesis_figures(sim_dir, out_dir, cfg):
    got = {"T_thm1_convergence": _copy_plot(os.path.join(sim_dir, "kernel_convergence"), "convergence.png", out_dir,
                                            "T_thm1_convergence", "[T] Theorem 1: kernel interpolation"),
           "T_sec2_2_impulse_of_shear": _copy_plot(os.path.join(sim_dir, "impulse_of_shear"), "profile.png",
                                                   out_dir, "T_sec2_2_impulse_of_shear", "[T] sec. 2.2"),
           "P_sec3_6_reversibility": _copy_plot(os.path.join(sim_dir, "reversibility"), "return.png", out_dir,
                                                "P_sec3_6_reversibility", "[P] sec. 3.6")}
    return {k: _summary(os.path.join(sim_dir, f), None, "its results")
            for k, f in zip(got, ("kernel_convergence", "impulse_of_shear", "reversibility"))}


DAM_BREAK_KEYS = ("dx", "t", "T", "toe_max_rel_dev_violeau", "toe_signed_dev_at_max_violeau",
                  "toe_max_rel_dev_koshizuka_oka_kincl", "toe_max_rel_dev_koshizuka_oka",
                  "toe_max_rel_dev_koshizuka_oka_mps", "energy_change_rel", "mass_drift", "n_outside_final")


def dam_break_figures(sim_dir, out_dir, cfg):
    """[T] Figs. 1.2 (snapshots, |v|) and 1.3 (the wavefront against Violeau and Koshizuka & Oka),
    drawn by the dam break application from its run (up to the stop, marked, if the guard
    stopped it); "not run" panels without one."""
    from sphgen.applications.dam_break_2d import thesis_figure_1_2, thesis_figure_1_3
    run = os.path.join(sim_dir, "dam_break")
    drawn = run_state(run) != "not run"
    for name, draw, title in (("T_fig1_2", thesis_figure_1_2, "[T] Fig. 1.2: dam break snapshots, |v|"),
                              ("T_fig1_3", thesis_figure_1_3, "[T] Fig. 1.3: wavefront x/a against T")):
        if drawn:
            os.makedirs(os.path.join(out_dir, name), exist_ok=True)
            draw(run, os.path.join(out_dir, name, name + ".png"))
            _mark_stopped(os.path.join(out_dir, name, name + ".png"), run)
        else:
            plt = _plt()
            fig, ax = plt.subplots(figsize=(5, 3))
            _not_run(ax, title)
            _save(fig, out_dir, name)
    res = read_results(run, "its wavefront deviations")
    out = pick(run, res, DAM_BREAK_KEYS) if res or run_state(run) == "stopped" else None
    _dump(out_dir, "T_fig1_3", out or {})
    return out


def figures(sim_dir, out_dir, cfg):
    """Every figure from what has finished; returns the numbers the figures show."""
    return {"P_fig1": p_fig1(out_dir), "T_fig1_1": t_fig1_1(out_dir),
            "plate": plate_figures(sim_dir, out_dir, cfg), "column": column_figures(sim_dir, out_dir, cfg),
            "couette": couette_figures(sim_dir, out_dir, cfg), "cavity": cavity_figures(sim_dir, out_dir, cfg),
            "thesis": thesis_figures(sim_dir, out_dir, cfg), "dam_break": dam_break_figures(sim_dir, out_dir, cfg)}


# ------------------------------------------------------------------ automan
class SHTCFigures(SphgenProblem):
    """Kincl et al. (2023) and Kincl's thesis (2023) ch. 1-2: every figure, the papers' sizes."""

    preset = "paper"

    def get_name(self):
        return "shtc" if self.preset == "paper" else "shtc_quick"

    def setup(self):
        job = dict(n_core=1, n_thread=1)
        self.cases = [Simulation(self.input_path(name), f"{self.sphgen(app)} {' '.join(args)}", job_info=job,
                                 threads=1)
                      for name, (app, args) in all_cases(CONFIG[self.preset]).items()]

    def run(self):
        self.make_output_dir()
        figures(self.input_path(), self.output_path(), CONFIG[self.preset])


class SHTCFiguresQuick(SHTCFigures):
    """The same figures from coarse runs (docs/shtc.md, "Figures: python automate.py shtc")."""

    preset = "quick"


PAPER_PROBLEMS = [SHTCFigures]
QUICK_PROBLEMS = [SHTCFiguresQuick]


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "outputs"
    preset = "quick" if "quick" in sys.argv[2:] else "paper"
    name = "shtc" if preset == "paper" else "shtc_quick"
    print(figures(os.path.join(root, name), os.path.join("manuscript", "figures", name), CONFIG[preset]))
