"""automation/ctvf_taylor_green.py: case list, orders and summary from finished runs."""
import json
import os

import numpy as np
import pytest

from automation.ctvf_taylor_green import all_cases, case_name, figures, order


def fake_run(folder, l1_final, umax_dev=0.0, completed=True):
    os.makedirs(folder)
    t = np.linspace(0.0, 2.0, 21)
    uex = np.exp(-8 * np.pi ** 2 * t / 100)
    l1 = l1_final * np.sin(np.pi * t / 4) ** 2 / np.sin(np.pi / 2) ** 2
    rows = np.column_stack([t, uex * (1 + umax_dev), uex, l1])
    with open(os.path.join(folder, "history.json"), "w") as f:
        json.dump({"rows": rows.tolist()}, f)
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump({"completed": completed}, f)


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
