"""``shtc_reversibility``: the free elastic plate of Kincl, Peshkov, Pavelka & Klika (2023),
sec. 4.1, with tau = infinity, run forward, velocities flipped, run back, returns to its start
within 1e-9 relative (issue 10; the scheme is time-reversible, sec. 3.6)."""
import json

import pytest

from sphgen.app import load_application
from sphgen.errors import InputError


def test_plate_returns_to_its_start(tmp_path):
    """8 across, perturbed lattice, 5x the bending velocity, 300 steps each way: the plate
    moves by several dr and comes back to round-off (measured 6e-14 at 1000 steps)."""
    app = load_application("shtc_reversibility")()
    app.run(["-d", str(tmp_path), "--disable-output", "--no-progress", "--threads", "1",
             "--nw", "8", "--steps", "300", "--amplitude", "5", "--perturb", "0.1"])
    res = json.loads((tmp_path / "results.json").read_text())
    assert res["displacement_forward"] > 2 * app.dr, res          # a real motion to undo
    assert res["return_error"] < 1e-9, res
    assert res["return_error_displacement"] < 1e-9, res
    assert res["velocity_error"] < 1e-9, res
    assert res["distortion_error"] < 1e-9, res
    assert (tmp_path / "return.png").exists()


def test_steps_must_be_positive(tmp_path):
    with pytest.raises(InputError):
        load_application("shtc_reversibility")().run(["-d", str(tmp_path), "--steps", "0", "--debug"])
