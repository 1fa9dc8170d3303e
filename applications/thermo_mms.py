"""Manufactured solution of Ghavamian et al. (2021), sec. 7.1 (Figs. 2-3): a unit cube in
linear thermo-elasticity,

    phi = X + (A t / L)(X . X) 1,    theta = theta_R [1 + B sin(pi X_1 / L)(t + 1)],

A = 0.2381 1/s, B = -0.0012 1/s, E = 50.05 kPa, nu = 0.3, rho_R = 1000, k = 10, C_v = 1,
alpha = 2.223e-4, theta_R = 293.15 K, to t = 0.001 s.  The body force and heat source are
derived here from the coded model (the paper's eqs. 89-90 are misprinted: 2 mu + lambda
for lambda + 4 mu, C_v for rho_R C_v, theta for theta_R; docs/thermo.md):

    f_R = -(lambda + 4 mu) a 1 + c_v Gamma_0 dtheta/dX_1 E_1,              a = 2 A t / L,
    s_R = c_v Gamma_0 theta tr(grad v) + c_v dtheta/dt + DIV Q,   Q = -J^-1 k H^T H grad theta,

with the DIV Q of the exact H = J I - a X (x) 1, J = 1 + a X . 1 (``heat_flux_divergence``).

Boundary data (the paper's are unclear): ``--bc buffer`` (default) prescribes the exact
velocity and temperature on every particle closer than 4h to the boundary and measures
the errors on the inner cube [0.25, 0.75]^3 (it needs dx <= 1/20); ``--bc surface`` only on
the surface particles (errors on the inner cube and on all particles).  Particles sit on
a vertex lattice of spacing 1/n with volumes dx^3 times 1/2 per face they lie on.
``results.json``: V-weighted L2 errors of p (3 components), P (9) and theta, absolute and
relative to the exact field's norm.  ``python -m sphgen.applications.thermo_mms --n 20 24
32 40`` runs the levels and prints the least-squares orders.
"""
import argparse
import os
import sys
from math import pi

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.particles import ParticleArray

from ..equations.thermo_materials import LinearThermoElastic
from ..schemes.thermo_upwind import ThermoUpwindScheme

PAPER = dict(E_young=50.05e3, nu=0.3, rho=1000.0, Cv=1.0, alpha=2.223e-4, theta_R=293.15, k_th=10.0)
A_PAPER, B_PAPER = 0.2381, -0.0012


class Manufactured:
    """The exact fields of eqs. 84-88 and the sources of the coded linear model."""

    def __init__(self, material, A=A_PAPER, B=B_PAPER, L=1.0):
        self.mat, self.A, self.B, self.L = material, A, B, L

    def velocity(self, X):
        return (self.A / self.L) * np.sum(X * X, axis=1)[:, None] * np.ones(3)

    def temperature(self, X, t):
        return self.mat.theta_R * (1.0 + self.B * np.sin(pi * X[:, 0] / self.L) * (t + 1.0))

    def deformation(self, X, t):
        """F = I + a 1 (x) X, H = J I - a X (x) 1, J = 1 + a X . 1 (a = 2 A t / L)."""
        a = 2.0 * self.A * t / self.L
        one = np.ones(3)
        F = np.eye(3) + a * np.einsum("i,aj->aij", one, X)
        J = 1.0 + a * X.sum(axis=1)
        H = J[:, None, None] * np.eye(3) - a * np.einsum("ai,j->aij", X, one)
        return F, H, J

    def stress(self, X, t):
        """P of the linear model at the exact F and theta."""
        F, _, _ = self.deformation(X, t)
        m = self.mat
        eps = 0.5 * (F + F.transpose(0, 2, 1)) - np.eye(3)
        tr = np.trace(eps, axis1=1, axis2=2)
        dth = self.temperature(X, t) - m.theta_R
        return 2.0 * m.mu * eps + (m.lam * tr - m.cv * m.Gamma0 * dth)[:, None, None] * np.eye(3)

    def dtheta_dX1(self, X, t, order=1):
        k = pi / self.L
        s = np.sin(k * X[:, 0]) if order == 2 else np.cos(k * X[:, 0])
        sign = -1.0 if order == 2 else 1.0
        return sign * self.mat.theta_R * self.B * (t + 1.0) * k ** order * s

    def heat_flux_divergence(self, X, t):
        """DIV Q for Q = -(k/J) H^T H grad theta with the exact H, J and grad theta = g E_1."""
        a = 2.0 * self.A * t / self.L
        J = 1.0 + a * X.sum(axis=1)
        xx = np.sum(X * X, axis=1)
        k = self.mat.k_th
        K11 = k * (J - 2.0 * a * X[:, 0] + a * a * xx / J)
        divK1 = k * (-3.0 * a + a * a * (2.0 * X.sum(axis=1) / J - 3.0 * a * xx / (J * J)))
        return -self.dtheta_dX1(X, t, 2) * K11 - self.dtheta_dX1(X, t) * divK1

    def body_force(self, X, t):
        m = self.mat
        a = 2.0 * self.A * t / self.L
        f = np.full((len(X), 3), -(m.lam + 4.0 * m.mu) * a)
        f[:, 0] += m.cv * m.Gamma0 * self.dtheta_dX1(X, t)
        return f

    def heat_source(self, X, t):
        m = self.mat
        trgv = 2.0 * self.A / self.L * X.sum(axis=1)
        dth_dt = m.theta_R * self.B * np.sin(pi * X[:, 0] / self.L)
        return (m.cv * m.Gamma0 * self.temperature(X, t) * trgv + m.cv * dth_dt
                + self.heat_flux_divergence(X, t))


def vertex_cube(n, L=1.0):
    """(X (N, 3), V): the vertices of an n^3-cell lattice of [0, L]^3, volumes halved per face."""
    dx = L / n
    g = np.arange(n + 1) * dx
    X = np.array(np.meshgrid(g, g, g, indexing="ij")).reshape(3, -1).T
    w = np.where((np.abs(X) < 1e-9 * L) | (np.abs(X - L) < 1e-9 * L), 0.5, 1.0)
    return X, dx ** 3 * w.prod(axis=1)


class ThermoMMS(Application):
    """Manufactured linear thermo-elastic cube (Ghavamian et al. 2021, sec. 7.1)."""

    tf = 0.001
    pfreq = 1000
    dim = 3
    error_key = "error_rms_rel"
    diagnostics = ("energies", "J_range", "theta_range")
    diagnostics_every = 1

    def add_user_options(self, group):
        group.add_argument("--n", type=int, default=20, help="cells per side, dx = 1/n (default %(default)s)")
        group.add_argument("--hdx", type=float, default=1.2, help="h / dx (default %(default)s)")
        group.add_argument("--kernel", choices=("wendland", "quintic"), default="wendland",
                           help="smoothing kernel (default %(default)s)")
        group.add_argument("--jumps", choices=("limited", "raw"), default="limited",
                           help="dissipation on limited reconstructed jumps or the paper's raw jumps "
                           "(default %(default)s)")
        group.add_argument("--bc", choices=("buffer", "surface"), default="buffer",
                           help="exact data on every particle within 4h of the boundary (default) or "
                           "on the surface particles only")
        group.add_argument("--form", choices=("E", "eta"), default="E", help="total energy or entropy")
        group.add_argument("--step", type=float, default=5e-4,
                           help="fixed time step on every level (default %(default)s s; 0: eq. 78)")
        group.add_argument("--no-sources", dest="sources", action="store_false",
                           help="drop f_R and s_R (an ablation: the error is then the sources')")
        group.add_argument("--A", type=float, default=A_PAPER, help="mapping rate A [1/s]")
        group.add_argument("--B", type=float, default=B_PAPER, help="temperature rate B [1/s]")

    def consume_user_options(self, o):
        if o.n < 4:
            raise InputError(f"--n must be at least 4, got {o.n}")
        if not (np.isfinite(o.hdx) and 0.5 <= o.hdx <= 3.0):
            raise InputError(f"--hdx must lie in [0.5, 3], got {o.hdx}")
        if not (np.isfinite(o.step) and o.step >= 0):
            raise InputError(f"--step must be >= 0, got {o.step}")
        self.dx = 1.0 / o.n
        self.material = LinearThermoElastic(**PAPER)
        self.exact = Manufactured(self.material, o.A, o.B)

    def create_particles(self):
        o = self.options
        X, V = vertex_cube(o.n)
        vel = self.exact.velocity(X)
        pa = ParticleArray("body", x=X[:, 0], y=X[:, 1], z=X[:, 2], u=vel[:, 0], v=vel[:, 1], w=vel[:, 2])
        pa.add_property("V", data=V)
        pa.add_property("theta", data=self.exact.temperature(X, 0.0))
        d = np.minimum(X, 1.0 - X).min(axis=1)
        fixed = d < (4.0 * o.hdx * self.dx if o.bc == "buffer" else 1e-9)
        pa.add_property("vfix", stride=3, data=np.repeat(fixed.astype(float), 3))
        pa.add_property("tfix", data=fixed.astype(float))
        return [pa]

    def create_scheme(self):
        o = self.options
        s = ThermoUpwindScheme(["body"], self.material, self.dx, hdx=o.hdx, kernel=o.kernel,
                               form=o.form, jumps=o.jumps, dt=o.step or None)
        ex = self.exact

        def sources(t, pa):
            X = np.stack([pa.x0, pa.y0, pa.z0], axis=1)
            if not o.sources:
                return None, None
            return ex.body_force(X, t), ex.heat_source(X, t)

        s.add_load("body", sources)
        s.set_dirichlet("body", velocity=lambda t, pa: ex.velocity(np.stack([pa.x0, pa.y0, pa.z0], 1)),
                        temperature=lambda t, pa: ex.temperature(np.stack([pa.x0, pa.y0, pa.z0], 1), t))
        return s

    # ------------------------------------------------------------------ errors
    def errors(self, pa, t):
        """V-weighted L2 errors of p, P and theta on the inner cube and on all particles."""
        X = np.stack([pa.x0, pa.y0, pa.z0], axis=1)
        rho = pa.rho[:, None]
        p = rho * np.stack([pa.u, pa.v, pa.w], axis=1)
        fields = {f"p_{c}": (p[:, k], rho[:, 0] * self.exact.velocity(X)[:, k]) for k, c in enumerate("xyz")}
        P, Pe = pa.P.reshape(-1, 3, 3), self.exact.stress(X, t)
        for i in range(3):
            for k in range(3):
                fields[f"P_{i + 1}{k + 1}"] = (P[:, i, k], Pe[:, i, k])
        fields["theta"] = (pa.theta, self.exact.temperature(X, t))
        inner = np.all((X >= 0.25 - 1e-9) & (X <= 0.75 + 1e-9), axis=1)
        out = {}
        for region, mask in (("inner", inner), ("all", np.ones(pa.n, bool))):
            V = pa.V[mask]
            for name, (num, ex) in fields.items():
                e = float(np.sqrt(np.sum(V * (num[mask] - ex[mask]) ** 2)))
                norm = float(np.sqrt(np.sum(V * ex[mask] ** 2)))
                out[f"{region}_{name}"] = e
                out[f"{region}_{name}_rel"] = e / norm if norm > 0 else None
        return out, int(inner.sum())

    def post_process(self, outdir):
        pa, t = self.scene.by_name["body"], self.solver.t
        err, n_inner = self.errors(pa, t)
        region = "inner" if n_inner else "all"
        rel = [err[f"{region}_{k}_rel"] for k in ("p_x", "p_y", "p_z", "theta")]
        rel += [err[f"{region}_P_{i}{k}_rel"] for i in (1, 2, 3) for k in (1, 2, 3)
                if err[f"{region}_P_{i}{k}_rel"] is not None]
        results = {"t": t, "n": self.options.n, "dx": self.dx, "n_particles": pa.n, "n_inner": n_inner,
                   "norm_region": region, "bc": self.options.bc, "jumps": self.options.jumps,
                   "form": self.options.form, "steps": self.solver.step,
                   "error_rms_rel": float(np.sqrt(np.mean(np.square(rel)))), **err,
                   "material": self.material.parameters()}
        io.write_json(os.path.join(outdir, "results.json"), results)
        print(f"thermo_mms: n={self.options.n} N={pa.n} t={t:.4g} ({region} norm, {n_inner} particles): "
              f"p_x {err[f'{region}_p_x']:.3e}  P_11 {err[f'{region}_P_11']:.3e}  "
              f"theta {err[f'{region}_theta']:.3e}")


# ---------------------------------------------------------------------- levels
KEYS = ["p_x", "p_y", "p_z"] + [f"P_{i}{k}" for i in (1, 2, 3) for k in (1, 2, 3)] + ["theta"]


def orders(rows, region="inner", last=3):
    """Least-squares slopes of log(error) against log(dx) over the ``last`` finest levels."""
    rows = sorted(rows, key=lambda r: r["dx"])[:last]
    dx = np.log([r["dx"] for r in rows])
    out = {}
    for k in KEYS:
        e = [r.get(f"{region}_{k}") for r in rows]
        if all(v is not None and v > 0 for v in e):
            out[k] = float(np.polyfit(dx, np.log(e), 1)[0])
    return out


def study(argv=None):
    """Run the levels ``--n ...`` (other options passed to every run) and print orders."""
    from sphgen.studies import run_one
    p = argparse.ArgumentParser(prog="python -m sphgen.applications.thermo_mms")
    p.add_argument("--n", type=int, nargs="+", required=True, help="levels (cells per side)")
    p.add_argument("-d", "--directory", default="thermo_mms_study")
    o, rest = p.parse_known_args(argv)
    rows = []
    for n in o.n:
        row = run_one("thermo_mms", ["--n", str(n), *rest], os.path.join(o.directory, f"n{n}"))
        if row["exit"] != 0:
            raise SystemExit(f"level n={n} failed: {row['message']}")
        rows.append(row["results"])
    region = rows[0]["norm_region"]
    table = {"levels": rows, "orders": orders(rows, region), "region": region}
    io.write_json(os.path.join(o.directory, "orders.json"), table)
    print(f"{'n':>4} {'N':>8} " + " ".join(f"{k:>9}" for k in KEYS))
    for r in sorted(rows, key=lambda r: -r["dx"]):
        print(f"{r['n']:>4} {r['n_particles']:>8} " + " ".join(f"{r[f'{region}_{k}']:9.2e}" for k in KEYS))
    print("order" + " " * 9 + " ".join(f"{table['orders'].get(k, float('nan')):9.2f}" for k in KEYS))
    return table


if __name__ == "__main__":
    study(sys.argv[1:])
