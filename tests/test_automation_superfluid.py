"""automation/superfluid.py: case lists and every figure of thesis ch. 3 from (fake) finished runs."""
import json
import os

import numpy as np
import pytest

from automation.superfluid import (CONFIG, START_TIMES, figures, fountain_cases, fountain_dt,
                                   second_sound_cases, ss_name)


def test_case_lists():
    ss = second_sound_cases(CONFIG["paper"])
    assert ss["ss_N300_A0.01_M50"] == dict(N=300, A=0.01, M=50)
    assert ss["ss_N200_A0.1_M25"] == dict(N=200, A=0.1, M=25)
    assert len(ss) == 3 * 4 + 2 * 3 - 2   # N = 200, A = 0.01 and 0.1, M = 50 serve both panels
    fo = fountain_cases(CONFIG["quick"])
    assert set(fo) == {"fountain_W60", "fountain_W80", "fountain_W100", "fountain_start_W80"}
    dt = fountain_dt("quick")
    assert dt == pytest.approx(1.085e-5, rel=2e-3)
    assert fo["fountain_W80"]["pfreq"] == round(0.12 / 8 / dt)
    assert fo["fountain_start_W80"]["pfreq"] * dt == pytest.approx(START_TIMES[0], rel=0.05)
    assert fountain_cases(CONFIG["paper"])["fountain_W60"]["pfreq"] * fountain_dt("paper") == \
        pytest.approx(0.0375, rel=1e-4)


def _fake_second_sound(folder, N, A, M):
    os.makedirs(folder)
    t = np.linspace(0, 7.5e-4, 11)
    s = 725.5 * (1 + A * 0.5 * np.cos(2 * np.pi * t / 7.5e-4))
    rows = np.column_stack([t, np.zeros_like(t), s, s, np.zeros_like(t)])
    with open(os.path.join(folder, "history.json"), "w") as f:
        json.dump({"columns": ["t", "entropy_error", "s_probe", "s_probe_exact", "mode"], "rows": rows.tolist()}, f)
    with open(os.path.join(folder, "results.json"), "w") as f:
        json.dump({"entropy_error": 0.1 / N + A, "energy_error": 1.0 / M ** 2}, f)


def _fake_fountain(folder, W, times):
    from sphgen import io
    from sphgen.particles import ParticleArray
    os.makedirs(folder)
    with open(os.path.join(folder, "results.json"), "w") as f:
        json.dump({"flux_series": [[0.01 * k, 0.1 * W / 80] for k in range(20)], "v_jet": 0.5,
                   "v_jet_theory": 0.52, "flux_error": -0.04, "flux": 0.1}, f)
    rng = np.random.default_rng(W)
    x, y = rng.uniform(-0.01, 0.01, 200), rng.uniform(0.0, 0.03, 200)
    for step, t in enumerate(times):
        pa = ParticleArray("helium", x=x, y=y, u=x, v=y, T=1.65 + 1e-3 * y)
        pa.add_property("ptype", dtype="int", data=np.zeros(200, np.int32))
        io.write(os.path.join(folder, f"fountain_{step:06d}.h5"), [pa], {"t": t, "dt": 1e-5, "step": step})


def test_figures_from_finished_runs(tmp_path):
    cfg = dict(CONFIG["quick"], N=(25, 50), A=(0.01, 0.1), Ms=(10, 25), fountain="quick")
    sim, out = tmp_path / "sim", tmp_path / "fig"
    for name, p in second_sound_cases(cfg).items():
        if name != ss_name(25, 0.1, 50):   # one missing run: its point is left out
            _fake_second_sound(sim / name, p["N"], p["A"], p["M"])
    _fake_fountain(sim / "fountain_start_W80", 80, START_TIMES)
    _fake_fountain(sim / "fountain_W80", 80, [0.015 * (k + 1) for k in range(8)])
    _fake_fountain(sim / "fountain_W60", 60, [0.12])
    s = figures(str(sim), str(out), cfg)
    assert s["fig3_2"]["entropy_error"]["25"] == [[0.01, pytest.approx(0.014)]]
    assert len(s["fig3_2"]["entropy_error"]["50"]) == 2
    assert s["fig3_2"]["energy_error"]["0.01"] == [[10, pytest.approx(0.01)], [25, pytest.approx(0.0016)]]
    assert s["fig3_2"]["energy_slope"]["0.01"] == pytest.approx(-2.0)
    assert set(s["fig3_5"]) == {60, 80}
    for k in range(1, 9):
        assert os.path.getsize(out / f"fig3_{k}" / f"fig3_{k}.png") > 5000, k


def _stop(folder, t):
    """The blow-up guard stopped this fake run at ``t``: no results.json."""
    os.remove(os.path.join(folder, "results.json"))
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump({"completed": False, "stopped": True, "t": t}, f)


def test_figures_with_stopped_runs(tmp_path, figure_texts, capsys):
    cfg = dict(CONFIG["quick"], N=(25, 50), A=(0.01, 0.1), Ms=(10, 25), fountain="quick")
    sim, out = tmp_path / "sim", tmp_path / "fig"
    for name, p in second_sound_cases(cfg).items():
        _fake_second_sound(sim / name, p["N"], p["A"], p["M"])
    _fake_fountain(sim / "fountain_W80", 80, [0.015 * (k + 1) for k in range(8)])
    _fake_fountain(sim / "fountain_W60", 60, [0.03])
    _fake_fountain(sim / "fountain_start_W80", 80, START_TIMES[:2])
    _stop(str(sim / "fountain_start_W80"), START_TIMES[1])
    _stop(str(sim / ss_name(25, 0.1, 50)), 2e-4)
    _stop(str(sim / ss_name(50, 0.01, 50)), 3e-4)         # also Fig. 3.3's run
    _stop(str(sim / "fountain_W60"), 0.03)
    s = figures(str(sim), str(out), cfg)
    assert s["fig3_2"]["entropy_error"]["25"] == [[0.01, pytest.approx(0.014)]]
    assert set(s["fig3_5"]) == {80}
    assert "N = 25 (A = 0.1 stopped at t = 0.0002)" in figure_texts["fig3_2.png"]
    assert "sphgen (stopped at t = 0.0003)" in figure_texts["fig3_3.png"]
    assert "jet speed (60 W/m stopped at t = 0.03)" in figure_texts["fig3_5.png"]
    assert "60 W/m (stopped at t = 0.03)" in figure_texts["fig3_7.png"]
    fig3_6 = figure_texts["fig3_6.png"]              # 0.75 and 1 ms: after the stop
    assert fig3_6.count("| stopped at t = 0.0005 |") == 2 and "80 W/m (stopped at t = 0.0005)" in fig3_6
    notes = capsys.readouterr().out
    assert f"note: {ss_name(25, 0.1, 50)} stopped at t = 0.0002: its entropy error (Fig. 3.2) missing" in notes
    assert "note: fountain_W60 stopped at t = 0.03: its flux series (Fig. 3.5) missing" in notes
