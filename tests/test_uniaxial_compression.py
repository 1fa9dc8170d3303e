"""Uniaxial compression (Adepu & Ramachandran 2021, section 4.5): the von Mises stress of
eqs. 68-70 and a coarse run with a fixed base and a driven piston."""
import json

import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.applications.uniaxial_compression import HEIGHT, PISTON_SPEED, von_mises


def test_von_mises_of_known_stress_states():
    def sd(sxx=0.0, syy=0.0, sxy=0.0):
        s = np.zeros(9)
        s[0], s[4], s[1], s[3] = sxx, syy, sxy, sxy
        return s
    # eq. 68 is the plane-stress form (sigma_3 = 0): equal biaxial in-plane stress gives |p|
    assert von_mises(np.array([5.0]), sd())[0] == pytest.approx(5.0)
    assert von_mises(np.array([0.0]), sd(syy=-3.0))[0] == pytest.approx(3.0)            # uniaxial
    assert von_mises(np.array([0.0]), sd(sxy=2.0))[0] == pytest.approx(2.0 * np.sqrt(3.0))   # pure shear
    # a rotated uniaxial state: the same von Mises stress
    c, s_ = np.cos(0.3), np.sin(0.3)
    assert von_mises(np.array([1.0]), sd(-3 * s_ * s_ + 1, -3 * c * c + 1, -3 * c * s_))[0] == pytest.approx(3.0)


def test_coarse_compression_run(tmp_path):
    """dx = 5 mm, 0.2 ms: the piston moved at 1.5 mm/s, the base held, the von Mises stress
    at A grows with the slope of the plane-strain estimate E V / ((1 - nu^2) H)."""
    app = load_application("uniaxial_compression")()
    app.run(["-d", str(tmp_path), "--disable-output", "--no-progress", "--threads", "1", "--dx", "0.005",
             "--tf", "2e-4", "--record-every", "1e-5"])
    res = json.load(open(tmp_path / "results.json"))
    assert res["reached_end"] and res["finite"]
    assert res["piston_displacement"] == pytest.approx(-PISTON_SPEED * 2e-4, rel=1e-6)
    pa = app.scene.by_name["solid"]
    base = np.isin(pa.gid, app.base)
    assert base.sum() == 3 * 16 and np.all(pa.v[base] == 0) and np.all(pa.y[base] < 0)
    assert np.all(pa.y[np.isin(pa.gid, app.piston)] > HEIGHT - PISTON_SPEED * 2e-4)
    assert 0.8 < res["von_mises_slope_over_estimate"] < 1.2, res      # measured 1.007


def test_driven_particles_are_checked():
    from sphgen.schemes.ctvf import CTVFSolidScheme
    with pytest.raises(ValueError, match="not among"):
        CTVFSolidScheme(["solid"], 2, 2300.0, 7.5e9, 0.398, 1e-3, 1e-3, driven={"piston": ([0], (0.0, -1.0))})
    with pytest.raises(ValueError, match="2 components"):
        CTVFSolidScheme(["solid"], 2, 2300.0, 7.5e9, 0.398, 1e-3, 1e-3, driven={"solid": ([0], (0.0, 0.0, 1.0))})
