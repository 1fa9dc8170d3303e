"""Runs that never lose data and answer a user mistake with one clear line.

The full tables (32 bad inputs, 10 kills) are in benchmarks/bad_input.py and
benchmarks/kill_test.py; these tests check each mechanism once.
"""
import hashlib
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from sphgen import io
from sphgen.threads import ThreadTuner, others_running
from sphgen.app import load_application, main
from sphgen.equation import Equation, Group, ParameterError
from sphgen.errors import BlowUpError, RestartError
from sphgen.scene import Scene

from conftest import lattice_cloud

TG = ["run", "taylor_green", "--no-progress", "--nx", "16", "--no-openmp"]


def digest(folder):
    return {f: hashlib.sha1(open(os.path.join(folder, f), "rb").read()).hexdigest()
            for f in sorted(os.listdir(folder))}


def refused(args, capsys):
    """Run sphgen with ``args``; it must exit non-zero with one line and no traceback."""
    with pytest.raises(SystemExit) as e:
        main(TG + args)
    err = capsys.readouterr().err.strip()
    assert e.value.code not in (0, None)
    assert "\n" not in err and "Traceback" not in err and 0 < len(err) <= 300, err
    return err


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    """A finished run of 15 steps with outputs every 5."""
    out = tmp_path_factory.mktemp("ref") / "run"
    main(TG + ["--tf", "0.02", "--pfreq", "5", "-d", str(out)])
    return out


def test_folder_with_another_run_is_refused_and_untouched(finished, capsys):
    before = digest(finished)
    err = refused(["--tf", "0.01", "-d", str(finished)], capsys)
    assert "already holds a run" in err and "--overwrite" in err
    assert digest(finished) == before


@pytest.mark.parametrize("args,match", [
    (["--re", "1000"], "options.re = 100.0 there, 1000.0 now"),
    (["--tf", "0.01"], "at or past --tf 0.01"),
])
def test_restart_of_another_scene_or_past_tf_is_refused(finished, tmp_path, capsys, args, match):
    mid = os.path.join(finished, "taylor_green_000005.h5")
    last = io.output_files(finished)[-1]
    before = digest(finished)
    err = refused(args + ["--restart", last if "--tf" in args else mid, "-d", str(tmp_path / "r")], capsys)
    assert match in err
    assert digest(finished) == before and not os.path.exists(tmp_path / "r")


def test_debug_shows_the_exception(finished, tmp_path):
    with pytest.raises(RestartError):
        main(TG + ["--re", "1000", "--restart", io.output_files(finished)[0], "-d", str(tmp_path / "x"),
                   "--debug"])


def test_overwrite_clears_the_other_run_and_dead_temporaries(finished, tmp_path):
    out = tmp_path / "again"
    subprocess.run(["cp", "-r", str(finished), str(out)], check=True)
    (out / "taylor_green_000099.h5.tmp-999999").write_bytes(b"half")
    (out / "my_notes.txt").write_text("keep me")
    main(TG + ["--tf", "0.01", "--pfreq", "5", "-d", str(out), "--overwrite"])
    names = os.listdir(out)
    assert "my_notes.txt" in names and not any(".tmp-" in n for n in names)
    assert json.load(open(out / "info.json"))["completed"]
    assert io.verify_xdmf(out / "taylor_green.xdmf")[0] == len(io.output_files(out))


def test_unknown_equation_keyword_has_a_hint():
    from sphgen.equations.edac import EDACPressureRate
    with pytest.raises(ParameterError, match="unknown parameter 'c00'; did you mean 'c0'"):
        EDACPressureRate("fluid", ["fluid"], c00=3.0, nu_edac=0.1)


def test_unstable_run_stops_at_the_first_bad_step_with_last_good_state(tmp_path):
    """Guard off: find the first step with a value out of bounds; guard on: it stops there."""
    App = load_application("taylor_green")
    args = ["--nx", "16", "--dt", "0.02", "--allow-unstable", "--tf", "1", "--no-progress",
            "--no-openmp", "--disable-output", "--debug"]
    first = {}

    class Unguarded(App):
        def _solver(self, integrator, dt):
            solver = super()._solver(integrator, dt)
            solver.guard = False
            return solver

        def post_step(self, solver):
            f = solver.scene.by_name["fluid"]
            lo, hi = self.scheme.density_bounds()["fluid"]
            finite = all(np.all(np.isfinite(a)) for a in f.data.values())
            if not finite or f.rho.min() < lo or f.rho.max() > hi or \
                    np.hypot(f.u, f.v).max() > self.scheme.speed_limit:
                first["step"] = solver.step
                raise KeyboardInterrupt

    with pytest.raises(Exception):
        Unguarded("taylor_green").run(args + ["-d", str(tmp_path / "a")])
    with pytest.raises(BlowUpError) as e:
        App("taylor_green").run(args + ["-d", str(tmp_path / "b")])
    msg = str(e.value)
    stop = int(msg.split(", step ")[1].split()[0])
    assert "particle" in msg and "fluid" in msg
    assert first and stop - first["step"] <= 3, (stop, first)
    good = io.load(str(tmp_path / "b" / "taylor_green_last_good.h5"))
    assert good["solver_data"]["step"] == stop - 1
    assert all(np.all(np.isfinite(a)) for a in good["arrays"]["fluid"].data.values())


def test_sigkill_leaves_readable_files_and_restart_is_bit_for_bit(tmp_path):
    exe = os.path.join(os.path.dirname(sys.executable), "sphgen")
    case = ["--nx", "16", "--tf", "0.06", "--pfreq", "2", "--no-progress", "--no-openmp"]
    ref, out = tmp_path / "ref", tmp_path / "killed"
    subprocess.run([exe, "run", "taylor_green", *case, "-d", str(ref)], check=True, capture_output=True)
    p = subprocess.Popen([exe, "run", "taylor_green", *case, "-d", str(out)],
                         stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    while p.poll() is None and len(io.output_files(out) if out.exists() else []) < 5:
        time.sleep(0.005)
    p.send_signal(signal.SIGKILL)
    p.wait()
    files = io.output_files(out)
    assert files, "killed before the first output: nothing to check"
    for f in files:
        io.load(f)
    assert io.verify_xdmf(out / "taylor_green.xdmf")[0] in (len(files), len(files) - 1)
    subprocess.run([exe, "run", "taylor_green", *case, "-d", str(out), "--restart", files[-1]],
                   check=True, capture_output=True)
    assert not [n for n in os.listdir(out) if ".tmp-" in n]
    a, b = io.load(io.output_files(ref)[-1]), io.load(io.output_files(out)[-1])
    assert a["solver_data"]["step"] == b["solver_data"]["step"]
    for prop in ("x", "y", "u", "v", "p", "rho"):
        np.testing.assert_array_equal(a["arrays"]["fluid"].data[prop], b["arrays"]["fluid"].data[prop])
    for name in ("history.json", "results.json", "diagnostics.json"):
        assert json.load(open(ref / name)) == json.load(open(out / name)), name
    info = json.load(open(out / "info.json"))
    assert info["completed"] is True and info["restarts"][-1]["step"] == io.step_of(files[-1])


def test_ctrl_c_writes_the_last_complete_step(tmp_path):
    app = load_application("taylor_green")()

    def stop(solver):
        if solver.step == 7:
            raise KeyboardInterrupt
    app.post_step = stop
    with pytest.raises(SystemExit) as e:
        app.run(["--nx", "16", "--tf", "0.02", "--no-progress", "--no-openmp", "-d", str(tmp_path)])
    assert e.value.code == 130
    last = io.output_files(tmp_path)[-1]
    assert io.load(last)["solver_data"]["step"] == 7   # the last complete step
    info = json.load(open(tmp_path / "info.json"))
    assert info["completed"] is False and info["stopped"] is False   # interrupted, not stopped by the guard


class _TwoThreadScene:
    """What ThreadTuner needs of a scene: its thread count and a way to set it."""
    threads = 2

    def set_threads(self, n):
        self.threads = n


def test_thread_tuner_drops_to_one_thread_under_load_and_returns():
    scene = _TwoThreadScene()
    tuner = ThreadTuner(scene, trial=3, first=4)
    tuner.busy = lambda: True        # the machine is seen loaded
    cost = {2: 4.0, 1: 1.0}          # loaded machine: 2 threads 4x slower than one
    for step in range(1, 40):
        tuner.record(step, cost[scene.threads])
    assert tuner.current == 1 and tuner.choices[0][1] == 1
    cost = {2: 0.55, 1: 1.0}         # load gone: 2 threads 1.8x faster
    for step in range(40, 200):
        tuner.record(step, cost[scene.threads])
    assert tuner.current == 2 and tuner.choices[-1][1] == 2
    n_trials = len(tuner.choices)
    for step in range(200, 2000):    # steady: trials become rare (intervals double)
        tuner.record(step, cost[scene.threads])
    assert tuner.every > 200 and len(tuner.choices) == n_trials


def test_thread_tuner_abandons_a_clearly_losing_trial_early():
    scene = _TwoThreadScene()
    tuner = ThreadTuner(scene, trial=6, first=20, early=2)
    tuner.busy = lambda: True        # another process seen, yet two threads still win
    serial_steps = 0
    for step in range(1, 1001):      # idle machine: one thread 1.8x slower
        serial_steps += scene.threads == 1
        tuner.record(step, {2: 1.0, 1: 1.8}[scene.threads])
    assert tuner.choices == []
    # trials after 20, 40, 80, 160, 320 steps of two threads: two serial steps each
    assert serial_steps == 2 * 5


def test_thread_tuner_tries_nothing_on_an_idle_machine():
    scene = _TwoThreadScene()
    tuner = ThreadTuner(scene, trial=6, first=20, early=2)
    tuner.busy = lambda: False
    for step in range(1, 1001):
        assert scene.threads == 2
        tuner.record(step, 1.0)
    assert tuner.choices == []


def test_others_running_reads_the_runnable_count(tmp_path):
    f = tmp_path / "loadavg"
    f.write_text("0.10 0.20 0.30 1/345 6789\n")
    assert others_running(str(f)) is False
    f.write_text("2.10 1.20 0.30 3/345 6789\n")
    assert others_running(str(f)) is True
    assert others_running(str(tmp_path / "missing")) is True   # cannot tell: try


@pytest.mark.parametrize("backend, nx", [("cython", "100"), ("python", "16")])
def test_snapshot_restores_every_array_bit_for_bit(tmp_path, backend, nx):
    """The guard's snapshot (one byte buffer; each thread copies its part of every array)
    brings back every property of every array, integers included, and the time."""
    App = load_application("taylor_green")
    kept = {}

    class Capture(App):
        def _solver(self, integrator, dt):
            kept["solver"] = solver = super()._solver(integrator, dt)
            return solver

    Capture("taylor_green").run(["--nx", nx, "--max-steps", "3", "--no-progress", "--threads", "2",
                                 "--backend", backend, "--disable-output", "-d", str(tmp_path)])
    solver = kept["solver"]
    solver._snapshot()
    before = {(pa.name, k): v.copy() for pa in solver.scene.arrays for k, v in pa.data.items()}
    t, step = solver.t, solver.step
    for pa in solver.scene.arrays:
        for v in pa.data.values():
            v[...] = 7 if v.dtype.kind in "iu" else np.nan
    solver.t, solver.step = -1.0, -1
    solver._restore_snapshot()
    assert (solver.t, solver.step) == (t, step)
    for pa in solver.scene.arrays:
        for k, v in pa.data.items():
            np.testing.assert_array_equal(v, before[(pa.name, k)], err_msg=f"{pa.name}.{k}")
    assert any(v.dtype.kind in "iu" for v in before.values())
    assert max(v.nbytes for v in before.values()) > 65536 or backend == "python"   # pieces

    # the speed check: each thread scans its part, then the parts' maxima are compared
    fluid = solver.scene.by_name["fluid"]
    rng = np.random.default_rng(3)
    for where in (0, fluid.n // 2 - 1, fluid.n // 2, fluid.n - 1):
        fluid.u[:] = rng.uniform(-1, 1, fluid.n)
        fluid.v[:] = rng.uniform(-1, 1, fluid.n)
        fluid.u[where], fluid.v[where] = 3.0, -2.0
        fluid.rho[:] = rng.uniform(0.9, 1.1, fluid.n)
        fluid.rho[where], fluid.rho[-1 - where] = 0.5, 2.0
        ((name, speed2, i, rmin, imin, rmax, imax),) = [e for e in solver.scene.extremes() if e[0] == "fluid"]
        assert (name, i) == ("fluid", where) and speed2 == 13.0
        assert (imin, rmin, imax, rmax) == (where, 0.5, fluid.n - 1 - where, 2.0)


class ReadState(Equation):
    """Reads what the guard sweeps: a strided property, the velocity and the density."""

    def initialize(self, d_idx, d_d, d_A, d_u, d_v, d_rho):
        d_d[d_idx] = d_A[4 * d_idx + 3] + d_u[d_idx] + d_v[d_idx] + d_rho[d_idx]


class ReadDensity(Equation):
    def initialize(self, d_idx, d_e, d_rho):
        d_e[d_idx] = d_rho[d_idx]


@pytest.mark.parametrize("backend", ["cython", "python"])
def test_state_is_good_finds_every_bad_value_in_one_sweep(backend):
    """The guard's per-step look (one parallel sweep of every part): a non-finite value of
    any component of a strided property, a speed above the limit and a density outside its
    array's own bounds each make it False, wherever the particle lies; a speed exactly at
    the limit and another array's bounds do not."""
    fluid = lattice_cloud("fluid", nx=20, seed=1)
    fluid.add_property("A", stride=4, data=np.random.default_rng(0).uniform(-1, 1, 4 * fluid.n))
    fluid.add_property("d")
    wall = lattice_cloud("wall", nx=8, seed=2)
    wall.y[:] += 1.0
    wall.add_property("e")
    sc = Scene([fluid, wall], [Group([ReadState("fluid"), ReadDensity("wall")])], dim=2, threads=2,
               backend=backend, outputs={"fluid": ["d"], "wall": ["e"]})
    sc.update_nnps()
    sc.compute(0, 0.0, 0.0)
    sc.set_guard_limits(2.0, {"fluid": (0.8, 1.2), "wall": (0.5, 1.5)})
    assert sc.state_is_good()
    n = fluid.n
    for i in (0, n // 2 - 1, n // 2, n - 1):
        for pa, changes, good in [
                (fluid, {"A": (4 * i + 3, np.nan)}, False),
                (fluid, {"A": (4 * i, -np.inf)}, False),
                (fluid, {"u": (i, np.inf)}, False),
                (fluid, {"u": (i, 1.5), "v": (i, 1.5)}, False),       # |u| = 2.12 > 2
                (fluid, {"u": (i, 2.0), "v": (i, 0.0)}, True),        # exactly at the limit
                (fluid, {"rho": (i, 0.79)}, False),
                (fluid, {"rho": (i, 1.21)}, False),
                (wall, {"rho": (i % wall.n, 1.6)}, False),
                (wall, {"rho": (i % wall.n, 1.4)}, True),             # above the fluid's bound only
                (wall, {"x": (i % wall.n, np.nan)}, False)]:
            kept = {p: (k, pa.get(p)[k]) for p, (k, _) in changes.items()}
            for p, (k, value) in changes.items():
                pa.get(p)[k] = value
            assert sc.state_is_good() is good, (backend, pa.name, changes)
            for p, (k, value) in kept.items():
                pa.get(p)[k] = value
            assert sc.state_is_good()
    sc.set_guard_limits(None, {})
    fluid.u[3] = 1e6
    fluid.rho[4] = 1e-6
    assert sc.state_is_good()           # no limits: only finiteness
