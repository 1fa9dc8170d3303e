"""Taylor-Green vortex with CTVF, Adepu & Ramachandran (2021) section 4.1, Figs. 6-12.

Cases (``outputs/ctvf_figs06-12_taylor_green/<case>``): CTVF with SPST and IPST at
Re = 100 and 1000 for nx = 50, 100, 150 (Figs. 6-9), the same without the correction
terms (Figs. 10-11 show 150 x 150; the coarser pairs say how the gain changes with nx), and the baselines on the same case (the uncorrected EDAC
scheme and GTVF at nx = 50); t = 2 (the paper states no end time).

Figures: ``fig06_re100_spst.png``, ``fig07_re100_ipst.png``, ``fig08_re1000_ipst.png``,
``fig09_re1000_spst.png`` (max |u| against the exact decay; L1 error of |u|, eq. 66),
``fig10_spst_corrections.png``, ``fig11_ipst_corrections.png`` (L1 with and without the
corrections at 150 x 150, Re 100 and 1000), ``fig12_re1000_pressure.png`` (particles
coloured by pressure at t = 2, Re 1000, 150 x 150, SPST); ``baselines.png`` and
``summary.json`` / ``summary.md`` (final and largest L1, convergence orders, largest
deviation of max |u| from the exact decay, CTVF against EDAC and GTVF).

``python -m automation.ctvf_taylor_green [outputs]`` draws what the finished cases allow
(missing cases are left out and listed), without running anything.  A case the blow-up guard
stopped is drawn up to its stop, labelled "stopped at t = ..."; its L1 at t = 2 and the orders
that need it are NaN (None in summary.json), with a printed note.
"""
import json
import os
import sys

import numpy as np

from .tasks import SphgenProblem, Simulation, missing, run_info, run_state, state_suffix

RES = (100, 1000)
SHIFTINGS = ("spst", "ipst")
NX = (50, 100, 150)
BASELINE_NX = 50
TF = 2.0


def case_name(re, scheme="ctvf", shifting="spst", nx=50, corrections=True):
    """Folder of one run: re1000_ctvf_spst_nx150, ..._nocorr, re100_edac_nx50."""
    body = f"{scheme}_{shifting}" if scheme == "ctvf" else scheme
    return f"re{re}_{body}_nx{nx}" + ("" if corrections else "_nocorr")


def case_params(re, scheme="ctvf", shifting="spst", nx=50, corrections=True, tf=TF):
    """The ``sphgen run taylor_green`` options of one run (automan keyword form)."""
    p = dict(scheme=scheme, nx=nx, re=re, tf=tf, pfreq=1000000, threads=1)
    if scheme == "ctvf":
        p["shifting"] = shifting
        if not corrections:
            p["no_corrections"] = None
    return p


def all_cases(nx=NX, baseline_nx=BASELINE_NX):
    """[(name, params)] in the order a serial queue should run them (cheap first)."""
    out = []
    for re in RES:
        for s in SHIFTINGS:
            for n in nx:
                out += [(re, "ctvf", s, n, True), (re, "ctvf", s, n, False)]
        out += [(re, "edac", "", baseline_nx, True), (re, "gtvf", "", baseline_nx, True)]
    return [(case_name(*c), case_params(*c)) for c in out]


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def _legend(ax):
    if ax.get_legend_handles_labels()[0]:
        ax.legend()


def history(folder):
    """(t, max|u|, exact max|u|, L1) of a run that ended or was stopped (up to its stop), or None."""
    if run_state(folder) == "not run":
        return None
    try:
        with open(os.path.join(folder, "history.json")) as f:
            rows = np.array(json.load(f)["rows"])
    except (OSError, ValueError, KeyError):
        return None
    return rows[:, 0], rows[:, 1], rows[:, 2], rows[:, 3]


def _none_if_nan(v):
    return None if np.isnan(v) else v


def order(e1, e2, n1, n2):
    """Observed order of a quantity that falls as nx^-p between nx = n1 and n2."""
    return float(np.log(e1 / e2) / np.log(n2 / n1))


def figures(sim_dir, out_dir, nx=NX):
    """Every figure and the summary from the finished runs under ``sim_dir``."""
    plt = _plt()
    os.makedirs(out_dir, exist_ok=True)
    hist = {name: history(os.path.join(sim_dir, name)) for name, _ in all_cases(nx)}
    folder = {name: os.path.join(sim_dir, name) for name in hist}
    label = {name: state_suffix(f) for name, f in folder.items()}         # " (stopped at t = ...)" or ""
    stopped = {name: run_info(f).get("t") for name, f in folder.items() if run_state(f) == "stopped"}
    summary = {"tf": TF, "missing": sorted(k for k, v in hist.items() if v is None), "stopped": stopped,
               "runs": {}, "orders": {}, "baselines": {}}
    for name, h in hist.items():
        if h is not None:
            t, umax, uex, l1 = h
            summary["runs"][name] = {"t": float(t[-1]), "l1_final": float(l1[-1]), "l1_max": float(l1.max()),
                                     "t_of_l1_max": float(t[np.argmax(l1)]),
                                     "max_u_dev_max": float(np.abs(umax / uex - 1).max()),
                                     "max_u_dev_final": float(umax[-1] / uex[-1] - 1)}
            if name in stopped:      # its values are up to the stop, not at t = 2
                summary["runs"][name]["stopped_at"] = stopped[name]
    # Figs. 6-9: decay and L1 over nx
    for fig, re, s in ((6, 100, "spst"), (7, 100, "ipst"), (8, 1000, "ipst"), (9, 1000, "spst")):
        f, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
        have = [(n, hist[case_name(re, "ctvf", s, n)]) for n in nx if hist[case_name(re, "ctvf", s, n)] is not None]
        for n, (t, umax, uex, l1) in have:
            a.semilogy(t, umax, label=f"{n} x {n}{label[case_name(re, 'ctvf', s, n)]}")
            b.plot(t, l1, label=f"{n} x {n}{label[case_name(re, 'ctvf', s, n)]}")
        if have:
            t, _, uex, _ = max((h for _, h in have), key=lambda h: h[0][-1])
            a.semilogy(t, uex, "k--", label="exact")
        a.set_ylabel("max |u|")
        b.set_ylabel("$L_1$ error of |u| (eq. 66)")
        for ax in (a, b):
            ax.set_xlabel("t")
            _legend(ax)
        f.suptitle(f"Fig. {fig}: CTVF, {s.upper()}, Re = {re}")
        f.tight_layout()
        f.savefig(os.path.join(out_dir, f"fig{fig:02d}_re{re}_{s}.png"), dpi=120)
        plt.close(f)
        final = [(n, _l1_at_end(folder[case_name(re, "ctvf", s, n)], summary["runs"][case_name(re, "ctvf", s, n)]))
                 for n, _ in have]
        summary["orders"][f"re{re}_{s}"] = {
            "l1_final": {str(n): _none_if_nan(e) for n, e in final},
            "order": [{"nx": [n1, n2], "p": _none_if_nan(order(e1, e2, n1, n2))}
                      for (n1, e1), (n2, e2) in zip(final, final[1:])]}
    # Figs. 10-11: with and without corrections at the finest nx that has both runs
    for fig, s in ((10, "spst"), (11, "ipst")):
        f, axes = plt.subplots(1, 2, figsize=(10, 4))
        for ax, re in zip(axes, RES):
            both = [n for n in nx if hist[case_name(re, "ctvf", s, n, True)] is not None
                    and hist[case_name(re, "ctvf", s, n, False)] is not None]
            n = both[-1] if both else nx[-1]
            for corr, style in ((True, "-"), (False, "--")):
                h = hist[case_name(re, "ctvf", s, n, corr)]
                if h is not None:
                    ax.plot(h[0], h[3], style, label=("with corrections" if corr else "without corrections")
                            + label[case_name(re, "ctvf", s, n, corr)])
            ax.set_title(f"Re = {re}, {n} x {n}")
            ax.set_xlabel("t")
            ax.set_ylabel("$L_1$ error of |u|")
            _legend(ax)
        f.suptitle(f"Fig. {fig}: CTVF, {s.upper()}, with and without corrections")
        f.tight_layout()
        f.savefig(os.path.join(out_dir, f"fig{fig:02d}_{s}_corrections.png"), dpi=120)
        plt.close(f)
    # Fig. 12: pressure at the end of Re 1000, finest nx, SPST
    _pressure_plot(plt, os.path.join(sim_dir, case_name(1000, "ctvf", "spst", nx[-1])),
                   os.path.join(out_dir, "fig12_re1000_pressure.png"))
    # beyond the paper: CTVF against EDAC and GTVF on the same case, over the whole run
    f, axes = plt.subplots(1, 2, figsize=(10, 4))
    for ax, re in zip(axes, RES):
        row = {}
        for scheme, name in (("CTVF SPST", case_name(re, "ctvf", "spst", BASELINE_NX)),
                            ("CTVF IPST", case_name(re, "ctvf", "ipst", BASELINE_NX)),
                            ("EDAC", case_name(re, "edac", nx=BASELINE_NX)),
                            ("GTVF", case_name(re, "gtvf", nx=BASELINE_NX))):
            if hist[name] is not None:
                ax.plot(hist[name][0], hist[name][3], label=scheme + label[name])
                row[scheme] = summary["runs"][name]
        summary["baselines"][f"re{re}_nx{BASELINE_NX}"] = row
        ax.set_title(f"Re = {re}, {BASELINE_NX} x {BASELINE_NX}")
        ax.set_xlabel("t")
        ax.set_ylabel("$L_1$ error of |u|")
        _legend(ax)
    f.tight_layout()
    f.savefig(os.path.join(out_dir, "baselines.png"), dpi=120)
    plt.close(f)
    with open(os.path.join(out_dir, "summary.json"), "w") as fh:
        json.dump(summary, fh, indent=1)
    with open(os.path.join(out_dir, "summary.md"), "w") as fh:
        fh.write(summary_table(summary))
    return summary


def summary_table(summary):
    """Markdown: one line per finished run, then the orders."""
    lines = ["| case | L1 at t = 2 | largest L1 (at t) | largest \\|max\\|u\\|/exact - 1\\| |",
             "| --- | --- | --- | --- |"]
    for name, r in sorted(summary["runs"].items()):
        at = r.get("stopped_at")
        end = f"{r['l1_final']:.4f}" if at is None else f"NaN (stopped at t = {at:.4g})"
        lines.append(f"| {name} | {end} | {r['l1_max']:.4f} ({r['t_of_l1_max']:.3g}) | "
                     f"{100 * r['max_u_dev_max']:.2f} % |")
    lines += ["", "| series | nx | order of L1 at t = 2 |", "| --- | --- | --- |"]
    for key, o in sorted(summary["orders"].items()):
        for p in o["order"]:
            p_text = "NaN" if p["p"] is None else f"{p['p']:.2f}"
            lines.append(f"| {key} | {p['nx'][0]} -> {p['nx'][1]} | {p_text} |")
    if summary["missing"]:
        lines += ["", "not run: " + ", ".join(summary["missing"])]
    return "\n".join(lines) + "\n"


def _l1_at_end(folder, run):
    """The run's L1 at t = 2 (its last sample), or NaN with a printed note if it was stopped."""
    if "stopped_at" not in run:
        return run["l1_final"]
    missing(folder, f"its L1 at t = {TF:g} (and the orders that use it)", "the run did not reach it")
    return float("nan")


def particle_plot(fig, ax, pa, values, label, title):
    """Particles of ``pa`` coloured by ``values``, with a colour bar, on equal axes."""
    sc = ax.scatter(pa.x, pa.y, c=values, s=0.5, cmap="jet")
    fig.colorbar(sc, ax=ax, label=label)
    ax.set_aspect("equal")
    ax.set_title(title)


def _pressure_plot(plt, folder, path):
    from sphgen import io
    try:
        last = io.output_files(folder, "taylor_green")[-1]
    except (IndexError, OSError):
        return
    data = io.load(last)
    f, ax = plt.subplots(figsize=(5.5, 4.5))
    fl = data["arrays"]["fluid"]
    particle_plot(f, ax, fl, fl.p, "p", f"Fig. 12: Re = 1000, t = {data['solver_data']['t']:.3g}"
                  + state_suffix(folder))
    f.tight_layout()
    f.savefig(path, dpi=120)
    plt.close(f)


class CTVFTaylorGreen(SphgenProblem):
    """Adepu & Ramachandran (2021), Figs. 6-12 and the baselines."""

    nx = NX

    def get_name(self):
        return "ctvf_figs06-12_taylor_green"

    def setup(self):
        cmd = self.sphgen("taylor_green")
        self.cases = [Simulation(self.input_path(name), cmd, job_info=dict(n_core=1, n_thread=1), **params)
                      for name, params in all_cases(self.nx)]

    def run(self):
        self.make_output_dir()
        figures(self.input_path(), self.output_path(), self.nx)


if __name__ == "__main__":
    root = sys.argv[1] if len(sys.argv) > 1 else "outputs"
    name = "ctvf_figs06-12_taylor_green"
    s = figures(os.path.join(root, name), os.path.join("manuscript", "figures", name))
    print(summary_table(s))
