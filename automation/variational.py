"""Variational time integration of da Silva & Giraldi (2024): the dam break of their section 6
(Figs. 2-5) and the time-integrator studies on a smooth periodic problem (docs/variational.md).

* ``variational_dam_break``: explicit leapfrog (eqs. 59-62) and the implicit midpoint scheme
  (alpha = 0.5, eps = 1e-3 m as printed) to t = 1 s at the paper's resolution; figures
  ``variational_fig2_implicit.png`` and ``variational_fig3_explicit.png`` (snapshots at 0.10, 0.25,
  0.50, 1.00 s, ejected particles marked), ``variational_fig4_D.png`` (D(t) of eq. 70),
  ``variational_fig5_Q.png`` (Q(t) = |sum m v|/M) and ``variational_dam_break.json`` (the numbers
  behind the qualitative claims).
* ``variational_order``: position error at t = 4 ms against a run at dt/8 of the finest dt, for
  alpha = 0.5 and the explicit leapfrog, summation (eq. 20) and continuity (eq. 67) density;
  slopes printed and in ``variational_order.json``, plot ``variational_order.png``.
* ``variational_energy``: 10 000 steps at dt = 1e-4 s of both integrators: energy error against
  time, ``variational_energy.png`` and ``variational_energy.json``.
"""
import json
import os

import numpy as np

from .tasks import SphgenProblem, Simulation, pick, run_info, run_state, state_suffix, stopped_at, stopped_marks

SNAPSHOTS = (0.10, 0.25, 0.50, 1.00)
"""Snapshot times of Figs. 2 and 3 (not printed in the paper; the project's digest of the paper, section 6)."""


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


class VariationalDamBreak(SphgenProblem):
    """da Silva & Giraldi (2024), section 6, Figs. 2-5."""

    tf = 1.0
    pfreq = 50          # an output every 5 ms (dt = 1e-4 s)

    def get_name(self):
        return "variational_dam_break"

    def setup(self):
        cmd = self.sphgen("dam_break_variational")
        common = dict(tf=self.tf, pfreq=self.pfreq, threads=1)
        self.cases = [
            Simulation(self.input_path("implicit"), cmd, job_info=dict(n_core=1, n_thread=1),
                       integrator="variational", alpha=0.5, tol=1e-3, **common),
            Simulation(self.input_path("explicit"), cmd, job_info=dict(n_core=1, n_thread=1),
                       integrator="explicit", **common),
            # extension: the second-order centred continuity density (docs/variational.md)
            Simulation(self.input_path("implicit_centred"), cmd, job_info=dict(n_core=1, n_thread=1),
                       integrator="variational", alpha=0.5, tol=1e-3, density="centred", **common),
        ]

    def run(self):
        from sphgen.applications.dam_break_variational import (ejected, outputs_by_time, positions,
                                                               scheme_difference)
        self.make_output_dir()
        plt = _plt()
        imp, exp, cen = (case.input_path() for case in self.cases)
        summary = {"snapshots": list(SNAPSHOTS)}
        for label, folder, fig in (("implicit", imp, "variational_fig2_implicit.png"),
                                   ("explicit", exp, "variational_fig3_explicit.png")):
            files = outputs_by_time(folder)
            f, axes = plt.subplots(2, 2, figsize=(9, 5.2), sharex=True, sharey=True)
            counts = []
            for ax, t in zip(axes.ravel(), SNAPSHOTS):
                path = files.get(round(t, 9))
                if path is None:               # a stopped run has no file after its stop
                    counts.append(None)
                    ax.set_title(f"t = {t:.2f} s: {stopped_at(folder) or 'no output'}", fontsize=9)
                    continue
                _, x, y = positions(path)
                out = ejected(x, y)
                counts.append(int(out.sum()))
                ax.plot(x[~out], y[~out], ".", ms=1.5, color="tab:blue")
                ax.plot(x[out], y[out], ".", ms=3, color="tab:red")
                ax.set_title(f"t = {t:.2f} s ({counts[-1]} ejected)", fontsize=9)
                ax.set_aspect("equal")
                ax.set_xlim(-0.01, 0.59)
                ax.set_ylim(-0.01, 0.30)
            f.suptitle(f"dam break, {label} ({'alpha = 0.5' if label == 'implicit' else 'leapfrog, eqs. 59-62'})"
                       + state_suffix(folder))
            f.tight_layout()
            f.savefig(self.output_path(fig), dpi=130)
            plt.close(f)
            summary[f"ejected_{label}"] = counts
        t, D = scheme_difference(imp, exp)
        tc, Dc = scheme_difference(cen, exp)
        f, (a1, a2) = plt.subplots(1, 2, figsize=(9, 3.6))
        a1.plot(t, D, "k-", label="implicit - explicit (eq. 70)" + state_suffix(imp) + state_suffix(exp))
        a1.plot(tc, Dc, "b--", lw=0.8, label="implicit, centred density - explicit" + state_suffix(cen)
                + state_suffix(exp))
        a1.legend(fontsize=8)
        a2.semilogy(t[D > 0], D[D > 0], "k-")
        a2.semilogy(tc[Dc > 0], Dc[Dc > 0], "b--", lw=0.8)
        for a in (a1, a2):
            a.set_xlabel("t (s)")
            a.set_ylabel("D(t) (m), eq. 70")
        f.tight_layout()
        f.savefig(self.output_path("variational_fig4_D.png"), dpi=130)
        plt.close(f)
        quarters = [_window_max(t, D, a, b) for a, b in ((0, .25), (.25, .5), (.5, .75), (.75, 1.0))]
        summary["D"] = {"final": _last(D), "t_final": _last(t), "max_per_quarter_second": quarters,
                        "at_snapshots": [_at(t, D, s) for s in SNAPSHOTS]}
        summary["D_centred_vs_explicit"] = {"final": _last(Dc), "t_final": _last(tc),
                                            "at_snapshots": [_at(tc, Dc, s) for s in SNAPSHOTS]}
        f, ax = plt.subplots(figsize=(6, 4))
        for label, case, style in (("implicit", self.cases[0], "k-"), ("explicit", self.cases[1], "r-"),
                                   ("implicit_centred", self.cases[2], "b--")):
            h = self.history(case)
            rows = np.array(h["rows"], dtype=float)
            c = {k: rows[:, i] for i, k in enumerate(h["columns"])}
            ax.plot(c["t"], c["Q"], style, label=label + state_suffix(case))
            late = (c["t"] >= 0.8) & (c["t"] <= 1.0)
            summary[f"Q_{label}"] = {"max": float(c["Q"].max()), "t_max": float(c["t"][np.argmax(c["Q"])]),
                                     "final": float(c["Q"][-1]),
                                     "mean_0.8_1.0": float(c["Q"][late].mean()) if late.any() else None,
                                     "min_0.8_1.0": float(c["Q"][late].min()) if late.any() else None,
                                     "local_maxima": _local_maxima(c["t"], c["Q"])}
            summary[f"Q_{label}"].update(pick(case, None, ()))       # stopped_at, for a stopped run
            summary[f"results_{label}"] = self.results(case)
        ax.set_xlabel("t (s)")
        ax.set_ylabel("Q = |sum m v| / M (m/s)")
        ax.legend()
        f.tight_layout()
        f.savefig(self.output_path("variational_fig5_Q.png"), dpi=130)
        plt.close(f)
        with open(self.output_path("variational_dam_break.json"), "w") as fh:
            json.dump(summary, fh, indent=1)
        print(json.dumps({k: v for k, v in summary.items() if not k.startswith("results")}, indent=1))


EJECTION_VARIANTS = {
    "closed_box": {},
    "open_top": dict(open_top=None),
    "weak_av": dict(av_a=0.1, av_b=0.0),
    "open_top_weak_av": dict(open_top=None, av_a=0.1, av_b=0.0),
    "summation_density": dict(density="summation"),
    "wall_power2": dict(wall_power=2),
    "K1_as_printed": dict(kernel="K1", tf=0.25),
    "K2_paper_cutoff": dict(kernel="K2", tf=0.25),
}
"""The explicit leapfrog dam break with one unprinted choice changed at a time (the paper's
"particles go out of the fluid volume", section 6): K1/K2 (651 neighbours) to 0.25 s only."""


class VariationalEjection(SphgenProblem):
    """Free-surface particle ejection (da Silva & Giraldi 2024, section 6, Figs. 2-3) against the
    choices the paper does not print: lid, AV strength, density, wall-force power, kernel."""

    tf, pfreq = 1.0, 250          # an output every 25 ms (dt = 1e-4 s)
    times = (0.10, 0.25, 0.50, 0.75, 1.00)

    def get_name(self):
        return "variational_ejection"

    def setup(self):
        cmd = self.sphgen("dam_break_variational")
        self.cases = []
        for name, kw in EJECTION_VARIANTS.items():
            kw = dict(dict(tf=self.tf), **kw)
            self.cases.append(Simulation(self.input_path(name), cmd, job_info=dict(n_core=1, n_thread=1),
                                         integrator="explicit", pfreq=self.pfreq, threads=1, **kw))

    def run(self):
        from sphgen.applications.dam_break_variational import DX, ejected, outputs_by_time, positions
        from sphgen.tools.probes import count_neighbours
        self.make_output_dir()
        plt = _plt()
        out = {"times": list(self.times), "rule_quarter_median": "fewer than 1/4 of the median neighbour "
               "count within 2.5 dx", "rule_digest": "at most 2 other fluid particles within 2 dx"}
        f, axes = plt.subplots(len(self.cases), 2, figsize=(9, 2.3 * len(self.cases)), sharex=True, sharey=True)
        for row, case in zip(axes, self.cases):
            name = os.path.basename(case.input_path())
            if run_state(case) == "not run":
                print(f"{name:18s} not run")
                continue
            files = outputs_by_time(case.input_path())
            rec = {"quarter_median": [], "digest": [], "y_max": [], "rho_max": None}
            for t in self.times:
                path = files.get(round(t, 9))
                if path is None:
                    for k in ("quarter_median", "digest", "y_max"):
                        rec[k].append(None)
                    continue
                _, x, y = positions(path)
                rec["quarter_median"].append(int(ejected(x, y).sum()))
                rec["digest"].append(int((count_neighbours((x, y), 2.0 * DX) < 4).sum()))
                rec["y_max"].append(float(y.max()))
            rec.update(pick(case, self.results(case), ("rho_min", "rho_max", "Q_max", "t")))
            out[name] = rec
            shown = [t for t in (0.25, 0.50) if files.get(round(t, 9))]
            for ax, t in zip(row, shown):
                _, x, y = positions(files[round(t, 9)])
                e = ejected(x, y)
                ax.plot(x[~e], y[~e], ".", ms=1, color="tab:blue")
                ax.plot(x[e], y[e], ".", ms=3, color="tab:red")
                ax.set_title(f"{name}{state_suffix(case)}, t = {t:.2f} s ({int(e.sum())} ejected)", fontsize=8)
                ax.set_aspect("equal")
            print(f"{name:18s} ejected (1/4 median) {rec['quarter_median']}  (<=2 nbrs in 2dx) {rec['digest']}"
                  f"{state_suffix(case)}")
        f.tight_layout()
        f.savefig(self.output_path("variational_ejection.png"), dpi=110)
        plt.close(f)
        with open(self.output_path("variational_ejection.json"), "w") as fh:
            json.dump(out, fh, indent=1)


def _local_maxima(t, q, smooth=5):
    """(t, Q) of the local maxima of Q smoothed over ``smooth`` samples (its oscillation)."""
    if q.size < 3 * smooth:
        return []
    s = np.convolve(q, np.ones(smooth) / smooth, mode="same")
    i = [k for k in range(smooth, s.size - smooth) if s[k] >= s[k - 1] and s[k] > s[k + 1]]
    return [[float(t[k]), float(s[k])] for k in i]


def _last(y):
    """The last sample of ``y``, or None if it has none."""
    return float(y[-1]) if len(y) else None


def _window_max(t, y, a, b):
    """The largest ``y`` over a < t <= b, or None if no sample falls there (a run stopped before a)."""
    inside = (t > a) & (t <= b)
    return float(y[inside].max()) if inside.any() else None


def _at(t, y, s, tol=1e-9):
    """``y`` at the sample nearest to time ``s``, or None if ``s`` is past the last sample."""
    if not len(t) or s > t[-1] + tol:
        return None
    return float(y[np.argmin(abs(t - s))])


def _error(results, key):
    """results[key], or NaN when the run has no results.json (stopped, or did not end)."""
    return float("nan") if results is None else float(results[key])


def _finite(values):
    """A list for JSON: NaN as None."""
    return [None if np.isnan(v) else float(v) for v in values]


def _rows(case):
    with open(case.input_path("history.json")) as f:
        h = json.load(f)
    rows = np.array(h["rows"], dtype=float)
    return {k: rows[:, i] for i, k in enumerate(h["columns"])}


INTEGRATORS = {"alpha0.5": dict(integrator="variational", alpha=0.5), "explicit": dict(integrator="explicit")}
DENSITY_RUNS = [(d, name) for d in ("summation", "continuity") for name in INTEGRATORS] + [("centred", "alpha0.5")]
"""(density, integrator) pairs of the studies: the centred density exists for the variational one only."""


class VariationalOrder(SphgenProblem):
    """Order of accuracy in dt on the periodic lattice (applications/lattice_variational.py)."""

    tf = 0.004
    dts = (1e-4, 5e-5, 2.5e-5, 1.25e-5)
    refine = 8          # the reference run: dt = dts[-1] / refine

    def get_name(self):
        return "variational_order"

    def setup(self):
        cmd = self.sphgen("lattice_variational")
        self.cases, self.groups = [], {}
        for density, name in DENSITY_RUNS:
            kw = INTEGRATORS[name]
            ref_dir = self.input_path(f"{name}_{density}_ref")
            ref = Simulation(ref_dir, cmd, job_info=dict(n_core=1, n_thread=1), tf=self.tf, density=density,
                             time_step=self.dts[-1] / self.refine, threads=1, **kw)
            runs = [Simulation(self.input_path(f"{name}_{density}_dt{dt:g}"), cmd,
                               job_info=dict(n_core=1, n_thread=1), depends=[ref], tf=self.tf,
                               density=density, time_step=dt, reference_run=ref_dir, threads=1, **kw)
                    for dt in self.dts]
            self.groups[(name, density)] = runs
            self.cases += [ref] + runs

    def run(self):
        self.make_output_dir()
        plt = _plt()
        f, ax = plt.subplots(figsize=(6, 4.5))
        out = {"tf": self.tf, "dt": list(self.dts), "reference_dt": self.dts[-1] / self.refine, "series": {}}
        for (name, density), runs in self.groups.items():
            e = np.array([_error(self.results(c, "its position error"), "position_error_max") for c in runs])
            slopes = np.diff(np.log(e)) / np.diff(np.log(self.dts))
            stopped = {f"dt{dt:g}": run_info(c).get("t") for dt, c in zip(self.dts, runs)
                       if run_state(c) == "stopped"}
            out["series"][f"{name}_{density}"] = {"error_max": _finite(e), "slopes": _finite(slopes),
                                                  "stopped_at": stopped}
            ax.loglog(self.dts, e, "o-", label=f"{name}, {density} density"
                      + stopped_marks({f"dt{dt:g}": c for dt, c in zip(self.dts, runs)}))
            print(f"{name:9s} {density:10s} errors {' '.join(f'{v:.3e}' for v in e)}  "
                  f"slopes {' '.join(f'{s:.2f}' for s in slopes)}")
        d = np.array(self.dts)
        ax.loglog(d, 1e-6 * (d / 1e-4) ** 2, "k:", label="slope 2")
        ax.loglog(d, 3e-6 * (d / 1e-4), "k--", label="slope 1")
        ax.set_xlabel("dt (s)")
        ax.set_ylabel(f"max position error at t = {self.tf} s (m)")
        ax.legend(fontsize=8)
        f.tight_layout()
        f.savefig(self.output_path("variational_order.png"), dpi=130)
        plt.close(f)
        with open(self.output_path("variational_order.json"), "w") as fh:
            json.dump(out, fh, indent=1)


class VariationalEnergy(SphgenProblem):
    """Energy error over 10 000 steps at dt = 1e-4 s, alpha = 0.5 against the explicit leapfrog."""

    steps, dt, nx = 10000, 1e-4, 16

    def get_name(self):
        return "variational_energy"

    def setup(self):
        cmd = self.sphgen("lattice_variational")
        self.cases = [Simulation(self.input_path(f"{name}_{density}"), cmd, job_info=dict(n_core=1, n_thread=1),
                                 tf=self.steps * self.dt, time_step=self.dt, density=density, threads=1,
                                 record_every=10, pfreq=self.steps, tol=1e-12, nx=self.nx, **INTEGRATORS[name])
                      for density, name in DENSITY_RUNS]

    def run(self):
        self.make_output_dir()
        plt = _plt()
        densities = list(dict.fromkeys(d for d, _ in DENSITY_RUNS))
        f, axes = plt.subplots(1, len(densities), figsize=(5 * len(densities), 4))
        out = {}
        for case, (density, _) in zip(self.cases, DENSITY_RUNS):
            ax = axes[densities.index(density)]
            c = _rows(case)
            rel = c["energy"] / c["energy"][0] - 1.0
            name = os.path.basename(case.input_path())
            ax.plot(c["t"], rel, label=name.split("_")[0] + state_suffix(case), lw=0.8)
            ax.set_title(f"{name.split('_')[1]} density")
            r = self.results(case) or {}
            out[name] = pick(case, r, ("energy_error", "energy_final", "energy_mean_second_half",
                                       "iterations_mean", "iterations_max", "contraction_max",
                                       "evaluations", "momentum_max"))
            out[name]["steps"] = int(round(r["t"] / self.dt)) if r.get("t") is not None else None
        for ax in axes:
            ax.set_xlabel("t (s)")
            ax.set_ylabel("E(t)/E(0) - 1")
            ax.legend()
        f.tight_layout()
        f.savefig(self.output_path("variational_energy.png"), dpi=130)
        plt.close(f)
        with open(self.output_path("variational_energy.json"), "w") as fh:
            json.dump(out, fh, indent=1)
        print(json.dumps(out, indent=1))


PROBLEMS = {p.__name__: p for p in (VariationalDamBreak, VariationalOrder, VariationalEnergy,
                                     VariationalEjection)}


def run_serially(name, sim_dir="outputs", out_dir="manuscript/figures"):
    """Run a problem's cases one after the other (in the order listed: references first) with
    ``nice``, skipping finished ones, then make its figures -- for a shared machine, where
    automan's scheduler waits for idle cores.  ``python -m automation.variational NAME``."""
    import shlex
    import subprocess
    from .tasks import SphgenTask
    problem = PROBLEMS[name](sim_dir, out_dir)
    for case in problem.cases:
        task = SphgenTask(case.command, case.root)
        if task._is_done():
            continue
        cmd = ["nice", "-n", "10"] + shlex.split(case.command) + ["-d", case.root, "--no-progress", "--overwrite"]
        print(" ".join(cmd), flush=True)
        subprocess.run(cmd, check=False)
    problem.run()


if __name__ == "__main__":
    import sys
    for arg in sys.argv[1:] or list(PROBLEMS):
        run_serially(arg)
