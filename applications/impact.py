"""High-velocity impact: an aluminium cylinder through a thin plate (Adepu & Ramachandran 2021,
section 4.7; the case of Zhang, Hu & Adams 2017 and Howell & Ball 2002).

A projectile of diameter 10 mm moving down at V0 = 3100 m/s strikes a target 50 mm wide
and 2 mm thick (plane strain).  Aluminium: rho0 = 2785 kg/m^3, c0 = 5328 m/s,
G = 27.6 GPa, elastic-perfectly plastic with Y0 = 0.3 GPa (the paper's kPa values),
Monaghan alpha = 1, h = dx (paper: dx = 0.5 mm), SPST with Ma = V0/c0 (``--mach``
overrides), one array for both bodies (they meet through the ordinary pair forces), end
time 8 us (``--tf``; the paper gives none).  E and the Poisson ratio follow from
K = rho0 c0^2 and G.

``results.json``: the hole width, the gap along x, at the end, between the innermost
target particles left and right of the axis among those still within three thicknesses
of the target (debris carried with the projectile excluded), centre to centre (``hole_width_in_plane``: only particles within the target's own
thickness, which leaves out the bent petals); beside the paper's 19.6 mm (its GTVF:
19.8 mm; Howell & Ball: 19.2 mm).  The paper does not say where it measures.  Plot: impact.png.
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import disk, rectangle
from sphgen.particles import ParticleArray
from sphgen.tools.plots import particle_panels

from ..schemes.ctvf import CTVFSolidScheme
from ..schemes.gtvf import GTVFSolidScheme

RHO0, C0, G, Y0, V0 = 2785.0, 5328.0, 2.76e10, 3.0e8, 3100.0
R_PROJECTILE, WIDTH, THICKNESS = 0.005, 0.05, 0.002
HOLE_PAPER = 0.0196
HOLE_REFERENCES = {"paper (CTVF)": 0.0196, "paper (GTVF)": 0.0198, "Howell & Ball (2002)": 0.0192}


def young_and_poisson(rho0=RHO0, c0=C0, G=G):
    """(E, nu) from the bulk modulus K = rho0 c0^2 and the shear modulus G."""
    K = rho0 * c0 * c0
    return 9.0 * K * G / (3.0 * K + G), (3.0 * K - 2.0 * G) / (2.0 * (3.0 * K + G))


def hole_width(x, y, target, thickness=THICKNESS, band=3.0):
    """Gap along x between the innermost target particles either side of x = 0 among those
    with y above -band*thickness (the target's top face at y = 0)."""
    keep = target & (y > -band * thickness)
    left, right = x[keep & (x < 0)], x[keep & (x > 0)]
    if left.size == 0 or right.size == 0:
        return float("nan")
    return float(right.min() - left.max())


class Impact(Application):
    """Aluminium cylinder through a plate at 3100 m/s, elastic-perfectly plastic."""

    tf = 8e-6
    pfreq = 200
    dim = 2

    def add_user_options(self, group):
        group.add_argument("--dx", type=float, default=0.0005, help="spacing (paper: 0.5 mm)")
        group.add_argument("--scheme", choices=("ctvf", "gtvf"), default="ctvf")
        group.add_argument("--shifting", default=None, help="spst (ctvf default) or gtvf (gtvf default)")
        group.add_argument("--mach", type=float, default=None, help="SPST Mach number (default V0/c0)")
        group.add_argument("--literal-plasticity", action="store_true",
                           help="beta = min(Y0^2/(3 J2), 1) as printed (default: its square root)")

    def consume_user_options(self, o):
        if not (math.isfinite(o.dx) and 0 < o.dx <= 0.001):
            raise InputError(f"--dx must be in (0, 1 mm], got {o.dx}")
        self.E, self.poisson = young_and_poisson()
        self.shifting = o.shifting or ("spst" if o.scheme == "ctvf" else "gtvf")

    def create_particles(self):
        dx = self.options.dx
        xt, yt = rectangle(-0.5 * WIDTH, 0.5 * WIDTH, -THICKNESS, 0.0, dx)
        xp, yp = disk(0.0, R_PROJECTILE + dx, R_PROJECTILE, dx)
        x, y = np.concatenate([xt, xp]), np.concatenate([yt, yp])
        n = x.size
        v = np.concatenate([np.zeros(xt.size), np.full(xp.size, -V0)])
        pa = ParticleArray("solid", x=x, y=y, v=v, rho=np.full(n, RHO0), m=np.full(n, RHO0 * dx * dx),
                           h=np.full(n, dx))
        self.target_gids = np.arange(xt.size)
        return [pa]

    def create_scheme(self):
        o = self.options
        common = dict(h=o.dx, dx=o.dx, umax=V0, shifting=self.shifting, alpha=1.0, yield_stress=Y0)
        if o.scheme == "gtvf":
            return GTVFSolidScheme(["solid"], 2, RHO0, self.E, self.poisson, **common)
        return CTVFSolidScheme(["solid"], 2, RHO0, self.E, self.poisson, mach=o.mach, **common)

    def history_meta(self):
        return {"dx": self.options.dx, "scheme": self.options.scheme, "shifting": self.shifting,
                "n_target": int(self.target_gids.size)}

    def post_process(self, outdir):
        if self.scene is not None:
            pa = self.scene.by_name["solid"]
            x, y, p, gid = pa.x, pa.y, pa.p, pa.gid
            t = self.solver.t
        else:
            d = io.load(io.output_files(outdir, self.name)[-1])
            pa = d["arrays"]["solid"]
            x, y, p, gid, t = pa.x, pa.y, pa.p, pa.gid, d["solver_data"]["t"]
        target = gid < self.target_gids.size
        width = hole_width(x, y, target)
        results = {"t": float(t), "dx": self.options.dx, "scheme": self.options.scheme,
                   "shifting": self.shifting, "hole_width": width, "hole_paper": HOLE_PAPER,
                   "hole_error": width / HOLE_PAPER - 1.0, "references": HOLE_REFERENCES,
                   "hole_width_in_plane": hole_width(x, y, target, band=1.0),
                   "finite": bool(np.all(np.isfinite(x)) and np.all(np.isfinite(p)))}
        io.write_json(os.path.join(outdir, "results.json"), results)
        particle_panels(os.path.join(outdir, "impact.png"),
                        [(f"{self.options.scheme.upper()} + {self.shifting.upper()}, t = {t * 1e6:.3g} us, "
                          f"hole {width * 1e3:.3g} mm", x, y, p)], size=(8.0, 6.0), marker=1)
        print(f"impact: t={t:.3g}  hole width {width * 1e3:.4g} mm (paper 19.6 mm, Howell & Ball 19.2 mm)\n"
              f"results: {os.path.join(outdir, 'results.json')}")
        return results
