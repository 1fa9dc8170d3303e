"""Conserved-quantity diagnostics: reductions over particle arrays, one row per sample.

Each diagnostic is a function ``f(arrays, dim) -> [values]`` with its column names in
:data:`DIAGNOSTICS`.  They are numpy reductions (compiled, vectorised, single-threaded):
sampled every few steps they cost far less than a step.  A scheme adds its own energy
terms through ``Scheme.energies(arrays)`` (e.g. the Tait internal energy, gravity's
potential); an application lists what it wants in ``Application.diagnostics`` and the
rows go to ``diagnostics.json``, which continues across restarts like ``history.json``.
"""
import numpy as np

_VEL = ("u", "v", "w")
_POS = ("x", "y", "z")


def _moving(arrays):
    """Arrays that carry velocities (walls without velocity arrays are skipped)."""
    return [pa for pa in arrays if "u" in pa.data and pa.n]


def mass(arrays, dim):
    """Total mass sum m over all arrays."""
    return [float(sum(np.sum(pa.m) for pa in arrays if pa.n))]


def kinetic_energy(arrays, dim):
    """sum m |u|^2 / 2 over arrays with velocities."""
    return [float(sum(0.5 * np.sum(pa.m * sum(pa.data[c] ** 2 for c in _VEL[:dim])) for pa in _moving(arrays)))]


def linear_momentum(arrays, dim):
    """sum m u, one column per dimension."""
    return [float(sum(np.sum(pa.m * pa.data[c]) for pa in _moving(arrays))) for c in _VEL[:dim]]


def angular_momentum(arrays, dim):
    """sum m x cross u about the origin: the z component in 2D, all three in 3D."""
    def cross(pa, i, j):
        return np.sum(pa.m * (pa.data[_POS[i]] * pa.data[_VEL[j]] - pa.data[_POS[j]] * pa.data[_VEL[i]]))
    comps = [(0, 1)] if dim == 2 else [(1, 2), (2, 0), (0, 1)]
    return [float(sum(cross(pa, i, j) for pa in _moving(arrays))) for i, j in comps]


def density_range(arrays, dim):
    """Smallest and largest density over arrays that have one."""
    rho = [pa.rho for pa in arrays if "rho" in pa.data and pa.n]
    return [float(min(r.min() for r in rho)), float(max(r.max() for r in rho))] if rho else [0.0, 0.0]


def pressure_range(arrays, dim):
    """Smallest and largest pressure over arrays that have one."""
    p = [pa.p for pa in arrays if "p" in pa.data and pa.n]
    return [float(min(a.min() for a in p)), float(max(a.max() for a in p))] if p else [0.0, 0.0]


def _range(prop):
    def smallest_and_largest(arrays, dim):
        vals = [pa.data[prop] for pa in arrays if prop in pa.data and pa.n]
        return [float(min(a.min() for a in vals)), float(max(a.max() for a in vals))] if vals else [0.0, 0.0]
    smallest_and_largest.__doc__ = f"Smallest and largest {prop} over arrays that have one."
    return smallest_and_largest


DIAGNOSTICS = {
    "mass": (mass, lambda dim: ["mass"]),
    "kinetic_energy": (kinetic_energy, lambda dim: ["kinetic_energy"]),
    "linear_momentum": (linear_momentum, lambda dim: [f"momentum_{c}" for c in "xyz"[:dim]]),
    "angular_momentum": (angular_momentum,
                         lambda dim: ["angular_momentum_z"] if dim == 2 else
                         [f"angular_momentum_{c}" for c in "xyz"]),
    "density_range": (density_range, lambda dim: ["rho_min", "rho_max"]),
    "pressure_range": (pressure_range, lambda dim: ["p_min", "p_max"]),
    # Total Lagrangian solids: volume ratio J (must stay > 0) and temperature
    "J_range": (_range("J"), lambda dim: ["J_min", "J_max"]),
    "theta_range": (_range("theta"), lambda dim: ["theta_min", "theta_max"]),
}


class Diagnostics:
    """The rows of the requested diagnostics (first column t), plus the scheme's energies."""

    def __init__(self, names, dim, scheme=None):
        unknown = [n for n in names if n not in DIAGNOSTICS and n != "energies"]
        if unknown:
            raise ValueError(f"unknown diagnostic '{unknown[0]}'; known: {', '.join(DIAGNOSTICS)}, energies")
        self.names, self.dim, self.scheme = list(names), dim, scheme
        self.rows = []

    def columns(self, arrays):
        cols = ["t"]
        for n in self.names:
            cols += sorted(self.scheme.energies(arrays)) if n == "energies" else DIAGNOSTICS[n][1](self.dim)
        return cols

    def sample(self, t, arrays):
        row = [t]
        for n in self.names:
            if n == "energies":
                e = self.scheme.energies(arrays)
                row += [e[k] for k in sorted(e)]
            else:
                row += DIAGNOSTICS[n][0](arrays, self.dim)
        self.rows.append(row)
        return row
