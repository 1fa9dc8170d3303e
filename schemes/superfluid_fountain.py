"""The superfluid fountain of Kincl (2023, thesis sec. 3.6): the two-fluid scheme with gravity, heater and superleak.

:class:`FountainScheme` is :class:`~sphgen.schemes.superfluid.SuperfluidScheme` (eqs. 3.34,
3.38-3.39, the Verlet-type integrator of sec. 3.4) plus the source terms of eq. 3.52:

* the heater (eq. 3.59, :class:`~sphgen.equations.superfluid_fountain.Heater`) in the
  entropy rate (step 4 of the integrator);
* the superleak (eq. 3.58), stiff, so applied as an exact relaxation of rho_n v_n on v
  (v_s untouched) with the removed kinetic energy returned as entropy, once per step after
  the first drift (between steps 2 and 3: where the authors' code applies it).

Gravity acts on v and v_s (the base scheme's ``gravity``).
"""
import numpy as np

from sphgen.equation import Group
from sphgen.errors import InputError
from sphgen.tools.probes import kernel_values, pairs_within

from ..equations.superfluid_fountain import Heater, WallPressureFloor, superleak_factor, superleak_rate
from ..equations.superfluid import FLUID
from ..equations.superfluid_energy import HELIUM_1_65K, linear_temperature, normal_fraction
from .superfluid import SuperfluidScheme, SuperfluidStep, SuperfluidVerlet


class FountainStep(SuperfluidStep):
    """The stages of :class:`~sphgen.schemes.superfluid.SuperfluidStep` plus the superleak (Kincl 2023, eq. 3.58)."""

    def __init__(self, dim=2, k0=0.0, y_sl=0.0, d_sl=1.0, r_sl=0.0, T0=1.0, s0=1.0, rhon0=0.5, cv=1.0,
                 gamma=0.0):
        super().__init__(dim)
        self.k0, self.yc, self.width, self.half = float(k0), float(y_sl), float(d_sl), float(r_sl)
        self.T0, self.s0, self.rhon0, self.cv, self.gamma = (float(v) for v in (T0, s0, rhon0, cv, gamma))

    def stage8(self, d_idx, d_ptype, d_x, d_y, d_u, d_v, d_us, d_vs, d_s, dt):
        """Superleak over dt: rho_n v_n = v - rho_s v_s times B = exp(-k dt), v_s fixed;
        s += rho_n |v_n|^2 (1 - B^2)/(2 T), the kinetic energy removed (2D)."""
        if d_ptype[d_idx] == 0:
            k = superleak_rate(d_x[d_idx], d_y[d_idx], self.k0, self.yc, self.width, self.half)
            if k > 0.0:
                s = d_s[d_idx]
                rhon = normal_fraction(s, self.s0, self.rhon0, self.gamma)
                rhos = 1.0 - rhon
                nu = d_u[d_idx] - rhos * d_us[d_idx]
                nv = d_v[d_idx] - rhos * d_vs[d_idx]
                uns = (d_u[d_idx] - d_us[d_idx]) / rhon
                vns = (d_v[d_idx] - d_vs[d_idx]) / rhon
                T = linear_temperature(s, uns * uns + vns * vns, self.T0, self.s0, self.cv, self.gamma)
                b = superleak_factor(k, dt)
                d_u[d_idx] = rhos * d_us[d_idx] + b * nu
                d_v[d_idx] = rhos * d_vs[d_idx] + b * nv
                d_s[d_idx] = s + 0.5 * (nu * nu + nv * nv) * (1.0 - b * b) / (rhon * T)


class FountainVerlet(SuperfluidVerlet):
    """:class:`~sphgen.schemes.superfluid.SuperfluidVerlet` with the superleak (stage 8) after the first drift.

    ``wet``: {array: (x, y, m)} of the fluid the walls will meet (the empty space above the
    level): the density constants of the array's wall particles are calibrated as if that
    fluid were there, so a wall reaches its calibrated density (and pressure) when wetted,
    not when dry (docs/superfluid.md, the fountain, decision 3).
    """

    position_time = dict(SuperfluidVerlet.position_time, stage8=0.5)

    def __init__(self, wet=None, kernel=None, **kw):
        super().__init__(**kw)
        self.wet, self.kernel = dict(wet or {}), kernel

    def calibrate_density(self, t, dt):
        super().calibrate_density(t, dt)
        for name, (gx, gy, gm) in self.wet.items():
            pa = self.scene.by_name[name]
            walls = np.flatnonzero(np.asarray(pa.ptype) != FLUID)
            h = pa.h[walls]
            i, j, r = pairs_within((pa.x[walls], pa.y[walls]), (gx, gy), self.kernel.radius_scale * h.max())
            w = kernel_values(self.kernel, r, h[i]) * np.broadcast_to(np.asarray(gm, dtype=float), np.shape(gx))[j]
            pa.crho[walls] -= np.bincount(i, w, minlength=walls.size)

    def sources(self, t, dt):
        """The superleak, between steps 2 and 3 of sec. 3.4."""
        self.stage("stage8", t, dt)


class FountainScheme(SuperfluidScheme):
    """Two-fluid helium-4 with gravity, heater and superleak (Kincl 2023, eqs. 3.52, 3.58-3.59).

    ``heater``: dict(x_heat, y_heat, H, power [W/m], t_ramp); ``superleak``: dict(k0 [1/s],
    y_sl, d_sl, r_sl) (lengths in m); ``wet``: see :class:`FountainVerlet`.  The rest as :class:`SuperfluidScheme`; 2D only
    (the thesis' fountain has translational symmetry); not the reversible variant
    (the sources are not reversible).
    """

    def __init__(self, arrays=("helium",), model=HELIUM_1_65K, heater=None, superleak=None, wet=None, **kw):
        if kw.get("dim", 2) != 2:
            raise InputError("FountainScheme: the fountain is 2D (dim=2)")
        if kw.get("reversible"):
            raise InputError("FountainScheme: the heater and superleak are not reversible")
        super().__init__(arrays=arrays, dim=2, model=model, **kw)
        self.output_props = self.output_props + ("qheat",)
        self.wet = wet
        self.heater = {**dict(x_heat=0.0, y_heat=0.0, H=1.0, power=0.0, t_ramp=0.0), **(heater or {})}
        self.superleak = {**dict(k0=0.0, y_sl=0.0, d_sl=1.0, r_sl=0.0), **(superleak or {})}

    def parameters(self):
        out = super().parameters()
        out.update({f"heater_{k}": v for k, v in self.heater.items()})
        out.update({f"superleak_{k}": v for k, v in self.superleak.items()})
        return out

    def setup_properties(self, arrays):
        super().setup_properties(arrays)
        for pa in arrays:
            if pa.name in self.arrays and not pa.has("qheat"):
                pa.add_property("qheat")

    def _density_state(self):
        groups = super()._density_state()
        last = groups[-1]
        return groups[:-1] + [Group(last.equations + [WallPressureFloor(d) for d in self.arrays])]

    def density_bounds(self):
        """(0.05, 2) rho0: dry walls sit far below rho0 (they are calibrated wet)."""
        return {a: (0.05 * self.model.rho0, 2.0 * self.model.rho0) for a in self.arrays}

    def _entropy_rate(self):
        return super()._entropy_rate() + [Heater(d, **self.heater) for d in self.arrays]

    def get_integrator(self):
        m = self.model
        step = FountainStep(2, T0=m.T0, s0=m.s0, rhon0=m.rhon0, cv=m.cv, gamma=m.gamma, **self.superleak)
        return FountainVerlet(calibrate=self.arrays if self.calibrate else (), wet=self.wet, kernel=self.kernel,
                              **{name: step for name in self.arrays})

    def heater_power(self, arrays):
        """sum_a m_a zeta_heat,a/rho_a: the power the particles received at the last entropy rate [W/m]."""
        return float(sum((pa.m * pa.qheat).sum() for pa in arrays if pa.name in self.arrays))
