"""Homogenisation (particle shifting) accelerations, selectable independently of the scheme.

Every technique here writes the homogenisation acceleration ``auhat, avhat, awhat``
(:math:`(d\\mathbf u/dt)_c`); a kick-drift-kick stepper turns it into the transport
velocity :math:`\\tilde{\\mathbf u} = \\mathbf u + \\tfrac{\\Delta t}{2}(d\\mathbf u/dt)_c`
(Adepu & Ramachandran 2021, eq. 55) with which particles move.

* ``spst``: Sun et al. (2019) shifting written as an acceleration
  (:class:`SunShiftingAcceleration`; Adepu & Ramachandran 2021, eq. 36);
* ``ipst``: iterative particle shifting of Huang et al. (2019), three groups
  (:class:`IPSTStart`, the iterated :class:`IPSTShift`, :class:`IPSTAcceleration`;
  Adepu & Ramachandran 2021, eqs. 37-41);
* ``gtvf``: the homogenisation of Zhang, Hu & Adams (2017), :class:`GTVFHomogenisation`;
* ``tvf``: the constant background pressure of Adami, Hu & Adams (2013),
  :class:`BackgroundPressureAcceleration`;
* ``none``: no shifting (:math:`\\tilde{\\mathbf u} = \\mathbf u`).

:class:`Shifting` bundles the choice: a scheme asks it for the equations that go into
its momentum group and for the extra groups (IPST), so every scheme offers every
technique without repeating the wiring.
"""
from math import fabs, sqrt  # noqa: F401  (the Python evaluator needs the names)

import numpy as np

from sphgen.equation import Equation, Group, helper

SHIFTINGS = ("spst", "ipst", "gtvf", "tvf", "none")


# ----------------------------------------------------------------------------- SPST
class SunShiftingAcceleration(Equation):
    """(du/dt)_c = -Ma (2h) c0 / dt sum_b [1 + R (W_ab / W(dx))^n] grad W_ab V_b, n = 4
    (Sun et al. 2019 as an acceleration: Adepu & Ramachandran 2021, eq. 36; R = 0.2)."""

    positive = ("mach", "c0", "wdx")
    nonnegative = ("R",)

    def __init__(self, dest, sources, mach=0.1, c0=1.0, wdx=1.0, R=0.2):
        super().__init__(dest, sources, mach=mach, c0=c0, wdx=wdx, R=R)

    def initialize(self, d_idx, d_auhat, d_avhat, d_awhat):
        d_auhat[d_idx] = 0.0
        d_avhat[d_idx] = 0.0
        d_awhat[d_idx] = 0.0

    def loop(self, d_idx, d_auhat, d_avhat, d_awhat, d_h, s_idx, s_m, s_rho, WIJ, DWIJ, dt):
        ratio = WIJ / self.wdx
        ratio2 = ratio * ratio
        fac = -self.mach * 2.0 * d_h[d_idx] * self.c0 / dt * (1.0 + self.R * ratio2 * ratio2)
        vb = s_m[s_idx] / s_rho[s_idx]
        d_auhat[d_idx] += fac * vb * DWIJ[0]
        d_avhat[d_idx] += fac * vb * DWIJ[1]
        d_awhat[d_idx] += fac * vb * DWIJ[2]


# ------------------------------------------------------------------------------ TVF
class BackgroundPressureAcceleration(Equation):
    """(du/dt)_c = -p_b sum_b m_b (1/rho_a^2 + 1/rho_b^2) grad W_ab: the TVF homogenisation
    (Adepu & Ramachandran 2021, eq. 20, in the symmetric form of Adami et al. 2013, eq. 13)."""

    positive = ("pb",)

    def initialize(self, d_idx, d_auhat, d_avhat, d_awhat):
        d_auhat[d_idx] = 0.0
        d_avhat[d_idx] = 0.0
        d_awhat[d_idx] = 0.0

    def loop(self, d_idx, d_auhat, d_avhat, d_awhat, d_rho, s_idx, s_m, s_rho, DWIJ):
        ra = 1.0 / d_rho[d_idx]
        rb = 1.0 / s_rho[s_idx]
        f = -self.pb * s_m[s_idx] * (ra * ra + rb * rb)
        d_auhat[d_idx] += f * DWIJ[0]
        d_avhat[d_idx] += f * DWIJ[1]
        d_awhat[d_idx] += f * DWIJ[2]


# ----------------------------------------------------------------------------- GTVF
@helper
def kernel_norm(fac=1.0, hi=1.0, dim=2):
    """A kernel's normalisation a_d / h^d from a_d (``fac``) and 1/h (``hi``)."""
    s = fac * hi
    if dim > 1:
        s = s * hi
    if dim > 2:
        s = s * hi
    return s


@helper
def quintic_dwdr(r=0.0, h=1.0, fac=1.0, dim=2):
    """dW/dr of the quintic spline at any smoothing length h (``fac`` is its normalisation
    sigma_d).  The scene's kernel is callable only at h_ab (the DWIJ symbol); this helper
    gives the reduced-h gradient of the GTVF and is tested against sphgen.kernels."""
    hi = 1.0 / h
    q = r * hi
    a = 3.0 - q
    b = 2.0 - q
    c = 1.0 - q
    val = 0.0
    if q < 1.0:
        val = a * a * a * a - 6.0 * b * b * b * b + 15.0 * c * c * c * c
    elif q < 2.0:
        val = a * a * a * a - 6.0 * b * b * b * b
    elif q < 3.0:
        val = a * a * a * a
    return -5.0 * kernel_norm(fac, hi, dim) * val * hi


@helper
def wendland_dwdr(r=0.0, h=1.0, fac=1.0, dim=2):
    """dW/dr of the Wendland C2 kernel at any smoothing length h (``fac`` its a_d), as
    :func:`quintic_dwdr` for the reduced-h gradient of the GTVF (Wendland 1995)."""
    hi = 1.0 / h
    q = r * hi
    val = 0.0
    if q < 2.0:
        t = 1.0 - 0.5 * q
        val = -5.0 * q * t * t * t
    return kernel_norm(fac, hi, dim) * val * hi


REDUCED_KERNELS = {"QuinticSpline": 0, "WendlandQuinticC2": 1}
"""Kernels whose gradient GTVFHomogenisation can take at a reduced h (``kernel`` switch)."""


class BodyPressureMax(Equation):
    """p_max = max_b |p_b| over the destination body, after the group (a reduction): the
    cap of the GTVF homogenisation's p0 with ``body_cap`` (:class:`GTVFHomogenisation`)."""

    def __init__(self, dest, sources=None):
        super().__init__(dest, None)

    def reduce(self, dst, t, dt):
        dst.p_max[0] = float(np.abs(dst.p).max()) if dst.n else 0.0


class GTVFHomogenisation(Equation):
    """(du/dt)_c = -p0_a sum_b m_b / rho_a^2 grad W(r_ab, hfac h_ab), p0_a = min(10 |p_a|, p_ref)
    (Zhang, Hu & Adams 2017, eqs. 22-23 with the sign of their eq. 25 moved in; hfac = 0.5).

    ``fac`` is the normalisation of the scene's kernel for ``dim`` (``kernel.fac``),
    ``kernel`` 0 for the quintic spline, 1 for the Wendland C2 (:data:`REDUCED_KERNELS`);
    ``hfac`` = 1 uses the scene kernel's DWIJ directly.  ``body_cap`` = 1: p0_a =
    min(10 |p_a|, p_max), p_max = max_b |p_b| of the body (the constant ``p_max`` that
    :class:`BodyPressureMax` sets every evaluation) instead of the fixed ``p_ref``.
    """

    positive = ("p_ref", "hfac", "fac")
    switches = ("dim", "hfac", "kernel", "body_cap")

    def __init__(self, dest, sources, p_ref=1.0, hfac=0.5, fac=1.0, dim=2, kernel=0, body_cap=0):
        super().__init__(dest, sources, p_ref=p_ref, hfac=hfac, fac=fac, dim=int(dim), kernel=int(kernel),
                         body_cap=int(body_cap))

    def initialize(self, d_idx, d_auhat, d_avhat, d_awhat):
        d_auhat[d_idx] = 0.0
        d_avhat[d_idx] = 0.0
        d_awhat[d_idx] = 0.0

    def loop(self, d_idx, d_auhat, d_avhat, d_awhat, d_p, d_rho, d_p_max, s_idx, s_m, XIJ, RIJ, HIJ, DWIJ):
        cap = self.p_ref
        if self.body_cap == 1:
            cap = d_p_max[0]
        p0 = min(10.0 * fabs(d_p[d_idx]), cap)
        ra = 1.0 / d_rho[d_idx]
        f = -p0 * s_m[s_idx] * ra * ra
        if self.hfac == 1.0:
            d_auhat[d_idx] += f * DWIJ[0]
            d_avhat[d_idx] += f * DWIJ[1]
            d_awhat[d_idx] += f * DWIJ[2]
        elif RIJ > 1e-12:
            dwdr = 0.0
            if self.kernel == 1:
                dwdr = wendland_dwdr(RIJ, self.hfac * HIJ, self.fac, self.dim)
            else:
                dwdr = quintic_dwdr(RIJ, self.hfac * HIJ, self.fac, self.dim)
            g = f * dwdr / RIJ
            d_auhat[d_idx] += g * XIJ[0]
            d_avhat[d_idx] += g * XIJ[1]
            d_awhat[d_idx] += g * XIJ[2]


# ----------------------------------------------------------------------------- IPST
class ZeroHomogenisation(Equation):
    """(du/dt)_c = 0: the steps between two IPST evaluations carry no shift."""

    def initialize(self, d_idx, d_auhat, d_avhat, d_awhat):
        d_auhat[d_idx] = 0.0
        d_avhat[d_idx] = 0.0
        d_awhat[d_idx] = 0.0


class IPSTStart(Equation):
    """Save r^0 and zero the accumulated shift before the IPST iterations
    (Adepu & Ramachandran 2021, section 3.3.2).  No sources."""

    switches = ("dim",)

    def __init__(self, dest, sources=None, dim=2):
        super().__init__(dest, None, dim=int(dim))

    def initialize(self, d_idx, d_x, d_y, d_z, d_ipst_x0, d_ipst_y0, d_ipst_z0,
                   d_ipst_sx, d_ipst_sy, d_ipst_sz):
        d_ipst_x0[d_idx] = d_x[d_idx]
        d_ipst_sx[d_idx] = 0.0
        if self.dim > 1:
            d_ipst_y0[d_idx] = d_y[d_idx]
            d_ipst_sy[d_idx] = 0.0
        if self.dim > 2:
            d_ipst_z0[d_idx] = d_z[d_idx]
            d_ipst_sz[d_idx] = 0.0

    def reduce(self, dst, t, dt):
        dst.ipst_iter[0] = 0.0


class IPSTShift(Equation):
    """One IPST iteration: chi_a = h^2 sum_b W_ab (eq. 40) and
    delta r_a = U_max dt sum_b V_b n_ab W_ab, n_ab = r_ab / |r_ab| (eq. 37).

    Put it alone in ``Group(iterate=True, update_nnps=True)``.  ``reduce`` (numpy)
    applies the shift r <- r + delta r (eq. 38) unless the configuration it was computed
    on already satisfies |max_a chi_a - chi_ref| <= tolerance (eq. 39); the first sweep
    always shifts, so every IPST evaluation moves the particles at least once, as in the
    paper.  ``chi_ref`` is the initial-configuration value (internal flows).
    """

    positive = ("umax", "chi_ref", "tolerance")
    switches = ("dim", "near_surface")

    def __init__(self, dest, sources, umax=1.0, chi_ref=1.0, tolerance=0.02, dim=2, near_surface=False):
        super().__init__(dest, sources, umax=umax, chi_ref=chi_ref, tolerance=tolerance, dim=int(dim),
                         near_surface=bool(near_surface))
        self.inhomogeneity = np.inf
        self.shifted = True

    def initialize(self, d_idx, d_ipst_dx, d_ipst_dy, d_ipst_dz, d_ipst_chi):
        d_ipst_chi[d_idx] = 0.0
        d_ipst_dx[d_idx] = 0.0
        if self.dim > 1:
            d_ipst_dy[d_idx] = 0.0
        if self.dim > 2:
            d_ipst_dz[d_idx] = 0.0

    def loop(self, d_idx, d_h, d_ipst_dx, d_ipst_dy, d_ipst_dz, d_ipst_chi, s_idx, s_m, s_rho,
             XIJ, RIJ, WIJ, dt):
        h = d_h[d_idx]
        d_ipst_chi[d_idx] += h * h * WIJ
        if RIJ > 1e-12:
            f = self.umax * dt * s_m[s_idx] / s_rho[s_idx] * WIJ / RIJ
            d_ipst_dx[d_idx] += f * XIJ[0]
            if self.dim > 1:
                d_ipst_dy[d_idx] += f * XIJ[1]
            if self.dim > 2:
                d_ipst_dz[d_idx] += f * XIJ[2]

    def post_loop(self, d_idx, d_ipst_dx, d_ipst_dy, d_ipst_dz, d_free_surface, d_h_b, d_h, d_normal):
        """``near_surface``: eq. 45, the filter of eq. 44 on every iteration's shift: none on
        a free-surface particle, no normal component where h_b < h (the flags, h_b and the
        normals of the step's start: section 3.5 computes them once per step)."""
        if self.near_surface:
            if d_free_surface[d_idx] > 0.5:
                d_ipst_dx[d_idx] = 0.0
                if self.dim > 1:
                    d_ipst_dy[d_idx] = 0.0
                if self.dim > 2:
                    d_ipst_dz[d_idx] = 0.0
            elif d_h_b[d_idx] < d_h[d_idx]:
                nx = d_normal[3 * d_idx]
                ny = d_normal[3 * d_idx + 1]
                nz = d_normal[3 * d_idx + 2]
                dn = d_ipst_dx[d_idx] * nx
                if self.dim > 1:
                    dn += d_ipst_dy[d_idx] * ny
                if self.dim > 2:
                    dn += d_ipst_dz[d_idx] * nz
                d_ipst_dx[d_idx] -= dn * nx
                if self.dim > 1:
                    d_ipst_dy[d_idx] -= dn * ny
                if self.dim > 2:
                    d_ipst_dz[d_idx] -= dn * nz

    def reduce(self, dst, t, dt):
        sweep = int(dst.ipst_iter[0])
        dst.ipst_iter[0] = sweep + 1
        self.inhomogeneity = abs(float(dst.ipst_chi.max()) - self.chi_ref)
        self.shifted = sweep == 0 or self.inhomogeneity > self.tolerance
        if self.shifted:   # written out: the generator finds what reduce reads as dst.<name>
            dst.x[:] += dst.ipst_dx
            dst.ipst_sx[:] += dst.ipst_dx
            if self.dim > 1:
                dst.y[:] += dst.ipst_dy
                dst.ipst_sy[:] += dst.ipst_dy
            if self.dim > 2:
                dst.z[:] += dst.ipst_dz
                dst.ipst_sz[:] += dst.ipst_dz

    def converged(self):
        return -1 if self.shifted else 1


class IPSTAcceleration(Equation):
    """(du/dt)_c = 2 (r^M - r^0) / dt^2 (eq. 41), then r <- r^0: the shift is applied by the
    integrator through the transport velocity.  No sources; needs ``update_nnps``."""

    switches = ("dim",)

    def __init__(self, dest, sources=None, dim=2):
        super().__init__(dest, None, dim=int(dim))

    def initialize(self, d_idx, d_x, d_y, d_z, d_ipst_x0, d_ipst_y0, d_ipst_z0, d_ipst_sx,
                   d_ipst_sy, d_ipst_sz, d_auhat, d_avhat, d_awhat, dt):
        f = 2.0 / (dt * dt)
        d_auhat[d_idx] = f * d_ipst_sx[d_idx]
        d_x[d_idx] = d_ipst_x0[d_idx]
        if self.dim > 1:
            d_avhat[d_idx] = f * d_ipst_sy[d_idx]
            d_y[d_idx] = d_ipst_y0[d_idx]
        if self.dim > 2:
            d_awhat[d_idx] = f * d_ipst_sz[d_idx]
            d_z[d_idx] = d_ipst_z0[d_idx]


def lattice_chi(kernel, dx, h, dim):
    """chi = h^2 sum_b W(|r_ab|, h) on a square/cubic lattice of spacing dx (eq. 40 at the
    initial configuration of an internal flow on a lattice)."""
    n = int(np.ceil(kernel.radius_scale * h / dx)) + 1
    axis = np.arange(-n, n + 1) * dx
    grid = np.meshgrid(*([axis] * dim), indexing="ij")
    r = np.sqrt(sum(g ** 2 for g in grid)).ravel()
    return float(h * h * sum(kernel.w(float(ri), h) for ri in r))


# ------------------------------------------------------------------- the selection
class Shifting:
    """One homogenisation technique, for any scheme.

    ``kind`` in :data:`SHIFTINGS`.  Parameters: ``dim``, ``h``, ``dx``, ``c0``, ``umax``,
    ``kernel`` (a :mod:`sphgen.kernels` instance), ``mach`` (SPST, default umax/c0),
    ``pb`` (TVF background pressure), ``p_ref`` (GTVF, default rho0 c0^2; 'body': the
    body's largest |p| each step, :meth:`pressure_equations`),
    ``ipst_tolerance``, ``ipst_max_iterations``, ``ipst_interval`` (IPST every k steps),
    ``chi_ref`` (IPST reference, default the lattice value of ``dx``).
    """

    def __init__(self, kind, dim, h, dx, c0, umax, kernel, rho0=1.0, mach=None, pb=None,
                 p_ref=None, ipst_tolerance=0.02, ipst_max_iterations=10, ipst_interval=1,
                 chi_ref=None, gtvf_hfac=0.5):
        if kind not in SHIFTINGS:
            raise ValueError(f"shifting must be one of {', '.join(SHIFTINGS)}; got {kind!r}")
        if kind == "gtvf" and type(kernel).__name__ not in REDUCED_KERNELS and gtvf_hfac != 1.0:
            raise ValueError("gtvf shifting at a reduced h is implemented for the quintic spline and the "
                             "Wendland C2 only")
        if isinstance(p_ref, str) and p_ref != "body":
            raise ValueError(f"p_ref must be a pressure or 'body' (the body's largest |p|), got {p_ref!r}")
        if not (isinstance(ipst_interval, int) and ipst_interval >= 1):
            raise ValueError(f"ipst_interval must be an integer >= 1, got {ipst_interval!r}")
        if not (isinstance(ipst_max_iterations, int) and ipst_max_iterations >= 1):
            raise ValueError(f"ipst_max_iterations must be an integer >= 1, got {ipst_max_iterations!r}")
        self.kind, self.dim, self.h, self.dx, self.c0, self.umax = kind, dim, h, dx, c0, umax
        self.kernel, self.rho0 = kernel, rho0
        self.mach = umax / c0 if mach is None else mach
        self.pb = 2.0 * rho0 * c0 * c0 if pb is None else pb
        self.p_ref = rho0 * c0 * c0 if p_ref is None else p_ref
        self.body_cap = self.p_ref == "body"
        self.ipst_tolerance, self.ipst_max_iterations = ipst_tolerance, ipst_max_iterations
        self.ipst_interval, self.gtvf_hfac = ipst_interval, gtvf_hfac
        self.chi_ref = lattice_chi(kernel, dx, h, dim) if (kind == "ipst" and chi_ref is None) else chi_ref

    @property
    def active(self):
        """Whether particles move with a transport velocity different from u."""
        return self.kind != "none"

    def parameters(self):
        """The settings that matter for the chosen kind (for Scheme.parameters)."""
        out = {"shifting": self.kind}
        if self.kind == "spst":
            out["mach"] = self.mach
        elif self.kind == "tvf":
            out["pb"] = self.pb
        elif self.kind == "gtvf":
            out.update(p_ref=self.p_ref, gtvf_hfac=self.gtvf_hfac)
        elif self.kind == "ipst":
            out.update(ipst_tolerance=self.ipst_tolerance, ipst_max_iterations=self.ipst_max_iterations,
                       ipst_interval=self.ipst_interval, chi_ref=self.chi_ref)
        return out

    def setup_properties(self, pa):
        """Declare what the technique writes on a destination array ``pa``."""
        for p in ("uhat", "vhat", "what", "auhat", "avhat", "awhat"):
            if not pa.has(p):
                pa.add_property(p)
        if self.kind == "gtvf" and self.body_cap and not pa.has("p_max"):
            pa.add_constant("p_max", 0.0)
        if self.kind == "ipst":
            for p in ("ipst_x0", "ipst_y0", "ipst_z0", "ipst_sx", "ipst_sy", "ipst_sz",
                      "ipst_dx", "ipst_dy", "ipst_dz", "ipst_chi"):
                if not pa.has(p):
                    pa.add_property(p)
            if not pa.has("ipst_iter"):
                pa.add_constant("ipst_iter", 0.0)

    def momentum_equations(self, dest, sources):
        """Equations that write (du/dt)_c of ``dest`` inside the momentum group."""
        if self.kind == "spst":
            wdx = self.kernel.w(self.dx, self.h)
            return [SunShiftingAcceleration(dest, sources, mach=self.mach, c0=self.c0, wdx=wdx)]
        if self.kind == "tvf":
            return [BackgroundPressureAcceleration(dest, sources, pb=self.pb)]
        if self.kind == "gtvf":
            return [GTVFHomogenisation(dest, sources, p_ref=1.0 if self.body_cap else self.p_ref,
                                       hfac=self.gtvf_hfac, fac=getattr(self.kernel, "fac", 1.0), dim=self.dim,
                                       kernel=REDUCED_KERNELS.get(type(self.kernel).__name__, 0),
                                       body_cap=self.body_cap)]
        if self.kind == "ipst" and self.ipst_interval > 1:
            return [ZeroHomogenisation(dest)]
        return []

    def pressure_equations(self, dest):
        """Equations to run with the equation of state (after it, in its group): the body's
        largest |p|, the cap of the GTVF p0 when ``p_ref`` is 'body'; [] otherwise."""
        if self.kind == "gtvf" and self.body_cap:
            return [BodyPressureMax(dest)]
        return []

    def _ipst_due(self, t, dt):
        return int(round(t / dt)) % self.ipst_interval == 0

    def groups(self, dests, sources, near_surface=False):
        """Groups to run after the momentum group (IPST: start, iterate, acceleration);
        ``near_surface``: every iteration's shift filtered as eq. 45 (free surfaces)."""
        if self.kind != "ipst":
            return []
        cond = None if self.ipst_interval == 1 else self._ipst_due
        return [Group([IPSTStart(d, dim=self.dim) for d in dests], condition=cond),
                Group([IPSTShift(d, sources, umax=self.umax, chi_ref=self.chi_ref,
                                 tolerance=self.ipst_tolerance, dim=self.dim, near_surface=near_surface)
                       for d in dests],
                      iterate=True, max_iterations=self.ipst_max_iterations, condition=cond,
                      update_nnps=True),
                Group([IPSTAcceleration(d, dim=self.dim) for d in dests], condition=cond,
                      update_nnps=True)]
