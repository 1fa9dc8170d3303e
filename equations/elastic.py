"""Elastic solids for the transport-velocity schemes: velocity gradient, Hooke's law with the
Jaumann rate and its transport correction, the divergence of the deviatoric stress.

Adepu & Ramachandran (2021), section 3.2 (eqs. 30-32), built on Gray, Monaghan & Swift
(2001).  The deviatoric stress sigma' is the flat stride-9 property ``sd`` (row-major, 3x3
even in 2D: plane strain keeps sigma'_zz), its rate ``asd``, the velocity gradient
``gradv`` ((grad u)_ij = du_i/dx_j at ``gradv[3 i + j]``).  The pressure is not here: the
schemes evolve it (EDAC, eq. 26) or take it from an equation of state.
"""
from math import sqrt  # noqa: F401  (the Python evaluator needs the name)

from sphgen.equation import Equation, declare  # noqa: F401  (declare: the Python evaluator)
from sphgen.linalg import dev3


class VelocityGradient(Equation):
    """(grad u)_a = -sum_b V_b (u_a - u_b) (x) grad_a W_ab (Adepu & Ramachandran 2021, eq. 31).

    ``transport=False`` (CTVF) differentiates the momentum velocity u; ``transport=True``
    the transport velocity u~ (``uhat``), as the GTVF of Zhang, Hu & Adams (2017) does.
    ``dim`` < 3: no w (its row stays zero).
    """

    switches = ("transport", "dim")

    def __init__(self, dest, sources, transport=False, dim=3):
        super().__init__(dest, sources, transport=bool(transport), dim=int(dim))

    def initialize(self, d_idx, d_gradv):
        for i in range(9):
            d_gradv[9 * d_idx + i] = 0.0

    def loop(self, d_idx, d_gradv, d_u, d_v, d_w, d_uhat, d_vhat, d_what, s_idx, s_m, s_rho,
             s_u, s_v, s_w, s_uhat, s_vhat, s_what, DWIJ):
        du = declare("matrix(3)")
        du[2] = 0.0
        if self.transport:
            du[0] = d_uhat[d_idx] - s_uhat[s_idx]
            du[1] = d_vhat[d_idx] - s_vhat[s_idx]
            if self.dim > 2:
                du[2] = d_what[d_idx] - s_what[s_idx]
        else:
            du[0] = d_u[d_idx] - s_u[s_idx]
            du[1] = d_v[d_idx] - s_v[s_idx]
            if self.dim > 2:
                du[2] = d_w[d_idx] - s_w[s_idx]
        vb = s_m[s_idx] / s_rho[s_idx]
        for i in range(self.dim):
            for j in range(3):
                d_gradv[9 * d_idx + 3 * i + j] -= vb * du[i] * DWIJ[j]


class HookeJaumannRate(Equation):
    """d sigma'/dt = 2G (eps' - tr(eps') I / 3) + sigma' Omega^T + Omega sigma', eps' and Omega the
    symmetric and antisymmetric parts of grad u (Adepu & Ramachandran 2021, eqs. 4-6 and
    the first line of eq. 32; "1/3 eps I" read as the trace).  In 2D grad u has no z row
    or column: plane strain, sigma'_zz evolves with eps'_zz = 0.  No sources: put it in a
    group after :class:`VelocityGradient`; it initialises ``asd``."""

    positive = ("G",)

    def __init__(self, dest, sources=None, G=1.0):
        super().__init__(dest, None, G=G)

    def initialize(self, d_idx, d_gradv, d_sd, d_asd):
        eps = declare("matrix(9)")
        om = declare("matrix(9)")
        for i in range(3):
            for j in range(3):
                gij = d_gradv[9 * d_idx + 3 * i + j]
                gji = d_gradv[9 * d_idx + 3 * j + i]
                eps[3 * i + j] = 0.5 * (gij + gji)
                om[3 * i + j] = 0.5 * (gij - gji)
        dev3(eps, eps)
        for i in range(3):
            for j in range(3):
                rot = 0.0
                for k in range(3):
                    rot += (d_sd[9 * d_idx + 3 * i + k] * om[3 * j + k]
                            + om[3 * i + k] * d_sd[9 * d_idx + 3 * k + j])
                d_asd[9 * d_idx + 3 * i + j] = 2.0 * self.G * eps[3 * i + j] + rot


class JaumannTransportCorrection(Equation):
    """d~sigma'_a/dt += sum_b V_b (sigma'_b - sigma'_a) (delta_b . grad W_ab), delta = u~ - u: the
    discrete div(sigma' (x) delta) - sigma' div(delta) = delta . grad sigma' of eq. 21
    (Adepu & Ramachandran 2021, eq. 32 second line, with the signs eq. 21 requires).
    Adds to ``asd``: after :class:`HookeJaumannRate` in the same group.  ``enabled`` is a
    switch (off: absent from the generated code)."""

    switches = ("enabled",)

    def __init__(self, dest, sources, enabled=True):
        super().__init__(dest, sources, enabled=bool(enabled))

    def loop(self, d_idx, d_sd, d_asd, s_idx, s_m, s_rho, s_sd, s_u, s_v, s_w, s_uhat, s_vhat,
             s_what, DWIJ):
        if self.enabled:
            ddw = ((s_uhat[s_idx] - s_u[s_idx]) * DWIJ[0] + (s_vhat[s_idx] - s_v[s_idx]) * DWIJ[1]
                   + (s_what[s_idx] - s_w[s_idx]) * DWIJ[2])
            f = s_m[s_idx] / s_rho[s_idx] * ddw
            for i in range(9):
                d_asd[9 * d_idx + i] += f * (s_sd[9 * s_idx + i] - d_sd[9 * d_idx + i])


class DeviatoricStressForce(Equation):
    """du_a/dt += sum_b m_b (sigma'_a / rho_a^2 + sigma'_b / rho_b^2) . grad_a W_ab, the deviatoric
    part of the solid momentum equation (Adepu & Ramachandran 2021, eq. 30; the pressure
    and Pi_ab parts are :class:`~sphgen.equations.momentum.PressureGradient` and
    :class:`~sphgen.equations.momentum.ArtificialViscosity`).  Antisymmetric pair by pair:
    it conserves linear momentum."""

    def loop(self, d_idx, d_au, d_av, d_aw, d_rho, d_sd, s_idx, s_m, s_rho, s_sd, DWIJ):
        ra = 1.0 / (d_rho[d_idx] * d_rho[d_idx])
        rb = 1.0 / (s_rho[s_idx] * s_rho[s_idx])
        mb = s_m[s_idx]
        f = declare("matrix(3)")
        for i in range(3):
            s = 0.0
            for j in range(3):
                s += (d_sd[9 * d_idx + 3 * i + j] * ra + s_sd[9 * s_idx + 3 * i + j] * rb) * DWIJ[j]
            f[i] = mb * s
        d_au[d_idx] += f[0]
        d_av[d_idx] += f[1]
        d_aw[d_idx] += f[2]


class PerfectPlasticity(Equation):
    """sigma' <- beta sigma', beta = min(sqrt(Y0^2 / (3 J2)), 1), J2 = sigma':sigma' / 2: elastic,
    perfectly plastic von Mises (Adepu & Ramachandran 2021, section 4.7, with the square
    root of the radial return; ``literal=True`` takes beta = min(Y0^2 / (3 J2), 1) as
    printed).  No sources: run it on the updated stress, before the momentum equation."""

    positive = ("yield_stress",)
    switches = ("literal",)

    def __init__(self, dest, sources=None, yield_stress=1.0, literal=False):
        super().__init__(dest, None, yield_stress=yield_stress, literal=bool(literal))

    def initialize(self, d_idx, d_sd):
        j2 = 0.0
        for i in range(9):
            j2 += d_sd[9 * d_idx + i] * d_sd[9 * d_idx + i]
        j2 = 0.5 * j2
        if j2 > 0.0:
            f = self.yield_stress * self.yield_stress / (3.0 * j2)
            if not self.literal:
                f = sqrt(f)
            if f < 1.0:
                for i in range(9):
                    d_sd[9 * d_idx + i] *= f
