"""Small-matrix helpers for 3x3 tensors stored flat (row-major, 9 values).

They are restricted Python marked ``@helper``: equations call them on local
``declare('matrix(9)')`` arrays, the generator translates them into ``noexcept nogil``
C functions, and the plain-Python evaluator runs them as they are.
"""
from .equation import helper


@helper
def det3(a=[0.0]):
    """Determinant of a 3x3 matrix."""
    return (a[0] * (a[4] * a[8] - a[5] * a[7]) - a[1] * (a[3] * a[8] - a[5] * a[6])
            + a[2] * (a[3] * a[7] - a[4] * a[6]))


@helper
def inv3(a=[0.0], out=[0.0]):
    """out = a^-1 (a must be invertible); returns det(a)."""
    d = det3(a)
    r = 1.0 / d
    out[0] = (a[4] * a[8] - a[5] * a[7]) * r
    out[1] = (a[2] * a[7] - a[1] * a[8]) * r
    out[2] = (a[1] * a[5] - a[2] * a[4]) * r
    out[3] = (a[5] * a[6] - a[3] * a[8]) * r
    out[4] = (a[0] * a[8] - a[2] * a[6]) * r
    out[5] = (a[2] * a[3] - a[0] * a[5]) * r
    out[6] = (a[3] * a[7] - a[4] * a[6]) * r
    out[7] = (a[1] * a[6] - a[0] * a[7]) * r
    out[8] = (a[0] * a[4] - a[1] * a[3]) * r
    return d


@helper
def matmul3(a=[0.0], b=[0.0], out=[0.0]):
    """out = a b (out must not alias a or b)."""
    for i in range(3):
        for j in range(3):
            s = 0.0
            for k in range(3):
                s += a[3 * i + k] * b[3 * k + j]
            out[3 * i + j] = s


@helper
def transpose3(a=[0.0], out=[0.0]):
    """out = a^T (out must not alias a)."""
    for i in range(3):
        for j in range(3):
            out[3 * i + j] = a[3 * j + i]


@helper
def dev3(a=[0.0], out=[0.0]):
    """out = a - tr(a)/3 I, the deviatoric part (out may alias a)."""
    tr = (a[0] + a[4] + a[8]) / 3.0
    for i in range(9):
        out[i] = a[i]
    out[0] -= tr
    out[4] -= tr
    out[8] -= tr
