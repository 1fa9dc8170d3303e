"""The reversible update of the distortion A: dA/dt = -A L (Kincl, Peshkov, Pavelka & Klika
(2023), eq. 6) by the implicit mid-point rule, i.e. the Cayley transform of eq. 23."""
from sphgen.equation import declare, helper

from sphgen.linalg import inv3, matmul3


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
    inv3(p, pi)
    matmul3(m, pi, p)
    matmul3(a, p, out)
