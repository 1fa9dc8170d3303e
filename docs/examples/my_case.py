"""A case written outside sphgen: heat diffusion of a sine mode in a periodic box.

    dT/dt = D lap(T) - kappa T,    T(x, y, 0) = sin(2 pi x)   on [0, 1)^2, periodic,

has the exact solution T = exp(-(k^2 D + kappa) t) sin(2 pi x) with k = 2 pi.  The
Laplacian is the Brookshaw (1985) / Cleary & Monaghan (1999) form; time stepping is
explicit Euler.  Run it with::

    python docs/examples/my_case.py --tf 1.0
    python docs/examples/my_case.py --show-plan
    python docs/examples/my_case.py --help

``post_process`` writes ``results.json`` with the measured and the exact amplitude.
"""
import os
from math import pi

import numpy as np

from sphgen import io
from sphgen.app import Application
from sphgen.equation import Equation, Group
from sphgen.errors import InputError
from sphgen.integrators import Integrator, IntegratorStep
from sphgen.nnps import Domain
from sphgen.particles import ParticleArray
from sphgen.scheme import Scheme


# ---------------------------------------------------------------- equations
class HeatEquation(Equation):
    """aT_a = sum_b V_b 2 D (T_a - T_b) r_ab . grad W_ab / (r_ab^2 + 0.01 h^2) - kappa T_a."""

    positive = ("D",)
    nonnegative = ("kappa",)
    switches = ("kappa",)       # kappa = 0 removes the post_loop from the generated code

    def initialize(self, d_idx, d_aT):
        d_aT[d_idx] = 0.0

    def loop(self, d_idx, d_aT, d_T, s_idx, s_T, s_m, s_rho, XIJ, DWIJ, R2IJ, EPS):
        vb = s_m[s_idx] / s_rho[s_idx]
        xdotdw = XIJ[0] * DWIJ[0] + XIJ[1] * DWIJ[1] + XIJ[2] * DWIJ[2]
        d_aT[d_idx] += 2.0 * self.D * vb * (d_T[d_idx] - s_T[s_idx]) * xdotdw / (R2IJ + EPS)

    def post_loop(self, d_idx, d_aT, d_T):
        if self.kappa != 0.0:
            d_aT[d_idx] -= self.kappa * d_T[d_idx]


class TemperatureGradient(Equation):
    """gradT_a = sum_b V_b (T_b - T_a) grad W_ab: a vector (stride 3), for output only."""

    def initialize(self, d_idx, d_gradT):
        for k in range(3):
            d_gradT[3 * d_idx + k] = 0.0

    def loop(self, d_idx, d_gradT, d_T, s_idx, s_T, s_m, s_rho, DWIJ):
        vb = s_m[s_idx] / s_rho[s_idx]
        for k in range(3):
            d_gradT[3 * d_idx + k] += vb * (s_T[s_idx] - d_T[d_idx]) * DWIJ[k]


# ---------------------------------------------------------------- time stepping
class EulerStep(IntegratorStep):
    """T^{n+1} = T^n + dt aT^n."""

    def stage1(self, d_idx, d_T, d_aT, dt):
        d_T[d_idx] += dt * d_aT[d_idx]


class ForwardEuler(Integrator):
    """One evaluation, one stage; particles do not move, so no neighbour update."""

    n_evaluations = 1

    def one_timestep(self, t, dt):
        self.compute_accelerations(0, t, dt)
        self.stage("stage1", t, dt)


# ---------------------------------------------------------------- scheme
class HeatScheme(Scheme):
    output_props = ("x", "y", "T", "m", "h", "rho")

    def __init__(self, array, D, kappa, h):
        self.array, self.D, self.kappa, self.h = array, D, kappa, h

    def setup_properties(self, arrays):
        for pa in arrays:
            pa.add_property("aT")
            pa.add_property("gradT", stride=3)

    def get_equations(self):
        a = self.array
        return [Group([HeatEquation(a, [a], D=self.D, kappa=self.kappa),
                       TemperatureGradient(a, [a])])]

    def get_integrator(self):
        return ForwardEuler(**{self.array: EulerStep()})

    def get_timestep(self):
        dt = 0.1 * self.h * self.h / self.D
        return min(dt, 0.1 / self.kappa) if self.kappa > 0 else dt


# ---------------------------------------------------------------- application
class MyCase(Application):
    """Diffusion of a sine mode in a periodic box (explicit Euler, Brookshaw Laplacian)."""

    tf = 1.0
    pfreq = 50
    dim = 2

    def add_user_options(self, group):
        group.add_argument("--nx", type=int, default=40, help="particles per side (default %(default)s)")
        group.add_argument("--D", type=float, default=0.01, help="diffusivity (default %(default)s)")
        group.add_argument("--kappa", type=float, default=0.0, help="decay rate (default %(default)s)")
        group.add_argument("--output-gradient", action="store_true", help="also compute and write gradT")

    def consume_user_options(self, o):
        if o.nx < 8:
            raise InputError(f"--nx must be at least 8, got {o.nx}")
        if not (np.isfinite(o.D) and o.D > 0 and np.isfinite(o.kappa) and o.kappa >= 0):
            raise InputError("--D must be > 0 and --kappa >= 0")
        self.dx = 1.0 / o.nx
        self.h = self.dx

    def create_particles(self):
        dx = self.dx
        x, y = np.mgrid[dx / 2:1:dx, dx / 2:1:dx]
        x, y = x.ravel(), y.ravel()
        slab = ParticleArray("slab", x=x, y=y, T=np.sin(2 * pi * x), m=np.full(x.size, dx * dx),
                             h=np.full(x.size, self.h), rho=np.ones(x.size))
        return [slab]

    def create_domain(self):
        return Domain(0.0, 1.0, 0.0, 1.0, periodic_in_x=True, periodic_in_y=True)

    def create_scheme(self):
        s = HeatScheme("slab", D=self.options.D, kappa=self.options.kappa, h=self.h)
        if self.options.output_gradient:
            s.output_props = s.output_props + ("gradT",)
        return s

    def post_process(self, outdir):
        slab = self.scene.by_name["slab"]
        t = self.solver.t
        mode = np.sin(2 * pi * slab.x)
        amplitude = float(np.dot(slab.T, mode) / np.dot(mode, mode))
        rate = (2 * pi) ** 2 * self.options.D + self.options.kappa
        exact = float(np.exp(-rate * t))
        results = {"t": t, "amplitude": amplitude, "amplitude_exact": exact,
                   "rel_error": amplitude / exact - 1.0, "nx": self.options.nx,
                   "D": self.options.D, "kappa": self.options.kappa}
        io.write_json(os.path.join(outdir, "results.json"), results)
        print(f"{self.name}: t={t:.4g} amplitude={amplitude:.6f} exact={exact:.6f} "
              f"({100 * results['rel_error']:+.3f}%)")
        return results


if __name__ == "__main__":
    # run as a script the module is '__main__', so give the case its name explicitly
    # (it names the default output folder and the output files)
    MyCase(name="my_case").run()
