"""Body-force-driven (Poiseuille) flow between two plates, EDAC with Adami walls.

Set-up after Morris, Fox & Zhu (1997, section 4.1) and Adami, Hu & Adams (2012, 2013):
plates at y = 0 and y = d = 1 (three layers of wall particles each, no slip by the ghost
velocity of AHA eqs. 22-23), periodic in x over a length d, fluid at rest at t = 0,
driven by a body force F along x with rho0 = 1, kinematic viscosity nu, u_max = F d^2/(8 nu)
= 1 and Re = u_max d / nu = ``--re`` (default 1).  ``--ny`` particles across the channel
(default 30), h = dx, c0 = 10 u_max, no particle shifting (the streamlines are straight).

The exact transient (Morris et al. 1997 eq. 21)
u(y, t) = F/(2 nu) y (d - y) - sum_n 4 F d^2 / (nu pi^3 (2n+1)^3) sin((2n+1) pi y/d)
e^{-(2n+1)^2 pi^2 nu t/d^2}
reaches the steady parabola to 1e-4 u_max after t = 0.93 d^2/nu; the default final time is
1.5 (= 1.5 d^2/nu at Re = 1; set ``--tf`` for other Re).  ``post_process`` bins the fluid particles by their row (y) and writes to
``results.json`` the largest deviation of the row-mean u from the parabola (and from
the transient) relative to u_max at the final time, with the history of both;
``profile.png`` plots the profiles.
"""
import os
from math import pi

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.geometry import layers_for_support, rectangle
from sphgen.nnps import Domain
from sphgen.particles import ParticleArray

from ..schemes.edac import EDACScheme

try:
    from sphgen.errors import InputError
except ImportError:  # pragma: no cover
    InputError = ValueError

D = 1.0         # channel width
LX = D          # periodic length (fixed, so every resolution shares one compiled module)
RHO0 = 1.0
UMAX = 1.0


def row_profile(y, u, dx, d=D):
    """Mean u of the particles of each row of height dx across [0, d] -> (y of row, mean u)."""
    k = np.clip(np.floor(y / dx).astype(int), 0, int(round(d / dx)) - 1)
    n = np.bincount(k, minlength=int(round(d / dx)))
    ok = n > 0
    ym = np.bincount(k, y, minlength=n.size)[ok] / n[ok]
    um = np.bincount(k, u, minlength=n.size)[ok] / n[ok]
    return ym, um


class ChannelFlow:
    """Common set-up of the plane channel flows (two walls, periodic in x, EDAC); mixed
    into an :class:`~sphgen.app.Application` (``sphgen run`` wants one per module)."""

    dim = 2
    pfreq = 1000
    history_columns = ("t", "dev_transient", "dev_steady", "u_mid")
    moving_top = False

    def add_user_options(self, group):
        group.add_argument("--ny", type=int, default=30, help="particles across the channel (default %(default)s)")
        group.add_argument("--re", type=float, default=1.0, help="Reynolds number u_max d/nu (default %(default)s)")
        group.add_argument("--c0-factor", type=float, default=10.0, help="c0 = factor * u_max (default %(default)s)")
        group.add_argument("--pst", choices=("none", "sun2019", "tvf"), default="none",
                           help="particle shifting (default %(default)s)")
        group.add_argument("--record-every", type=float, default=0.01,
                           help="time between profile samples (default %(default)s)")

    def consume_user_options(self, o):
        if o.ny < 7:
            raise InputError(f"--ny must be at least 7 (the periodic length must exceed the kernel "
                             f"support twice), got {o.ny}")
        for name in ("re", "c0_factor", "record_every"):
            v = getattr(o, name)
            if not (np.isfinite(v) and v > 0):
                raise InputError(f"--{name.replace('_', '-')} must be a positive finite number, got {v}")
        self.dx = D / o.ny
        self.h = self.dx
        self.nu = UMAX * D / o.re
        self.c0 = o.c0_factor * UMAX
        self.n_layers = layers_for_support(3.0, 1.0)
        self.t_visc = D * D / self.nu
        self.history = []
        self._next_record = 0.0

    def create_particles(self):
        dx = self.dx
        self.lx = lx = LX
        x, y = rectangle(0.0, lx, 0.0, D, dx)
        fluid = ParticleArray("fluid", x=x, y=y, rho=np.full(x.size, RHO0), m=np.full(x.size, RHO0 * dx * dx),
                              h=np.full(x.size, self.h))
        walls = []
        for name, lo, hi, ny in (("bottom", -self.n_layers * dx, 0.0, 1.0),
                                 ("top", D, D + self.n_layers * dx, -1.0)):
            xw, yw = rectangle(0.0, lx, lo, hi, dx)
            w = ParticleArray(name, x=xw, y=yw, rho=np.full(xw.size, RHO0), m=np.full(xw.size, RHO0 * dx * dx),
                              h=np.full(xw.size, self.h))
            w.add_property("normal", stride=3,
                           data=np.column_stack([0 * xw, np.full(xw.size, ny), 0 * xw]).ravel())
            if name == "top" and self.moving_top:
                for p, v in (("uw", UMAX), ("vw", 0.0)):   # 2D: no ww
                    w.add_property(p, data=np.full(xw.size, v))
            walls.append(w)
        return [fluid] + walls

    def create_domain(self):
        return Domain(0.0, self.lx, 0.0, 0.0, periodic_in_x=True)

    def body_force(self):
        return 0.0

    def create_scheme(self):
        return EDACScheme(["fluid"], dim=2, rho0=RHO0, c0=self.c0, nu=self.nu, h=self.h, dx=self.dx,
                          umax=UMAX, pst=self.options.pst, walls=["bottom", "top"], gx=self.body_force(),
                          moving_walls=["top"] if self.moving_top else [])

    # exact solutions, overridden
    def exact(self, y, t):
        raise NotImplementedError

    def steady(self, y):
        raise NotImplementedError

    def history_meta(self):
        return {"dx": self.dx, "nu": self.nu, "c0": self.c0, "t_visc": self.t_visc}

    def post_step(self, solver):
        if solver.t + 1e-12 >= self._next_record or solver.t >= solver.tf - 1e-12:
            self.history.append(self.history_row(self.scene.by_name["fluid"], solver.t))
            self._next_record = solver.t + self.options.record_every

    def history_row(self, f, t):
        ym, um = row_profile(f.y, f.u, self.dx)
        mid = np.argmin(np.abs(ym - 0.5 * D))
        return [t, float(np.abs(um - self.exact(ym, t)).max() / UMAX),
                float(np.abs(um - self.steady(ym)).max() / UMAX), float(um[mid])]

    def post_process(self, outdir):
        hist, rows = io.read_history(outdir)
        t, dev_tr, dev_st, umid = rows.T
        if self.scene is not None:
            f = self.scene.by_name["fluid"]
        else:
            f = io.load(io.output_files(outdir, self.name)[-1])["arrays"]["fluid"]
        ym, um = row_profile(f.y, f.u, hist["dx"])
        mid = int(np.argmin(np.abs(ym - 0.5 * D)))
        results = {"t": float(t[-1]), "t_over_d2_nu": float(t[-1] / hist["t_visc"]),
                   "ny": int(round(D / hist["dx"])), "re": UMAX * D / hist["nu"], "c0": hist["c0"],
                   "max_dev_steady_over_umax": float(dev_st[-1]),
                   "max_dev_transient_over_umax": float(dev_tr[-1]),
                   "max_dev_transient_over_umax_all_times": float(dev_tr.max()),
                   "y_mid": float(ym[mid]), "u_mid": float(um[mid]),
                   "u_mid_exact": float(self.exact(ym[mid:mid + 1], t[-1])[0])}
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(outdir, ym, um, t, dev_tr, dev_st, t[-1])
        print(f"{self.name}: t={results['t']:.4g} ({results['t_over_d2_nu']:.3g} d^2/nu)  max |u - exact|/U: "
              f"steady {100 * results['max_dev_steady_over_umax']:.2f}%, transient "
              f"{100 * results['max_dev_transient_over_umax']:.2f}%\n"
              f"results: {os.path.join(outdir, 'results.json')}\nfigure:  {os.path.join(outdir, 'profile.png')}")
        return results

    def plot(self, outdir, ym, um, t, dev_tr, dev_st, tf):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 4))
        yy = np.linspace(0, D, 101)
        a.plot(self.steady(yy), yy, "k-", label="steady exact")
        a.plot(self.exact(yy, tf), yy, "b--", label=f"exact at t = {tf:.3g}")
        a.plot(um, ym, "ro", ms=3, label="sphgen EDAC (row means)")
        a.set_xlabel("u")
        a.set_ylabel("y")
        a.legend()
        b.semilogy(t, np.maximum(dev_tr, 1e-6), "b-", label="max |u - exact transient| / U")
        b.semilogy(t, np.maximum(dev_st, 1e-6), "k-", label="max |u - steady| / U")
        b.axhline(0.02, color="0.6", ls=":")
        b.set_xlabel("t")
        b.legend()
        fig.tight_layout()
        fig.savefig(os.path.join(outdir, "profile.png"), dpi=100)
        plt.close(fig)


class Poiseuille(ChannelFlow, Application):
    """Poiseuille flow driven by a body force, EDAC with Adami no-slip walls, periodic in x."""

    tf = 1.5   # d^2/nu at the default Re = 1

    def body_force(self):
        return 8.0 * self.nu * UMAX / (D * D)

    def steady(self, y):
        F = self.body_force()
        return F / (2.0 * self.nu) * y * (D - y)

    def exact(self, y, t, terms=60):
        F = self.body_force()
        u = self.steady(y)
        for n in range(terms):
            k = 2 * n + 1
            u = u - 4.0 * F * D * D / (self.nu * pi ** 3 * k ** 3) * np.sin(k * pi * y / D) * \
                np.exp(-k * k * pi * pi * self.nu * t / (D * D))
        return u
