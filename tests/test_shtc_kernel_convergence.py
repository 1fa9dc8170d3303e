"""The kernel-interpolation convergence study of Theorem 1 of Kincl's thesis (2023), eq. 1.26."""
import json

import pytest

from sphgen.app import load_application
from sphgen.applications.shtc_kernel_convergence import convergence_study

HS = (0.016, 0.022, 0.032, 0.045)


@pytest.mark.parametrize("kernel", ["wendland", "quintic", "gaussian", "quartic"])
def test_interpolation_error_converges_as_h_squared(kernel):
    """Slope 2 +- 0.2 (the digest's proposal), under Theorem 1's bound, and the error tends to
    its Taylor term (C/d) h^2 max|lap f|, on a lattice whose quadrature error is negligible."""
    r = convergence_study(kernel, HS, 512)
    assert abs(r["slope"] - 2.0) <= 0.2
    assert r["bound_holds"]
    assert r["quadrature_check"] < 1e-3 and r["partition_of_unity_defect"] < 1e-5
    assert r["error_over_h2_lap"][0] == pytest.approx(r["leading_constant"], rel=0.01)


def test_theorem_1_constant_of_the_wendland_kernel():
    """C = 1/2 int |x|^2 W_1 dV = 5/18 in 2D for the Wendland kernel."""
    r = convergence_study("wendland", (0.032, 0.045), 256)
    assert r["theorem_1_constant"] == pytest.approx(5.0 / 18.0, rel=1e-7)


def test_application_writes_results_and_plot(tmp_path):
    out = tmp_path / "kc"
    load_application("shtc_kernel_convergence")().run(["-d", str(out), "--n", "256", "--h", "0.032", "0.045",
                                                       "0.064", "0.09"])
    res = json.load(open(out / "results.json"))
    assert set(res["kernels"]) == {"wendland", "quintic", "gaussian", "quartic"}
    assert abs(res["kernels"]["wendland"]["slope"] - 2.0) <= 0.2
    assert (out / "convergence.png").stat().st_size > 0
    assert json.load(open(out / "info.json"))["completed"] is True      # automan's "finished"


def test_too_coarse_a_lattice_is_refused(tmp_path):
    with pytest.raises(SystemExit):
        load_application("shtc_kernel_convergence")().run(["-d", str(tmp_path / "x"), "--n", "64", "--h", "0.05", "0.1"])
