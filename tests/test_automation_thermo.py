"""automation/thermo.py: case lists, the automan problems and every figure of Ghavamian et al.
(2021) from (fake) finished runs; nothing is simulated."""
import json
import os

import numpy as np
import pytest

from automation import thermo
from automation.thermo import (BALL_TIMES, CONFIG, DISK_TIMES, GRIPPER_TIMES, LBLOCK_TIMES, PUNCH_TIMES,
                               all_cases, punch_middle)
from sphgen.applications._thermo_solid import cylinder_lattice

COLUMNS = ("t", "L_x", "L_y", "L_z", "A_x", "A_y", "A_z", "sum_V_abs_p", "kinetic", "internal", "total",
           "ballistic", "entropy", "W_ext", "Q_in", "E_Dir", "J_min", "theta_min", "theta_max", "probe_vx",
           "probe_vy", "probe_vz", "probe_ux", "probe_uy", "probe_uz", "probe_theta", "probe_P11")


def test_case_lists_follow_the_presets():
    quick, paper = all_cases(CONFIG["quick"]), all_cases(CONFIG["paper"])
    assert quick["lblock_dx1"][0] == "l_block"
    assert quick["disk_eta_dx0.5"] == ("thermo_disk", ["--dx", "0.5", "--form", "eta", "--output-at",
                                                       *map(str, thermo._times(DISK_TIMES))])
    # every snapshot time of a figure is written by its runs
    assert set(LBLOCK_TIMES["fig9_p"][1:]) <= set(map(float, quick["lblock_dx1"][1][3:]))
    assert "--disable-output" in quick["lblock_ablation_noproj"][1]
    assert "--no-projection" in quick["lblock_ablation_noproj"][1]
    assert quick["punch_ablation_limited"][1][:4] == ["--dx", punch_middle(CONFIG["quick"]), "--jumps", "limited"]
    assert f"punch_reduced_E_dx{thermo._dx_label(punch_middle(CONFIG['paper']))}" in paper
    # the punch at the paper's dx = 1/10, 1/13, 1/16; Figs. 16, 19 at 1/13 (the paper's 5000)
    assert [float(d) for d in CONFIG["paper"]["punch_dx"]] == pytest.approx([1 / 10, 1 / 13, 1 / 16], rel=1e-15)
    assert [cylinder_lattice(float(d), 1.0, 0.0, 1.0, 0.5)[0].size
            for d in CONFIG["paper"]["punch_dx"]] == [2728, 5488, 10268]
    assert "punch_reduced_E_dx0.07692" in paper and "punch_full_eta_dx0.0625" in paper
    assert sum(k.startswith("mms_") for k in paper) == 4 * 4
    # the quick preset's levels are the coarsest: never finer than the paper's finest
    for key in ("lblock_dx", "disk_dx", "punch_dx", "gripper_dx", "ball_dx"):
        assert min(map(float, CONFIG["quick"][key])) >= min(map(float, CONFIG["paper"][key]))
    assert len(quick) < len(paper) + 1


def test_problems_have_distinct_names_and_commands(tmp_path):
    names = set()
    for cls in thermo.PAPER_PROBLEMS + thermo.QUICK_PROBLEMS:
        prob = cls(str(tmp_path / "outputs"), str(tmp_path / "figures"))
        names.add(prob.get_name())
        cmds = [c.command for c in prob.cases]
        assert cmds and all(" run " in c and "--threads=1" in c for c in cmds)
    assert len(names) == 12 and "thermo_punch_quick" in names


def _history(folder, n=21, tf=1.0, err=0.0):
    """Smooth curves plus ``err`` times a bump (a level's error)."""
    t = np.linspace(0, tf, n)
    rows = np.zeros((n, len(COLUMNS)))
    rows[:, 0] = t
    for k, c in enumerate(COLUMNS[1:], 1):
        rows[:, k] = np.sin(t * k) + k + err * np.cos(t)
    with open(os.path.join(folder, "history.json"), "w") as f:
        json.dump({"columns": list(COLUMNS), "rows": rows.tolist()}, f)


def _snapshots(folder, prefix, times):
    from sphgen import io
    from sphgen.particles import ParticleArray
    rng = np.random.default_rng(len(times))
    x, y, z = rng.uniform(0, 1, (3, 60))
    for step, t in enumerate((0.0, *times)):
        pa = ParticleArray("body", x=x, y=y, z=z, p=x * (1 + t), theta=293.15 + y)
        io.write(os.path.join(folder, f"{prefix}_{step:06d}.h5"), [pa], {"t": t, "dt": 1e-3, "step": step})


def _fake(sim, name, app, results=None, times=(), tf=1.0, err=0.0):
    folder = sim / name
    os.makedirs(folder)
    _history(str(folder), tf=tf, err=err)
    with open(folder / "results.json", "w") as f:
        json.dump(results or {"t": tf, "n_particles": 60, "J_min": 0.9, "energy_residual": 1e-16}, f)
    if times:
        _snapshots(str(folder), app, times)


def _mms(sim, cfg):
    for name, (_, args) in thermo.mms_cases(cfg).items():
        n = int(args[1])
        res = {"dx": 1.0 / n, "n": n}
        for k in ("p_x", "p_y", "p_z", "theta") + tuple(f"P_{i}{j}" for i in (1, 2, 3) for j in (1, 2, 3)):
            res[f"inner_{k}"] = 1e-3 * n ** -2.0 if "limited" in name else 1e-3 / n
        os.makedirs(sim / name)
        with open(sim / name / "results.json", "w") as f:
            json.dump(res, f)


@pytest.mark.filterwarnings("ignore")
def test_mms_disk_and_gripper_figures_from_finished_runs(tmp_path):
    """Every kind of figure (sketch, 3-D snapshots, series, ablation, Fig. 3's orders, the
    convergence and E-vs-eta measures) on three sections; the slow test draws all 24."""
    cfg = CONFIG["quick"]
    sim, out = tmp_path / "sim", tmp_path / "fig"
    _mms(sim, cfg)
    mms = thermo.mms_figures(str(sim), str(out), cfg)
    assert mms["fig3"]["limited, buffer"]["orders"]["P_12"] == pytest.approx(2.0)
    assert mms["fig3"]["raw, surface"]["orders"]["theta"] == pytest.approx(1.0)
    _disk(sim, out, cfg)
    for name, (app, _) in thermo.gripper_cases(cfg).items():
        _fake(sim, name, app, times=thermo._times(GRIPPER_TIMES), tf=0.5)
    thermo.gripper_figures(str(sim), str(out), cfg)
    for k in (1, 2, 3, 10, 11, 12, 13, 14, 20, 21, 22):
        assert os.path.getsize(out / f"fig{k}" / f"fig{k}.png") > 5000, k
    assert os.path.getsize(out / "ablation_disk" / "ablation_disk.png") > 5000
    with open(out / "fig14" / "fig14.json") as f:
        assert json.load(f)["theta theta 4.5"]["t"] == 4.5     # the panel is at its time (--output-at)


def _disk(sim, out, cfg):
    eta_err = {"1": 0.0, "0.5": 0.1}                       # E: errors ~ dx^2; eta: growing
    for name, (app, args) in thermo.disk_cases(cfg).items():
        err = 0.05 if "ablation" in name else float(args[1]) ** 2 if "_E_" in name else eta_err.get(args[1], 0.3)
        _fake(sim, name, app, times=thermo._times(DISK_TIMES) if "ablation" not in name else (), tf=10.0, err=err)
    di = thermo.disk_figures(str(sim), str(out), cfg)
    conv = di["fig12"]["convergence"]
    assert conv["E"]["converging"] and not conv["eta"]["converging"] and conv["E"]["levels"] == 3
    gap = di["fig12"]["E_vs_eta"]["0.3333"]["probe_vz"]
    assert 0 < gap < 0.1
    assert set(di["ablation"]) == {"default (limited jumps, projection)", "raw jumps", "no projection",
                                   "S^E of eq. 76"}
    assert di["ablation_SE_vs_eta"]["S^E eq. 76"]["probe_vz"] > 0


@pytest.mark.slow
@pytest.mark.filterwarnings("ignore")
def test_every_figure_from_finished_runs(tmp_path):
    cfg = CONFIG["quick"]
    sim, out = tmp_path / "sim", tmp_path / "fig"
    _mms(sim, cfg)
    thermo.mms_figures(str(sim), str(out), cfg)
    lt = thermo._times(LBLOCK_TIMES)
    for name, (app, _) in thermo.lblock_cases(cfg).items():
        if name != "lblock_dx1":           # a missing run: its panels say "not run"
            _fake(sim, name, app, times=lt if "ablation" not in name else (), tf=40.0)
    _fake(sim, "lblock_short", "l_block", tf=2.0)        # ended before the load did
    lb = thermo.lblock_figures(str(sim), str(out), cfg)
    assert lb["fig4"] > 100 and set(lb["ablation"]) == {"default (limited jumps, projection)", "raw jumps",
                                                         "no projection"}
    thermo.ablation_figure(str(out), "ablation_short", [("short", str(sim / "lblock_short"))], "", free_from=5.0)
    _disk(sim, out, cfg)
    snaps = {"0.07": {"R_p": 0.3}, "0.21": {"R_p": 0.2}}
    for name, (app, _) in thermo.punch_cases(cfg).items():
        _fake(sim, name, app, {"snapshots": snaps, "t": 0.4}, thermo._times(PUNCH_TIMES) if "abl" not in name else (),
              tf=0.4)
    pu = thermo.punch_figures(str(sim), str(out), cfg)
    assert pu["R_p"]["full"]["0.21"] == 0.2
    for name, (app, _) in thermo.gripper_cases(cfg).items():
        _fake(sim, name, app, times=thermo._times(GRIPPER_TIMES), tf=0.5)
    thermo.gripper_figures(str(sim), str(out), cfg)
    for name, (app, _) in thermo.ball_cases(cfg).items():
        _fake(sim, name, app, times=thermo._times(BALL_TIMES), tf=0.042)
    thermo.ball_figures(str(sim), str(out), cfg)
    for k in range(1, 25):
        assert os.path.getsize(out / f"fig{k}" / f"fig{k}.png") > 5000, k
    for name in ("ablation_lblock", "ablation_disk", "ablation_punch"):
        assert os.path.getsize(out / name / f"{name}.png") > 5000
    with open(out / "fig9" / "fig9.json") as f:
        shown = json.load(f)
    assert shown["theta theta 25"]["t"] == 25.0     # the panel is at its time (--output-at)
    with open(out / "fig5" / "fig5.json") as f:
        assert "dx = 1 p 7.7" not in json.load(f)  # the missing level is not drawn


def _stop(folder, t):
    """The blow-up guard stopped this fake run at ``t``: no results.json."""
    os.remove(os.path.join(folder, "results.json"))
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump({"completed": False, "stopped": True, "t": t}, f)


@pytest.mark.filterwarnings("ignore")
def test_disk_figures_with_stopped_runs(tmp_path, figure_texts, capsys):
    """The finest E-form level stopped at t = 2.5 (its snapshots after the stop say so) and an
    ablation stopped: drawn, labelled, their results None, named in the convergence measures."""
    from sphgen import io
    cfg = CONFIG["quick"]
    sim, out = tmp_path / "sim", tmp_path / "fig"
    fine = f"disk_E_dx{thermo._dx_label(cfg['disk_dx'][-1])}"
    for name, (app, args) in thermo.disk_cases(cfg).items():
        _fake(sim, name, app, times=thermo._times(DISK_TIMES) if "ablation" not in name else (),
              tf=2.5 if name == fine else 10.0, err=float(args[1]) ** 2)
    for path in io.output_files(str(sim / fine)):          # the stopped run wrote nothing after t = 2.5
        if io.read_solver_data(path)["t"] > 2.5:
            os.remove(path)
    _stop(str(sim / fine), 2.5)
    _stop(str(sim / "disk_ablation_raw"), 10.0)
    di = thermo.disk_figures(str(sim), str(out), cfg)
    assert di["ablation"]["raw jumps"]["stopped_at"] == 10.0 and di["ablation"]["raw jumps"]["J_min"] is None
    assert di["fig12"]["convergence"]["E"]["stopped"] == {fine: 2.5}
    assert "stopped" not in di["fig12"]["convergence"]["eta"]
    assert f"E dx={thermo._dx_label(cfg['disk_dx'][-1])} (stopped at t = 2.5)" in figure_texts["fig12.png"]
    assert "raw jumps (stopped at t = 10)" in figure_texts["ablation_disk.png"]
    fig14 = figure_texts["fig14.png"]
    assert "(stopped at t = 2.5)" in fig14 and "| stopped at t = 2.5 |" in fig14   # a title; an empty panel
    assert "note: disk_ablation_raw stopped at t = 10: its checks (ablation) missing" in capsys.readouterr().out
