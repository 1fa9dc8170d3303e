"""Shared fixtures: small jittered particle clouds, compiled-vs-Python runners, and the texts
of the figures a test draws."""
import os

import numpy as np
import pytest

from sphgen.nnps import Domain
from sphgen.particles import ParticleArray


def lattice_cloud(name="fluid", nx=12, dim=2, jitter=0.2, seed=0, L=1.0, **extra):
    """A jittered lattice in [0, L]^dim with h = dx, unit density and random velocities."""
    dx = L / nx
    axes = [np.arange(nx) * dx + dx / 2] * dim
    grid = np.meshgrid(*axes, indexing="ij")
    rng = np.random.default_rng(seed)
    pos = [g.ravel() + jitter * dx * rng.uniform(-1, 1, g.size) for g in grid]
    n = pos[0].size
    props = dict(zip("xyz", pos))
    for k, u in zip(range(dim), "uvw"):
        props[u] = rng.uniform(-1, 1, n)
    props.update(m=np.full(n, dx ** dim), h=np.full(n, dx), rho=1.0 + 0.05 * rng.uniform(-1, 1, n))
    props.update(extra)
    return ParticleArray(name, **props)


def periodic_box(dim, L=1.0):
    kw = {}
    for ax in "xyz"[:dim]:
        kw.update({f"{ax}min": 0.0, f"{ax}max": L, f"periodic_in_{ax}": True})
    return Domain(**kw)


def assert_close(a, b, rtol=1e-12, what=""):
    scale = max(np.abs(b).max(), 1e-300)
    err = np.abs(a - b).max() / scale
    assert err <= rtol, f"{what}: relative difference {err:.3e} > {rtol:.1e}"


@pytest.fixture
def tmp_cache(tmp_path, monkeypatch):
    """An empty compile cache for this test only."""
    d = tmp_path / "cache"
    monkeypatch.setenv("SPHGEN_CACHE", str(d))
    return d


def march(integ, dt, steps, t=0.0):
    """The integrator's start-up evaluations, then ``steps`` steps of ``dt`` from ``t``; the end time."""
    integ.initial_accelerations(t, dt)
    for _ in range(steps):
        integ.one_timestep(t, dt)
        t += dt
    return t


@pytest.fixture
def figure_texts(monkeypatch):
    """{file name: every text (titles, legend entries, labels) of each matplotlib figure saved
    during the test, joined by " | "}."""
    from matplotlib.figure import Figure
    from matplotlib.text import Text
    saved, savefig = {}, Figure.savefig

    def record(fig, fname, *args, **kwargs):
        saved[os.path.basename(os.fspath(fname))] = " | ".join(t.get_text() for t in fig.findobj(Text)
                                                               if t.get_text())
        return savefig(fig, fname, *args, **kwargs)

    monkeypatch.setattr(Figure, "savefig", record)
    return saved
