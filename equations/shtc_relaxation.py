"""Strain relaxation of the distortion: dA/dt = -(1/theta) eps_A with 1/theta = 3/(tau cs^2)
(Kincl, Peshkov, Pavelka & Klika (2023), eq. 24c), integrated by the classical RK4 of eq. 25d.

The paper's footnote 1 and the thesis (Kincl 2023, eq. 2.11) give theta = tau cs^2/3
|det A|^(-5/3); the paper drops the determinant in all its computations.  ``detpow`` = 0 is
the paper's choice, 5/3 the thesis' full form.

Linearised about A = I the symmetric deviatoric part decays at the rate 6/tau, so the
explicit RK4 step is stable for dt < 2.785 tau/6 = 0.464 tau (the scheme refuses larger steps).
"""
from math import fabs, pow

from sphgen.equation import declare, helper
from sphgen.linalg import det3

from .shtc_stress import shear_force


@helper
def relaxation_rate(a=[0.0], rate=0.0, model=0, detpow=0.0, out=[0.0]):
    """out = -rate |det A|^detpow eps_A/cs^2 (rate = 3/tau: Kincl et al. (2023), eq. 24c)."""
    f = rate
    if detpow != 0.0:
        f = rate * pow(fabs(det3(a)), detpow)
    shear_force(a, model, out)
    for i in range(9):
        out[i] = -f * out[i]


@helper
def relax_rk4(a=[0.0], dt=0.0, rate=0.0, model=0, detpow=0.0):
    """A <- A + dt/6 (K1 + 2 K2 + 2 K3 + K4), classical RK4 on dA/dt = relaxation_rate(A)
    (Kincl et al. (2023), eq. 25d, whose b = (1, 1/2, 1/2, 1) with K_0 = 0 is exactly RK4)."""
    k = declare("matrix(9)")
    s = declare("matrix(9)")
    acc = declare("matrix(9)")
    relaxation_rate(a, rate, model, detpow, k)
    for i in range(9):
        acc[i] = k[i]
        s[i] = a[i] + 0.5 * dt * k[i]
    relaxation_rate(s, rate, model, detpow, k)
    for i in range(9):
        acc[i] += 2.0 * k[i]
        s[i] = a[i] + 0.5 * dt * k[i]
    relaxation_rate(s, rate, model, detpow, k)
    for i in range(9):
        acc[i] += 2.0 * k[i]
        s[i] = a[i] + dt * k[i]
    relaxation_rate(s, rate, model, detpow, k)
    for i in range(9):
        a[i] += dt / 6.0 * (acc[i] + k[i])
