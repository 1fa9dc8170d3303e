"""The reversible update of the distortion A: dA/dt = -A L (Kincl, Peshkov, Pavelka & Klika
(2023), eq. 6) by the implicit mid-point rule, i.e. the Cayley transform of eq. 23."""
from sphgen.equation import declare, helper

from .shtc_stress import inverse3


@helper
def cayley_update(a=[0.0], l=[0.0], dt=0.0, out=[0.0]):
    """out = A (I - dt/2 L)(I + dt/2 L)^-1 (Kincl et al. (2023), eq. 23; the factors commute).

    For antisymmetric L (rigid rotation) the factor is orthogonal, so an orthogonal A stays
    orthogonal; with L -> -L the step is undone exactly.
    """
    m = declare("matrix(9)")
    p = declare("matrix(9)")
    pi = declare("matrix(9)")
    for i in range(9):
        m[i] = -0.5 * dt * l[i]
        p[i] = 0.5 * dt * l[i]
    m[0] += 1.0
    m[4] += 1.0
    m[8] += 1.0
    p[0] += 1.0
    p[4] += 1.0
    p[8] += 1.0
    inverse3(p, pi)
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                s += m[3 * i + k] * pi[3 * k + j]
            p[3 * i + j] = s
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                s += a[3 * i + k] * p[3 * k + j]
            out[3 * i + j] = s
