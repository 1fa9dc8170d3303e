"""The time loop: dt control, output schedule, progress bar, blow-up guard, restart."""
import math
import os
import time

import numpy as np

from . import io


class BlowUpError(RuntimeError):
    """A non-finite value appeared; the message says where, the last good state is on disk."""


class Solver:
    """Advance a :class:`~sphgen.scene.Scene` with an integrator from t to tf.

    dt: fixed step, or the largest step when ``adaptive`` is on; adaptive steps use
    ``dt_props``: per-particle admissible steps written by equations (e.g. ``dt_cfl``),
    the step is ``cfl * min`` over all arrays that have them.
    """

    def __init__(self, scene, integrator, dt, tf, *, adaptive=False, dt_props=("dt_cfl",), cfl=1.0,
                 max_steps=None, pfreq=100, output_at_times=(), outdir=None, prefix="sphgen",
                 disable_output=False, progress=True, guard=True, speed_limit=None, sort_every=50):
        if not (isinstance(dt, (int, float)) and math.isfinite(dt) and dt > 0):
            raise ValueError(f"time step dt={dt!r} must be a positive finite number")
        if not (math.isfinite(tf) and tf >= 0):
            raise ValueError(f"final time tf={tf!r} must be a non-negative finite number")
        if pfreq is not None and pfreq < 1:
            raise ValueError(f"output frequency pfreq={pfreq!r} must be >= 1")
        self.scene = scene
        self.integrator = integrator
        integrator.attach(scene)
        if adaptive and not any(p in pa.data for pa in scene.arrays for p in dt_props):
            raise ValueError(f"adaptive time step reads {', '.join(dt_props)}, which no array of the "
                             "scene computes: add an equation that writes it and list it in the "
                             "scene's outputs so the generator keeps it")
        self.dt = float(dt)
        self.tf = float(tf)
        self.adaptive = adaptive
        self.dt_props = tuple(dt_props)
        self.cfl = cfl
        self.max_steps = max_steps
        self.pfreq = pfreq
        self.output_at_times = sorted(output_at_times)
        self.outdir = outdir
        self.prefix = prefix
        self.disable_output = disable_output or outdir is None
        self.progress = progress
        self.guard = guard
        self.speed_limit = speed_limit
        # particles drift away from their memory neighbours; re-sorting keeps the
        # neighbour loops cache-friendly (carry a 'gid' property to track particles)
        self.sort_every = sort_every
        self.t = 0.0
        self.step = 0
        self.post_step_callbacks = []
        self.wall_time = 0.0
        self.outputs_written = []
        self._good = None
        self.restarted = False

    # ---------------------------------------------------------------- state
    def restart_from(self, path):
        """Load arrays and time from an output file written by a run of the same scene."""
        data = io.load(path)
        for pa in self.scene.arrays:
            if pa.name not in data["arrays"]:
                raise ValueError(f"restart file {path} has no array '{pa.name}'")
            src = data["arrays"][pa.name]
            if src.n != pa.n:
                raise ValueError(f"restart file {path}: array '{pa.name}' has {src.n} particles, "
                                 f"the scene has {pa.n}")
            for name, arr in pa.data.items():
                if name in src.data:
                    arr[:] = src.data[name]
            for name, arr in pa.constants.items():
                if name in src.constants:
                    arr[:] = src.constants[name]
        sd = data["solver_data"]
        self.t, self.step = float(sd["t"]), int(sd["step"])
        self.restarted = True
        self.scene.update_nnps()

    def _snapshot(self):
        if self._good is None:
            self._good = {(pa.name, k): np.empty_like(v) for pa in self.scene.arrays for k, v in pa.data.items()}
        for pa in self.scene.arrays:
            for k, v in pa.data.items():
                np.copyto(self._good[(pa.name, k)], v)
        self._good_t, self._good_step = self.t, self.step

    def _restore_snapshot(self):
        for pa in self.scene.arrays:
            for k, v in pa.data.items():
                np.copyto(v, self._good[(pa.name, k)])

    def write_output(self, path=None):
        if self.outdir is None:
            return None
        path = path or os.path.join(self.outdir, f"{self.prefix}_{self.step:06d}.h5")
        io.write(path, self.scene.arrays, {"t": self.t, "dt": self.dt, "step": self.step})
        return path

    # ---------------------------------------------------------------- dt
    def next_dt(self):
        dt = self.dt
        if self.adaptive:
            for pa in self.scene.arrays:
                for p in self.dt_props:
                    if p in pa.data and pa.n:
                        dt = min(dt, self.cfl * float(pa.data[p].min()))
            if not (dt > 0 and math.isfinite(dt)):
                raise BlowUpError(f"adaptive time step became {dt!r} at t={self.t:.6g}, step {self.step}")
        for tout in self.output_at_times:
            if self.t < tout < self.t + dt * (1 + 1e-12):
                dt = tout - self.t
                break
        if self.t + dt > self.tf:
            dt = self.tf - self.t
        return dt

    def _should_output(self, tprev):
        if self.disable_output:
            return False
        if self.pfreq and self.step % self.pfreq == 0:
            return True
        return any(tprev < tout <= self.t + 1e-12 for tout in self.output_at_times)

    # ---------------------------------------------------------------- loop
    def run(self):
        """Step until tf (or max_steps). Returns the number of steps taken."""
        if self.outdir:
            os.makedirs(self.outdir, exist_ok=True)
        t_start = time.perf_counter()
        integ = self.integrator
        if not self.restarted:
            # a restart file carries the accelerations of its step: recomputing them from
            # the end-of-step velocities would not reproduce the uninterrupted run
            integ.initial_accelerations(self.t, self.dt)
        if not self.disable_output and self.step == 0:
            self.outputs_written.append(self.write_output())
        bar = None
        if self.progress:
            from tqdm import tqdm
            bar = tqdm(total=self.tf, unit="t", bar_format="{l_bar}{bar}| t={n:.4g}/{total:.4g} "
                       "[{elapsed}<{remaining}{postfix}]", leave=False, mininterval=0.5)
            bar.update(self.t)
        if self.guard:
            self._snapshot()
        eps = 1e-12 * max(1.0, self.tf)
        try:
            while self.t < self.tf - eps:
                if self.max_steps is not None and self.step >= self.max_steps:
                    break
                dt = self.next_dt()
                tprev = self.t
                try:
                    integ.one_timestep(self.t, dt)
                except ValueError:
                    # e.g. the neighbour search met a non-finite position mid-step
                    bad = self.scene.check_finite() if self.guard else None
                    if bad is None:
                        raise
                    self.step += 1
                    self.t += dt
                    self._blow_up(bad, dt)
                self.t += dt
                self.step += 1
                self.last_dt = dt
                if self.guard:
                    bad = self.scene.check_finite()
                    if bad is not None:
                        self._blow_up(bad, dt)
                    if self.speed_limit is not None:
                        self._check_speed(dt)
                    self._snapshot()
                if self.sort_every and self.step % self.sort_every == 0:
                    self.scene.sort()
                for cb in self.post_step_callbacks:
                    cb(self)
                if self._should_output(tprev):
                    self.outputs_written.append(self.write_output())
                if bar is not None:
                    bar.update(self.t - tprev)
                    if self.step % 50 == 0:
                        bar.set_postfix_str(f"step={self.step}, dt={dt:.3g}", refresh=False)
        finally:
            if bar is not None:
                bar.close()
            self.wall_time += time.perf_counter() - t_start
        if not self.disable_output and (not self.outputs_written or
                                        not self.outputs_written[-1].endswith(f"_{self.step:06d}.h5")):
            self.outputs_written.append(self.write_output())
        if not self.disable_output:
            io.write_xdmf(self.outdir, self.prefix)
        return self.step

    def _check_speed(self, dt):
        """A particle faster than the scheme's limit (e.g. Mach 1 for weak compressibility)."""
        for name, speed2, i in self.scene.max_speed2():
            if speed2 > self.speed_limit ** 2:
                what = (f"speed {np.sqrt(speed2):.3g} of {name} particle {i} exceeds the "
                        f"scheme's limit {self.speed_limit:.3g}")
                self._blow_up(None, dt, what)

    def _blow_up(self, bad, dt, what=None):
        if what is None:
            arr, prop, idx = bad
            what = f"non-finite {arr}.{prop} at particle {idx}"
        where = f"{what}, step {self.step} (t={self.t:.6g}, dt={dt:.3g})"
        saved = ""
        if self._good is not None:
            # the arrays go back to the last good state, for post-mortem in memory and on disk
            self._restore_snapshot()
            self.t, self.step = self._good_t, self._good_step
            if self.outdir is not None:
                path = self.write_output(os.path.join(self.outdir, f"{self.prefix}_last_good.h5"))
                saved = f"; last good state (step {self.step}, t={self.t:.6g}) written to {path}"
        raise BlowUpError(where + saved)
