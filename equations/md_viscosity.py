"""Physical viscosity in the molecular-dynamics form that Kincl (2023) takes from Monaghan
(thesis eq. 1.81): conserves linear and angular momentum."""
from sphgen.equation import Equation


class MDViscosity(Equation):
    """a_visc,a = f_visc,h/rho_a = (2 (d+2) mu/rho_a) sum_b (m_b/rho_b) (v_ab . x_ab)/(r_ab^2 + eta^2) grad w_ab
    (Kincl 2023, eq. 1.81, with the vector factor grad w_ab that the print omits).

    Writes ``au_visc, av_visc, aw_visc`` (separate from the conservative ``au, av, aw``: the viscous
    Verlet step of Kincl 2023, eq. 1.82, applies it on its own).  ``mu`` is the dynamic
    viscosity rho0 nu, ``eta2`` = eta^2 the regulariser.  Walls with v = 0 among the sources
    give the no-slip condition of the thesis' dummy particles.
    """

    switches = ("dim",)
    nonnegative = ("mu", "eta2")

    def __init__(self, dest, sources, dim=2, mu=0.0, eta2=0.0):
        super().__init__(dest, sources, dim=dim, mu=mu, eta2=eta2)

    def initialize(self, d_idx, d_au_visc, d_av_visc, d_aw_visc):
        d_au_visc[d_idx] = 0.0
        d_av_visc[d_idx] = 0.0
        d_aw_visc[d_idx] = 0.0

    def loop(self, d_idx, d_au_visc, d_av_visc, d_aw_visc, d_rho, s_idx, s_m, s_rho, XIJ, VIJ, DWIJ, R2IJ):
        vx = VIJ[0] * XIJ[0] + VIJ[1] * XIJ[1] + VIJ[2] * XIJ[2]
        f = 2.0 * (self.dim + 2) * self.mu * s_m[s_idx] * vx / (
            d_rho[d_idx] * s_rho[s_idx] * (R2IJ + self.eta2))
        d_au_visc[d_idx] += f * DWIJ[0]
        d_av_visc[d_idx] += f * DWIJ[1]
        d_aw_visc[d_idx] += f * DWIJ[2]
