"""The figures of Kincl (2023, thesis ch. 3), superfluid helium-4 (docs/superfluid.md).

``python automate.py superfluid`` runs the thesis' cases (second sound N = 100, 200, 300;
the fountain's paper preset: days, docs/superfluid.md) and ``python automate.py
superfluid_quick`` a coarse set (second sound N <= 100, the fountain's quick preset, meant for
under half an hour on 2 cores; not timed).  Each figure goes to a folder named after it:

* ``fig3_1``: rho_n/rho and rho_s/rho against T: the linear model (eq. 3.25 with eq. 3.30)
  around 1.65 and 1.9 K.  The thesis plots Donnelly-Barenghi data that it does not print;
  none is shipped here, so only the model's lines are drawn (``fig3_1.png``);
* ``fig3_2``: left, the entropy error against A, a line per N (M = 50); right, the energy
  error against M, a line per A, with its log-log slope (``fig3_2.png``, numbers in
  ``fig3_2.json``);
* ``fig3_3``: s - s0 at (L/4, L/4) against eq. 3.51, A = 0.01, M = 50, the finest N;
* ``fig3_4``: the fountain's particles by type (no run needed);
* ``fig3_5``: the jet speed over time against eqs. 3.56-3.57 (60 and 80 W/m);
* ``fig3_6``: T in the cell at t = 0.25, 0.5, 0.75, 1 ms (80 W/m, a 1 ms run);
* ``fig3_7``: |v| at the end, three powers;
* ``fig3_8``: T and the shape at 80 W/m every tf/8 (37.5 ms for the paper preset).

A figure whose runs are missing is drawn with "not run" panels.  A run the blow-up guard stopped
is drawn up to its stop, labelled "stopped at t = ..."; the points only its results.json would
give (Figs. 3.2, 3.5) are left out, named in the legend or title and in a printed note.
``python -m automation.superfluid [outputs] [quick]`` redraws from finished runs.
"""
import json
import os
import sys

import numpy as np

from sphgen.applications.second_sound import loglog_slope

from .tasks import SphgenProblem, Simulation, reached, read_results, state_suffix, state_text, stopped_marks

CONFIG = {
    "paper": dict(N=(100, 200, 300), A=(0.01, 0.03, 0.05, 0.1), energy_N=200, Ms=(25, 50, 100),
                  energy_A=(0.01, 0.1), fountain="paper", powers=(60, 80, 100)),
    "quick": dict(N=(25, 50, 100), A=(0.01, 0.1), energy_N=50, Ms=(10, 25, 50),
                  energy_A=(0.01, 0.1), fountain="quick", powers=(60, 80, 100)),
}
M_ENTROPY = 50
START_TIMES = (0.25e-3, 0.5e-3, 0.75e-3, 1.0e-3)   # Fig. 3.6
SNAPSHOTS = 8                                       # Fig. 3.8: every tf/8


def ss_name(N, A, M):
    return f"ss_N{N}_A{A:g}_M{M:g}"


def second_sound_cases(cfg):
    """{name: sphgen run second_sound options} of Figs. 3.2-3.3."""
    out = {ss_name(N, A, M_ENTROPY): dict(N=N, A=A, M=M_ENTROPY) for N in cfg["N"] for A in cfg["A"]}
    out.update({ss_name(cfg["energy_N"], A, M): dict(N=cfg["energy_N"], A=A, M=M)
                for A in cfg["energy_A"] for M in cfg["Ms"]})
    return out


def fountain_dt(preset):
    """The fountain's time step at a preset: 0.4 h/c1, h = 1.4 dr, dr = r_cap/ratio."""
    from sphgen.applications.fountain import HDX, MODEL, PRESETS, R_CAP
    return 0.4 * HDX * R_CAP / PRESETS[preset]["ratio"] / MODEL.c1


def fountain_cases(cfg):
    """{name: sphgen run fountain options}: one run per power (outputs every tf/8) and the
    1 ms start at 80 W/m (outputs every 0.25 ms) of Fig. 3.6."""
    from sphgen.applications.fountain import PRESETS
    preset = cfg["fountain"]
    dt, tf = fountain_dt(preset), PRESETS[preset]["tf"]
    out = {f"fountain_W{W}": dict(preset=preset, power=W, pfreq=max(1, int(round(tf / SNAPSHOTS / dt))))
           for W in cfg["powers"]}
    out["fountain_start_W80"] = dict(preset=preset, power=80, tf=START_TIMES[-1] * (1 + 1e-6),
                                     pfreq=max(1, int(round(START_TIMES[0] / dt))))
    return out


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _json(folder, name):
    try:
        with open(os.path.join(folder, name)) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def _save(fig, out_dir, name):
    folder = os.path.join(out_dir, name)
    os.makedirs(folder, exist_ok=True)
    fig.tight_layout()
    fig.savefig(os.path.join(folder, name + ".png"), dpi=110)
    _plt().close(fig)
    return folder


def fig3_1(out_dir):
    """rho_n/rho and rho_s/rho of the linear model (eqs. 3.25, 3.30) around both presets."""
    from sphgen.equations.superfluid_energy import HELIUM_1_65K, HELIUM_1_9K
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 4))
    for model, color in ((HELIUM_1_65K, "tab:blue"), (HELIUM_1_9K, "tab:red")):
        T = np.linspace(model.T0 - 0.1, model.T0 + 0.1, 50)
        rhon = model.rhon0 + model.gamma * model.cv * (T - model.T0) / model.T0
        ax.plot(T, rhon, "-", color=color, label=f"rho_n/rho, linear model at {model.T0:g} K")
        ax.plot(T, 1 - rhon, "--", color=color, label=f"rho_s/rho, linear model at {model.T0:g} K")
    ax.set_xlabel("T [K]")
    ax.set_ylabel("fraction")
    ax.set_title("Fig. 3.1: the linear model only (no Donnelly-Barenghi data shipped)", fontsize=9)
    ax.legend(fontsize=7)
    _save(fig, out_dir, "fig3_1")


def fig3_2(sim_dir, out_dir, cfg):
    """Entropy error against A per N (M = 50); energy error against M per A (N = energy_N)."""
    plt = _plt()
    fig, (a, b) = plt.subplots(1, 2, figsize=(11, 4))
    data = {"entropy_error": {}, "energy_error": {}, "energy_slope": {}}
    for N in cfg["N"]:
        runs = {f"A = {A:g}": os.path.join(sim_dir, ss_name(N, A, M_ENTROPY)) for A in cfg["A"]}
        pts = [[A, r["entropy_error"]] for A, run in zip(cfg["A"], runs.values())
               if (r := read_results(run, "its entropy error (Fig. 3.2)"))]
        data["entropy_error"][str(N)] = pts
        if pts:
            a.plot(*zip(*pts), "o-", label=f"N = {N}{stopped_marks(runs)}")
    a.set_xlabel("A")
    a.set_ylabel("max RMS (s - s_exact)/(A s0)")
    a.set_title(f"entropy error, M = {M_ENTROPY}, one period")
    for A in cfg["energy_A"]:
        runs = {f"M = {M:g}": os.path.join(sim_dir, ss_name(cfg["energy_N"], A, M)) for M in cfg["Ms"]}
        pts = [[M, r["energy_error"]] for M, run in zip(cfg["Ms"], runs.values())
               if (r := read_results(run, "its energy error (Fig. 3.2)"))]
        data["energy_error"][f"{A:g}"] = pts
        if pts:
            M, e = np.array(pts).T
            label = f"A = {A:g}{stopped_marks(runs)}"
            if len(pts) > 1:   # the log-log slope of the energy error against M (issue 13)
                data["energy_slope"][f"{A:g}"] = slope = loglog_slope(M, e)
                label += f", slope {slope:.2f}"
            b.plot(np.log10(1 / M), np.log10(e), "o-", label=label)
    b.set_xlabel("log10(1/M)")
    b.set_ylabel("log10 max |E - E0|/E0")
    b.set_title(f"energy error, N = {cfg['energy_N']}")
    for ax in (a, b):
        if ax.lines:
            ax.legend()
        else:
            ax.text(0.5, 0.5, "not run", ha="center", transform=ax.transAxes)
    folder = _save(fig, out_dir, "fig3_2")
    with open(os.path.join(folder, "fig3_2.json"), "w") as f:
        json.dump(data, f, indent=1)
    return data


def fig3_3(sim_dir, out_dir, cfg):
    """s - s0 at (L/4, L/4) against eq. 3.51 (A = 0.01, M = 50, the finest N)."""
    from sphgen.applications.second_sound import MODEL
    plt = _plt()
    N = max(cfg["N"])
    run = os.path.join(sim_dir, ss_name(N, 0.01, M_ENTROPY))
    hist = _json(run, "history.json")
    fig, ax = plt.subplots(figsize=(6, 4))
    if hist is None:
        ax.text(0.5, 0.5, "not run", ha="center", transform=ax.transAxes)
    else:
        rows = np.array(hist["rows"])
        c = {k: rows[:, i] for i, k in enumerate(hist["columns"])}
        ax.plot(c["t"] * 1e3, c["s_probe_exact"] - MODEL.s0, "k-", label="eq. 3.51")
        ax.plot(c["t"][::4] * 1e3, c["s_probe"][::4] - MODEL.s0, "r.", ms=4, label="sphgen" + state_suffix(run))
        ax.legend()
    ax.set_xlabel("t [ms]")
    ax.set_ylabel("s - s0 at (L/4, L/4) [J/(kg K)]")
    ax.set_title(f"Fig. 3.3: A = 0.01, M = {M_ENTROPY}, N = {N}", fontsize=9)
    _save(fig, out_dir, "fig3_3")


def fig3_4(out_dir, cfg):
    """The apparatus: the particles of the preset by type (drawn from the application's lattice)."""
    from sphgen.applications.fountain import HDX, PRESETS, R_CAP, apparatus
    from sphgen.geometry import layers_for_support
    plt = _plt()
    dr = R_CAP / PRESETS[cfg["fountain"]]["ratio"]
    x, y, ptype, _ = apparatus(dr, layers_for_support(2.0, HDX))
    fig, ax = plt.subplots(figsize=(5, 9))
    for t, color, label in ((0, "tab:blue", "FLUID"), (1, "tab:gray", "ADIABATIC"), (2, "tab:cyan", "COOLER")):
        k = ptype == t
        ax.scatter(x[k] * 1e3, y[k] * 1e3, s=0.2 if x.size > 20000 else 1.5, color=color, label=f"{label} ({k.sum()})")
    ax.set_aspect("equal")
    ax.set_xlabel("x [mm]")
    ax.set_ylabel("y [mm]")
    ax.legend(markerscale=8, fontsize=7, loc="upper right")
    ax.set_title(f"Fig. 3.4: {cfg['fountain']} preset, dr = {dr * 1e3:.4g} mm", fontsize=9)
    _save(fig, out_dir, "fig3_4")


def fig3_5(sim_dir, out_dir, cfg):
    """Jet speed (flux over rho0 2 r_cap, moving mean) against eqs. 3.56-3.57, 60 and 80 W/m."""
    from sphgen.applications.fountain import MODEL, R_CAP
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 4))
    out = {}
    runs = {f"{W} W/m": os.path.join(sim_dir, f"fountain_W{W}") for W in (60, 80)}
    for (W, run), color in zip(zip((60, 80), runs.values()), ("tab:blue", "tab:red")):
        res = read_results(run, "its flux series (Fig. 3.5)")
        if res is None:
            continue
        fs = np.array(res["flux_series"])
        v = fs[:, 1] / (MODEL.rho0 * 2 * R_CAP)   # eq. 3.57: Q = rho0 v_jet 2 r_cap
        k = min(10, len(v))   # moving mean over k output intervals, no edge padding
        box = np.ones(k) / k
        ax.plot(np.convolve(fs[:, 0], box, "valid"), np.convolve(v, box, "valid"), "-", color=color,
                label=f"{W} W/m (moving mean of {k})")
        ax.axhline(res["v_jet_theory"], color=color, ls="--", label=f"eqs. 3.56-3.57, {W} W/m")
        out[W] = {"v_jet": res["v_jet"], "v_jet_theory": res["v_jet_theory"], "flux_error": res["flux_error"]}
    if not ax.lines:
        ax.text(0.5, 0.5, "not run", ha="center", transform=ax.transAxes)
    else:
        ax.legend(fontsize=7)
    ax.set_xlabel("t [s]")
    ax.set_ylabel("v_jet [m/s]")
    ax.set_title("Fig. 3.5: jet speed" + stopped_marks(runs), fontsize=9)
    folder = _save(fig, out_dir, "fig3_5")
    with open(os.path.join(folder, "fig3_5.json"), "w") as f:
        json.dump(out, f, indent=1)
    return out


def snapshots(folder, times, upto_stop=True):
    """{time: (output file, its time)} of the files nearest to each time: None if no file or,
    with ``upto_stop``, a time the run did not reach before the guard stopped it."""
    from sphgen import io
    try:
        files = io.output_files(folder, "fountain")
    except OSError:
        files = []
    if not files:
        return {t: None for t in times}
    have = np.array([io.read_solver_data(p)["t"] for p in files])
    return {t: (files[int(np.argmin(np.abs(have - t)))], float(have[np.argmin(np.abs(have - t))]))
            if not upto_stop or reached(folder, t, have.max()) else None for t in times}


def _field_panels(ax_list, shots, field, label, window, cmap, run):
    from sphgen import io
    from sphgen.applications.fountain import MODEL
    for ax, (t, hit) in zip(ax_list, shots.items()):
        if hit is None:
            ax.text(0.5, 0.5, state_text(run), ha="center", transform=ax.transAxes)
            ax.set_title(f"t = {t * 1e3:g} ms", fontsize=8)
            continue
        path, t_file = hit
        pa = io.load(path)["arrays"]["helium"]
        k = np.asarray(pa.ptype) == 0
        x, y = pa.x[k] * 1e3, pa.y[k] * 1e3
        c = field(pa, MODEL)[k]
        inside = (x > window[0]) & (x < window[1]) & (y > window[2]) & (y < window[3])
        size = float(np.clip(3000.0 / max(int(inside.sum()), 1), 0.3, 12.0))   # fill the panel
        sc = ax.scatter(x[inside], y[inside], c=c[inside], s=size, cmap=cmap)
        ax.set_aspect("equal")
        ax.set_xlim(window[:2])
        ax.set_ylim(window[2:])
        ax.set_title(f"t = {t_file * 1e3:.4g} ms", fontsize=8)
        ax.figure.colorbar(sc, ax=ax, shrink=0.7, label=label)


def fig3_6(sim_dir, out_dir):
    """T - T0 in the cell at 0.25, 0.5, 0.75 and 1 ms (80 W/m)."""
    plt = _plt()
    fig, axes = plt.subplots(1, 4, figsize=(15, 3.8))
    run = os.path.join(sim_dir, "fountain_start_W80")
    shots = snapshots(run, START_TIMES)
    _field_panels(axes, shots, lambda pa, M: (pa.T - M.T0) * 1e3, "T - T0 [mK]", (-8.5, 8.5, -0.5, 17.5), "inferno",
                  run)
    fig.suptitle("Fig. 3.6: temperature in the cell, 80 W/m" + state_suffix(run))
    _save(fig, out_dir, "fig3_6")


def fig3_7(sim_dir, out_dir, cfg):
    """|v| at the end of the run, every power."""
    from sphgen.applications.fountain import PRESETS
    plt = _plt()
    tf = PRESETS[cfg["fountain"]]["tf"]
    fig, axes = plt.subplots(1, len(cfg["powers"]), figsize=(4 * len(cfg["powers"]), 6))
    for ax, W in zip(np.atleast_1d(axes), cfg["powers"]):
        run = os.path.join(sim_dir, f"fountain_W{W}")
        shots = snapshots(run, (tf,), upto_stop=False)            # a stopped run: its last state
        _field_panels([ax], shots, lambda pa, M: np.hypot(pa.u, pa.v), "|v| [m/s]", (-25, 25, -10, 60), "viridis",
                      run)
        ax.set_title(f"{W} W/m{state_suffix(run)}, " + ax.get_title(), fontsize=8)
    fig.suptitle("Fig. 3.7: |v| at the end")
    _save(fig, out_dir, "fig3_7")


def fig3_8(sim_dir, out_dir, cfg):
    """T - T0 and the shape of the fluid at 80 W/m every tf/8."""
    from sphgen.applications.fountain import PRESETS
    plt = _plt()
    tf = PRESETS[cfg["fountain"]]["tf"]
    times = tuple(tf * (k + 1) / SNAPSHOTS for k in range(SNAPSHOTS))
    fig, axes = plt.subplots(2, SNAPSHOTS // 2, figsize=(16, 9))
    run = os.path.join(sim_dir, "fountain_W80")
    shots = snapshots(run, times)
    _field_panels(axes.ravel(), shots, lambda pa, M: (pa.T - M.T0) * 1e3, "T - T0 [mK]", (-25, 25, -10, 60), "inferno",
                  run)
    fig.suptitle("Fig. 3.8: temperature and shape, 80 W/m" + state_suffix(run))
    _save(fig, out_dir, "fig3_8")


def figures(sim_dir, out_dir, cfg):
    """Every figure from what has finished; returns the numbers of Figs. 3.2 and 3.5."""
    fig3_1(out_dir)
    summary = {"fig3_2": fig3_2(sim_dir, out_dir, cfg)}
    fig3_3(sim_dir, out_dir, cfg)
    fig3_4(out_dir, cfg)
    summary["fig3_5"] = fig3_5(sim_dir, out_dir, cfg)
    fig3_6(sim_dir, out_dir)
    fig3_7(sim_dir, out_dir, cfg)
    fig3_8(sim_dir, out_dir, cfg)
    return summary


class Superfluid(SphgenProblem):
    """Kincl (2023), thesis ch. 3: Figs. 3.1-3.8 at the thesis' resolutions."""

    preset = "paper"

    def get_name(self):
        return "superfluid" if self.preset == "paper" else "superfluid_quick"

    def setup(self):
        cfg = CONFIG[self.preset]
        job = dict(n_core=1, n_thread=1)
        ss, fo = self.sphgen("second_sound"), self.sphgen("fountain")
        self.cases = [Simulation(self.input_path(n), ss, job_info=job, threads=1, disable_output=None, **p)
                      for n, p in second_sound_cases(cfg).items()]
        self.cases += [Simulation(self.input_path(n), fo, job_info=job, threads=1, **p)
                       for n, p in fountain_cases(cfg).items()]

    def run(self):
        self.make_output_dir()
        figures(self.input_path(), self.output_path(), CONFIG[self.preset])


class SuperfluidQuick(Superfluid):
    """The same figures from coarse runs (second sound N <= 100, the fountain's quick preset)."""

    preset = "quick"


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "outputs"
    preset = "quick" if "quick" in sys.argv[2:] else "paper"
    name = "superfluid" if preset == "paper" else "superfluid_quick"
    print(figures(os.path.join(root, name), os.path.join("manuscript", "figures", name), CONFIG[preset]))
