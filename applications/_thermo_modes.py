"""Linearised rates of a thermo-elastic application of Ghavamian et al. (2021), sec. 7, at the
state it reached, and the TVD-RK2 (eq. 77) amplification of their modes at the step of eq. 78.

The unknowns are p (as v), F, H, J and E per particle (E-form, full scheme); the positions and
the wave speeds are held (they are frozen over a step, Algorithm 1).  The Jacobian is built by
central differences of the compiled rates (state update, then the rate equations with the
angular-momentum projection if on).  Usage (one thread):

    python -m sphgen.applications._thermo_modes thermo_disk --dx 1 --tf 7 --cfl 0.25 --variant full [app options]
        [--alphas 0.25 0.3] [--without-projection]

runs the application to --tf, then prints for each alpha_CFL the largest |1 + z + z^2/2|,
z = lambda dt, over the fast modes (|z| > 0.3 at that alpha): above 1, TVD-RK2 amplifies
that mode every step.
"""
import argparse
import sys

import numpy as np

UNKNOWNS = (("u", 1), ("v", 1), ("w", 1), ("F", 9), ("H", 9), ("J", 1), ("E", 1))


def state_vector(pa):
    """(v_x, v_y, v_z, F, H, J, E) of every particle, one flat vector."""
    return np.concatenate([pa.get(name) for name, _ in UNKNOWNS])


def set_state(pa, y):
    k = 0
    for name, m in UNKNOWNS:
        a = pa.get(name)
        a[:] = y[k:k + a.size]
        k += a.size


def rates(app, y, t):
    """d/dt of ``state_vector`` at the state y (the application's compiled equations)."""
    pa = app.scene.by_name["body"]
    integ = app.solver.integrator
    set_state(pa, y)
    app.scene.stage("stage1", t, 0.0)           # the projection point x^n
    integ.compute_accelerations(1, t, 0.0)      # theta, P
    integ.compute_accelerations(0, t, 0.0)      # the rates (and the projection)
    a = pa.tint.reshape(-1, 3) / pa.rho[:, None]
    return np.concatenate([a[:, 0], a[:, 1], a[:, 2], pa.aF, pa.aH, pa.aJ, pa.aE])


def central_jacobian(f, y0, rel=1e-7, floor=1e-3):
    """The Jacobian of f at y0 by central differences, step rel x max(|y_i|, floor)."""
    jac = np.empty((y0.size, y0.size))
    for i in range(y0.size):
        e = rel * max(abs(y0[i]), floor)
        yp, ym = y0.copy(), y0.copy()
        yp[i] += e
        ym[i] -= e
        jac[:, i] = (f(yp) - f(ym)) / (2 * e)
    return jac


def rate_jacobian(app, rel=1e-7):
    """The Jacobian of ``rates`` at the application's current state (central differences,
    step rel x max(|y_i|, 1e-3)); the state is restored afterwards."""
    pa, t = app.scene.by_name["body"], app.solver.t
    y0 = state_vector(pa).copy()
    jac = central_jacobian(lambda y: rates(app, y, t), y0, rel)
    rates(app, y0, t)
    return jac


def rk2_amplification(z):
    """|1 + z + z^2/2|: the growth per step of a mode d/dt y = lambda y, z = lambda dt, under
    the TVD-RK2 of eq. 77 (Heun's method)."""
    z = np.asarray(z)
    return np.abs(1.0 + z + 0.5 * z * z)


def fast_mode_amplification(lam, dt_per_alpha, alphas, fast=0.3):
    """For each alpha: (largest amplification over the modes with |lambda dt| > fast, its z)."""
    out = {}
    for a in alphas:
        z = lam * a * dt_per_alpha
        idx = np.flatnonzero(np.abs(z) > fast)
        if idx.size == 0:
            out[a] = (0.0, 0j)
            continue
        g = rk2_amplification(z[idx])
        out[a] = (float(g.max()), complex(z[idx[np.argmax(g)]]))
    return out


def main(argv=None):
    argv = list(sys.argv[1:] if argv is None else argv)
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("app", choices=("thermo_disk", "thermo_punch", "l_block", "thermo_gripper", "thermo_ball"))
    p.add_argument("--alphas", type=float, nargs="+", default=(0.25, 0.27, 0.28, 0.29, 0.3))
    p.add_argument("--without-projection", action="store_true",
                   help="linearise the rates without the angular-momentum projection (same state)")
    o, rest = p.parse_known_args(argv)
    from sphgen.app import load_application
    app = load_application(o.app)()
    app.run(["--no-progress", "--disable-output", "--threads", "1", *rest])
    if app.options.form != "E" or app.options.variant == "reduced":
        raise SystemExit("_thermo_modes: the E-form full scheme only (unknowns v, F, H, J, E)")
    if o.without_projection:
        from sphgen.equations import thermo_upwind
        thermo_upwind.AngularMomentumProjection.reduce = lambda self, dst, t, dt: None
    lam = np.linalg.eigvals(rate_jacobian(app))
    dt_per_alpha = app.scheme.dx / app.scheme.max_wave_speed()
    print(f"_thermo_modes: {o.app} at t = {app.solver.t:.4g}, {lam.size} modes, h_min / c_p,max = "
          f"{dt_per_alpha:.4g} s{' (linearised without the projection)' if o.without_projection else ''}")
    for a, (g, z) in fast_mode_amplification(lam, dt_per_alpha, o.alphas).items():
        print(f"  alpha_CFL {a:g}: largest |1 + z + z^2/2| over the fast modes {g:.5f} at z = {z:.4f}")
    return lam


if __name__ == "__main__":
    main()
