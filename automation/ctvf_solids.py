"""Elastic solids with CTVF, Adepu & Ramachandran (2021) sections 4.4-4.7, Figs. 18-29, Table 1.

Six problems, each with the paper preset and a ``quick`` one (coarse and short: the
whole quick set runs in a few minutes on one core; it checks the pipeline, not the
physics):

* ``ctvf_figs18-20_plate``: the oscillating plate (``sphgen run oscillating_plate``) with
  GTVF (Fig. 18a), GTVF + SPST (Fig. 18b), both with the Wendland C2 at h = 1.3 dx,
  CTVF + SPST (Fig. 19) and CTVF + SPST with H = 0.01 (Fig. 20); particles at the
  separation time, tip y(t), ``summary.json``.
* ``ctvf_table1_plate``: CTVF + SPST and GTVF over V_f = 0.001, 0.01, 0.03, 0.05; the period
  of the tip against Table 1 (``table1.md``, ``table1.json``, ``table1_period.png``).
* ``ctvf_fig21_plate_ipst``: CTVF + IPST with 10, 20, 30 particles across H; tip y(t).
* ``ctvf_fig23_uniaxial``: the uniaxial compression (``sphgen run uniaxial_compression``)
  at dx = 0.5, 1, 2 mm with CTVF and 1 mm with GTVF; von Mises stress at A against t.
* ``ctvf_figs24-28_rings``: the colliding rings (``sphgen run rings``): nu = 0.3975 and
  0.47 with SPST and IPST; particles (Figs. 24-26), points A and B (Fig. 28).
* ``ctvf_fig29_impact``: the high-velocity impact (``sphgen run impact``) with CTVF + SPST
  and GTVF; particles at four times, hole widths against the paper's.

Every figure is drawn from the runs' own outputs (``history.json``, ``results.json``,
``snapshot.npz``, the particle files).  A run the blow-up guard stopped is drawn up to its stop
and labelled "stopped at t = ..."; the numbers only its results.json would hold are None in the
summaries (and named in a printed note).  ``python -m automation.ctvf_solids [outputs]
[quick]`` redraws from finished runs without running anything.
"""
import json
import os
import sys

import numpy as np

from sphgen.tools.plots import particle_panels

from .tasks import SphgenProblem, Simulation, paper_and_quick, pick, reached, read_results, run_state, state_suffix

VF = (0.001, 0.01, 0.03, 0.05)
"""V_f of Table 1 (Adepu & Ramachandran 2021)."""

PRESETS = {
    "paper": dict(
        plate=dict(nh=10, tf=0.3, separation_time=0.22, tf_thin=0.6, separation_time_thin=0.51),
        table1=dict(nh=10, tf=0.3),
        fig21=dict(nh=(10, 20, 30), tf=1.0),
        uniaxial=dict(dx=(0.0005, 0.001, 0.002), gtvf_dx=0.001, tf=0.002),
        rings=dict(dx=0.001, tf=0.016, pfreq=2000),
        impact=dict(dx=0.0005, tf=8e-6, pfreq=135),
    ),
    "quick": dict(
        plate=dict(nh=4, tf=0.02, separation_time=0.01, tf_thin=0.02, separation_time_thin=0.01),
        table1=dict(nh=4, tf=0.2),
        fig21=dict(nh=(4, 6), tf=0.02),
        uniaxial=dict(dx=(0.005, 0.01), gtvf_dx=0.01, tf=2e-4),
        rings=dict(dx=0.004, tf=0.016, pfreq=400),
        impact=dict(dx=0.001, tf=8e-6, pfreq=70),
    ),
}


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _read(folder, name):
    """The JSON file ``name`` of a run that ended or was stopped, or None (not run, not ended)."""
    if run_state(folder) == "not run":
        return None
    try:
        with open(os.path.join(folder, name)) as f:
            return json.load(f)
    except (OSError, ValueError):
        return None


def _dump(out_dir, name, obj):
    with open(os.path.join(out_dir, name), "w") as fh:
        json.dump(obj, fh, indent=1)


def _rows(folder):
    hist = _read(folder, "history.json")
    return None if hist is None or not hist.get("rows") else np.array(hist["rows"], dtype=float)


def _drawn(folder, keys, what):
    """(results or None, summary entry, history rows) of a run that ended or was stopped (its
    results.json-only ``keys`` None, ``what`` named in a note, if stopped); None if not run."""
    rows = _rows(folder)
    if rows is None:
        return None
    res = read_results(folder, what)
    return res, pick(folder, res, keys), rows


def _num(value, fmt, scale=1.0, unit=""):
    """``value * scale`` formatted, or "n/a" for a missing value (words and yes/no as they are)."""
    if value is None:
        return "n/a"
    if isinstance(value, (str, bool)):
        return str(value).lower()
    return f"{value * scale:{fmt}}{unit}"


def overlay(path, series, xlabel, ylabel, title, reference=None):
    """Curves (label, x, y) on one axis; ``reference``: (x, y, label) drawn dashed black."""
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6.5, 4))
    for label, x, y in series:
        ax.plot(x, y, label=label)
    if reference is not None:
        ax.plot(reference[0], reference[1], "k--", label=reference[2])
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title, fontsize=9)
    if ax.get_legend_handles_labels()[0]:
        ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def snapshots(folder, app, arrays, times, value="p"):
    """[(t, x, y, value)] from the particle files nearest to ``times`` (of the arrays named); the
    times a stopped run did not reach are left out."""
    from sphgen import io
    try:
        files = io.output_files(folder, app)
    except OSError:
        return []
    if not files:
        return []
    loaded = [io.load(f) for f in files]
    ts = np.array([d["solver_data"]["t"] for d in loaded])
    out = []
    for t in (t for t in times if reached(folder, t, ts.max())):
        d = loaded[int(np.argmin(np.abs(ts - t)))]
        pas = [d["arrays"][a] for a in arrays]
        out.append((float(d["solver_data"]["t"]), *(np.concatenate([getattr(pa, c) for pa in pas])
                                                      for c in ("x", "y", value))))
    return out


# ------------------------------------------------------------------ oscillating plate
GTVF_KERNEL = dict(kernel="wendland", hdx=1.3)
"""The kernel of both GTVF panels of Fig. 18: the Wendland C2 at h = 1.3 dx (the public GTVF
plate script's; with the quintic at h = dx our GTVF plate fractures, docs/ctvf.md, "Fig. 18a")."""
PLATE_CASES = {
    "gtvf": ("Fig. 18a: GTVF", dict(scheme="gtvf", **GTVF_KERNEL)),
    "gtvf_spst": ("Fig. 18b: GTVF + SPST", dict(scheme="gtvf", shifting="spst", free_surface=None, **GTVF_KERNEL)),
    "ctvf_spst": ("Fig. 19: CTVF + SPST", dict(scheme="ctvf")),
    "ctvf_spst_h001": ("Fig. 20: CTVF + SPST, H = 0.01", dict(scheme="ctvf", height=0.01)),
}


def plate_cases(cfg):
    """{name: params} of ``ctvf_figs18-20_plate`` (automan keyword form)."""
    out = {}
    for name, (_, extra) in PLATE_CASES.items():
        thin = "height" in extra
        out[name] = dict(nh=cfg["nh"], tf=cfg["tf_thin" if thin else "tf"], threads=1, pfreq=1000000,
                         separation_time=cfg["separation_time_thin" if thin else "separation_time"], **extra)
    return out


def plate_figures(sim_dir, out_dir, cfg):
    """fig18_gtvf.png, fig19_ctvf_spst.png, fig20_ctvf_spst_h001.png, plate_tip.png, summary.json."""
    os.makedirs(out_dir, exist_ok=True)
    summary, tips = {}, []
    for name, (label, _) in PLATE_CASES.items():
        folder = os.path.join(sim_dir, name)
        got = _drawn(folder, ("t", "period", "period_paper", "period_error", "separated_upto", "separation_upto",
                              "separation_time"), "its period and separation")
        if got is None:
            continue
        _, summary[name], rows = got
        tips.append((label + state_suffix(folder), rows[:, 0], rows[:, 1]))
    panels = {}
    for name, (label, _) in PLATE_CASES.items():
        path = os.path.join(sim_dir, name, "snapshot.npz")
        if name in summary and os.path.exists(path):
            d = np.load(path)
            sep = summary[name]["separation_upto"]
            gap = "" if sep is None else f": bond gap {sep['bond_gap_max']:.2f} dx, {sep['pieces_max']} piece(s)"
            panels[name] = (f"{label}{state_suffix(os.path.dirname(path))}, t = {float(d['t']):.3g} s{gap}",
                            d["x"], d["y"], d["p"])
    for fig, names in (("fig18_gtvf.png", ("gtvf", "gtvf_spst")), ("fig19_ctvf_spst.png", ("ctvf_spst",)),
                       ("fig20_ctvf_spst_h001.png", ("ctvf_spst_h001",))):
        have = [panels[n] for n in names if n in panels]
        if have:
            particle_panels(os.path.join(out_dir, fig), have)
    overlay(os.path.join(out_dir, "plate_tip.png"), tips, "t [s]", "tip y [m]",
            "oscillating plate, V_f = 0.05: tip of the centre line")
    _dump(out_dir, "summary.json", summary)
    return summary


TABLE1_SCHEMES = {"ctvf": ("CTVF + SPST", {}), "gtvf": ("GTVF", dict(scheme="gtvf", **GTVF_KERNEL))}
"""Table 1's two numerical rows: CTVF (SPST) and GTVF (its own homogenisation, Fig. 18a's kernel)."""


def table1_cases(cfg):
    """{name: params} of ``ctvf_table1_plate``: CTVF + SPST and GTVF over V_f."""
    return {f"{'' if scheme == 'ctvf' else scheme + '_'}vf{vf:g}":
            dict(vf=vf, nh=cfg["nh"], tf=cfg["tf"], threads=1, pfreq=1000000, **extra)
            for scheme, (_, extra) in TABLE1_SCHEMES.items() for vf in VF}


def table1_figures(sim_dir, out_dir, cfg):
    """table1.json, table1.md, table1_period.png, table1_tip.png (tip y / (V_f c0))."""
    from sphgen.applications.oscillating_plate import PERIOD_PAPER, PERIOD_PAPER_GTVF
    paper = {"ctvf": PERIOD_PAPER, "gtvf": PERIOD_PAPER_GTVF}
    os.makedirs(out_dir, exist_ok=True)
    rows, tips = {}, []
    for name, p in table1_cases(cfg).items():
        folder = os.path.join(sim_dir, name)
        hist = _read(folder, "history.json")
        if hist is None or not hist.get("rows"):
            continue
        scheme = p.get("scheme", "ctvf")
        res = read_results(folder, "its period")
        rows[name] = {"scheme": scheme, "vf": p["vf"], "period_paper": paper[scheme][p["vf"]],
                      **pick(folder, res, ("period", "period_from", "period_thin_plate", "separated", "t"))}
        period = rows[name]["period"]       # the error against this scheme's row of Table 1
        rows[name]["period_error"] = None if period is None else period / rows[name]["period_paper"] - 1.0
        r = np.array(hist["rows"], dtype=float)
        tips.append((f"{TABLE1_SCHEMES[scheme][0]}, V_f = {p['vf']:g}{state_suffix(folder)}", r[:, 0],
                     r[:, 1] / (p["vf"] * hist["c0"])))
    lines = ["| scheme | V_f | T (sphgen) | from | T (Table 1) | error | T thin plate | separated |",
             "| --- | --- | --- | --- | --- | --- | --- | --- |"]
    for name, r in rows.items():
        stop = state_suffix(os.path.join(sim_dir, name))
        lines.append(f"| {TABLE1_SCHEMES[r['scheme']][0]} | {r['vf']:g}{stop} | {_num(r['period'], '.4f', unit=' s')} | "
                     f"{_num(r['period_from'], '')} | {r['period_paper']} s | "
                     f"{_num(r['period_error'], '+.1f', 100, ' %')} | "
                     f"{_num(r['period_thin_plate'], '.4f', unit=' s')} | {_num(r['separated'], '')} |")
    with open(os.path.join(out_dir, "table1.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    _dump(out_dir, "table1.json", rows)
    plt = _plt()
    fig, ax = plt.subplots(figsize=(5.5, 4))
    for (scheme, (label, _)), (paper_style, ours_style) in zip(TABLE1_SCHEMES.items(),
                                                               (("ks--", "ro-"), ("k^:", "b^-"))):
        ax.semilogx(VF, [paper[scheme][v] for v in VF], paper_style, label=f"{label}, Table 1")
        got = [(r["vf"], r["period"]) for r in rows.values() if r["scheme"] == scheme and r["period"] is not None]
        if got:
            ax.semilogx(*zip(*got), ours_style, label=f"sphgen {label}")
    ax.set_xlabel("V_f")
    ax.set_ylabel("period of the tip [s]")
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(os.path.join(out_dir, "table1_period.png"), dpi=110)
    plt.close(fig)
    overlay(os.path.join(out_dir, "table1_tip.png"), tips, "t [s]", "tip y / (V_f c0) [s]",
            "tip displacement scaled by the initial tip speed")
    return rows


def fig21_cases(cfg):
    """{name: params} of ``ctvf_fig21_plate_ipst``: CTVF + IPST, V_f = 0.05, nh across H."""
    return {f"ipst_nh{n}": dict(shifting="ipst", nh=n, tf=cfg["tf"], threads=1, pfreq=1000000) for n in cfg["nh"]}


def fig21_figures(sim_dir, out_dir, cfg):
    """fig21_ipst_convergence.png (tip y against t for each resolution), summary.json."""
    os.makedirs(out_dir, exist_ok=True)
    series, summary = [], {}
    for name, p in fig21_cases(cfg).items():
        folder = os.path.join(sim_dir, name)
        got = _drawn(folder, ("t", "dx", "period", "period_from", "period_paper", "separated"), "its period")
        if got is None:
            continue
        res, summary[name], rows = got
        dx = "" if res is None else f" (dx = {res['dx'] * 1e3:.3g} mm)"
        series.append((f"{p['nh']} across H{dx}{state_suffix(folder)}", rows[:, 0], rows[:, 1]))
    overlay(os.path.join(out_dir, "fig21_ipst_convergence.png"), series, "t [s]", "tip y [m]",
            "Fig. 21: CTVF + IPST, V_f = 0.05, L = 0.2, H = 0.02")
    _dump(out_dir, "summary.json", summary)
    return summary


# ------------------------------------------------------------------ uniaxial compression
def uniaxial_cases(cfg):
    """{name: params} of ``ctvf_fig23_uniaxial``."""
    out = {f"ctvf_dx{dx * 1e3:g}mm": dict(dx=dx, tf=cfg["tf"], threads=1, pfreq=1000000) for dx in cfg["dx"]}
    out[f"gtvf_dx{cfg['gtvf_dx'] * 1e3:g}mm"] = dict(scheme="gtvf", dx=cfg["gtvf_dx"], tf=cfg["tf"], threads=1,
                                                     pfreq=1000000)
    return out


def uniaxial_figures(sim_dir, out_dir, cfg):
    """fig23_von_mises.png (von Mises at A against t, beside the plane-strain ramp), summary.json."""
    os.makedirs(out_dir, exist_ok=True)
    series, summary, ramp = [], {}, None
    for name in uniaxial_cases(cfg):
        folder = os.path.join(sim_dir, name)
        got = _drawn(folder, ("t", "von_mises_A_final", "von_mises_estimate_final", "von_mises_slope_over_estimate"),
                     "its final von Mises stress")
        if got is None:
            continue
        _, summary[name], rows = got
        series.append((name.replace("_", ", ").upper().replace("MM", " mm") + state_suffix(folder),
                       rows[:, 0] * 1e3, rows[:, 1] / 1e3))
        ramp = (rows[:, 0] * 1e3, rows[:, 2] / 1e3, "E V t / ((1 - nu^2) H)")
    overlay(os.path.join(out_dir, "fig23_von_mises.png"), series, "t [ms]", "von Mises stress at A [kPa]",
            "Fig. 23 (Das & Cleary's curves not shipped: the free-side plane-strain ramp instead)", ramp)
    _dump(out_dir, "summary.json", summary)
    return summary


# ------------------------------------------------------------------ rings
RING_CASES = {
    "nu0.3975_spst": ("Fig. 24: nu = 0.3975, SPST", dict(poisson=0.3975, shifting="spst")),
    "nu0.47_spst": ("Fig. 25: nu = 0.47, SPST", dict(poisson=0.47, shifting="spst")),
    "nu0.47_ipst": ("Fig. 26: nu = 0.47, IPST", dict(poisson=0.47, shifting="ipst")),
    "nu0.3975_ipst": ("Fig. 28: nu = 0.3975, IPST", dict(poisson=0.3975, shifting="ipst")),
}


def ring_cases(cfg):
    """{name: params} of ``ctvf_figs24-28_rings``."""
    return {name: dict(dx=cfg["dx"], tf=cfg["tf"], threads=1, pfreq=cfg["pfreq"], **extra)
            for name, (_, extra) in RING_CASES.items()}


def ring_figures(sim_dir, out_dir, cfg):
    """fig24-26 (particles coloured by p at four times), fig28_points.png, rings_energy.png,
    rings_gap.png, summary.json."""
    os.makedirs(out_dir, exist_ok=True)
    summary, points, energy, gap = {}, [], [], []
    times = cfg["tf"] * np.array([0.0, 1 / 3, 2 / 3, 1.0])
    for k, (name, (label, _)) in enumerate(RING_CASES.items()):
        folder = os.path.join(sim_dir, name)
        got = _drawn(folder, ("t", "energy_final_over_initial", "energy_max_over_initial", "gap_final_over_dx",
                              "separated", "bounced", "max_speed_over_c0"), "its energy, gap and bounce numbers")
        if got is None:
            continue
        _, summary[name], rows = got
        label += state_suffix(folder)
        t = rows[:, 0] * 1e3
        e = rows[:, 1] + rows[:, 2] + rows[:, 10]
        energy.append((label, t, e / e[0]))
        gap.append((label, t, rows[:, 11]))
        if name.startswith("nu0.3975"):
            points += [(f"{label[9:]}: x_A", t, rows[:, 4]), (f"{label[9:]}: y_B", t, rows[:, 7])]
        if k < 3:
            snaps = snapshots(folder, "rings", ("left", "right"), times)
            if snaps:
                particle_panels(os.path.join(out_dir, f"fig{24 + k}_rings_{name.replace('.', '')}.png"),
                                [(f"{label}, t = {ts * 1e3:.3g} ms", x, y, p) for ts, x, y, p in snaps],
                                size=(8.0, 3.2), marker=1)
    overlay(os.path.join(out_dir, "fig28_points.png"), points, "t [ms]", "position [m]",
            "Fig. 28: A (outer left), B (outer top) of the left ring; Gray et al. not shipped")
    overlay(os.path.join(out_dir, "rings_energy.png"), energy, "t [ms]", "E / E(0) (kinetic + elastic + contact)",
            "colliding rings: total energy")
    overlay(os.path.join(out_dir, "rings_gap.png"), gap, "t [ms]", "gap between the rings / dx",
            "colliding rings: in contact below 1 dx")
    _dump(out_dir, "summary.json", summary)
    return summary


# ------------------------------------------------------------------ impact
IMPACT_CASES = {"ctvf_spst": ("CTVF + SPST", dict(scheme="ctvf")), "gtvf": ("GTVF", dict(scheme="gtvf"))}


def impact_cases(cfg):
    """{name: params} of ``ctvf_fig29_impact``."""
    return {name: dict(dx=cfg["dx"], tf=cfg["tf"], threads=1, pfreq=cfg["pfreq"], **extra)
            for name, (_, extra) in IMPACT_CASES.items()}


def impact_figures(sim_dir, out_dir, cfg):
    """fig29_impact_<case>.png (particles coloured by p at four times), summary.json, summary.md."""
    os.makedirs(out_dir, exist_ok=True)
    summary = {}
    times = cfg["tf"] * np.array([0.0, 0.25, 0.5, 1.0])
    for name, (label, _) in IMPACT_CASES.items():
        folder = os.path.join(sim_dir, name)
        if run_state(folder) == "not run":
            continue
        res = read_results(folder, "its hole width")
        summary[name] = pick(folder, res, ("t", "hole_width", "hole_width_in_plane", "hole_paper", "hole_error"))
        snaps = snapshots(folder, "impact", ("solid",), times)
        if snaps:
            particle_panels(os.path.join(out_dir, f"fig29_impact_{name}.png"),
                            [(f"Fig. 29: {label}{state_suffix(folder)}, t = {ts * 1e6:.3g} us", x, y, p)
                             for ts, x, y, p in snaps], size=(6.0, 4.5), marker=1)
    lines = ["| case | t | hole width (petals) | in plane | paper (CTVF) | error |", "| --- | --- | --- | --- | --- | --- |"]
    for name, r in summary.items():
        t = r["t"] if r["t"] is not None else r.get("stopped_at")
        widths = " | ".join(_num(r[k], ".3g", 1e3, " mm") for k in ("hole_width", "hole_width_in_plane", "hole_paper"))
        lines.append(f"| {name}{state_suffix(os.path.join(sim_dir, name))} | {_num(t, '.3g', 1e6, ' us')} | "
                     f"{widths} | {_num(r['hole_error'], '+.1f', 100, ' %')} |")
    with open(os.path.join(out_dir, "summary.md"), "w") as fh:
        fh.write("\n".join(lines) + "\n")
    _dump(out_dir, "summary.json", summary)
    return summary


# ------------------------------------------------------------------ automan problems
SECTIONS = {
    # key: (output folder, application, case list, figures, figure files every finished run makes)
    "plate": ("ctvf_figs18-20_plate", "oscillating_plate", plate_cases, plate_figures,
              ("fig18_gtvf.png", "fig19_ctvf_spst.png", "fig20_ctvf_spst_h001.png", "plate_tip.png",
               "summary.json")),
    "table1": ("ctvf_table1_plate", "oscillating_plate", table1_cases, table1_figures,
               ("table1.md", "table1.json", "table1_period.png", "table1_tip.png")),
    "fig21": ("ctvf_fig21_plate_ipst", "oscillating_plate", fig21_cases, fig21_figures,
              ("fig21_ipst_convergence.png", "summary.json")),
    "uniaxial": ("ctvf_fig23_uniaxial", "uniaxial_compression", uniaxial_cases, uniaxial_figures,
                 ("fig23_von_mises.png", "summary.json")),
    "rings": ("ctvf_figs24-28_rings", "rings", ring_cases, ring_figures,
              ("fig24_rings_nu03975_spst.png", "fig25_rings_nu047_spst.png", "fig26_rings_nu047_ipst.png",
               "fig28_points.png", "rings_energy.png", "rings_gap.png", "summary.json")),
    "impact": ("ctvf_fig29_impact", "impact", impact_cases, impact_figures,
               ("fig29_impact_ctvf_spst.png", "fig29_impact_gtvf.png", "summary.json", "summary.md")),
}


class _CTVFSolidSection(SphgenProblem):
    """One section of the CTVF solids (``section``) at one preset."""

    section = None
    preset = "paper"

    def get_name(self):
        return SECTIONS[self.section][0] + ("" if self.preset == "paper" else f"_{self.preset}")

    def setup(self):
        _, app, cases, _, _ = SECTIONS[self.section]
        cmd = self.sphgen(app)
        self.cases = [Simulation(self.input_path(name), cmd, job_info=dict(n_core=1, n_thread=1), **params)
                      for name, params in cases(PRESETS[self.preset][self.section]).items()]

    def run(self):
        self.make_output_dir()
        SECTIONS[self.section][3](self.input_path(), self.output_path(), PRESETS[self.preset][self.section])


CLASS_NAMES = {"plate": ("CTVFPlate", "Figs. 18-20"), "table1": ("CTVFPlateTable1", "Table 1"),
               "fig21": ("CTVFPlateIPST", "Fig. 21"), "uniaxial": ("CTVFUniaxial", "Fig. 23"),
               "rings": ("CTVFRings", "Figs. 24-28"), "impact": ("CTVFImpact", "Fig. 29")}
"""automan class of each section (its quick preset: the name + ``Quick``) and its figures."""
_PAIRS = [paper_and_quick(_CTVFSolidSection, name, f"Adepu & Ramachandran (2021), {figs}", __name__, section=key)
          for key, (name, figs) in CLASS_NAMES.items()]
PAPER_PROBLEMS = [paper for paper, _ in _PAIRS]
QUICK_PROBLEMS = [quick for _, quick in _PAIRS]
globals().update({cls.__name__: cls for cls in PAPER_PROBLEMS + QUICK_PROBLEMS})   # CTVFPlate, CTVFPlateQuick, ...

if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "outputs"
    preset = "quick" if "quick" in sys.argv[2:] else "paper"
    for key, (folder, _, _, draw, _) in SECTIONS.items():
        name = folder + ("" if preset == "paper" else f"_{preset}")
        print(name, draw(os.path.join(root, name), os.path.join("manuscript", "figures", name), PRESETS[preset][key]))
