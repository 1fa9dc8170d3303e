"""Plane Couette flow between SHTC-SPH dummy walls: the slip of the walls of Kincl, Peshkov,
Pavelka & Klika (2023), section 4.4 (a lid of immobile particles whose velocity enters only L).

Fluid in (0, W) x (0, 1), periodic in x, on the cavity's isometric ``filling_lattice`` (a
square lattice shows an odd-even pattern of the row velocities of +-0.06 U at dr = 1/20);
below y = 0 and above y = 1 ceil(2h/dr) = 3 square-lattice layers of dummy particles that carry their own state; the top
ones are immobile and carry u = U (ramped linearly over 0.4 as the cavity's lid).  The steady
profile is u = U y; ``results.json``: the least-squares line through the row-mean u of the
rows more than 2h from both walls, its slip at the fixed wall (u_fit(0)/U) and at the lid
(1 - u_fit(1)/U), the slip lengths (slip / slope), and the largest deviation of the row means
from U y.  The steady profile does not depend on nu, so nu = 1 (--nu) reaches it by t = 1.
"""
import os

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.geometry import layers_for_support
from sphgen.nnps import Domain
from sphgen.particles import ParticleArray

from ..schemes.shtc import SHTCScheme, viscosity_factor
from .shtc_cavity import C0, CS, HDR, RHO0, ULID, add_wall_velocity_option, filling_lattice, lid_motion
from .shtc_shear_wave import fluid_relaxation_time

WIDTH = 0.5


def row_means(y, u, nrows):
    """(mean y, mean u) in ``nrows`` equal bins of (0, 1) (one lattice row each)."""
    k = np.clip((y * nrows).astype(int), 0, nrows - 1)
    count = np.bincount(k, minlength=nrows)
    return np.bincount(k, weights=y, minlength=nrows) / count, np.bincount(k, weights=u, minlength=nrows) / count


class SHTCCouette(Application):
    """Plane Couette flow, SHTC-SPH fluid between a lid and a fixed dummy wall: the wall slip."""

    tf = 1.0
    pfreq = 100000
    dim = 2

    def add_user_options(self, group):
        group.add_argument("--ny", type=int, default=40, help="particles across: dr = 1/ny (default %(default)s)")
        group.add_argument("--nu", type=float, default=1.0, help="kinematic viscosity (default %(default)s)")
        add_wall_velocity_option(group, default="prescribed")   # the walls of [P] unless told
        group.add_argument("--cs", type=float, default=CS, help="shear sound speed (default %(default)s, the cavity's)")

    def consume_user_options(self, o):
        if o.ny < 8:
            raise InputError(f"--ny must be at least 8, got {o.ny}")
        self.dr = 1.0 / o.ny
        self.tau = fluid_relaxation_time(o)

    def create_particles(self):
        dr = self.dr
        nl = layers_for_support(2.0, HDR)
        xs = (np.arange(int(round(WIDTH / dr))) + 0.5) * dr
        yb = -(np.arange(nl) + 0.5) * dr
        xf, yf = filling_lattice(dr, width=WIDTH)

        def array(name, ys, x=None):
            if x is None:
                x, ys = (c.ravel() for c in np.meshgrid(xs, ys))
            x, y = x, ys
            n = x.size
            return ParticleArray(name, x=x, y=y, u=np.zeros(n), v=np.zeros(n), m=np.full(n, RHO0 * dr * dr),
                                 h=np.full(n, HDR * dr), rho=np.full(n, RHO0))
        return [array("fluid", yf, xf), array("wall", yb), array("lid", 1.0 - yb)]

    def create_domain(self):
        return Domain(0.0, WIDTH, -1.0, 2.0, periodic_in_x=True)

    def create_scheme(self):
        return SHTCScheme(["fluid"], 2, rho0=RHO0, c0=C0, cs=self.options.cs, h=HDR * self.dr, dr=self.dr,
                          tau=self.tau, model="dprz", cp=0.0, walls=["wall", "lid"], moving_walls=["lid"],
                          motions={"lid": lid_motion()},
                          wall_velocity=self.options.wall_velocity)

    def post_process(self, outdir):
        """results.json: slip at both walls from the interior line."""
        f = self.scene.by_name["fluid"]
        y, u = row_means(f.y, f.u, int(round(1.0 / (0.75 ** 0.25 * self.dr))))
        inner = (y > 2 * HDR * self.dr) & (y < 1 - 2 * HDR * self.dr)
        slope, u0 = np.polyfit(y[inner], u[inner], 1)
        slip_wall, slip_lid = u0 / ULID, 1.0 - (u0 + slope) / ULID
        results = {"t": float(self.solver.t), "ny": self.options.ny, "dr": self.dr,
                   "dt_over_tau": self.solver.dt / self.tau,
                   "viscosity_factor": viscosity_factor(self.solver.dt / self.tau),
                   "slope": float(slope), "slip_wall": float(slip_wall), "slip_lid": float(slip_lid),
                   "slip_length_wall": float(u0 / slope), "slip_length_lid": float(slip_lid * ULID / slope),
                   "max_deviation": float(np.abs(u - ULID * y).max() / ULID),
                   "rows_y": y.tolist(), "rows_u": u.tolist()}
        io.write_json(os.path.join(outdir, "results.json"), results)
        print(f"shtc_couette: dr = {self.dr:.4g}  slope {slope:.4f}  slip at the wall {slip_wall:+.4f}, "
              f"at the lid {slip_lid:+.4f} (lengths {results['slip_length_wall'] / self.dr:.3f} dr, "
              f"{results['slip_length_lid'] / self.dr:.3f} dr)  max |u - U y| {results['max_deviation']:.4f}")
        return results
