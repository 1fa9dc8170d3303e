"""Reversibility of SHTC-SPH for an elastic solid (Kincl, Peshkov, Pavelka & Klika (2023),
sec. 3.6: with tau = infinity the Verlet + Cayley step is time-reversible).

The free beryllium plate of ``beryllium_plate`` (sec. 4.1: same lattice, material, penalty and
bending-mode velocity, optionally scaled by ``--amplitude`` and perturbed by ``--perturb``)
runs ``--steps`` steps forward; the velocities are flipped and it runs the same number of
steps back.  In exact arithmetic every particle returns to its start with the opposite
velocity and A = I; in floating point the return is limited by round-off.

``results.json``: ``return_error`` = max |r - r(0)| / max |r(0)| over the particles (the
measure of issue 10's "returns within 1e-9 relative"), the same error over the largest
displacement of the forward run (``return_error_displacement``), the velocity error
max |v + v(0)| / max |v(0)| (``velocity_error``) and max |A - I| (``distortion_error``).
Plot: return.png (the centre's y against the step, and the total energy).
"""
import math
import os

import numpy as np

from sphgen import io
from sphgen.errors import InputError

from .beryllium_plate import BerylliumPlate


class SHTCReversibility(BerylliumPlate):
    """Free elastic plate (tau = infinity) run forward, velocities flipped, run back."""

    pfreq = 100000
    error_key = "return_error"

    def add_user_options(self, group):
        super().add_user_options(group)
        group.set_defaults(nw=8)
        group.add_argument("--steps", type=int, default=200,
                           help="steps forward, and as many back (default %(default)s)")
        group.add_argument("--amplitude", type=float, default=1.0,
                           help="scale of the bending-mode velocity (default %(default)s)")

    def consume_user_options(self, o):
        super().consume_user_options(o)
        if o.steps < 1:
            raise InputError(f"--steps must be at least 1, got {o.steps}")
        if not (math.isfinite(o.amplitude) and o.amplitude > 0):
            raise InputError(f"--amplitude must be positive, got {o.amplitude}")
        if getattr(o, "restart", None):
            raise InputError("shtc_reversibility: --restart cannot continue the forward-and-back run "
                             "(its start and forward displacement are not in the output files); "
                             "run it from the start")
        # the run is counted in steps: an end time never shortens the last step
        # (the plate's steps are ~1e-8 s: 1 s is never reached)
        o.max_steps, o.tf = 2 * o.steps, 1.0

    def create_particles(self):
        arrays = super().create_particles()
        pa = arrays[0]
        self._v0 *= self.options.amplitude
        pa.v[:] = self._v0
        self.start = {c: pa.get(c).copy() for c in ("x", "y", "u", "v")}
        self.moved = 0.0
        return arrays

    def post_step(self, solver):
        pa = self.scene.by_name["plate"]
        if not self.history:
            self.record(0.0, first=True)
        self.record(solver.t)
        if solver.step == self.options.steps:
            g = pa.gid
            self.moved = float(np.hypot(pa.x - self.start["x"][g], pa.y - self.start["y"][g]).max())
            pa.u[:] *= -1.0
            pa.v[:] *= -1.0

    def post_process(self, outdir):
        """results.json (the return errors) and return.png."""
        pa = self.scene.by_name["plate"]
        g, s = pa.gid, self.start
        back = float(np.hypot(pa.x - s["x"][g], pa.y - s["y"][g]).max())
        scale = float(np.hypot(s["x"], s["y"]).max())
        dv = float(np.hypot(pa.u - s["u"][g], pa.v + s["v"][g]).max())   # u(0) = 0: only v flips sign
        A = np.asarray(pa.A).reshape(-1, 3, 3)
        rows = np.array(self.history)
        results = {"steps": self.options.steps, "nw": self.options.nw, "dt": self.solver.dt,
                   "amplitude": self.options.amplitude, "perturb": self.options.perturb,
                   "cp_factor": self.options.cp_factor,
                   "return_error": back / scale, "return_error_displacement": back / self.moved,
                   "displacement_forward": self.moved,
                   "velocity_error": dv / float(np.hypot(s["u"], s["v"]).max()),
                   "distortion_error": float(np.abs(A - np.eye(3)).max()),
                   "energy_drift": float(np.abs(rows[:, -1] / rows[0, -1] - 1.0).max())}
        io.write_json(os.path.join(outdir, "results.json"), results)
        self.plot_return(os.path.join(outdir, "return.png"), rows)
        print(f"shtc_reversibility: {self.options.steps} steps forward and back: position error "
              f"{results['return_error']:.3g} of the body's size, {results['return_error_displacement']:.3g} "
              f"of its motion; velocity {results['velocity_error']:.3g}; |A - I| {results['distortion_error']:.3g}")
        return results

    def plot_return(self, path, rows):
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
        step = np.arange(rows.shape[0])
        fig, (a, b) = plt.subplots(1, 2, figsize=(10, 3.6))
        a.plot(step, rows[:, 1], "r-")
        a.axvline(self.options.steps, color="k", lw=0.6, ls="--")
        a.set_xlabel("step (velocities flipped at the dashed line)")
        a.set_ylabel("y of the centre [m]")
        b.plot(step, rows[:, -1] / rows[0, -1] - 1.0)
        b.set_xlabel("step")
        b.set_ylabel("E_total / E_total(0) - 1")
        fig.tight_layout()
        fig.savefig(path, dpi=100)
        plt.close(fig)
