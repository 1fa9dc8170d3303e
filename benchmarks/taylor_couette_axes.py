#!/usr/bin/env python
"""The Taylor-Couette profile error at every output of a finished run, on four half-axes.

Kincl et al. (2023), sec. 4.3: the issue's measure is the mean of |v_theta - eq. 28| / (omega
R2) along y = 0 at one instant.  The steady flow is axisymmetric, so the same measure on the
+x, +y, -x and -y half-axes, at every output from ``--from`` on, shows how much one sample
says (docs/shtc.md, "The paper's Re = 20 at one instant is noise-limited"); the last line is
the error of the profile averaged over all those samples.

    python benchmarks/taylor_couette_axes.py RUN_FOLDER [--from 3.5]
"""
import argparse

import numpy as np

import sphgen.applications.taylor_couette as tc
from sphgen import io
from sphgen.kernels import get_kernel
from sphgen.tools.probes import line_probe

HALF_AXES = {"+x": 0.0, "+y": 0.5 * np.pi, "-x": np.pi, "-y": 1.5 * np.pi}


def tangential_profiles(arrays, kernel):
    """{half-axis: v_theta at tc.PROBE_POINTS radii from R1 to R2} of one output."""
    x, y, h, m, rho, u, v = tc.TaylorCouette._stack(arrays, "u", "v")
    out = {}
    for name, ang in HALF_AXES.items():
        c, s = np.cos(ang), np.sin(ang)
        _, vals = line_probe((tc.R1 * c, tc.R1 * s), (tc.R2 * c, tc.R2 * s), tc.PROBE_POINTS,
                             x, y, h, m, rho, np.stack([u, v], 1), kernel)
        out[name] = -s * vals[:, 0] + c * vals[:, 1]
    return out


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("run")
    p.add_argument("--from", dest="t0", type=float, default=3.5, help="first output time (default %(default)s)")
    o = p.parse_args(argv)
    kernel = get_kernel("wendland", 2)
    r = np.linspace(tc.R1, tc.R2, tc.PROBE_POINTS)
    exact = tc.exact_tangential_velocity(r)
    error = lambda vt: float(np.mean(np.abs(vt - exact)) / (tc.OMEGA * tc.R2))  # noqa: E731
    total, n = np.zeros_like(r), 0
    print("t        " + "  ".join(f"{k:>6s}" for k in HALF_AXES))
    for fn in io.output_files(o.run, "taylor_couette"):
        d = io.load(fn)
        t = d["solver_data"]["t"]
        if t < o.t0:
            continue
        prof = tangential_profiles(d["arrays"], kernel)
        print(f"{t:<8.3f} " + "  ".join(f"{100 * error(vt):5.2f}%" for vt in prof.values()))
        for vt in prof.values():
            total += vt
            n += 1
    if n:
        print(f"profile averaged over {n} samples: {100 * error(total / n):.2f}%")


if __name__ == "__main__":
    main()
