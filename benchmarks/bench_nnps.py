"""Neighbour search alone: time per update (binning + CSR lists) and pairs per second.

Taylor-Green's particle set (a jittered square lattice in the periodic unit box, h = dx,
quintic support 3h), serial and with 2 threads, each in its own process (OMP_NUM_THREADS).
Medians of --repeat processes, each timing --updates updates after one warm-up.

    python benchmarks/bench_nnps.py [--nx 100] [--repeat 5] [--updates 50]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import time

import numpy as np


def one(nx, updates):
    """Time ``updates`` updates in this process; returns a dict of seconds per update."""
    from sphgen.nnps import Domain, NeighbourSearch
    from sphgen.particles import ParticleArray
    dx = 1.0 / nx
    g = (np.arange(nx) + 0.5) * dx
    x, y = (a.ravel() for a in np.meshgrid(g, g, indexing="ij"))
    rng = np.random.default_rng(1)
    x = x + 0.1 * dx * rng.standard_normal(x.size)
    y = y + 0.1 * dx * rng.standard_normal(y.size)
    pa = ParticleArray("fluid", x=x, y=y, h=np.full(x.size, dx))
    nps = NeighbourSearch([pa], 2, 3.0, Domain(0, 1, 0, 1, periodic_in_x=True,
                                                  periodic_in_y=True))
    nps.update()
    off, _ = nps.neighbours("fluid", "fluid")
    pairs = int(off[-1])
    t_bin = t_csr = 0.0
    for _ in range(updates):
        t0 = time.perf_counter()
        nps.update()
        t1 = time.perf_counter()
        nps.neighbours("fluid", "fluid")
        t2 = time.perf_counter()
        t_bin += t1 - t0
        t_csr += t2 - t1
    return {"bin": t_bin / updates, "csr": t_csr / updates, "pairs": pairs, "n": x.size}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--nx", type=int, default=100)
    ap.add_argument("--repeat", type=int, default=5)
    ap.add_argument("--updates", type=int, default=50)
    ap.add_argument("--one", action="store_true", help=argparse.SUPPRESS)
    a = ap.parse_args()
    if a.one:
        print(json.dumps(one(a.nx, a.updates)))
        return
    res = {}
    for threads in (1, 2):
        env = dict(os.environ, OMP_NUM_THREADS=str(threads))
        runs = []
        for _ in range(a.repeat):
            out = subprocess.run([sys.executable, __file__, "--one", "--nx", str(a.nx),
                                  "--updates", str(a.updates)], env=env, check=True,
                                 capture_output=True, text=True).stdout
            runs.append(json.loads(out))
        res[threads] = {k: statistics.median(r[k] for r in runs) for k in ("bin", "csr")}
        res[threads].update(pairs=runs[0]["pairs"], n=runs[0]["n"])
    for threads, r in res.items():
        tot = r["bin"] + r["csr"]
        print(f"{threads} thread(s): bin {1e3 * r['bin']:.3f} ms, lists {1e3 * r['csr']:.3f} ms, "
              f"{r['pairs'] / tot / 1e6:.1f} M pairs/s ({r['n']} particles, {r['pairs']} pairs)")
    s = {k: res[1][k] / res[2][k] for k in ("bin", "csr")}
    print(f"speed-up 1 -> 2 threads: bin {s['bin']:.2f}x, lists {s['csr']:.2f}x")


if __name__ == "__main__":
    main()
