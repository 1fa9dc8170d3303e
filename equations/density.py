"""Density re-initialisation for schemes that evolve the density by continuity."""
from sphgen.equation import Equation


class SaveDensity(Equation):
    """rho*_a = rho_a: the density before a re-initialisation, read by the neighbours of the
    next group (its own group cannot both write rho and read the neighbours' rho).  No sources."""

    def __init__(self, dest, sources=None):
        super().__init__(dest, None)

    def initialize(self, d_idx, d_rho, d_rhostar):
        d_rhostar[d_idx] = d_rho[d_idx]


class CorrectedSummationDensity(Equation):
    """rho_a = sum_b m_b W_ab / min(1, sum_b m_b W_ab / rho*_b): summation density, divided
    by the Shepard sum where the support is incomplete (Zhang, Hu & Adams 2017, eq. 13).
    Needs :class:`SaveDensity` in an earlier group; writes ``rho`` and ``shepard``."""

    def initialize(self, d_idx, d_rho, d_shepard):
        d_rho[d_idx] = 0.0
        d_shepard[d_idx] = 0.0

    def loop(self, d_idx, d_rho, d_shepard, s_idx, s_m, s_rhostar, WIJ):
        mw = s_m[s_idx] * WIJ
        d_rho[d_idx] += mw
        d_shepard[d_idx] += mw / s_rhostar[s_idx]

    def post_loop(self, d_idx, d_rho, d_shepard):
        d_rho[d_idx] = d_rho[d_idx] / min(1.0, d_shepard[d_idx])
