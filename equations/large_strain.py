"""Tensor algebra of large-strain solid mechanics: the tensor cross product and friends.

3x3 tensors are flat, row-major (``A[3 * i + I]`` is A_iI), as every tensor property of
sphgen.  The tensor cross product of Bonet, Gil & Ortigosa (2016),

    (A x B)_iI = e_ijk e_IJK A_jJ B_kK,

gives the cofactor H = (F x F)/2 and J = (H : F)/3, and the rates dH = F x dF
(Ghavamian et al. (2021), eqs. 3a, 12).  Restricted Python (``@helper``): the same
functions run compiled inside equations and as plain Python in tests.
"""
from sphgen.equation import declare, helper


@helper
def cross33(a=[0.0], b=[0.0], out=[0.0]):
    """out = a x b, the tensor cross product (out must not alias a or b)."""
    j = declare("int")
    k = declare("int")
    jj = declare("int")
    kk = declare("int")
    for i in range(3):
        j = (i + 1) % 3
        k = (i + 2) % 3
        for ii in range(3):
            jj = (ii + 1) % 3
            kk = (ii + 2) % 3
            out[3 * i + ii] = (a[3 * j + jj] * b[3 * k + kk] - a[3 * j + kk] * b[3 * k + jj]
                               - a[3 * k + jj] * b[3 * j + kk] + a[3 * k + kk] * b[3 * j + jj])


@helper
def ddot33(a=[0.0], b=[0.0]):
    """a : b = a_iI b_iI."""
    s = 0.0
    for i in range(9):
        s += a[i] * b[i]
    return s


@helper
def matvec3(a=[0.0], x=[0.0], out=[0.0]):
    """out = a x (matrix times vector; out must not alias x)."""
    for i in range(3):
        out[i] = a[3 * i] * x[0] + a[3 * i + 1] * x[1] + a[3 * i + 2] * x[2]


@helper
def tmatvec3(a=[0.0], x=[0.0], out=[0.0]):
    """out = a^T x (out must not alias x)."""
    for i in range(3):
        out[i] = a[i] * x[0] + a[3 + i] * x[1] + a[6 + i] * x[2]


@helper
def dot3(a=[0.0], b=[0.0]):
    """a . b of two 3-vectors."""
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
