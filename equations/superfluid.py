"""Two-fluid (Landau-Tisza) SPH of helium-4: the pair forms of Kincl (2023, thesis) eqs. 3.34 and 3.38-3.39.

One particle kind carries m, rho, s, the barycentric velocity v = (u, v, w), the superfluid
velocity v_s = (us, vs, ws) and a type ``ptype``: FLUID, ADIABATIC (solid wall: v = v_s = 0,
no heat across) or COOLER (solid wall held at s = s0, so T = T0).  :class:`SuperfluidState`
derives per particle rho_n/rho (``rhon``), v_ns = (v - v_s)/rho_n (``uns, vns, wns``),
v_n = (v - rho_s v_s)/rho_n (``un, vn, wn``), p and T of the linear model
(:mod:`.superfluid_energy`), and J/rho^2 = rho_s s v_ns/rho (``jx, jy, jz``), the entropy
flux J = rho rho_s s v_ns over rho^2.

The operators are the zero-order ones of eq. 2.36 and their duals (eq. 2.46 with R = I):
div_a{phi} = -1/rho_a sum_b m_b phi_ab . grad W_ab and
div*_a(psi) = rho_a sum_b m_b (psi_a/rho_a^2 + psi_b/rho_b^2) . grad W_ab.  Written out
(grad W_ab is ``DWIJ``, P = p/rho^2, Q = rho_s rho_n/rho):

* ds_a/dt = -sum_b m_b (J_a/rho_a^2 + J_b/rho_b^2) . grad W_ab                (:class:`EntropyFlux`)
* dv_a/dt = -sum_b m_b [(P_a + P_b) grad W_ab + Q_a (v_ns,a . grad W_ab) v_ns,a
  + Q_b (v_ns,b . grad W_ab) v_ns,b]                  (:class:`SuperfluidPressure`, :class:`CounterflowStress`)
* dv_s,a/dt = -sum_b m_b (P_a + P_b) grad W_ab - rho_n,a/rho_a sum_b m_b (v_n,ab . v_ns,a) grad W_ab
  - s_a/rho_a sum_b m_b (T_a - T_b) grad W_ab
  (:class:`SuperfluidPressure`, :class:`CounterflowCoupling`, :class:`Thermomechanical`)

and the irreversible part (eqs. 3.38-3.39, F_ab = W'_ab/r_ab <= 0, d the dimension):

* ds_a/dt += 2 beta sum_b m_b F_ab T_ab/(rho_a rho_b) + zeta_a/(T_a rho_a)  (:class:`EntropyProduction`)
* zeta_a = -beta sum_b m_b/rho_b F_ab T_ab^2
  - mu (d+2) sum_b m_b/rho_b F_ab (v_n,ab . x_ab)^2/(r_ab^2 + eta^2)  (>= 0)
* dv_a/dt += 2 mu (d+2) sum_b m_b F_ab/(rho_a rho_b) (v_n,ab . x_ab)/(r_ab^2 + eta^2) x_ab
  (:class:`NormalViscosity`)

A pair with an ADIABATIC partner, on either side, carries no entropy flux, no entropy
diffusion and no thermomechanical force (``masked``; the mask is symmetric in a and b, so
the conservation identities of Theorems 9-10 hold with it).  With no ADIABATIC particle in
the scene ``masked`` is 0 and the test disappears from the generated code; ``beta`` and
``mu`` are switches, so at 0 their terms disappear too.
"""
from math import sqrt  # noqa: F401  (the Python evaluator's math)

from sphgen.equation import Equation

from .basic import SummationDensityWithConstant  # noqa: F401  (re-exported)
from .superfluid_energy import linear_pressure, linear_temperature, normal_fraction

FLUID, ADIABATIC, COOLER = 0, 1, 2
"""Values of the integer property ``ptype`` (the literals 0, 1, 2 in the compiled code)."""


class SuperfluidState(Equation):
    """rho_n/rho, v_ns, v_n, p, T and J/rho^2 of each particle (Kincl 2023, eqs. 3.1-3.3, 3.25, 3.27, 3.30).

    ``renormalise``: J/rho^2 is divided by the particle's thermal normalisation ``lam``
    (:class:`ThermalNormalisation`)."""

    switches = ("dim", "renormalise")

    def __init__(self, dest, sources=None, dim=2, T0=1.0, rho0=1.0, s0=1.0, rhon0=0.5, c1=1.0,
                 cv=1.0, gamma=0.0, renormalise=0):
        super().__init__(dest, None, dim=dim, T0=T0, rho0=rho0, s0=s0, rhon0=rhon0, c1=c1, cv=cv,
                         gamma=gamma, renormalise=renormalise)

    def post_loop(self, d_idx, d_rho, d_s, d_u, d_v, d_w, d_us, d_vs, d_ws, d_rhon, d_uns, d_vns,
                  d_wns, d_un, d_vn, d_wn, d_p, d_T, d_jx, d_jy, d_jz, d_lam):
        rhon = normal_fraction(d_s[d_idx], self.s0, self.rhon0, self.gamma)
        rhos = 1.0 - rhon
        irn = 1.0 / rhon
        uns = (d_u[d_idx] - d_us[d_idx]) * irn
        vns = (d_v[d_idx] - d_vs[d_idx]) * irn
        vns2 = uns * uns + vns * vns
        d_un[d_idx] = (d_u[d_idx] - rhos * d_us[d_idx]) * irn
        d_vn[d_idx] = (d_v[d_idx] - rhos * d_vs[d_idx]) * irn
        if self.dim > 2:
            wns = (d_w[d_idx] - d_ws[d_idx]) * irn
            vns2 += wns * wns
            d_wns[d_idx] = wns
            d_wn[d_idx] = (d_w[d_idx] - rhos * d_ws[d_idx]) * irn
        d_rhon[d_idx] = rhon
        d_uns[d_idx] = uns
        d_vns[d_idx] = vns
        d_p[d_idx] = linear_pressure(d_rho[d_idx], self.rho0, self.c1)
        d_T[d_idx] = linear_temperature(d_s[d_idx], vns2, self.T0, self.s0, self.cv, self.gamma)
        f = rhos * d_s[d_idx] / d_rho[d_idx]
        if self.renormalise:
            f = f / d_lam[d_idx]
        d_jx[d_idx] = f * uns
        d_jy[d_idx] = f * vns
        if self.dim > 2:
            d_jz[d_idx] = f * wns


class EntropyFlux(Equation):
    """ds_a/dt = -sum_b m_b (J_a/rho_a^2 + J_b/rho_b^2) . grad W_ab, J = rho rho_s s v_ns (Kincl 2023, eq. 3.34)."""

    switches = ("dim", "masked")

    def __init__(self, dest, sources, dim=2, masked=0):
        super().__init__(dest, sources, dim=dim, masked=masked)

    def initialize(self, d_idx, d_sdot):
        d_sdot[d_idx] = 0.0

    def loop(self, d_idx, d_sdot, d_jx, d_jy, d_jz, d_ptype, s_idx, s_m, s_jx, s_jy, s_jz, s_ptype,
             DWIJ):
        thermal = 1.0
        if self.masked:
            if d_ptype[d_idx] == 1 or s_ptype[s_idx] == 1:
                thermal = 0.0
        if thermal > 0.0:
            f = (d_jx[d_idx] + s_jx[s_idx]) * DWIJ[0] + (d_jy[d_idx] + s_jy[s_idx]) * DWIJ[1]
            if self.dim > 2:
                f += (d_jz[d_idx] + s_jz[s_idx]) * DWIJ[2]
            d_sdot[d_idx] += -s_m[s_idx] * f


class EntropyProduction(Equation):
    """Entropy diffusion beta and the dissipation zeta_a/(T_a rho_a) of diffusion and normal viscosity (Kincl 2023, eqs. 3.38-3.39)."""

    switches = ("dim", "masked", "beta", "mu")
    nonnegative = ("beta", "mu", "eta2")

    def __init__(self, dest, sources, dim=2, masked=0, beta=0.0, mu=0.0, eta2=0.0):
        super().__init__(dest, sources, dim=dim, masked=masked, beta=beta, mu=mu, eta2=eta2)

    def initialize(self, d_idx, d_zeta):
        if self.beta != 0.0 or self.mu != 0.0:
            d_zeta[d_idx] = 0.0

    def loop(self, d_idx, d_sdot, d_zeta, d_rho, d_T, d_un, d_vn, d_wn, d_ptype, s_idx, s_m, s_rho,
             s_T, s_un, s_vn, s_wn, s_ptype, XIJ, RIJ, R2IJ, WDASHIJ):
        if self.beta != 0.0 or self.mu != 0.0:
            fij = 0.0
            if RIJ > 1e-12:
                fij = WDASHIJ / RIJ
            mb = s_m[s_idx] / s_rho[s_idx]
            if self.beta != 0.0:
                thermal = 1.0
                if self.masked:
                    if d_ptype[d_idx] == 1 or s_ptype[s_idx] == 1:
                        thermal = 0.0
                if thermal > 0.0:
                    tab = d_T[d_idx] - s_T[s_idx]
                    d_sdot[d_idx] += 2.0 * self.beta * mb * fij * tab / d_rho[d_idx]
                    d_zeta[d_idx] += -self.beta * mb * fij * tab * tab
            if self.mu != 0.0:
                vx = (d_un[d_idx] - s_un[s_idx]) * XIJ[0] + (d_vn[d_idx] - s_vn[s_idx]) * XIJ[1]
                if self.dim > 2:
                    vx += (d_wn[d_idx] - s_wn[s_idx]) * XIJ[2]
                d_zeta[d_idx] += -self.mu * (self.dim + 2.0) * mb * fij * vx * vx / (R2IJ + self.eta2)

    def post_loop(self, d_idx, d_sdot, d_zeta, d_T, d_rho):
        if self.beta != 0.0 or self.mu != 0.0:
            d_sdot[d_idx] += d_zeta[d_idx] / (d_T[d_idx] * d_rho[d_idx])


class SuperfluidPressure(Equation):
    """-sum_b m_b (p_a/rho_a^2 + p_b/rho_b^2) grad W_ab on both dv/dt and dv_s/dt (Kincl 2023, eq. 3.34)."""

    switches = ("dim",)

    def __init__(self, dest, sources, dim=2):
        super().__init__(dest, sources, dim=dim)

    def initialize(self, d_idx, d_au, d_av, d_aw, d_aus, d_avs, d_aws):
        d_au[d_idx] = 0.0
        d_av[d_idx] = 0.0
        d_aus[d_idx] = 0.0
        d_avs[d_idx] = 0.0
        if self.dim > 2:
            d_aw[d_idx] = 0.0
            d_aws[d_idx] = 0.0

    def loop(self, d_idx, d_au, d_av, d_aw, d_aus, d_avs, d_aws, d_p, d_rho, s_idx, s_m, s_p, s_rho,
             DWIJ):
        pa = d_p[d_idx] / (d_rho[d_idx] * d_rho[d_idx])
        pb = s_p[s_idx] / (s_rho[s_idx] * s_rho[s_idx])
        f = -s_m[s_idx] * (pa + pb)
        d_au[d_idx] += f * DWIJ[0]
        d_av[d_idx] += f * DWIJ[1]
        d_aus[d_idx] += f * DWIJ[0]
        d_avs[d_idx] += f * DWIJ[1]
        if self.dim > 2:
            d_aw[d_idx] += f * DWIJ[2]
            d_aws[d_idx] += f * DWIJ[2]


class CounterflowStress(Equation):
    """dv_a/dt += -1/rho_a div*_a(rho rho_s rho_n v_ns (x) v_ns) (Kincl 2023, eq. 3.34)."""

    switches = ("dim",)

    def __init__(self, dest, sources, dim=2):
        super().__init__(dest, sources, dim=dim)

    def loop(self, d_idx, d_au, d_av, d_aw, d_rho, d_rhon, d_uns, d_vns, d_wns, s_idx, s_m, s_rho,
             s_rhon, s_uns, s_vns, s_wns, DWIJ):
        qa = (1.0 - d_rhon[d_idx]) * d_rhon[d_idx] / d_rho[d_idx]
        qb = (1.0 - s_rhon[s_idx]) * s_rhon[s_idx] / s_rho[s_idx]
        da = d_uns[d_idx] * DWIJ[0] + d_vns[d_idx] * DWIJ[1]
        db = s_uns[s_idx] * DWIJ[0] + s_vns[s_idx] * DWIJ[1]
        if self.dim > 2:
            da += d_wns[d_idx] * DWIJ[2]
            db += s_wns[s_idx] * DWIJ[2]
        fa = -s_m[s_idx] * qa * da
        fb = -s_m[s_idx] * qb * db
        d_au[d_idx] += fa * d_uns[d_idx] + fb * s_uns[s_idx]
        d_av[d_idx] += fa * d_vns[d_idx] + fb * s_vns[s_idx]
        if self.dim > 2:
            d_aw[d_idx] += fa * d_wns[d_idx] + fb * s_wns[s_idx]


class CounterflowCoupling(Equation):
    """dv_s,a/dt += rho_n,a grad_a{v_n}^T v_ns,a (Kincl 2023, eq. 3.34)."""

    switches = ("dim",)

    def __init__(self, dest, sources, dim=2):
        super().__init__(dest, sources, dim=dim)

    def loop(self, d_idx, d_aus, d_avs, d_aws, d_rho, d_rhon, d_uns, d_vns, d_wns, d_un, d_vn, d_wn,
             s_idx, s_m, s_un, s_vn, s_wn, DWIJ):
        d = (d_un[d_idx] - s_un[s_idx]) * d_uns[d_idx] + (d_vn[d_idx] - s_vn[s_idx]) * d_vns[d_idx]
        if self.dim > 2:
            d += (d_wn[d_idx] - s_wn[s_idx]) * d_wns[d_idx]
        f = -s_m[s_idx] * d_rhon[d_idx] * d / d_rho[d_idx]
        d_aus[d_idx] += f * DWIJ[0]
        d_avs[d_idx] += f * DWIJ[1]
        if self.dim > 2:
            d_aws[d_idx] += f * DWIJ[2]


class Thermomechanical(Equation):
    """dv_s,a/dt += s_a grad_a{T} = -s_a/rho_a sum_b m_b (T_a - T_b) grad W_ab (Kincl 2023, eq. 3.34).

    ``renormalise``: the gradient is divided by ``lam_a`` (:class:`ThermalNormalisation`)."""

    switches = ("dim", "masked", "renormalise")

    def __init__(self, dest, sources, dim=2, masked=0, renormalise=0):
        super().__init__(dest, sources, dim=dim, masked=masked, renormalise=renormalise)

    def loop(self, d_idx, d_aus, d_avs, d_aws, d_s, d_rho, d_T, d_lam, d_ptype, s_idx, s_m, s_T,
             s_ptype, DWIJ):
        thermal = 1.0
        if self.masked:
            if d_ptype[d_idx] == 1 or s_ptype[s_idx] == 1:
                thermal = 0.0
        if thermal > 0.0:
            f = -s_m[s_idx] * d_s[d_idx] * (d_T[d_idx] - s_T[s_idx]) / d_rho[d_idx]
            if self.renormalise:
                f = f / d_lam[d_idx]
            d_aus[d_idx] += f * DWIJ[0]
            d_avs[d_idx] += f * DWIJ[1]
            if self.dim > 2:
                d_aws[d_idx] += f * DWIJ[2]


class ThermalNormalisation(Equation):
    """lam_a = -1/d sum_b (m_b/rho_b) x_ab . grad W_ab over the pairs that carry heat (1 in a
    full, fine support): the scalar first-moment normalisation of the thermal operators
    (not in Kincl 2023; docs/superfluid.md).  Dividing grad T by lam_a and J by lam in the
    entropy flux keeps the pair of operators dual, so Theorem 9 holds."""

    switches = ("dim", "masked")

    def __init__(self, dest, sources, dim=2, masked=0):
        super().__init__(dest, sources, dim=dim, masked=masked)

    def initialize(self, d_idx, d_lam):
        d_lam[d_idx] = 0.0

    def loop(self, d_idx, d_lam, d_ptype, s_idx, s_m, s_rho, s_ptype, XIJ, DWIJ):
        thermal = 1.0
        if self.masked:
            if d_ptype[d_idx] == 1 or s_ptype[s_idx] == 1:
                thermal = 0.0
        if thermal > 0.0:
            xd = XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1]
            if self.dim > 2:
                xd += XIJ[2] * DWIJ[2]
            d_lam[d_idx] += -s_m[s_idx] / s_rho[s_idx] * xd / self.dim

    def post_loop(self, d_idx, d_lam):
        if d_lam[d_idx] < 0.1:   # an isolated particle (or a wall): no renormalisation
            d_lam[d_idx] = 1.0


class NormalViscosity(Equation):
    """dv_a/dt += 2 mu (d+2) sum_b m_b F_ab/(rho_a rho_b) (v_n,ab . x_ab)/(r^2 + eta^2) x_ab (Kincl 2023, eq. 3.38)."""

    switches = ("dim", "mu")
    nonnegative = ("mu", "eta2")

    def __init__(self, dest, sources, dim=2, mu=0.0, eta2=0.0):
        super().__init__(dest, sources, dim=dim, mu=mu, eta2=eta2)

    def loop(self, d_idx, d_au, d_av, d_aw, d_rho, d_un, d_vn, d_wn, s_idx, s_m, s_rho, s_un, s_vn,
             s_wn, XIJ, RIJ, R2IJ, WDASHIJ):
        if self.mu != 0.0:
            fij = 0.0
            if RIJ > 1e-12:
                fij = WDASHIJ / RIJ
            vx = (d_un[d_idx] - s_un[s_idx]) * XIJ[0] + (d_vn[d_idx] - s_vn[s_idx]) * XIJ[1]
            if self.dim > 2:
                vx += (d_wn[d_idx] - s_wn[s_idx]) * XIJ[2]
            f = (2.0 * self.mu * (self.dim + 2.0) * s_m[s_idx] * fij * vx
                 / (d_rho[d_idx] * s_rho[s_idx] * (R2IJ + self.eta2)))
            d_au[d_idx] += f * XIJ[0]
            d_av[d_idx] += f * XIJ[1]
            if self.dim > 2:
                d_aw[d_idx] += f * XIJ[2]


class SuperfluidGravity(Equation):
    """g on both dv/dt and dv_s/dt (Kincl 2023, eq. 3.52)."""

    switches = ("dim",)

    def __init__(self, dest, sources=None, dim=2, gx=0.0, gy=0.0, gz=0.0):
        super().__init__(dest, None, dim=dim, gx=gx, gy=gy, gz=gz)

    def post_loop(self, d_idx, d_au, d_av, d_aw, d_aus, d_avs, d_aws):
        d_au[d_idx] += self.gx
        d_av[d_idx] += self.gy
        d_aus[d_idx] += self.gx
        d_avs[d_idx] += self.gy
        if self.dim > 2:
            d_aw[d_idx] += self.gz
            d_aws[d_idx] += self.gz
