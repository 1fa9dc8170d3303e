"""The time loop: dt control, output schedule, progress bar, blow-up guard, restart.

``Solver.run`` is the few steps a reader expects: prepare, then per step advance,
check, after-step work (sorting, callbacks, output), then finish.  Output is always
consistent on disk: every HDF5 file is complete or absent, and the XDMF index is
rewritten (atomically) after each output, so ParaView opens a killed run.
"""
import math
import os
import time

import numpy as np

from . import io
from .errors import BlowUpError, RestartError, SphgenError
from .threads import ThreadTuner


class Interrupted(SphgenError):
    """The user stopped the run (Ctrl-C); the last complete step is on disk."""

    exit_code = 130


class Solver:
    """Advance a :class:`~sphgen.scene.Scene` with an integrator from t to tf.

    dt: fixed step, or the largest step when ``adaptive`` is on; adaptive steps use
    ``dt_props``: per-particle admissible steps written by equations (e.g. ``dt_cfl``),
    the step is ``cfl * min`` over all arrays that have them.

    The guard (on by default) checks every step for non-finite values, a particle
    faster than ``speed_limit``, a density outside ``density_bounds`` ({array: (lo,
    hi)}) and a jump of the neighbour count (``neighbour_jump`` times the initial
    pairs of a list, except the (dest, source) pairs in ``neighbour_exempt``, e.g. bodies
    that come into contact); it stops the run naming step, array, property and particle, and
    writes the last good state to ``<prefix>_last_good.h5``.

    ``metadata`` is written into every output file's solver data (the application
    stores the scene's identity there, which a restart checks).
    """

    def __init__(self, scene, integrator, dt, tf, *, adaptive=False, dt_props=("dt_cfl",), cfl=1.0,
                 max_steps=None, pfreq=100, output_at_times=(), outdir=None, prefix="sphgen",
                 disable_output=False, progress=True, guard=True, speed_limit=None,
                 density_bounds=None, neighbour_jump=4.0, sort_every=200, metadata=None,
                 tune_threads=None):
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
        self.dt, self.tf = float(dt), float(tf)
        self.adaptive, self.dt_props, self.cfl = adaptive, tuple(dt_props), cfl
        self.max_steps = max_steps
        self.pfreq = pfreq
        self.output_at_times = sorted(output_at_times)
        self.outdir, self.prefix = outdir, prefix
        self.disable_output = disable_output or outdir is None
        self.progress = progress
        self.guard = guard
        self.speed_limit = speed_limit
        self.density_bounds = dict(density_bounds or {})
        self.neighbour_jump = neighbour_jump
        self.neighbour_exempt = set()
        # particles drift away from their memory neighbours; re-sorting keeps the
        # neighbour loops cache-friendly (carry a 'gid' property to track particles).  A
        # sort costs a rebuild and a permutation of every array (1.5 ms on the dam break's
        # 3 384 particles, 4.9 ms on Taylor-Green nx = 100); between sorts the passes lose
        # little, but each rebuild's rows need more sorting (dam break 1.2 ms right after a
        # sort, 1.36 ms 200 steps later, 1.65 ms 500 later; Taylor-Green 4.4, 7.1, 7.6 ms):
        # every 200 steps costs least on both (docs/performance.md)
        self.sort_every = sort_every
        self.metadata = dict(metadata or {})
        # the thread count is an upper bound: under load one thread may be faster
        # (SPHGEN_TUNE_THREADS=0 keeps the count fixed, for benchmarks)
        if tune_threads is None:
            tune_threads = os.environ.get("SPHGEN_TUNE_THREADS", "1") != "0"
        self.tuner = ThreadTuner(scene) if tune_threads else None
        self.t = 0.0
        self.step = 0
        self.post_step_callbacks = []
        self.output_callbacks = []
        self.wall_time = 0.0
        self.outputs_written = []
        self.index = None
        self.restarted = False
        self.log = []
        self._good = None
        self._pairs0 = {}
        self._bar = None

    # ---------------------------------------------------------------- state
    def restart_from(self, path):
        """Load arrays and time from an output file written by a run of the same scene."""
        try:
            data = io.load(path)
        except (OSError, ValueError, KeyError) as e:
            raise RestartError(f"--restart {path}: {e}") from None
        for pa in self.scene.arrays:
            if pa.name not in data["arrays"]:
                raise RestartError(f"--restart {path} has no array '{pa.name}'")
            src = data["arrays"][pa.name]
            if src.n != pa.n:
                raise RestartError(f"--restart {path}: array '{pa.name}' has {src.n} particles, "
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
        self.integrator.restarted(self.step, self.t)
        self.scene.update_nnps()

    def _snapshot_arrays(self):
        """Every array's data, in a fixed order (the snapshot's layout)."""
        return [v for pa in self.scene.arrays for v in pa.data.values()]

    def _snapshot(self):
        """Copy every array's data into one byte buffer (the guard runs every step, so the
        backend copies it in parallel pieces, one call)."""
        arrays = self._snapshot_arrays()
        layout = [v.nbytes for v in arrays]
        if self._good is None or self._good[0] != layout:
            self._good = (layout, np.empty(sum(layout), dtype=np.uint8))
        self.scene.engine.copy_arrays(arrays, self._good[1], True)
        self._good_t, self._good_step = self.t, self.step

    def _restore_snapshot(self):
        self.scene.engine.copy_arrays(self._snapshot_arrays(), self._good[1], False)
        self.t, self.step = self._good_t, self._good_step

    def write_output(self, path=None):
        """Write the state; a series file is added to the XDMF index, which is rewritten."""
        if self.outdir is None:
            return None
        series = path is None
        path = path or os.path.join(self.outdir, f"{self.prefix}_{self.step:06d}.h5")
        if series:
            # time series first: a kill between the two leaves them ahead of the output
            # file, and a restart keeps only the rows up to its time
            for cb in self.output_callbacks:
                cb(self, path)
        io.write(path, self.scene.arrays, {"t": self.t, "dt": self.dt, "step": self.step, **self.metadata})
        if series:
            self.outputs_written.append(path)
            if self.index is None:
                self.index = io.XdmfIndex(self.outdir, self.prefix)
            self.index.add(path)
            self.index.write()
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
        self._prepare()
        t_start = time.perf_counter()
        try:
            while not self._finished():
                tprev = self.t
                dt = self._advance()
                self._check(dt)
                self._after_step(tprev, dt)
        except KeyboardInterrupt:
            self._interrupted()
        finally:
            if self._bar is not None:
                self._bar.close()
            self.wall_time += time.perf_counter() - t_start
        self._finish()
        return self.step

    def _prepare(self):
        """Output folder and index, initial accelerations and output, guard snapshot."""
        if not self.disable_output:
            os.makedirs(self.outdir, exist_ok=True)
            self.index = io.XdmfIndex(self.outdir, self.prefix)
            for path in io.output_files(self.outdir, self.prefix):
                if self.restarted and io.step_of(path) > self.step:
                    os.remove(path)  # the future of the run being continued: recomputed
                    self.log.append(f"removed {os.path.basename(path)} (after the restart step)")
                elif self.restarted:
                    self.index.add(path)
        if not self.restarted:
            if self.integrator.motions or self.integrator.clamps:
                self.integrator.impose(self.t)
            # a restart file carries the accelerations of its step: recomputing them from
            # the end-of-step velocities would not reproduce the uninterrupted run
            self.integrator.initial_accelerations(self.t, self.dt)
        if not self.disable_output and self.step == 0:
            self.write_output()
        elif self.index is not None:
            self.index.write()
        if self.progress:
            from tqdm import tqdm
            self._bar = tqdm(total=self.tf, unit="t", bar_format="{l_bar}{bar}| t={n:.4g}/{total:.4g} "
                             "[{elapsed}<{remaining}{postfix}]", leave=False, mininterval=0.5)
            self._bar.update(self.t)
        if self.guard:
            self._pairs0 = self.scene.nnps.pair_totals()
            self.scene.set_guard_limits(self.speed_limit, self.density_bounds or {})
            self._snapshot()

    def _finished(self):
        if self.max_steps is not None and self.step >= self.max_steps:
            return True
        return self.t >= self.tf - 1e-12 * max(1.0, self.tf)

    def _advance(self):
        """One integrator step; a neighbour search that meets a non-finite position is a blow-up."""
        dt = self.next_dt()
        start = time.perf_counter()
        try:
            self.integrator.advance(self.t, dt)
        except BlowUpError as e:     # raised inside the step (e.g. an iteration that diverged)
            raise BlowUpError(f"{e}{self._save_last_good()}") from None
        except ValueError:
            bad = self.scene.check_finite() if self.guard else None
            if bad is None:
                raise
            self.t, self.step = self.t + dt, self.step + 1
            self._blow_up(dt, "non-finite {}.{} at particle {}".format(*bad))
        self.t += dt
        self.step += 1
        self.last_dt = dt
        if self.tuner is not None:
            self.tuner.record(self.step, time.perf_counter() - start)
        return dt

    def _check(self, dt):
        """The guard's checks, every step: one sweep for finite values, speeds and densities
        (the slower looks that say where run only when it fails), the neighbour counts; a
        good state is snapshotted."""
        if not self.guard:
            return
        if not self.scene.state_is_good():
            self._name_the_bad_value(dt)
        what = self._check_neighbours()
        if what:
            self._blow_up(dt, what)
        self._snapshot()

    def _name_the_bad_value(self, dt):
        """Stop with the array, property and particle that failed the guard's sweep."""
        bad = self.scene.check_finite()
        if bad is not None:
            self._blow_up(dt, "non-finite {}.{} at particle {}".format(*bad))
        extremes = self.scene.extremes()
        for what in (self._check_speed(extremes), self._check_density(extremes)):
            if what:
                self._blow_up(dt, what)
        self._blow_up(dt, "the guard's sweep failed, yet no value is non-finite or beyond a limit "
                          "(report this)")

    def _after_step(self, tprev, dt):
        if self.sort_every and self.step % self.sort_every == 0:
            self.scene.sort()
        for cb in self.post_step_callbacks:
            cb(self)
        if self._should_output(tprev):
            self.write_output()
        if self._bar is not None:
            self._bar.update(self.t - tprev)
            if self.step % 50 == 0:
                self._bar.set_postfix_str(f"step={self.step}, dt={dt:.3g}", refresh=False)

    def _finish(self):
        """The final state is always in the series."""
        if self.disable_output:
            return
        if not self.outputs_written or not self.outputs_written[-1].endswith(f"_{self.step:06d}.h5"):
            self.write_output()

    # ---------------------------------------------------------------- guard
    def _check_speed(self, extremes):
        """A particle faster than the scheme's limit (e.g. Mach 1 for weak compressibility)."""
        if self.speed_limit is None:
            return None
        for name, speed2, i, *_ in extremes:
            if i >= 0 and speed2 > self.speed_limit ** 2:
                comps = ", ".join(("u", "v", "w")[:self.scene.dim])
                return (f"speed |({comps})| = {np.sqrt(speed2):.3g} of {name} particle {i} is above "
                        f"the scheme's limit {self.speed_limit:.3g}")
        return None

    def _check_density(self, extremes):
        """A density outside the scheme's bounds (from the same sweep as the speeds)."""
        for name, _, _, rmin, i, rmax, j in extremes:
            if name not in self.density_bounds:
                continue
            lo, hi = self.density_bounds[name]
            if i >= 0 and rmin < lo:
                return f"density {name}.rho = {rmin:.4g} at particle {i} is below the bound {lo:.4g}"
            if j >= 0 and rmax > hi:
                return f"density {name}.rho = {rmax:.4g} at particle {j} is above the bound {hi:.4g}"
        return None

    def _check_neighbours(self):
        totals = {k: n for k, n in self.scene.nnps.pair_totals().items() if k not in self.neighbour_exempt}
        if not any(self._pairs0.get(key, 0) and n > self.neighbour_jump * self._pairs0[key]
                   for key, n in totals.items()):
            return None
        for d, s, pairs, i, count in self.scene.nnps.busiest():   # only to say where
            start = self._pairs0.get((d, s))
            if start and (d, s) not in self.neighbour_exempt and pairs > self.neighbour_jump * start:
                return (f"neighbour pairs {d}<-{s} jumped from {start} to {pairs} (particle {i} of "
                        f"{d} has {count} neighbours): particles are clumping")
        return None

    def _blow_up(self, dt, what):
        where = f"{what}, step {self.step} (t={self.t:.6g}, dt={dt:.3g})"
        raise BlowUpError(where + self._save_last_good())

    def _save_last_good(self):
        """Arrays back to the last good state, in memory and on disk; the saying of where."""
        if self._good is None:
            return ""
        self._restore_snapshot()
        if self.outdir is None:
            return ""
        path = self.write_output(os.path.join(self.outdir, f"{self.prefix}_last_good.h5"))
        return f"; last good state (step {self.step}, t={self.t:.6g}) written to {path}"

    def _interrupted(self):
        """Ctrl-C: the last complete step goes into the series so ``--restart`` continues it."""
        if self._good is None or self.disable_output:
            raise Interrupted(f"interrupted at step {self.step} (t={self.t:.6g}); nothing written")
        self._restore_snapshot()
        path = self.write_output()
        raise Interrupted(f"interrupted at step {self.step} (t={self.t:.6g}); that state is in {path}: "
                          f"continue with --restart {path}")
