"""Kernel-interpolation convergence: the O(h^2) of Theorem 1 of Kincl's thesis (2023), eq. 1.26.

Theorem 1 bounds the continuous interpolation error, |f * W_h - f| <= C h^2 max|lap f| with
C = 1/2 int |x|^2 W_1 dV (5/18 for the 2D Wendland kernel).  The thesis gives the theory only;
this is the numerical study that checks it.  f is a smooth periodic function on the unit square
(two Fourier modes); f * W_h is the lattice sum sum_b V W_h(|x_a - x_b|) f_b over a square
lattice of spacing delta much finer than h (delta = 1/n), done for every lattice point at once
by FFT (the sum is a periodic discrete convolution).  The lattice sum is the quadrature of the
convolution; for f a sum of Fourier modes its error is the aliasing sum of the kernel's Fourier
transform at the reciprocal-lattice vectors 2 pi/delta (Poisson summation), which for a C2
kernel decays as (h/delta)^-(d+3): negligible for h >= 8 delta.  As h -> 0 the error tends to
(C/d) h^2 lap f (Taylor expansion of f; ``leading_constant``), half of Theorem 1's bound in 2D.  ``results.json`` also reports
the check of that: the smallest h redone on a lattice twice as fine (the error changes by
``quadrature_check``, relative), and the lattice's partition of unity max|sum_b V W - 1|.
No particles, no compiled scene: the kernels are sphgen's own (sphgen/kernels.py), evaluated
with the probes' ``kernel_values``.
"""
import math
import os

import numpy as np

from sphgen import io, run_folder
from sphgen.app import Application
from sphgen.errors import InputError
from sphgen.kernels import KERNELS
from sphgen.tools.probes import kernel_values

from .second_sound import loglog_slope

TWO_PI = 2.0 * math.pi
# f = sin(2 pi x) sin(2 pi y) + 1/2 cos(2 pi (x + 2 y)): amplitude and wave vector of each mode
MODES = ((1.0, (1, 1)), (0.5, (1, 2)))


def periodic_function(x, y):
    """The smooth periodic f of the study and its Laplacian."""
    f = np.sin(TWO_PI * x) * np.sin(TWO_PI * y) + 0.5 * np.cos(TWO_PI * (x + 2.0 * y))
    lap = -TWO_PI ** 2 * (2.0 * np.sin(TWO_PI * x) * np.sin(TWO_PI * y) + 2.5 * np.cos(TWO_PI * (x + 2.0 * y)))
    return f, lap


def theorem_1_constant(kernel):
    """C = 1/2 int |x|^2 W_1 dV of Kincl (2023), eq. 1.26 (2D), by the radial quadrature
    int 2 pi r^3 W_1(r) dr by the trapezoidal rule on 20001 points (relative error ~1e-8)."""
    r = np.linspace(0.0, kernel.radius_scale, 20001)
    g = TWO_PI * r ** 3 * kernel_values(kernel, r, 1.0)
    return 0.5 * float(np.sum(0.5 * (g[1:] + g[:-1]) * np.diff(r)))


def lattice_kernel(kernel, h, n):
    """W_h at the periodic offsets of an n x n lattice of the unit square (zero beyond the support)."""
    d = np.minimum(np.arange(n), n - np.arange(n)) / n
    r = np.hypot(d[:, None], d[None, :])
    w = np.zeros((n, n))
    inside = r < kernel.radius_scale * h
    w[inside] = kernel_values(kernel, r[inside], h)
    return w


def interpolation_error(kernel, h, n):
    """max|f * W_h - f| over the lattice points, max|lap f|, and max|sum_b V W_h - 1|."""
    x = np.arange(n) / n
    f, lap = periodic_function(x[:, None], x[None, :])
    w = lattice_kernel(kernel, h, n)
    conv = np.real(np.fft.ifft2(np.fft.fft2(f) * np.fft.fft2(w))) / n ** 2
    return float(np.max(np.abs(conv - f))), float(np.max(np.abs(lap))), float(abs(w.sum() / n ** 2 - 1.0))


def convergence_study(kernel_name, hs, n):
    """Errors per h, the fitted log-log slope, Theorem 1's bound and the quadrature check."""
    kernel = KERNELS[kernel_name](2)
    c = theorem_1_constant(kernel)
    rows = [interpolation_error(kernel, h, n) for h in hs]
    errors = [e for e, _, _ in rows]
    lap = rows[0][1]
    fine = interpolation_error(kernel, min(hs), 2 * n)[0]
    coarse = errors[int(np.argmin(hs))]
    return {"h": list(hs), "error": errors, "slope": loglog_slope(hs, errors),
            "error_over_h2_lap": [e / (h * h * lap) for h, e in zip(hs, errors)],
            "theorem_1_constant": c, "leading_constant": c / kernel.dim,
            "theorem_1_bound": [c * h * h * lap for h in hs],
            "bound_holds": all(e <= c * h * h * lap for h, e in zip(hs, errors)),
            "partition_of_unity_defect": max(p for _, _, p in rows),
            "quadrature_check": abs(coarse - fine) / fine, "max_laplacian": lap}


class SHTCKernelConvergence(Application):
    """Kernel interpolation error against h (Theorem 1 of Kincl's thesis): the O(h^2) slope."""

    dim = 2
    kernels = ("wendland", "quintic", "gaussian", "quartic")

    def add_user_options(self, group):
        group.add_argument("--n", type=int, default=1024,
                           help="lattice points per side of the quadrature lattice (default %(default)s)")
        group.add_argument("--h", type=float, nargs="+", default=[0.01, 0.014, 0.02, 0.028, 0.04],
                           help="smoothing lengths (default %(default)s)")
        group.add_argument("--kernel", nargs="+", choices=sorted(KERNELS), default=list(self.kernels),
                           help="kernels (default %(default)s)")

    def consume_user_options(self, o):
        if not all(math.isfinite(h) and h > 0 for h in o.h):
            raise InputError(f"--h must be positive, got {o.h}")
        if len(o.h) < 2 or len(set(o.h)) < 2:
            raise InputError("--h needs at least two different smoothing lengths for a slope")
        for name in o.kernel:
            support = KERNELS[name].radius_scale
            if max(o.h) * support >= 0.5:
                raise InputError(f"--h {max(o.h)}: the {name} support {support} h must stay below half the box")
        if min(o.h) * o.n < 8:
            raise InputError(f"--h {min(o.h)} is below 8 lattice spacings (1/{o.n}): the quadrature "
                             "error would not be negligible; raise --n")

    def _run(self, argv):
        """No particles and no time loop: the study is a quadrature on a lattice."""
        opts = self.options = self.parser().parse_args(argv)
        if opts.show_plan:
            raise InputError(f"{self.name} compiles no scene (a quadrature on a lattice, no particles): "
                             "there is no plan to show")
        self.consume_user_options(opts)
        self.outdir = opts.directory or f"{self.name}_output"
        run_folder.check_output_folder(self.outdir, opts.overwrite)
        run_folder.prepare_output_folder(self.outdir, opts.overwrite)
        results = self.post_process(self.outdir)
        # a finished run, as the time-loop applications mark theirs (automan does not run it again)
        io.write_json(os.path.join(self.outdir, "info.json"), {"completed": True, "error": None,
                                                               "options": vars(opts)})
        return results

    def post_process(self, outdir):
        """results.json (errors per h, slope, Theorem 1's bound per kernel) and convergence.png."""
        o = self.options
        hs = sorted(o.h)
        results = {"n": o.n, "lattice_spacing": 1.0 / o.n, "function": "sin(2 pi x) sin(2 pi y) + "
                   "0.5 cos(2 pi (x + 2 y))", "kernels": {k: convergence_study(k, hs, o.n) for k in o.kernel}}
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot(os.path.join(outdir, "convergence.png"), results)
        for name, r in results["kernels"].items():
            print(f"shtc_kernel_convergence: {name}: slope {r['slope']:.4f}, error {r['error'][0]:.3e} .. "
                  f"{r['error'][-1]:.3e}, within Theorem 1's bound: {r['bound_holds']}, "
                  f"quadrature check {r['quadrature_check']:.1e}")
        return results

    @staticmethod
    def plot(png_path, results):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        fig, ax = plt.subplots(figsize=(5, 4))
        for name, r in results["kernels"].items():
            line, = ax.loglog(r["h"], r["error"], "o-", label=f"{name} (slope {r['slope']:.2f})")
            ax.loglog(r["h"], r["theorem_1_bound"], ":", color=line.get_color())
        ax.loglog([], [], ":", color="0.4", label="Theorem 1 bound (same colour)")
        ax.set_xlabel("h")
        ax.set_ylabel("max |f * W_h - f|")
        ax.legend(fontsize=7, loc="upper left")
        fig.tight_layout()
        fig.savefig(png_path, dpi=90)
        plt.close(fig)
