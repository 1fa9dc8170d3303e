"""automation/shtc.py: case lists of both presets, the automan problem, and every figure of
Kincl et al. (2023) and of Kincl's thesis ch. 1-2 from (fake) finished runs; nothing is simulated."""
import json
import os

import numpy as np
import pytest

import automate
from automation import shtc
from automation.shtc import CAVITY_RE, CAVITY_TIMES, CONFIG, all_cases, cavity_name
from sphgen.app import load_application

RK4_RELAXATION_LIMIT = 0.464      # the guard of SHTCScheme (docs/shtc.md row 15)


def test_case_lists_follow_the_presets():
    for preset in ("paper", "quick"):
        cases = all_cases(CONFIG[preset])
        apps = {app for app, _ in cases.values()}
        assert {"beryllium_plate", "twisting_column", "taylor_couette", "shtc_cavity", "shtc_kernel_convergence",
                "shtc_impulse_of_shear", "shtc_reversibility", "dam_break_2d"} == apps
        assert "--cp-factor" in cases["plate_cp0"][1] and "--cp-factor" not in cases["plate_cp10"][1]
        cav = CONFIG[preset]["cavity"]
        assert tuple(re for re, _, _, _ in cav) == CAVITY_RE
        for re, nx, cs, dt in cav:
            args = cases[cavity_name(re, nx)][1]
            assert args[args.index("--re") + 1] == str(re) and args[args.index("--dt") + 1] == dt
            assert args[args.index("--cs") + 1] == cs
            tau = 6.0 / re / float(cs) ** 2              # tau = 6 nu / cs^2, nu = 1/Re ([P] eq. 29)
            assert float(dt) / tau < RK4_RELAXATION_LIMIT   # the guard would refuse the run
        # Re 100 writes its particles at the snapshot times of Figs. 10-11
        re, nx, _, dt = cav[0]
        args = cases[cavity_name(re, nx)][1]
        every = int(args[args.index("--pfreq") + 1]) * float(dt)
        assert all(abs(t / every - round(t / every)) < 1e-4 for t in CAVITY_TIMES)
    # the paper's cavity step at Re 100 ([P] Table 1) and resolution; quick is coarser everywhere
    assert CONFIG["paper"]["cavity"][0] == (100, 200, "20", "1.5e-05")
    for key in ("plate_nw", "column_n", "couette_nr"):
        assert CONFIG["quick"][key] < CONFIG["paper"][key]
    assert all(q[1] < p[1] for q, p in zip(CONFIG["quick"]["cavity"], CONFIG["paper"]["cavity"]))
    # the thesis dam break: dr = a/100 as the authors' code, quick coarser
    assert float(CONFIG["paper"]["dam_break_dx"]) == 0.01 < float(CONFIG["quick"]["dam_break_dx"])


@pytest.mark.parametrize("preset", ["paper", "quick"])
def test_every_case_is_accepted_by_its_application(preset):
    """Each case's options parse and pass the application's checks (nothing is built or run)."""
    for name, (app_name, args) in all_cases(CONFIG[preset]).items():
        app = load_application(app_name)()
        app.options = app.parser().parse_args(args)
        app.consume_user_options(app.options)


@pytest.mark.parametrize("preset", ["paper", "quick"])
def test_dam_break_outputs_fall_near_the_snapshot_times(preset):
    """Fig. 1.2's snapshots (thesis_figure_1_2's default times) are within 0.1 % of an output:
    dt = 0.2 h/c0 with h = 1.5 dr and c0 = 50 m/s (the scheme's rule), an output every pfreq steps."""
    from sphgen.applications.dam_break_2d import C0_THESIS, thesis_figure_1_2
    cfg = CONFIG[preset]
    every = cfg["dam_break_pfreq"] * 0.2 * 1.5 * float(cfg["dam_break_dx"]) / C0_THESIS
    for t in thesis_figure_1_2.__defaults__[1]:
        assert abs(t / every - round(t / every)) * every < 1e-3 * max(t, 0.1)


def test_problems_build_their_cases_and_are_registered(tmp_path):
    names = set()
    for cls in shtc.PAPER_PROBLEMS + shtc.QUICK_PROBLEMS:
        prob = cls(str(tmp_path / "outputs"), str(tmp_path / "figures"))
        names.add(prob.get_name())
        cmds = [c.command for c in prob.cases]
        assert len(cmds) == len(all_cases(CONFIG[prob.preset]))
        assert all(" run " in c and "--threads=1" in c for c in cmds)
    assert names == {"shtc", "shtc_quick"}
    assert automate.PAPERS["shtc"] == shtc.PAPER_PROBLEMS and automate.PAPERS["shtc_quick"] == shtc.QUICK_PROBLEMS


def test_fig1_kernel_h_derivatives_match_finite_differences():
    r = np.linspace(0.01, 1.99, 50)
    for dim in (2, 3):
        g, m, fg, fm = shtc.kernel_h_derivatives(dim, r)
        assert np.abs(g - fg).max() < 1e-6 * np.abs(g).max()
        assert np.abs(m - fm).max() < 1e-6 * np.abs(m).max()


# ------------------------------------------------------------------ fake runs
def _history(folder, columns, n=11, tf=1.0):
    t = np.linspace(0, tf, n)
    rows = np.column_stack([t] + [np.cos(t * k) + k for k in range(1, len(columns))])
    with open(os.path.join(folder, "history.json"), "w") as f:
        json.dump({"columns": list(columns), "rows": rows.tolist()}, f)


def _particles(folder, prefix, name, times, dim=2, tensor=False):
    from sphgen import io
    from sphgen.particles import ParticleArray
    rng = np.random.default_rng(3)
    x, y, z = rng.uniform(0, 1, (3, 40))
    for step, t in enumerate(times):
        props = dict(x=x, y=y, u=y * t, v=-x * t, p=x + t)
        if dim == 3:
            props["z"] = z
        pa = ParticleArray(name, **props)
        if tensor:
            pa.add_property("A", stride=9, data=np.tile(np.eye(3).ravel(), 40) + 0.01 * t)
        io.write(os.path.join(folder, f"{prefix}_{step:06d}.h5"), [pa], {"t": t, "dt": 1e-3, "step": step})


def _results(folder, res):
    with open(os.path.join(folder, "results.json"), "w") as f:
        json.dump(res, f)


def _fake_dam_break(folder):
    """A dam break folder as `dam_break_2d --scheme symplectic` leaves it (toe against T, snapshots)."""
    from sphgen import io
    from sphgen.particles import ParticleArray
    os.makedirs(folder)
    T = np.linspace(0.0, 3.1, 32)
    with open(os.path.join(folder, "history.json"), "w") as f:
        json.dump({"columns": ["t", "T", "toe"], "rows": np.column_stack([T / 4.427, T, 1 + T]).tolist(),
                   "dx": 0.02, "scheme": "symplectic"}, f)
    x, y = np.meshgrid(np.linspace(0, 1, 6), np.linspace(0, 2, 6))
    for step, t in enumerate((0.0, 0.2, 0.4, 0.6)):
        fluid = ParticleArray("fluid", x=x.ravel() + t, y=y.ravel(), u=np.full(36, t), v=np.zeros(36))
        wall = ParticleArray("wall", x=np.linspace(0, 4, 9), y=np.zeros(9), u=np.zeros(9), v=np.zeros(9))
        io.write(os.path.join(folder, f"dam_break_2d_{step:06d}.h5"), [fluid, wall], {"t": t, "dt": 1e-4, "step": step})
    _results(folder, {"dx": 0.02, "t": 0.7, "toe_max_rel_dev_violeau": 0.041})
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump({"completed": True}, f)


def _fake_runs(sim, cfg):
    from sphgen.tools.reference import ghia_1982
    for name in ("plate_cp10", "plate_cp0"):
        os.makedirs(sim / name)
        _history(str(sim / name), ("t", "y_centre", "kinetic", "bulk", "shear", "penalty", "total"), tf=3e-5)
        _particles(str(sim / name), "beryllium_plate", "plate", (0.0, 1e-5, 2e-5, 3e-5))
        _results(str(sim / name), {"energy_drift": 1e-6, "torn": name == "plate_cp0", "nw": 4})
    os.makedirs(sim / "column")
    _history(str(sim / "column"), ("t", "z_top", "omega_top", "kinetic", "bulk", "shear", "penalty", "total",
                                   "detA_min"), tf=0.2)
    _particles(str(sim / "column"), "twisting_column", "column", (0.0, 0.1, 0.2), dim=3)
    _results(str(sim / "column"), {"energy_drift": 1e-6})
    os.makedirs(sim / "couette")
    xs = np.linspace(1, 2, 51)
    _results(str(sim / "couette"), {"t": 10.0, "profile_error": 0.02, "profile_x": xs.tolist(),
                                     "profile_v": (xs - 1).tolist(), "profile_exact": (xs - 1).tolist()})
    _particles(str(sim / "couette"), "taylor_couette", "fluid", (0.0, 10.0), tensor=True)
    for re, nx, _, _ in cfg["cavity"]:
        folder = sim / cavity_name(re, nx)
        os.makedirs(folder)
        g = ghia_1982(re)
        _results(str(folder), {"t": 20.0, "nx": nx, "ghia_error": 0.04, "ghia_error_averaged": 0.03,
                               "averaged_from": 10.0, "u_centre": g["u"].tolist(), "v_centre": g["v"].tolist(),
                               "u_centre_averaged": g["u"].tolist(), "v_centre_averaged": g["v"].tolist()})
        if re == 100:
            _particles(str(folder), "shtc_cavity", "fluid", (0.0, *CAVITY_TIMES), tensor=True)
    plt = shtc._plt()
    for name, png in (("kernel_convergence", "convergence.png"), ("impulse_of_shear", "profile.png"),
                      ("reversibility", "return.png")):
        os.makedirs(sim / name)
        fig, ax = plt.subplots(figsize=(1, 1))
        fig.savefig(sim / name / png)
        plt.close(fig)
        _results(str(sim / name), {"ok": True})
    _fake_dam_break(str(sim / "dam_break"))


FIGURES = (["P_fig%d" % k for k in range(1, 13)]
           + ["T_fig1_1", "T_fig1_2", "T_fig1_3"] + ["T_fig2_%d" % k for k in range(1, 7)]
           + ["T_thm1_convergence", "T_sec2_2_impulse_of_shear", "P_sec3_6_reversibility"])


@pytest.mark.filterwarnings("ignore")
def test_every_figure_from_finished_and_from_missing_runs(tmp_path):
    cfg = CONFIG["quick"]
    sim, out = tmp_path / "outputs", tmp_path / "figures"
    _fake_runs(sim, cfg)
    got = shtc.figures(str(sim), str(out), cfg)
    for name in FIGURES:
        assert os.path.getsize(out / name / f"{name}.png") > 0, name
    with open(out / "T_fig2_6" / "T_fig2_6.json") as f:
        assert set(json.load(f)) == {f"Re{re}" for re in CAVITY_RE}
    with open(out / "P_fig11" / "P_fig11.json") as f:
        shown = json.load(f)
    assert sorted(float(t) for t in shown) == sorted(CAVITY_TIMES)
    assert shown["20"]["max"] == pytest.approx(0.2)       # A_xy of the fake file at t = 20
    assert got["plate"]["plate_cp0"]["torn"] is True
    assert got["dam_break"]["toe_max_rel_dev_violeau"] == 0.041
    with open(out / "T_fig1_3" / "T_fig1_3.json") as f:
        assert json.load(f)["dx"] == 0.02
    # no runs at all: the same folders, "not run" panels
    empty = tmp_path / "empty_figures"
    shtc.figures(str(tmp_path / "nothing"), str(empty), cfg)
    for name in FIGURES:
        assert os.path.getsize(empty / name / f"{name}.png") > 0, name


def _stop(folder, t):
    """Turn a fake finished run into one the blow-up guard stopped at ``t``: no results.json."""
    os.remove(os.path.join(folder, "results.json"))
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump({"completed": False, "stopped": True, "error": "speed above the limit", "t": t}, f)


@pytest.mark.filterwarnings("ignore")
def test_stopped_runs_are_drawn_up_to_the_stop_and_labelled(tmp_path, figure_texts, capsys):
    cfg = CONFIG["quick"]
    sim, out = tmp_path / "outputs", tmp_path / "figures"
    _fake_runs(sim, cfg)
    re400 = cavity_name(*cfg["cavity"][1][:2])
    for name, t in (("plate_cp10", 3e-5), ("couette", 10.0), (re400, 7.5), ("dam_break", 0.6),
                    ("reversibility", 0.01), ("column", 0.1)):
        _stop(str(sim / name), t)
    os.remove(sim / "column" / "twisting_column_000002.h5")      # its file at t = 0.2: after the stop
    got = shtc.figures(str(sim), str(out), cfg)
    for name in FIGURES:
        assert os.path.getsize(out / name / f"{name}.png") > 0, name
    assert got["plate"]["plate_cp10"] == {"stopped_at": 3e-5} and got["plate"]["plate_cp0"]["torn"] is True
    assert "SHTC-SPH (sphgen) (stopped at t = 3e-05)" in figure_texts["P_fig2.png"]
    assert "c_p = 10 c0, t = 3e-05 s (stopped at t = 3e-05)" in figure_texts["P_fig4.png"]
    assert "stopped at t = 10" in figure_texts["P_fig8.png"] and "(stopped at t = 10)" in figure_texts["P_fig9.png"]
    assert got["couette"] == {"stopped_at": 10.0} and got["column"] == {"stopped_at": 0.1}
    p5 = figure_texts["P_fig5.png"]        # 0.05 and 0.1 drawn; 0.15 and 0.2 after the stop
    assert p5.count("| stopped at t = 0.1 |") == 2 and "t = 0.1 s" in p5 and "(stopped at t = 0.1)" in p5
    with open(out / "T_fig2_6" / "T_fig2_6.json") as f:
        centre = json.load(f)
    assert centre["Re400"]["stopped_at"] == 7.5 and centre["Re400"]["ghia_error"] is None
    assert centre["Re100"]["ghia_error"] == 0.04
    assert "stopped at t = 7.5" in figure_texts["T_fig2_6.png"]
    assert "dam_break (stopped at t = 0.6)" in figure_texts["T_fig1_3.png"]
    assert got["dam_break"]["stopped_at"] == 0.6 and got["dam_break"]["toe_max_rel_dev_violeau"] is None
    assert got["thesis"]["P_sec3_6_reversibility"] == {"stopped_at": 0.01}
    notes = capsys.readouterr().out
    for name in ("plate_cp10", "couette", re400, "dam_break"):
        assert f"note: {name} stopped at t = " in notes, name
