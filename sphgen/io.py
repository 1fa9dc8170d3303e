"""Output files (HDF5), loading them back, an XDMF index for ParaView, atomic JSON.

One output file holds the state of every particle array at one step::

    /                          attrs: format="sphgen-output", format_version=1
    /solver_data               attrs: t, dt, step (native types) and json (the whole dict as JSON)
    /arrays/<name>             attrs: n, declared (JSON {prop: [stride, dtype, default]} of all
                               declared properties, allocated or not)
    /arrays/<name>/properties/<prop>
                               dataset, shape (n,) for stride 1 else (n, stride);
                               float64 ('double') or int32 ('int');
                               attrs: stride, dtype ('double'|'int')
    /arrays/<name>/constants/<c>
                               dataset, float64, 1-D

Files are named ``<prefix>_<step:06d>.h5``; ``<prefix>_last_good.h5`` (written when a run blows
up) and temporaries (``<file>.tmp-<pid>``) are not part of the series.  Every file this module
writes (HDF5, XDMF, JSON) is first written under a temporary name in the same folder, flushed to
disk and then moved into place with ``os.replace``, so a killed run never leaves a half-written
file under the final name.
"""
import contextlib
import json
import os
import re
import xml.etree.ElementTree as ET

import h5py
import numpy as np

from sphgen.errors import InputError
from sphgen.particles import ParticleArray

FORMAT = "sphgen-output"
FORMAT_VERSION = 1
_SERIES = re.compile(r"^(?P<prefix>.+)_(?P<step>\d+)\.h5$")


# ------------------------------------------------------------------ helpers
def _jsonable(obj):
    """json.dumps default: numpy scalars/arrays and paths."""
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, os.PathLike):
        return os.fspath(obj)
    raise TypeError(f"{type(obj).__name__} is not JSON serialisable: {obj!r}")


def _dumps(obj, **kw):
    return json.dumps(obj, default=_jsonable, **kw)


def _fsync(path):
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)


@contextlib.contextmanager
def _atomic(path):
    """Yield a temporary name next to ``path``; on success move it to ``path``, else remove it."""
    path = os.fspath(path)
    tmp = f"{path}.tmp-{os.getpid()}"
    try:
        yield tmp
        _fsync(tmp)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(OSError):
            os.remove(tmp)
        raise


def _write_text(path, text):
    with _atomic(path) as tmp:
        with open(tmp, "w", encoding="utf-8") as f:
            f.write(text)


# ------------------------------------------------------------------ writing
def write(path, arrays, solver_data, compress=False):
    """Write the arrays and solver data to one HDF5 output file, atomically."""
    missing = [k for k in ("t", "dt", "step") if k not in solver_data]
    if missing:
        raise ValueError(f"{path}: solver_data needs {', '.join(missing)}")
    names = [pa.name for pa in arrays]
    if len(set(names)) != len(names):
        raise ValueError(f"{path}: duplicate particle array names {names}")
    sd_json = _dumps(solver_data)
    opts = dict(compression="gzip", compression_opts=4, shuffle=True) if compress else {}
    with _atomic(path) as tmp:
        with h5py.File(tmp, "w", track_order=True) as f:
            f.attrs["format"] = FORMAT
            f.attrs["format_version"] = FORMAT_VERSION
            sd = f.create_group("solver_data")
            sd.attrs["t"] = float(solver_data["t"])
            sd.attrs["dt"] = float(solver_data["dt"])
            sd.attrs["step"] = int(solver_data["step"])
            sd.attrs["json"] = sd_json
            groups = f.create_group("arrays", track_order=True)
            for pa in arrays:
                _write_array(groups, pa, opts)


def _write_array(parent, pa, opts):
    g = parent.create_group(pa.name)
    g.attrs["n"] = pa.n
    g.attrs["declared"] = _dumps({k: [p.stride, p.dtype, p.default] for k, p in pa.props.items()})
    props = g.create_group("properties", track_order=True)
    for name, arr in pa.data.items():
        p = pa.props[name]
        shape = (pa.n,) if p.stride == 1 else (pa.n, p.stride)
        data = np.asarray(arr, dtype=p.np_dtype).reshape(shape)
        ds = props.create_dataset(name, data=data, **(opts if data.size else {}))
        ds.attrs["stride"] = p.stride
        ds.attrs["dtype"] = p.dtype
    consts = g.create_group("constants", track_order=True)
    for name, value in pa.constants.items():
        consts.create_dataset(name, data=np.asarray(value, dtype=np.float64).reshape(-1))


def write_json(path, obj):
    """Atomic JSON write; numpy scalars and arrays are converted."""
    _write_text(path, _dumps(obj, indent=2) + "\n")


def read_history(outdir, allow_empty=False):
    """``(history, rows)`` of a run folder's ``history.json``: the dict and its sample
    rows as a float array (one row per sample, columns ``history["columns"]``).
    A missing file, or one without samples unless ``allow_empty``, is an InputError."""
    path = os.path.join(outdir, "history.json")
    try:
        with open(path) as fh:
            hist = json.load(fh)
    except (OSError, ValueError) as e:
        raise InputError(f"{path}: cannot read the run's time series ({e})") from None
    rows = np.array(hist.get("rows", []), dtype=float)
    if rows.size == 0 and not allow_empty:
        raise InputError(f"{path} has no samples (run for at least one step)")
    return hist, rows


# ------------------------------------------------------------------ loading
def _open(path):
    """Open an output file for reading, or raise ValueError naming it."""
    if not os.path.isfile(path):
        raise FileNotFoundError(f"{path}: no such output file")
    try:
        f = h5py.File(path, "r")
    except OSError as e:
        raise ValueError(f"{path} is not a sphgen output file (not readable as HDF5: {e})") from None
    if f.attrs.get("format") != FORMAT or "arrays" not in f or "solver_data" not in f:
        f.close()
        raise ValueError(f"{path} is not a sphgen output file (no '{FORMAT}' format marker)")
    return f


def load(path):
    """Read an output file -> {'arrays': {name: ParticleArray}, 'solver_data': dict}."""
    with _open(path) as f:
        solver_data = json.loads(f["solver_data"].attrs["json"])
        arrays = {}
        for name, g in f["arrays"].items():
            pa = ParticleArray(name, n=int(g.attrs["n"]))
            for prop, (stride, dtype, default) in json.loads(g.attrs["declared"]).items():
                pa.add_property(prop, stride=stride, dtype=dtype, default=default)
            for prop, ds in g["properties"].items():
                p = pa.props[prop]
                # straight into pa.data: a file is reproduced as written (no finiteness check)
                pa.data[prop] = np.ascontiguousarray(ds[()], dtype=p.np_dtype).reshape(-1)
            for c, ds in g["constants"].items():
                pa.constants[c] = np.asarray(ds[()], dtype=np.float64).reshape(-1)
            arrays[name] = pa
    return {"arrays": arrays, "solver_data": solver_data}


def read_solver_data(path):
    """The solver data (t, dt, step, and what the run stored with them) of an output file."""
    with _open(path) as f:
        return json.loads(f["solver_data"].attrs["json"])


def output_files(directory, prefix=None):
    """Output files ``<prefix>_<step>.h5`` of a directory, sorted by step (full paths)."""
    found = []
    for fname in os.listdir(directory):
        m = _SERIES.match(fname)
        if m and (prefix is None or m["prefix"] == prefix):
            found.append((int(m["step"]), fname))
    return [os.path.join(directory, fname) for _, fname in sorted(found)]


# ------------------------------------------------------------------ XDMF
_ATTRIBUTE_TYPE = {1: "Scalar", 3: "Vector", 6: "Tensor6", 9: "Tensor"}


def _data_item(parent, fname, dsname, ds):
    dims = " ".join(str(d) for d in ds.shape)
    number, precision = ("Int", "4") if ds.dtype.kind == "i" else ("Float", "8")
    item = ET.SubElement(parent, "DataItem", Dimensions=dims, NumberType=number,
                         Precision=precision, Format="HDF")
    item.text = f"{fname}:{dsname}"
    return item


def _array_grid(parent, fname, g):
    """One Uniform Polyvertex grid for the array group ``g``; None if it cannot be shown."""
    n = int(g.attrs["n"])
    props = g["properties"]
    coords = [c for c in ("x", "y", "z") if c in props]
    if n == 0 or not coords:
        return None
    grid = ET.SubElement(parent, "Grid", Name=g.name.rsplit("/", 1)[-1], GridType="Uniform")
    ET.SubElement(grid, "Topology", TopologyType="Polyvertex", NumberOfElements=str(n),
                  NodesPerElement="1")
    geom = ET.SubElement(grid, "Geometry", GeometryType="X_Y_Z")
    for c in ("x", "y", "z"):
        if c in props:
            _data_item(geom, fname, props[c].name, props[c])
        else:  # an unallocated coordinate (e.g. z in 2D) is shown as zeros
            fn = ET.SubElement(geom, "DataItem", ItemType="Function", Function="0*$0",
                               Dimensions=str(n))
            _data_item(fn, fname, props[coords[0]].name, props[coords[0]])
    for name, ds in props.items():
        stride = int(ds.attrs["stride"])
        att = ET.SubElement(grid, "Attribute", Name=name, Center="Node",
                            AttributeType=_ATTRIBUTE_TYPE.get(stride, "Matrix"))
        _data_item(att, fname, ds.name, ds)
    return grid


class XdmfIndex:
    """The XDMF index of one output series, rewritten atomically after every output.

    Each output file is opened once, when it is added; the index lists only the files
    added to it, so files of another run in the same folder never enter it.
    """

    def __init__(self, directory, prefix):
        self.directory, self.prefix = os.fspath(directory), prefix
        self.path = os.path.join(self.directory, f"{prefix}.xdmf")
        self._steps = {}

    def add(self, path):
        """Index one output file (replacing an earlier entry of the same step)."""
        fname = os.path.basename(path)  # the xdmf lives in the same folder: relative paths
        with _open(path) as f:
            sd = f["solver_data"].attrs
            step = ET.Element("Grid", Name=f"step_{int(sd['step'])}", GridType="Collection",
                              CollectionType="Spatial")
            ET.SubElement(step, "Time", Value=repr(float(sd["t"])))
            for g in f["arrays"].values():
                _array_grid(step, fname, g)
            self._steps[int(sd["step"])] = step

    def write(self):
        """(Re)write the index file atomically; returns its path."""
        root = ET.Element("Xdmf", Version="3.0")
        series = ET.SubElement(ET.SubElement(root, "Domain"), "Grid", Name=self.prefix,
                               GridType="Collection", CollectionType="Temporal")
        for step in sorted(self._steps):
            series.append(self._steps[step])
        ET.indent(root)
        _write_text(self.path, '<?xml version="1.0" ?>\n' + ET.tostring(root, encoding="unicode") + "\n")
        return self.path


def write_xdmf(directory, prefix=None, max_step=None):
    """(Re)write ``<directory>/<prefix>.xdmf`` indexing the series' files; returns its path."""
    files = output_files(directory, prefix)
    if prefix is None:
        prefixes = {_SERIES.match(os.path.basename(p))["prefix"] for p in files}
        if len(prefixes) != 1:
            raise ValueError(f"{directory}: cannot tell which output series to index "
                             f"(prefixes found: {sorted(prefixes) or 'none'}); pass prefix=")
        prefix = prefixes.pop()
    index = XdmfIndex(directory, prefix)
    for path in files:
        if max_step is None or step_of(path) <= max_step:
            index.add(path)
    return index.write()


def step_of(path):
    """The step number in an output file's name ``<prefix>_<step>.h5``."""
    return int(_SERIES.match(os.path.basename(path))["step"])


# ------------------------------------------------------------------ folders
_TMP = re.compile(r"^.+\.tmp-(?P<pid>\d+)$")
RUN_FILES = ("info.json", "results.json", "history.json", "diagnostics.json")


def _pid_alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True
    return True


def remove_stray_temporaries(directory):
    """Remove ``*.tmp-<pid>`` files left by writers that are no longer running."""
    removed = []
    for fname in sorted(os.listdir(directory)):
        m = _TMP.match(fname)
        if m and int(m["pid"]) != os.getpid() and not _pid_alive(int(m["pid"])):
            with contextlib.suppress(FileNotFoundError):
                os.remove(os.path.join(directory, fname))
                removed.append(fname)
    return removed


def run_files(directory):
    """Files of a sphgen run in a folder: output series, last-good states, XDMF, run JSON."""
    if not os.path.isdir(directory):
        return []
    out = []
    for fname in sorted(os.listdir(directory)):
        if (_SERIES.match(fname) or fname.endswith("_last_good.h5") or fname.endswith(".xdmf")
                or fname in RUN_FILES):
            out.append(fname)
    return out


def verify_xdmf(path):
    """Open every dataset an XDMF index names, as a reader would; returns (steps, datasets).

    Raises ValueError naming the first entry that does not resolve or has the wrong shape.
    """
    directory = os.path.dirname(os.path.abspath(path))
    root = ET.parse(path).getroot()
    steps = root.findall("./Domain/Grid/Grid")
    n = 0
    for item in root.iter("DataItem"):
        if item.get("Format") != "HDF":
            continue
        fname, dsname = item.text.strip().split(":", 1)
        want = tuple(int(d) for d in item.get("Dimensions").split())
        with h5py.File(os.path.join(directory, fname), "r") as f:
            if dsname not in f:
                raise ValueError(f"{path}: {fname} has no dataset {dsname}")
            if f[dsname].shape != want:
                raise ValueError(f"{path}: {fname}:{dsname} has shape {f[dsname].shape}, index says {want}")
            f[dsname][()]
        n += 1
    return len(steps), n
