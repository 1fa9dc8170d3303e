"""Conserved-quantity diagnostics: values on known fields, and the written Taylor-Green series."""
import json

import numpy as np
import pytest

from sphgen.app import main
from sphgen.particles import ParticleArray
from sphgen.tools.diagnostics import Diagnostics


def test_diagnostics_of_a_rigid_rotation():
    rng = np.random.default_rng(3)
    x, y = rng.uniform(-1, 1, (2, 200))
    m = rng.uniform(0.5, 1.5, 200)
    omega = 2.0
    fluid = ParticleArray("fluid", x=x, y=y, u=-omega * y + 1.0, v=omega * x, m=m, rho=np.ones(200))
    wall = ParticleArray("wall", x=[5.0], y=[5.0], m=[3.0])          # no velocities: skipped
    d = Diagnostics(["mass", "linear_momentum", "angular_momentum", "kinetic_energy"], 2)
    t, mass, px, py, lz, ke = d.sample(0.0, [fluid, wall])
    assert mass == pytest.approx(m.sum() + 3.0)
    assert px == pytest.approx(np.sum(m * (1.0 - omega * y))) and py == pytest.approx(np.sum(m * omega * x))
    assert lz == pytest.approx(np.sum(m * (x * omega * x - y * (1.0 - omega * y))))
    assert ke == pytest.approx(0.5 * np.sum(m * ((1.0 - omega * y) ** 2 + (omega * x) ** 2)))
    assert d.columns([fluid]) == ["t", "mass", "momentum_x", "momentum_y", "angular_momentum_z",
                                  "kinetic_energy"]
    with pytest.raises(ValueError, match="unknown diagnostic 'energy'"):
        Diagnostics(["energy"], 2)


def test_taylor_green_momentum_series_conserved_to_round_off(tmp_path):
    out = tmp_path / "tg"
    main(["run", "taylor_green", "--nx", "20", "--tf", "0.05", "--no-bql", "--no-progress", "-d", str(out)])
    d = json.load(open(out / "diagnostics.json"))
    rows = np.array(d["rows"])
    cols = d["columns"]
    assert len(rows) >= 5 and rows[0, 0] == 0.0
    scale = rows[0, cols.index("mass")] * 1.0          # sum m |u| <= M U with U = 1
    for c in ("momentum_x", "momentum_y"):
        assert np.abs(rows[:, cols.index(c)] - rows[0, cols.index(c)]).max() < 1e-13 * scale, c
    assert np.ptp(rows[:, cols.index("mass")]) == 0.0
    assert (out / "diagnostics.png").stat().st_size > 1000
