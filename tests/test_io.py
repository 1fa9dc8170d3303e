"""Tests of sphgen.io: HDF5 output round trip, atomic writes, file series, XDMF index, JSON."""
import json
import os
import shutil
import xml.etree.ElementTree as ET

import h5py
import numpy as np
import pytest

from sphgen import io
from sphgen.particles import ParticleArray


def make_arrays(n_fluid=5, n_solid=3, seed=0):
    rng = np.random.default_rng(seed)
    fluid = ParticleArray("fluid", x=rng.random(n_fluid), y=rng.random(n_fluid),
                          z=rng.random(n_fluid), rho=1000 + rng.random(n_fluid))
    fluid.add_property("vel", stride=3, data=rng.random(3 * n_fluid))
    fluid.add_property("tau", stride=9, data=rng.random(9 * n_fluid))
    fluid.add_property("tag", dtype="int", data=np.arange(n_fluid) * 7 - 3)
    fluid.add_property("unused", stride=3, default=2.5)  # declared, never allocated
    fluid.add_constant("c0", 10.0)
    fluid.add_constant("gravity", [0.0, -9.81, 0.0])
    solid = ParticleArray("solid", x=rng.random(n_solid), y=rng.random(n_solid), z=np.zeros(n_solid))
    solid.add_property("normal", stride=3, data=rng.random(3 * n_solid))
    solid.add_constant("u_solid", [1.5, 0.0, 0.0])
    return [fluid, solid]


def assert_same_array(a, b):
    assert a.name == b.name and a.n == b.n
    assert sorted(a.data) == sorted(b.data)
    for k, p in a.props.items():
        q = b.props[k]
        assert (q.stride, q.dtype, q.default) == (p.stride, p.dtype, p.default), k
    assert sorted(a.props) == sorted(b.props)
    for k, v in a.data.items():
        assert b.data[k].dtype == v.dtype, k
        assert b.data[k].shape == v.shape, k
        np.testing.assert_array_equal(b.data[k], v)
    assert sorted(a.constants) == sorted(b.constants)
    for k, v in a.constants.items():
        np.testing.assert_array_equal(b.constants[k], v)


@pytest.mark.parametrize("compress", [False, True])
def test_round_trip(tmp_path, compress):
    arrays = make_arrays()
    sd = {"t": 0.1 + 0.2, "dt": 1e-4 / 3, "step": 123, "scheme": "wcsph",
          "cfl": np.float64(0.25), "n_threads": np.int64(4), "h0": np.array([0.1, 0.2])}
    path = tmp_path / "run_000123.h5"
    io.write(path, arrays, sd, compress=compress)
    out = io.load(path)
    assert list(out["arrays"]) == ["fluid", "solid"]
    for a in arrays:
        assert_same_array(a, out["arrays"][a.name])
    got = out["solver_data"]
    assert got["t"] == sd["t"] and got["dt"] == sd["dt"] and got["step"] == 123
    assert isinstance(got["step"], int)
    assert got["scheme"] == "wcsph" and got["cfl"] == 0.25 and got["n_threads"] == 4
    assert got["h0"] == [0.1, 0.2]
    fluid = out["arrays"]["fluid"]
    assert fluid.tag.dtype == np.int32 and list(fluid.tag) == [-3, 4, 11, 18, 25]
    assert fluid.props["tau"].stride == 9 and fluid.tau.size == 45
    assert "unused" in fluid.props and "unused" not in fluid.data
    assert fluid.allocate("unused").tolist() == [2.5] * 15


def test_round_trip_empty_array_and_non_finite(tmp_path):
    empty = ParticleArray("empty", n=0)
    empty.allocate("x")
    empty.add_property("vel", stride=3).allocate("vel")
    blown = ParticleArray("blown", x=[0.0, 1.0])
    blown.data["x"][1] = np.nan  # a diverged state must still be written and read back as is
    io.write(tmp_path / "e_000000.h5", [empty, blown], {"t": 0.0, "dt": 0.1, "step": 0},
             compress=True)
    out = io.load(tmp_path / "e_000000.h5")["arrays"]
    assert_same_array(empty, out["empty"])
    assert out["empty"].vel.shape == (0,)
    assert out["blown"].x[0] == 0.0 and np.isnan(out["blown"].x[1])


def test_write_requires_t_dt_step_and_unique_names(tmp_path):
    with pytest.raises(ValueError, match="dt"):
        io.write(tmp_path / "a_000001.h5", make_arrays(), {"t": 0.0, "step": 1})
    with pytest.raises(ValueError, match="duplicate"):
        io.write(tmp_path / "a_000001.h5", make_arrays()[:1] * 2, {"t": 0, "dt": 1, "step": 1})
    assert os.listdir(tmp_path) == []


class Crash(RuntimeError):
    pass


def crash_after(monkeypatch, calls):
    """Make the `calls`-th h5py create_dataset raise, i.e. die halfway through a write."""
    real = h5py.Group.create_dataset
    count = [0]

    def flaky(self, *a, **kw):
        count[0] += 1
        if count[0] >= calls:
            raise Crash("simulated crash during write")
        return real(self, *a, **kw)

    monkeypatch.setattr(h5py.Group, "create_dataset", flaky)
    return count


def test_crash_keeps_previous_good_file(tmp_path, monkeypatch):
    path = tmp_path / "run_000010.h5"
    good = make_arrays(seed=1)
    io.write(path, good, {"t": 1.0, "dt": 0.1, "step": 10})
    count = crash_after(monkeypatch, 4)
    with pytest.raises(Crash):
        io.write(path, make_arrays(seed=2), {"t": 2.0, "dt": 0.1, "step": 10})
    assert count[0] == 4  # it really died halfway, after writing some datasets
    monkeypatch.undo()
    out = io.load(path)
    assert out["solver_data"]["t"] == 1.0
    for a in good:
        assert_same_array(a, out["arrays"][a.name])
    assert sorted(os.listdir(tmp_path)) == ["run_000010.h5"]  # temporary cleaned up


def test_crash_leaves_no_file_under_final_name(tmp_path, monkeypatch):
    crash_after(monkeypatch, 2)
    with pytest.raises(Crash):
        io.write(tmp_path / "run_000020.h5", make_arrays(), {"t": 2.0, "dt": 0.1, "step": 20})
    assert os.listdir(tmp_path) == []
    assert io.output_files(tmp_path) == []


def test_killed_run_temporary_is_ignored(tmp_path):
    io.write(tmp_path / "run_000000.h5", make_arrays(), {"t": 0.0, "dt": 0.1, "step": 0})
    # what a SIGKILL mid-write leaves behind: a truncated temporary
    (tmp_path / "run_000005.h5.tmp-4242").write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 10)
    assert io.output_files(tmp_path, "run") == [os.path.join(tmp_path, "run_000000.h5")]
    xdmf = ET.parse(io.write_xdmf(tmp_path, "run")).getroot()
    assert "tmp" not in ET.tostring(xdmf, encoding="unicode")


def test_output_files_order_and_exclusions(tmp_path):
    names = ["tg_000100.h5", "tg_000002.h5", "tg_1000000.h5", "tg_999999.h5", "tg_000010.h5",
             "tg_last_good.h5", "tg_000300.h5.tmp-123", "tg.xdmf", "info.json",
             "other_000001.h5", "tg_000050.h5.bak", "tg_abc.h5"]
    for n in names:
        (tmp_path / n).write_bytes(b"")
    d = str(tmp_path)
    assert io.output_files(d, "tg") == [os.path.join(d, n) for n in
                                        ["tg_000002.h5", "tg_000010.h5", "tg_000100.h5",
                                         "tg_999999.h5", "tg_1000000.h5"]]
    assert [os.path.basename(p) for p in io.output_files(d)] == [
        "other_000001.h5", "tg_000002.h5", "tg_000010.h5", "tg_000100.h5", "tg_999999.h5",
        "tg_1000000.h5"]
    assert io.output_files(d, "nothing") == []


def write_series(directory, prefix="tg", steps=(0, 50, 100)):
    for step in steps:
        arrays = make_arrays(seed=step)
        io.write(os.path.join(directory, f"{prefix}_{step:06d}.h5"), arrays,
                 {"t": step * 0.01, "dt": 0.01, "step": step})


def check_xdmf(xdmf_path):
    """Parse the xdmf; every HDF5 reference must resolve with the declared dimensions."""
    root = ET.parse(xdmf_path).getroot()
    base = os.path.dirname(xdmf_path)
    n_refs = 0
    for item in root.iter("DataItem"):
        if item.get("Format") != "HDF":
            continue
        fname, dsname = item.text.strip().split(":", 1)
        assert not os.path.isabs(fname)
        dims = tuple(int(d) for d in item.get("Dimensions").split())
        with h5py.File(os.path.join(base, fname), "r") as f:
            assert dsname in f, dsname
            ds = f[dsname]
            assert ds.shape == dims and ds.size == int(np.prod(dims))
            kind = "Int" if ds.dtype.kind == "i" else "Float"
            assert item.get("NumberType") == kind
            assert int(item.get("Precision")) == ds.dtype.itemsize
        n_refs += 1
    return root, n_refs


def test_write_xdmf(tmp_path):
    write_series(tmp_path)
    (tmp_path / "tg_last_good.h5").write_bytes(b"not even hdf5")
    path = io.write_xdmf(tmp_path)  # single series: prefix inferred
    assert path == os.path.join(tmp_path, "tg.xdmf")
    root, n_refs = check_xdmf(path)
    assert root.tag == "Xdmf" and root.get("Version") == "3.0"
    (series,) = root.find("Domain").findall("Grid")
    assert series.get("CollectionType") == "Temporal"
    steps = series.findall("Grid")
    assert [float(g.find("Time").get("Value")) for g in steps] == [0.0, 0.5, 1.0]
    for step in steps:
        assert step.get("CollectionType") == "Spatial"
        grids = step.findall("Grid")
        assert [g.get("Name") for g in grids] == ["fluid", "solid"]
        fluid = grids[0]
        topo = fluid.find("Topology")
        assert topo.get("TopologyType") == "Polyvertex" and topo.get("NumberOfElements") == "5"
        geom = fluid.find("Geometry")
        assert geom.get("GeometryType") == "X_Y_Z"
        assert [i.text.split("/")[-1] for i in geom.findall("DataItem")] == ["x", "y", "z"]
        atts = {a.get("Name"): a for a in fluid.findall("Attribute")}
        assert all(a.get("Center") == "Node" for a in atts.values())
        assert atts["rho"].get("AttributeType") == "Scalar"
        assert atts["tag"].get("AttributeType") == "Scalar"
        assert atts["vel"].get("AttributeType") == "Vector"
        assert atts["tau"].get("AttributeType") == "Tensor"
        assert "unused" not in atts
        assert atts["vel"].find("DataItem").get("Dimensions") == "5 3"
        assert atts["tau"].find("DataItem").get("Dimensions") == "5 9"
    # per file: fluid and solid geometry + attributes (each with its persistent id gid)
    assert n_refs == 3 * ((3 + 8) + (3 + 5))
    assert not [f for f in os.listdir(tmp_path) if ".tmp-" in f]


def test_write_xdmf_folder_can_be_moved_and_is_rewritten(tmp_path):
    run = tmp_path / "run"
    run.mkdir()
    write_series(run, steps=(0, 10))
    io.write_xdmf(run, "tg")
    moved = tmp_path / "moved"
    shutil.move(str(run), str(moved))
    root, _ = check_xdmf(os.path.join(moved, "tg.xdmf"))
    assert len(root.find("Domain/Grid").findall("Grid")) == 2
    write_series(moved, steps=(20,))
    root, _ = check_xdmf(io.write_xdmf(moved, "tg"))
    assert len(root.find("Domain/Grid").findall("Grid")) == 3


def test_write_xdmf_missing_z_and_ambiguous_prefix(tmp_path):
    flat = ParticleArray("flat", x=[0.0, 1.0, 2.0], y=[0.0, 0.0, 1.0])
    io.write(tmp_path / "a_000000.h5", [flat], {"t": 0.0, "dt": 0.1, "step": 0})
    root, _ = check_xdmf(io.write_xdmf(tmp_path, "a"))
    items = root.find("Domain/Grid/Grid/Grid/Geometry").findall("DataItem")
    assert len(items) == 3 and items[2].get("ItemType") == "Function"
    assert items[2].get("Dimensions") == "3"
    io.write(tmp_path / "b_000000.h5", [flat], {"t": 0.0, "dt": 0.1, "step": 0})
    with pytest.raises(ValueError, match="prefix"):
        io.write_xdmf(tmp_path)


def test_load_rejects_non_output_files(tmp_path):
    text = tmp_path / "notes_000001.h5"
    text.write_text("hello")
    with pytest.raises(ValueError, match="notes_000001.h5.*not a sphgen output file"):
        io.load(text)
    other = tmp_path / "other.h5"
    with h5py.File(other, "w") as f:
        f["data"] = np.arange(3)
    with pytest.raises(ValueError, match="other.h5.*not a sphgen output file"):
        io.load(other)
    with pytest.raises(FileNotFoundError, match="missing.h5"):
        io.load(tmp_path / "missing.h5")


def test_write_json(tmp_path):
    path = tmp_path / "results.json"
    path.write_text("old")
    obj = {"l2": np.float64(1.5e-3), "n": np.int32(7), "errs": np.array([1.0, 2.0]),
           "ok": np.bool_(True), "name": "tg", "out": tmp_path}
    io.write_json(path, obj)
    got = json.loads(path.read_text())
    assert got == {"l2": 1.5e-3, "n": 7, "errs": [1.0, 2.0], "ok": True, "name": "tg",
                   "out": str(tmp_path)}
    with pytest.raises(TypeError):
        io.write_json(path, {"bad": object()})
    assert json.loads(path.read_text()) == got  # failed write left the old file intact
    assert sorted(os.listdir(tmp_path)) == ["results.json"]
