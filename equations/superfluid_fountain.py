"""Sources of the superfluid fountain: the heater and the superleak (Kincl 2023, thesis eqs. 3.52, 3.58-3.59).

* Heater (eq. 3.59): zeta_heat,a = W_dot W_H(|x_a - x_heat|) enters ds_a/dt as
  zeta_heat,a/(T_a rho_a) (eq. 3.52), W_H the 2D Wendland C2 kernel with its own smoothing
  length H (support 2H), switched on linearly over ``t_ramp``.  The heater's power per unit
  mass, zeta_heat/rho, is kept in ``qheat`` so that sum_a m_a qheat_a is the power the
  particles receive (W_dot times the discrete partition of unity of W_H).
* Superleak (eq. 3.58): a friction f = -k(x) rho_n v_n on v alone (v_s untouched) in the
  band |x| <= r_sl, |y - y_sl| < d_sl, with k = k0 (15/16)(1 - d^2)^2, d = (y - y_sl)/d_sl
  (W_H * delta of the band: the 1D biweight profile of the authors' code, k0 = 1/tau).
  Stiff (k0 dt ~ 1), so it is integrated exactly: rho_n v_n decays as exp(-k dt) at fixed
  v_s (:func:`superleak_factor`), and the kinetic energy it removes,
  rho_n |v_n|^2 (1 - B^2)/2 per unit mass, is returned as entropy, ds = -de_kin/T
  (the -f.v_n/T term of eq. 3.52), so the total energy is kept to first order.
"""
from math import exp, sqrt  # noqa: F401  (the Python evaluator's math)

from sphgen.equation import Equation, helper

from .superfluid_energy import linear_temperature, normal_fraction  # noqa: F401


@helper
def source_kernel(r=0.0, H=1.0):
    """W_H(r): the 2D Wendland C2 kernel, support 2H, of the heater (Kincl 2023, eq. 3.59)."""
    q = r / H
    w = 0.0
    if q < 2.0:
        a = 1.0 - 0.5 * q
        w = 7.0 / (4.0 * 3.141592653589793 * H * H) * a * a * a * a * (1.0 + 2.0 * q)
    return w


@helper
def superleak_rate(x=0.0, y=0.0, k0=0.0, yc=0.0, width=1.0, half=0.0):
    """k(x) = k0 (15/16)(1 - d^2)^2, d = (y - y_sl)/d_sl, in the band |x| <= r_sl, |d| < 1 (Kincl 2023, eq. 3.58);
    yc = y_sl, width = d_sl, half = r_sl."""
    k = 0.0
    d = (y - yc) / width
    if x <= half and x >= -half and d < 1.0 and d > -1.0:
        e = 1.0 - d * d
        k = k0 * 0.9375 * e * e
    return k


@helper
def superleak_factor(k=0.0, dt=0.0):
    """B = exp(-k dt): the exact decay of rho_n v_n under f = -k rho_n v_n at fixed v_s (Kincl 2023, eq. 3.58)."""
    return exp(-k * dt)


class Heater(Equation):
    """ds_a/dt += zeta_heat,a/(T_a rho_a), zeta_heat,a = min(1, t/t_ramp) W_dot W_H(|x_a - x_heat|) (Kincl 2023, eqs. 3.52, 3.59).

    On FLUID particles only; ``qheat`` = zeta_heat/rho (W/kg).  Place it after the entropy
    equations (their ``initialize`` zeroes ``sdot``)."""

    nonnegative = ("power", "H", "t_ramp")

    def __init__(self, dest, sources=None, x_heat=0.0, y_heat=0.0, H=1.0, power=0.0, t_ramp=0.0):
        super().__init__(dest, None, x_heat=x_heat, y_heat=y_heat, H=H, power=power, t_ramp=t_ramp)

    def post_loop(self, d_idx, d_ptype, d_x, d_y, d_sdot, d_T, d_rho, d_qheat, t):
        q = 0.0
        if d_ptype[d_idx] == 0:
            ramp = 1.0
            if t < self.t_ramp:
                ramp = t / self.t_ramp
            dx = d_x[d_idx] - self.x_heat
            dy = d_y[d_idx] - self.y_heat
            q = ramp * self.power * source_kernel(sqrt(dx * dx + dy * dy), self.H) / d_rho[d_idx]
            d_sdot[d_idx] += q / d_T[d_idx]
        d_qheat[d_idx] = q


class WallPressureFloor(Equation):
    """p_a = max(p_a, 0) on solid (ADIABATIC, COOLER) particles: a dry wall, below its calibrated
    density, does not pull the fluid (docs/superfluid.md, the fountain, decision 3; not in Kincl 2023)."""

    def __init__(self, dest, sources=None):
        super().__init__(dest, None)

    def post_loop(self, d_idx, d_ptype, d_p):
        if d_ptype[d_idx] != 0:
            if d_p[d_idx] < 0.0:
                d_p[d_idx] = 0.0
