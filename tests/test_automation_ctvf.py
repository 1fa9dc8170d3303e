"""automation/ctvf_taylor_green.py: case list, orders and summary from finished runs."""
import json
import os

import numpy as np
import pytest

from automation.ctvf_taylor_green import all_cases, case_name, figures, order


def fake_run(folder, l1_final, umax_dev=0.0, completed=True, stopped_at=None):
    """A run folder; ``stopped_at``: the blow-up guard ended it there (history up to it)."""
    os.makedirs(folder)
    t = np.linspace(0.0, 2.0, 21)
    t = t[t <= stopped_at] if stopped_at is not None else t
    uex = np.exp(-8 * np.pi ** 2 * t / 100)
    l1 = l1_final * np.sin(np.pi * t / 4) ** 2 / np.sin(np.pi / 2) ** 2
    rows = np.column_stack([t, uex * (1 + umax_dev), uex, l1])
    with open(os.path.join(folder, "history.json"), "w") as f:
        json.dump({"rows": rows.tolist()}, f)
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump({"completed": completed and stopped_at is None, "stopped": stopped_at is not None,
                   "t": 2.0 if stopped_at is None else stopped_at}, f)


def test_case_list_names_and_options():
    cases = dict(all_cases())
    assert len(cases) == 2 * 2 * 3 * 2 + 4
    p = cases["re1000_ctvf_ipst_nx150_nocorr"]
    assert p["shifting"] == "ipst" and p["nx"] == 150 and p["re"] == 1000 and "no_corrections" in p
    assert cases["re100_edac_nx50"] == dict(scheme="edac", nx=50, re=100, tf=2.0, pfreq=1000000, threads=1)
    assert case_name(100, "gtvf", nx=50) == "re100_gtvf_nx50"


def test_order_and_summary_from_partial_runs(tmp_path):
    assert order(0.04, 0.01, 50, 100) == pytest.approx(2.0)
    sim = tmp_path / "sim"
    fake_run(sim / case_name(1000, "ctvf", "spst", 50), 0.04)
    fake_run(sim / case_name(1000, "ctvf", "spst", 100), 0.01, umax_dev=-0.02)
    fake_run(sim / case_name(1000, "ctvf", "spst", 150), 0.001, completed=False)   # not finished
    fake_run(sim / case_name(1000, "edac", nx=50), 0.08)
    from sphgen import io
    from sphgen.particles import ParticleArray
    x, y = np.random.default_rng(0).uniform(0, 1, (2, 100))
    io.write(str(sim / case_name(1000, "ctvf", "spst", 150) / "taylor_green_000010.h5"),
             [ParticleArray("fluid", x=x, y=y, p=x * y)], {"t": 2.0, "dt": 0.01, "step": 10})
    s = figures(str(sim), str(tmp_path / "fig"))
    assert s["orders"]["re1000_spst"]["order"] == [{"nx": [50, 100], "p": pytest.approx(2.0)}]
    assert case_name(1000, "ctvf", "spst", 150) in s["missing"]
    r = s["runs"][case_name(1000, "ctvf", "spst", 100)]
    assert r["l1_final"] == pytest.approx(0.01) and r["max_u_dev_max"] == pytest.approx(0.02)
    assert set(s["baselines"]["re1000_nx50"]) == {"CTVF SPST", "EDAC"}
    for name in ("fig09_re1000_spst.png", "fig10_spst_corrections.png", "baselines.png", "summary.md",
                 "fig12_re1000_pressure.png"):
        assert os.path.getsize(tmp_path / "fig" / name) > 100


def test_a_stopped_case_is_drawn_up_to_its_stop_and_its_orders_are_nan(tmp_path, figure_texts, capsys):
    sim = tmp_path / "sim"
    fake_run(sim / case_name(1000, "ctvf", "spst", 50), 0.04)
    fake_run(sim / case_name(1000, "ctvf", "spst", 100), 0.01, stopped_at=0.85)
    fake_run(sim / case_name(1000, "ctvf", "spst", 150), 0.0025)
    fake_run(sim / case_name(1000, "edac", nx=50), 0.08, stopped_at=1.2)
    s = figures(str(sim), str(tmp_path / "fig"))
    stopped = case_name(1000, "ctvf", "spst", 100)
    assert s["stopped"] == {stopped: 0.85, case_name(1000, "edac", nx=50): 1.2}
    assert stopped not in s["missing"] and s["runs"][stopped]["stopped_at"] == 0.85
    assert s["runs"][stopped]["t"] == pytest.approx(0.8)            # its history up to the stop
    o = s["orders"]["re1000_spst"]
    assert o["l1_final"] == {"50": 0.04, "100": None, "150": pytest.approx(0.0025)}
    assert [p["p"] for p in o["order"]] == [None, None]              # both need the missing L1 at t = 2
    assert "100 x 100 (stopped at t = 0.85)" in figure_texts["fig09_re1000_spst.png"]
    assert "150 x 150 |" in figure_texts["fig09_re1000_spst.png"] + " |"
    assert "EDAC (stopped at t = 1.2)" in figure_texts["baselines.png"]
    md = (tmp_path / "fig" / "summary.md").read_text()
    assert f"| {stopped} | NaN (stopped at t = 0.85) |" in md and "| re1000_spst | 50 -> 100 | NaN |" in md
    assert f"note: {stopped} stopped at t = 0.85: its L1 at t = 2" in capsys.readouterr().out


def test_cavity_void_figure_from_finished_runs(tmp_path):
    """automation/ctvf_cavity.py: the Fig. 13 pair, titled with its largest empty disc."""
    from automation.ctvf_cavity import case_params, figure
    from sphgen import io
    from sphgen.particles import ParticleArray
    assert "no_corrections" in case_params(corrections=False) and case_params()["nx"] == 150
    sim = tmp_path / "sim"
    folder = sim / "nx20"
    os.makedirs(folder)
    x, y = np.random.default_rng(0).uniform(0, 1, (2, 400))
    io.write(str(folder / "cavity_000100.h5"), [ParticleArray("fluid", x=x, y=y, u=x, v=y)],
             {"t": 2.0, "dt": 0.01, "step": 100})
    with open(folder / "results.json", "w") as f:
        json.dump({"t": 2.0, "largest_empty_disc_over_dx": 1.7}, f)
    out = figure(str(sim), str(tmp_path / "fig"), nx=20)
    assert out == {"nx20": {"t": 2.0, "largest_empty_disc_over_dx": 1.7}}     # nx20_nocorr: not run
    assert os.path.getsize(tmp_path / "fig" / "fig13_cavity_void.png") > 1000


# ------------------------------------------------------------------ automation/ctvf_solids.py
def test_solid_problems_define_their_runs_and_figures(tmp_path):
    """Every CTVF solid problem (both presets): distinct folders, one ``sphgen run`` per case
    with one thread, and the figure files it promises (nothing is run)."""
    from automation import ctvf_solids as cs
    names = set()
    for cls in cs.PAPER_PROBLEMS + cs.QUICK_PROBLEMS:
        prob = cls(str(tmp_path / "outputs"), str(tmp_path / "figures"))
        names.add(prob.get_name())
        folder, app, cases, draw, figs = cs.SECTIONS[cls.section]
        assert prob.cases and all(f"run {app} " in c.command and "--threads=1" in c.command for c in prob.cases)
        assert len({c.root for c in prob.cases}) == len(prob.cases)
        assert figs and callable(draw)
    assert len(names) == 12 and "ctvf_figs24-28_rings_quick" in names
    paper = cs.PRESETS["paper"]
    table1 = cs.table1_cases(paper["table1"])
    assert [p["vf"] for p in table1.values()] == [0.001, 0.01, 0.03, 0.05] * 2
    assert [p.get("scheme", "ctvf") for p in table1.values()] == ["ctvf"] * 4 + ["gtvf"] * 4
    assert all(p["kernel"] == "wendland" and p["hdx"] == 1.3 for n, p in table1.items() if n.startswith("gtvf"))
    plate = cs.plate_cases(paper["plate"])
    assert plate["gtvf_spst"]["shifting"] == "spst" and "free_surface" in plate["gtvf_spst"]
    assert all(plate[n]["kernel"] == "wendland" and plate[n]["hdx"] == 1.3 for n in ("gtvf", "gtvf_spst"))
    assert "kernel" not in plate["ctvf_spst"]
    assert plate["ctvf_spst_h001"]["height"] == 0.01 and plate["ctvf_spst_h001"]["separation_time"] == 0.51
    assert [p["nh"] for p in cs.fig21_cases(paper["fig21"]).values()] == [10, 20, 30]
    assert {p["shifting"] for p in cs.ring_cases(paper["rings"]).values()} == {"spst", "ipst"}
    assert set(cs.uniaxial_cases(paper["uniaxial"])) == {"ctvf_dx0.5mm", "ctvf_dx1mm", "ctvf_dx2mm", "gtvf_dx1mm"}
    # the quick preset is never finer than the paper's
    assert cs.PRESETS["quick"]["rings"]["dx"] >= paper["rings"]["dx"]
    assert min(cs.PRESETS["quick"]["uniaxial"]["dx"]) >= min(paper["uniaxial"]["dx"])


def test_impact_quick_preset_end_to_end(tmp_path):
    """CTVFImpactQuick: its two runs through the automan task, then its figures."""
    import subprocess
    from automation.ctvf_solids import PRESETS, SECTIONS, CTVFImpactQuick
    from automation.tasks import SphgenTask
    prob = CTVFImpactQuick(str(tmp_path / "outputs"), str(tmp_path / "figures"))
    for case in prob.cases:
        task = SphgenTask(case.command, case.root)
        assert not task.complete()
        subprocess.run(task.command, check=True, capture_output=True)
        assert task.complete()
    prob.run()
    out = tmp_path / "figures" / prob.get_name()
    for name in SECTIONS["impact"][4]:
        assert os.path.getsize(out / name) > 100, name
    with open(out / "summary.json") as f:
        summary = json.load(f)
    assert set(summary) == {"ctvf_spst", "gtvf"}
    for r in summary.values():
        assert r["t"] == pytest.approx(PRESETS["quick"]["impact"]["tf"]) and r["hole_width"] > 0
    assert "| ctvf_spst |" in (out / "summary.md").read_text()



def _solid_history(folder, stopped_at, columns=12):
    """history.json of a solid run the blow-up guard stopped at ``stopped_at`` (no results.json)."""
    os.makedirs(folder)
    t = np.linspace(0.0, stopped_at, 6)
    rows = np.column_stack([t] + [1.0 + 0.1 * k * np.sin(t) for k in range(1, columns)])
    with open(os.path.join(folder, "history.json"), "w") as f:
        json.dump({"rows": rows.tolist(), "c0": 50.0}, f)
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump({"completed": False, "stopped": True, "error": "speed above the limit", "t": stopped_at}, f)


def _solid_particles(folder, prefix, arrays, times):
    from sphgen import io
    from sphgen.particles import ParticleArray
    x, y = np.random.default_rng(1).uniform(0, 1, (2, 30))
    for step, t in enumerate(times):
        io.write(os.path.join(folder, f"{prefix}_{step:06d}.h5"),
                 [ParticleArray(a, x=x, y=y, p=x * t) for a in arrays], {"t": t, "dt": 1e-7, "step": step})


@pytest.mark.parametrize("section", ["plate", "table1", "fig21", "uniaxial", "rings", "impact"])
def test_solid_figures_draw_stopped_runs_labelled(tmp_path, section, figure_texts, capsys):
    """Every case of the section stopped by the guard: its curves and particles up to the stop,
    labelled "stopped at t = ...", its results.json-only numbers None in the summary."""
    from automation import ctvf_solids as cs
    folder_name, app, cases, draw, figs = cs.SECTIONS[section]
    cfg = cs.PRESETS["quick"][section]
    sim = tmp_path / "sim"
    for name, params in cases(cfg).items():
        stop = 0.6 * params["tf"]
        _solid_history(sim / name, stop)
        arrays = {"rings": ("left", "right"), "impact": ("solid",)}.get(section)
        if arrays:
            _solid_particles(sim / name, app, arrays, (0.0, 0.3 * params["tf"], stop))
    summary = draw(str(sim), str(tmp_path / "fig"), cfg)
    assert set(summary) == set(cases(cfg))
    for name, r in summary.items():
        stop = 0.6 * cases(cfg)[name]["tf"]
        assert r["stopped_at"] == pytest.approx(stop) and r["t"] is None
        assert all(v is None for k, v in r.items() if k not in ("stopped_at", "scheme", "vf", "period_paper"))
    texts = " || ".join(figure_texts.values())
    assert texts.count("(stopped at t = ") >= len(summary)
    if arrays:      # particle panels only at the times before the stop (0.6 tf)
        reached = {"rings": 2, "impact": 3}[section]      # of tf * (0, 1/3, 2/3, 1), tf * (0, 1/4, 1/2, 1)
        panels = [k for k in figure_texts if k.startswith(("fig24", "fig29"))]
        assert panels and all(figure_texts[k].count("(stopped at t = ") == reached for k in panels)
    for md in ("table1.md", "summary.md"):
        if md in figs:
            table = (tmp_path / "fig" / md).read_text()
            assert "(stopped at t = " in table and "n/a" in table
    out = capsys.readouterr().out
    assert all(f"note: {name} stopped at t = " in out for name in summary)


def test_cavity_void_figure_with_a_stopped_run(tmp_path, figure_texts, capsys):
    """The run without corrections stopped at t = 3.5: drawn at its last output, its disc None."""
    from automation.ctvf_cavity import figure
    from sphgen import io
    from sphgen.particles import ParticleArray
    x, y = np.random.default_rng(0).uniform(0, 1, (2, 400))
    for name, t in (("nx20", 25.0), ("nx20_nocorr", 3.5)):
        folder = tmp_path / "sim" / name
        os.makedirs(folder)
        io.write(str(folder / "cavity_000100.h5"), [ParticleArray("fluid", x=x, y=y, u=x, v=y)],
                 {"t": t, "dt": 0.01, "step": 100})
    with open(tmp_path / "sim" / "nx20" / "results.json", "w") as f:
        json.dump({"t": 25.0, "largest_empty_disc_over_dx": 1.7}, f)
    with open(tmp_path / "sim" / "nx20_nocorr" / "info.json", "w") as f:
        json.dump({"completed": False, "stopped": True, "t": 3.5}, f)
    out = figure(str(tmp_path / "sim"), str(tmp_path / "fig"), nx=20)
    assert out["nx20_nocorr"] == {"t": None, "largest_empty_disc_over_dx": None, "stopped_at": 3.5}
    assert out["nx20"] == {"t": 25.0, "largest_empty_disc_over_dx": 1.7}
    texts = figure_texts["fig13_cavity_void.png"]
    assert "without corrections (stopped at t = 3.5), t = 3.5" in texts and "largest empty disc 1.70 dx" in texts
    assert "note: nx20_nocorr stopped at t = 3.5: its largest empty disc missing" in capsys.readouterr().out


def test_edac_baseline_figures_with_a_stopped_run(tmp_path, figure_texts):
    """automation/taylor_green.py: nx = 100 stopped at t = 0.9, drawn up to it and labelled."""
    from automation.taylor_green import TaylorGreenEDAC
    prob = TaylorGreenEDAC(str(tmp_path / "sim"), str(tmp_path / "fig"))
    for case in prob.cases:
        fake_run(case.input_path(), 0.01, stopped_at=0.9 if case.params["nx"] == 100 else None)
    prob.run()
    assert "nx = 100 (stopped at t = 0.9)" in figure_texts["tg_edac_decay.png"]
    l1 = figure_texts["tg_edac_l1.png"]
    assert "nx = 50 |" in l1 and "nx = 100 (stopped at t = 0.9)" in l1
