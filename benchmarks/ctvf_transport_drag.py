#!/usr/bin/env python
"""The symmetric A term's zeroth-order drag in a finished Taylor-Green run (docs/ctvf.md).

Eq. 27's A term in the symmetric form equals a divergence plus 2 u_a (delta_a . S_a),
S_a = sum_b V_b grad_a W_ab (Adepu & Ramachandran 2021, eq. 27; docs/ctvf.md, "The late
drift at Re 1000").  From the last particle file of each run folder (periodic unit box,
quintic spline, delta_a = dt/2 auhat_a as in eq. 55) this prints the rms of S and delta,
the mean of delta . S and the decay rate of |u| that the error term gives,
-2 sum_a (delta_a . S_a) |u_a|^2 / sum_a |u_a|^2, next to the viscous 8 pi^2 / Re.

    python benchmarks/ctvf_transport_drag.py RUN_FOLDER [RUN_FOLDER ...]
"""
import glob
import json
import os
import sys

import h5py
import numpy as np

from sphgen.kernels import QuinticSpline


def kernel_sums(x, y, h, vol, chunk=512):
    """S_a = sum_b V_b grad_a W_ab in the periodic unit box (quintic spline), in row chunks."""
    fac = QuinticSpline(2).fac
    sx, sy = np.zeros_like(x), np.zeros_like(y)
    for i in range(0, x.size, chunk):
        dx = x[i:i + chunk, None] - x[None, :]
        dy = y[i:i + chunk, None] - y[None, :]
        dx -= np.round(dx)
        dy -= np.round(dy)
        r = np.hypot(dx, dy)
        q = r / h
        a, b, c = (np.clip(s - q, 0.0, None) for s in (3.0, 2.0, 1.0))
        dwdr = -5.0 * fac / h ** 3 * (a ** 4 - 6.0 * b ** 4 + 15.0 * c ** 4)
        f = np.divide(dwdr, r, out=np.zeros_like(r), where=r > 0) * vol[None, :]
        sx[i:i + chunk] = (f * dx).sum(axis=1)
        sy[i:i + chunk] = (f * dy).sum(axis=1)
    return sx, sy


def drag(folder):
    last = sorted(glob.glob(os.path.join(folder, "taylor_green_*.h5")))[-1]
    with open(os.path.join(folder, "info.json")) as f:
        dt = json.load(f)["dt"]
    with open(os.path.join(folder, "results.json")) as f:
        re = json.load(f)["re"]
    with h5py.File(last) as h5:
        p = {n: np.asarray(h5[f"arrays/fluid/properties/{n}"])
             for n in ("x", "y", "u", "v", "m", "rho", "h", "auhat", "avhat")}
    sx, sy = kernel_sums(p["x"], p["y"], p["h"][0], p["m"] / p["rho"])
    ddx, ddy = 0.5 * dt * p["auhat"], 0.5 * dt * p["avhat"]
    e = ddx * sx + ddy * sy
    u2 = p["u"] ** 2 + p["v"] ** 2
    return {"S_rms": float(np.sqrt(np.mean(sx ** 2 + sy ** 2))),
            "delta_rms": float(np.sqrt(np.mean(ddx ** 2 + ddy ** 2))),
            "delta_dot_S": float(e.mean()), "drag_rate": float(-2.0 * np.sum(e * u2) / np.sum(u2)),
            "viscous_rate": 8.0 * np.pi ** 2 / re, "file": os.path.basename(last)}


def main(argv=None):
    for folder in (sys.argv[1:] if argv is None else argv):
        d = drag(folder)
        print(f"{folder}: |S| rms {d['S_rms']:.3f}, |delta| rms {d['delta_rms']:.2e}, <delta.S> "
              f"{d['delta_dot_S']:+.2e}, decay rate of |u| from the error term {d['drag_rate']:.4f} "
              f"(viscous {d['viscous_rate']:.4f}) [{d['file']}]")


if __name__ == "__main__":
    main()
