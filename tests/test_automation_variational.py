"""automation/variational.py: the figures of the variational presets from (fake) run folders,
one of them stopped by the blow-up guard (info.json stopped, history.json, no results.json);
nothing is simulated."""
import json
import os

import numpy as np
import pytest

from automation import variational as va

STOP = 0.42


def _json(folder, name, obj):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, name), "w") as f:
        json.dump(obj, f)


def fake_run(case, columns=None, rows=None, results=None, stopped_at=None):
    """A run folder as sphgen leaves it: ``stopped_at`` = the guard ended it there (no results.json)."""
    folder = case.input_path()
    t = stopped_at if stopped_at is not None else (results or {}).get("t", 1.0)
    _json(folder, "info.json", {"completed": stopped_at is None, "stopped": stopped_at is not None,
                                "error": "speed above the limit" if stopped_at is not None else None, "t": t})
    if rows is not None:
        _json(folder, "history.json", {"columns": list(columns), "rows": np.asarray(rows).tolist()})
    if results is not None and stopped_at is None:
        _json(folder, "results.json", results)


def test_energy_figure_with_a_stopped_case(tmp_path, figure_texts, capsys):
    prob = va.VariationalEnergy(str(tmp_path / "sim"), str(tmp_path / "fig"))
    stopped = prob.cases[1]
    for case in prob.cases:
        stop = STOP if case is stopped else None
        t = np.linspace(0.0, STOP if stop else 1.0, 11)
        fake_run(case, ("t", "energy"), np.column_stack([t, 1.0 + 1e-6 * t]),
                 {"t": 1.0, "energy_error": 1e-6, "momentum_max": 1e-14}, stop)
    prob.run()
    name = os.path.basename(stopped.input_path())
    with open(tmp_path / "fig" / "variational_energy" / "variational_energy.json") as f:
        out = json.load(f)
    assert out[name]["stopped_at"] == STOP
    assert out[name]["energy_error"] is None and out[name]["steps"] is None    # only results.json has them
    others = [k for k in out if k != name]
    assert all(out[k]["energy_error"] == 1e-6 and "stopped_at" not in out[k] for k in others)
    assert f"{name.split('_')[0]} (stopped at t = 0.42)" in figure_texts["variational_energy.png"]
    assert f"note: {name} stopped at t = 0.42" in capsys.readouterr().out


def test_order_table_has_nan_for_a_stopped_case(tmp_path, figure_texts, capsys):
    prob = va.VariationalOrder(str(tmp_path / "sim"), str(tmp_path / "fig"))
    (key, runs), = [(k, r) for k, r in prob.groups.items() if k == ("explicit", "continuity")]
    for group in prob.groups.values():
        for dt, case in zip(prob.dts, group):
            fake_run(case, results={"t": prob.tf, "position_error_max": 3.0 * dt ** 2},
                     stopped_at=STOP * prob.tf if case is runs[2] else None)
    prob.run()
    with open(tmp_path / "fig" / "variational_order" / "variational_order.json") as f:
        series = json.load(f)["series"]
    got = series["explicit_continuity"]
    assert got["error_max"][2] is None and got["slopes"][1] is None and got["slopes"][2] is None
    assert got["slopes"][0] == pytest.approx(2.0)
    assert got["stopped_at"] == {f"dt{prob.dts[2]:g}": pytest.approx(STOP * prob.tf)}
    assert all(s == pytest.approx(2.0) for k, v in series.items() if k != "explicit_continuity" for s in v["slopes"])
    assert f"dt{prob.dts[2]:g} stopped at t = " in figure_texts["variational_order.png"]
    out = capsys.readouterr().out
    assert f"note: {os.path.basename(runs[2].input_path())} stopped at t = " in out and "nan" in out


def _outputs(folder, times, n=60):
    """Fluid output files (gid, x, y) at ``times``, the column sliding right as t grows."""
    from sphgen import io
    from sphgen.particles import ParticleArray
    x0, y0 = np.meshgrid(np.arange(10) * va_dx(), np.arange(n // 10) * va_dx())
    for step, t in enumerate(times):
        pa = ParticleArray("fluid", x=x0.ravel() + 0.1 * t, y=y0.ravel(), gid=np.arange(n))
        io.write(os.path.join(folder, f"dam_break_variational_{step:06d}.h5"), [pa], {"t": t, "dt": 1e-4, "step": step})


def va_dx():
    from sphgen.applications.dam_break_variational import DX
    return DX


@pytest.mark.filterwarnings("ignore")
def test_dam_break_figures_with_a_stopped_explicit_run(tmp_path, figure_texts, capsys):
    """The explicit run stopped at t = 0.42: Figs. 2-5 drawn up to it, labelled, no results."""
    prob = va.VariationalDamBreak(str(tmp_path / "sim"), str(tmp_path / "fig"))
    times = [0.0, 0.1, 0.25, 0.4, 0.5, 0.75, 1.0]
    for case in prob.cases:
        stop = STOP if "explicit" == os.path.basename(case.input_path()) else None
        ts = [t for t in times if stop is None or t <= stop]
        tq = np.linspace(0.0, stop or 1.0, 41)
        fake_run(case, ("t", "Q"), np.column_stack([tq, 1e-3 * np.sin(20 * tq) ** 2]), {"t": 1.0, "rho_max": 1.0},
                 stop)
        _outputs(case.input_path(), ts)
    prob.run()
    with open(tmp_path / "fig" / "variational_dam_break" / "variational_dam_break.json") as f:
        s = json.load(f)
    assert s["results_explicit"] is None and s["results_implicit"] == {"t": 1.0, "rho_max": 1.0}
    assert s["Q_explicit"]["stopped_at"] == STOP and "stopped_at" not in s["Q_implicit"]
    assert s["ejected_explicit"][2:] == [None, None]          # 0.5 and 1.0 s: after the stop
    assert s["D"]["t_final"] == 0.4 and s["D"]["max_per_quarter_second"][2:] == [None, None]
    assert s["D"]["at_snapshots"][2:] == [None, None]
    assert "t = 0.50 s: stopped at t = 0.42" in figure_texts["variational_fig3_explicit.png"]
    assert "stopped at t = 0.42" not in figure_texts["variational_fig2_implicit.png"]
    assert "explicit (stopped at t = 0.42)" in figure_texts["variational_fig5_Q.png"]
    assert "(stopped at t = 0.42)" in figure_texts["variational_fig4_D.png"]
    assert "note: explicit stopped at t = 0.42" in capsys.readouterr().out


def test_ejection_study_keeps_a_stopped_variant(tmp_path, figure_texts):
    prob = va.VariationalEjection(str(tmp_path / "sim"), str(tmp_path / "fig"))
    stopped = prob.cases[0]
    for case in prob.cases[:2]:
        stop = 0.3 if case is stopped else None
        fake_run(case, ("t", "Q"), [[0.0, 0.0]], {"t": 1.0, "rho_max": 1.01}, stop)
        _outputs(case.input_path(), [t for t in prob.times if stop is None or t <= stop])
    prob.run()
    with open(tmp_path / "fig" / "variational_ejection" / "variational_ejection.json") as f:
        out = json.load(f)
    assert out["closed_box"]["stopped_at"] == 0.3 and out["closed_box"]["rho_max"] is None
    assert out["closed_box"]["y_max"][2:] == [None, None, None] and out["closed_box"]["y_max"][0] is not None
    assert out["open_top"]["rho_max"] == 1.01 and "weak_av" not in out
    assert "closed_box (stopped at t = 0.3), t = 0.25 s" in figure_texts["variational_ejection.png"]
