"""Reference data loaders: shapes, boundary values, sources named."""
import glob
import os

import numpy as np
import pytest

from sphgen.tools import reference


@pytest.mark.parametrize("re", reference.GHIA_RE)
def test_ghia_shapes_and_boundary_values(re):
    d = reference.ghia_1982(re)
    assert d["y"].shape == d["u"].shape == (17,)
    assert d["x"].shape == d["v"].shape == (17,)
    assert d["y"][0] == 1.0 and d["u"][0] == 1.0        # lid row: u = 1
    assert d["y"][-1] == 0.0 and d["u"][-1] == 0.0      # no slip at the bottom
    assert d["v"][0] == 0.0 and d["v"][-1] == 0.0       # no slip at the side walls
    assert np.all(np.diff(d["y"]) < 0) and np.all(np.diff(d["x"]) < 0)
    assert np.all(np.abs(d["u"]) <= 1.0) and np.all(np.abs(d["v"]) < 1.0)
    assert d["u"].min() < -0.2 and d["v"].min() < -0.2 and d["v"].max() > 0.15   # the vortex


def test_ghia_known_values_and_bad_re():
    assert reference.ghia_1982(100)["u"][8] == -0.20581     # y = 0.5
    assert reference.ghia_1982(1000)["v"][5] == -0.51550    # x = 0.9063
    with pytest.raises(ValueError, match="Re"):
        reference.ghia_1982(3200)


def test_dam_break_fronts():
    T, Z = reference.koshizuka_oka_1996()
    assert T.shape == Z.shape == (9,) and T[0] == 0.0 and Z[0] == 1.0
    for a, n in ((2.25, 15), (1.125, 10)):
        Tm, Zm = reference.martin_moyce_1952(a)
        assert Tm.shape == Zm.shape == (n,)
        assert np.all(np.diff(Tm) > 0) and np.all(np.diff(Zm) > 0) and np.all(Zm > 1)
    assert np.array_equal(reference.martin_moyce_1952()[0], reference.martin_moyce_1952(2.25)[0])
    assert np.all(np.diff(T) > 0) and np.all(np.diff(Z) > 0)
    Tm, Zm = reference.koshizuka_oka_1996_mps()     # the MPS curve of Adepu & Ramachandran's Fig. 16
    assert Tm.shape == Zm.shape == (18,) and Tm[0] == 0.0 and Zm[0] == 1.002
    assert Tm[-1] == 2.943 and Zm[-1] == 3.997      # the front at the far wall of the 4L tank
    assert np.all(np.diff(Tm) > 0) and np.all(np.diff(Zm) > 0)
    assert np.all(np.interp(T[2:-1], Tm, Zm) > Z[2:-1])   # from T = 0.77 the computation runs ahead of the experiment
    with pytest.raises(ValueError, match="Martin"):
        reference.martin_moyce_1952(1.0)


def test_every_file_names_its_source():
    files = sorted(glob.glob(os.path.join(reference.DATA_DIR, "*.csv")))
    assert len(files) == 8
    for f in files:
        text = reference.source(os.path.basename(f))
        assert "Source:" in text and "How obtained:" in text and "doi:" in text
        cols = reference.read_csv(os.path.basename(f))
        assert all(np.all(np.isfinite(c)) for c in cols.values())
