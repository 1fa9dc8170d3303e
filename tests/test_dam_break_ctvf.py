"""Dam break with CTVF (Adepu & Ramachandran 2021, section 4.3): continuity density, EDAC,
walls, free-surface treatment, against Koshizuka & Oka (1996)."""
import json
import sys
from types import SimpleNamespace

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.tools import reference


def run_dam_break(tmp_path, *args):
    app = load_application("dam_break_2d")()
    out = tmp_path / "db"
    app.run(["--scheme", "ctvf", "--no-progress", "--disable-output", "--threads", "1", "-d", str(out)] + list(args))
    with open(out / "results.json") as f:
        res = json.load(f)
    with open(out / "history.json") as f:
        hist = json.load(f)
    return res, np.array(hist["rows"]), app


def test_ctvf_dam_break_short_run(tmp_path):
    """dx = L/20 to T = 0.89: the toe follows Koshizuka & Oka (experiment and MPS) within 10 %, nothing leaves
    the tank, mass is exact, the column's free surface is found and carries p = 0."""
    res, rows, app = run_dam_break(tmp_path, "--dx", "0.05", "--tf", "0.2")
    assert type(app.scheme).__name__ == "CTVFScheme" and app.scheme.free_surface and res["scheme"] == "ctvf"
    T, Z = rows[:, 1], rows[:, 2]
    Tk, Zk = reference.koshizuka_oka_1996()
    assert T[-1] == pytest.approx(0.2 * np.sqrt(2 * 9.81), rel=1e-3)
    assert abs(Z[-1] / np.interp(T[-1], Tk, Zk) - 1) < 0.10
    assert Z[-1] > 1.2
    # against the MPS curve (the paper's Fig. 16 reference) over the points reached: 7.3 % behind
    assert res["toe_max_rel_dev_koshizuka_oka_mps"] < 0.10 and res["toe_signed_dev_at_max_koshizuka_oka_mps"] < 0
    assert res["n_outside_max"] == 0 and abs(res["mass_drift"]) < 1e-12
    assert -0.05 < res["energy_change_rel"] <= 0.0      # kinetic + potential: dissipated, a little
    f = app.scene.by_name["fluid"]
    fs = f.free_surface > 0
    assert 40 < fs.sum() < 150                          # about the perimeter of the column, not the bulk
    assert np.all(f.p[fs] == 0.0) and f.p.max() > 0.5 * 1000 * 9.81 * 2.0 * 0.5
    assert not fs[(f.y < 0.5) & (f.x < 0.5)].any()      # deep inside, at the wall corner: not surface


@pytest.mark.slow
def test_ctvf_dam_break_toe_against_koshizuka_oka(tmp_path):
    """Issue 9: toe within 10 % of Koshizuka & Oka's MPS curve (the reference of Adepu &
    Ramachandran's Fig. 16) over its data range T <= 2.943, dx = L/33 (docs/ctvf.md: 7.3 %,
    behind).  Their experimental points (not the paper's reference) are 12.8 % behind ours."""
    res, _, _ = run_dam_break(tmp_path, "--tf", "0.7")
    assert res["T"] >= 2.943 and res["n_outside_max"] == 0
    assert res["toe_max_rel_dev_koshizuka_oka_mps"] < 0.10, res


def test_toe_deviation_of_a_synthetic_front():
    """The chain the dam-break check runs, on synthetic particle sets: a bulk on the lattice
    with its front 5 % behind Koshizuka & Oka's MPS curve (to within dx/2), plus a detached
    one-row strip on the floor's first layer 3 dx ahead and a droplet further on: the toe
    (front_position) is the bulk's and the largest deviation over the MPS data range is 5 %."""
    app = sys.modules[load_application("dam_break_2d").__module__]
    dx = 1.0 / 33
    Tm, Zm = reference.koshizuka_oka_1996_mps()
    T = np.linspace(0.0, 3.0, 31)
    target = 0.95 * np.interp(T, Tm, Zm)
    Z, front = [], []
    for toe in target:
        n = int(round(toe / dx + 0.5))                    # front particle at (n - 1/2) dx ~ toe
        x, y = np.meshgrid((np.arange(n) + 0.5) * dx, (np.arange(8) + 0.5) * dx)
        x = np.concatenate([x.ravel(), (n + 3 + np.arange(3)) * dx, [n * dx + 0.5]])
        y = np.concatenate([y.ravel(), np.full(3, 0.5 * dx), [0.5 * dx]])
        Z.append(app.DamBreak2D.row(SimpleNamespace(x=x, y=y), dx)[0])
        front.append((n - 0.5) * dx)
    Z = np.array(Z)
    assert np.allclose(Z, front, atol=1e-12) and np.all(np.abs(Z - target) <= 0.5 * dx + 1e-12)
    dev, signed = app.max_rel_deviation(T, Z, Tm, Zm, *app.MPS_RANGE)
    assert signed < 0 and abs(dev - 0.05) < 0.5 * dx
    # the same front is more than 10 % ahead of Koshizuka & Oka's experimental points: the two
    # reference sets differ by more than the tolerance
    dev_exp, signed_exp = app.max_rel_deviation(T, Z, *reference.koshizuka_oka_1996())
    assert signed_exp > 0.10
