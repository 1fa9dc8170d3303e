"""The manufactured solution of Ghavamian et al. (2021) sec. 7.1 (applications/thermo_mms.py).

The sources are those of the coded linear model: they must equal rho dv/dt - DIV P and
dE/dt - DIV(P^T v - Q) - f . v computed by finite differences from the material's own
stress and energy with the exact fields.  A short run then checks the E-form energy
budget with loads and essential conditions (E_tot - E_tot(0) = W_ext + Q_in + E_Dir to
round-off) and that the interior error is the scheme's, not the sources'.
"""
import json
import os

import numpy as np
import pytest

from sphgen.applications.thermo_mms import PAPER, Manufactured, ThermoMMS, orders, vertex_cube
from sphgen.equations.thermo_materials import LinearThermoElastic


def test_sources_are_those_of_the_coded_model():
    mat = LinearThermoElastic(**PAPER)
    ex = Manufactured(mat)
    rng = np.random.default_rng(0)

    def at(X, t):
        F, H, J = ex.deformation(X[None], t)
        th = ex.temperature(X[None], t)[0]
        v = ex.velocity(X[None])[0]
        P = mat.stress(F[0], H[0], J[0], th)
        E = 0.5 * mat.rho * v @ v + mat.energy_R(F[0], H[0], J[0]) + mat.cv * (th - mat.theta_R)
        return F[0], H[0], J[0], th, v, P, E

    def heat_flux(X, t, e=1e-5):
        _, H, J, _, _, _, _ = at(X, t)
        g = np.array([(at(X + e * d, t)[3] - at(X - e * d, t)[3]) / (2 * e) for d in np.eye(3)])
        return -(mat.k_th / J) * H.T @ H @ g

    for _ in range(3):
        X, t, e = rng.uniform(0, 1, 3), rng.uniform(0, 0.3), 1e-4
        divP, divflux = np.zeros(3), 0.0
        for k, d in enumerate(np.eye(3)):
            p, m = at(X + e * d, t), at(X - e * d, t)
            divP += (p[5][:, k] - m[5][:, k]) / (2 * e)
            divflux += ((p[5].T @ p[4] - heat_flux(X + e * d, t))[k]
                        - (m[5].T @ m[4] - heat_flux(X - e * d, t))[k]) / (2 * e)
        f_fd = -divP                         # the exact velocity does not depend on time
        s_fd = (at(X, t + e)[6] - at(X, t - e)[6]) / (2 * e) - divflux - f_fd @ at(X, t)[4]
        f, s = ex.body_force(X[None], t)[0], ex.heat_source(X[None], t)[0]
        assert np.abs(f - f_fd).max() < 1e-7 * np.abs(f).max()
        assert abs(s - s_fd) < 1e-7 * abs(s)
    # the paper's eq. 89 has 2 mu + lambda where the model gives lambda + 4 mu
    f0 = ex.body_force(np.array([[0.5, 0.5, 0.5]]), 1.0)[0]
    assert f0[1] == pytest.approx(-(mat.lam + 4 * mat.mu) * 2 * ex.A, rel=1e-12)


def test_vertex_cube_volumes_sum_to_one():
    X, V = vertex_cube(6)
    assert len(X) == 7 ** 3 and V.sum() == pytest.approx(1.0, rel=1e-14)


def mms_run(out, *extra):
    ThermoMMS().run(["--n", "10", "--bc", "surface", "-d", str(out), "--no-progress",
                     "--disable-output", "--threads", "1", *extra])
    with open(out / "results.json") as f:
        return json.load(f)


def test_short_run_balances_energy_and_its_error_is_the_schemes(tmp_path):
    out = tmp_path / "mms"
    r = mms_run(out)
    with open(out / "diagnostics.json") as f:
        d = json.load(f)
    c, rows = d["columns"], np.array(d["rows"])
    col = {k: rows[:, c.index(k)] for k in c}
    residual = col["total"] - col["total"][0] - col["W_ext"] - col["Q_in"] - col["E_Dir"]
    scale = np.max(col["kinetic"] + np.abs(col["W_ext"]) + np.abs(col["Q_in"]) + np.abs(col["E_Dir"]))
    assert np.abs(residual).max() <= 1e-10 * scale
    assert abs(col["Q_in"][-1]) > 1e-3 * scale and abs(col["E_Dir"][-1]) > 1e-6 * scale
    assert r["steps"] == 2 and r["n_inner"] == 125 and os.path.exists(out / "info.json")
    # the interior error is the scheme's: without the sources it is at least five times larger
    r0 = mms_run(tmp_path / "nosources", "--no-sources")
    for k in ("p_x", "p_y", "P_11", "P_22", "theta"):
        assert r[f"inner_{k}"] < 0.2 * r0[f"inner_{k}"], k


def test_orders_are_least_squares_slopes():
    rows = [{"dx": dx, "inner_theta": 3.0 * dx ** 2, "inner_p_x": dx} for dx in (0.1, 0.05, 0.025, 0.0125)]
    o = orders(rows)
    assert o["theta"] == pytest.approx(2.0) and o["p_x"] == pytest.approx(1.0)


def level(out, n, *extra):
    ThermoMMS().run(["--n", str(n), "-d", str(out), "--no-progress", "--disable-output", "--threads", "1",
                     *extra])
    with open(out / "results.json") as f:
        return json.load(f)


def test_interior_errors_fall_at_second_order_between_two_levels(tmp_path):
    """Fast version of the order check (buffer data, limited jumps, dt = 5e-4 on both
    levels): from n = 24 to n = 32 every component of p and P and theta falls at an
    observed order >= 1.8; the paper's raw jumps leave p an error over 1000 times larger
    even on the coarser n = 20 lattice."""
    rows = [level(tmp_path / f"n{n}", n) for n in (24, 32)]
    o = orders(rows, last=2)
    assert len(o) == 13 and min(o.values()) >= 1.8, o
    raw = level(tmp_path / "raw", 20, "--jumps", "raw")
    assert raw["inner_p_x"] > 1e3 * rows[0]["inner_p_x"]


@pytest.mark.slow
def test_least_squares_orders_over_the_three_finest_of_four_levels(tmp_path):
    """Ghavamian et al. (2021) Fig. 3: second order for p, P and theta at t = 0.001 s.
    Levels n = 20, 24, 32, 40, dt = 5e-4 s on all, buffer data, limited jumps: each
    component's least-squares order over n = 24, 32, 40 is >= 1.8 (docs/thermo.md)."""
    from sphgen.applications.thermo_mms import study
    table = study(["--n", "20", "24", "32", "40", "-d", str(tmp_path), "--threads", "1", "--disable-output"])
    assert table["region"] == "inner" and len(table["orders"]) == 13
    assert min(table["orders"].values()) >= 1.8, table["orders"]
