"""ParticleArray: numpy-backed particle properties (scalars, vectors, tensors by stride).

A property is *declared* with a stride and a default; it is *allocated* (given memory)
only when it holds user data or when the scene's plan says an equation, integrator
stage, output or diagnostic touches it.  Tensors are flat with stride 9 (3x3,
row-major) even in 2D; vectors have stride 3.  Constants are small arrays that do not
scale with the number of particles (``d_<const>[0]`` in equations).
"""
import difflib

import numpy as np

from .errors import SphgenError


class PropertyError(SphgenError, ValueError):
    """A property is missing, misspelled, or has the wrong shape."""


class Property:
    """Metadata of one per-particle property."""

    __slots__ = ("name", "stride", "dtype", "default", "explicit_default")

    def __init__(self, name, stride=1, dtype="double", default=None):
        if stride not in (1, 2, 3, 4, 6, 9) and not (isinstance(stride, int) and stride > 0):
            raise PropertyError(f"property '{name}': stride must be a positive int, got {stride!r}")
        if dtype not in ("double", "int"):
            raise PropertyError(f"property '{name}': dtype must be 'double' or 'int', got {dtype!r}")
        self.explicit_default = default is not None
        self.name, self.stride, self.dtype = name, int(stride), dtype
        self.default = 0.0 if default is None else default

    @property
    def np_dtype(self):
        return np.float64 if self.dtype == "double" else np.int32


class ParticleArray:
    """A named set of particles; ``pa.x`` is the numpy array of property ``x``."""

    POSITION = ("x", "y", "z")

    def __init__(self, name, n=None, constants=None, **props):
        if not name.isidentifier():
            raise PropertyError(f"array name {name!r} must be a Python identifier")
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "props", {})
        object.__setattr__(self, "data", {})
        object.__setattr__(self, "constants", {})
        lengths = {k: np.asarray(v).size for k, v in props.items()}
        if n is None:
            n = max(lengths.values()) if lengths else 0
        object.__setattr__(self, "n", int(n))
        for p in ("x", "y", "z", "u", "v", "w", "m", "h", "rho"):
            self.add_property(p)
        self.add_property("gid", dtype="int")
        for k, v in props.items():
            if k not in self.props:
                self.add_property(k)
            self.set(k, v)
        if "gid" not in self.data:
            # a persistent id: sorting moves particles in memory, gid follows them
            self.set("gid", np.arange(self.n))
        for k, v in (constants or {}).items():
            self.add_constant(k, v)

    # ---------------------------------------------------------------- declaring
    def add_property(self, name, stride=1, dtype="double", default=None, data=None):
        """Declare a property; memory is given only with ``data`` or by the plan.

        A property that is read but neither set nor computed is an error unless it
        was declared with an explicit ``default``.
        """
        if not name.isidentifier():
            raise PropertyError(f"array '{self.name}': property name {name!r} is not an identifier")
        old = self.props.get(name)
        if old is not None and (old.stride != stride or old.dtype != dtype):
            if name in self.data:
                raise PropertyError(
                    f"array '{self.name}': property '{name}' already exists with stride "
                    f"{old.stride} ({old.dtype}); asked for stride {stride} ({dtype})")
        self.props[name] = Property(name, stride, dtype, default)
        if data is not None:
            self.set(name, data)
        return self

    def add_constant(self, name, value):
        """A constant: a small array that does not scale with the particle count."""
        arr = np.atleast_1d(np.asarray(value, dtype=np.float64)).copy()
        if not np.all(np.isfinite(arr)):
            raise PropertyError(f"array '{self.name}': constant '{name}' is not finite: {value!r}")
        self.constants[name] = arr
        return self

    # ---------------------------------------------------------------- memory
    def allocate(self, name):
        """Give memory to a declared property (filled with its default)."""
        if name in self.data:
            return self.data[name]
        if name not in self.props:
            raise PropertyError(self.missing_message(name))
        p = self.props[name]
        arr = np.full(self.n * p.stride, p.default, dtype=p.np_dtype)
        self.data[name] = arr
        return arr

    def release(self, name):
        """Drop the memory of a property nobody touches (it stays declared)."""
        self.data.pop(name, None)

    def set(self, name, value):
        p = self.props.get(name)
        if p is None:
            raise PropertyError(self.missing_message(name))
        arr = np.asarray(value, dtype=p.np_dtype)
        if arr.ndim == 0:
            arr = np.full(self.n * p.stride, arr, dtype=p.np_dtype)
        arr = np.ascontiguousarray(arr).reshape(-1)
        if arr.size != self.n * p.stride:
            raise PropertyError(
                f"array '{self.name}': property '{name}' has stride {p.stride} so it needs "
                f"{self.n}x{p.stride} = {self.n * p.stride} values; got {arr.size}")
        if p.dtype == "double" and not np.all(np.isfinite(arr)):
            bad = int(np.flatnonzero(~np.isfinite(arr))[0]) // p.stride
            raise PropertyError(f"array '{self.name}': property '{name}' is not finite at particle {bad}")
        self.data[name] = arr.copy()

    def get(self, name):
        if name in self.data:
            return self.data[name]
        if name in self.constants:
            return self.constants[name]
        if name in self.props:
            raise PropertyError(f"array '{self.name}': property '{name}' is declared but not "
                                "allocated (no equation, stage or output of this scene uses it)")
        raise PropertyError(self.missing_message(name))

    def has(self, name):
        return name in self.props or name in self.constants

    def missing_message(self, name):
        """'array X has no property Y; did you mean Z? (known: ...)'."""
        known = sorted(set(self.props) | set(self.constants))
        close = difflib.get_close_matches(name, known, n=1)
        hint = f"; did you mean '{close[0]}'?" if close else ""
        return f"array '{self.name}' has no property '{name}'{hint} (known: {', '.join(known)})"

    def permute(self, perm):
        """Reorder the particles in place (spatial sorting); pointers stay valid."""
        perm = np.asarray(perm)
        for name, arr in self.data.items():
            s = self.props[name].stride
            if s == 1:
                arr[:] = arr[perm]
            else:
                arr.reshape(self.n, s)[:] = arr.reshape(self.n, s)[perm]

    def __getattr__(self, name):
        try:
            return self.get(name)
        except PropertyError as e:
            raise AttributeError(str(e)) from None

    def __setattr__(self, name, value):
        if name in self.props or name in self.data:
            if name in self.data and np.shape(value) == self.data[name].shape:
                self.data[name][:] = value
            else:
                self.set(name, value)
        elif name in self.constants:
            self.constants[name][:] = value
        else:
            object.__setattr__(self, name, value)

    def __repr__(self):
        return f"ParticleArray({self.name!r}, n={self.n}, allocated={sorted(self.data)})"

    def state(self):
        """All allocated data and constants (for output and restart)."""
        return {"properties": dict(self.data), "constants": dict(self.constants),
                "strides": {k: self.props[k].stride for k in self.data}}
