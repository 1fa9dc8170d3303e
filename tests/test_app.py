"""Application, solver and output: info.json, cache, restart, blow-up guard, XDMF."""
import json
import os
import re
import subprocess
import sys

import numpy as np
import pytest

from sphgen import io
from sphgen.app import load_application, main
from sphgen.solver import BlowUpError


def tg(args):
    app = load_application("taylor_green")()
    app.run(["--no-progress", "--nx", "16"] + args)
    return app


def test_info_json_outputs_and_xdmf(tmp_path):
    out = tmp_path / "run"
    tg(["--tf", "0.02", "--pfreq", "10", "-d", str(out)])
    info = json.load(open(out / "info.json"))
    for key in ("completed", "t", "steps", "n_particles", "wall_time", "compile_time", "threads",
                "options", "time_per_particle_step", "neighbour_pairs_per_step"):
        assert key in info, key
    assert info["completed"] is True and info["stopped"] is False and info["n_particles"] == 256
    assert info["t"] == pytest.approx(0.02) and info["options"]["nx"] == 16
    files = io.output_files(out)
    assert len(files) == info["steps"] // 10 + 1 + (info["steps"] % 10 > 0)
    assert (out / "taylor_green.xdmf").exists()
    last = io.load(files[-1])
    assert last["solver_data"]["step"] == info["steps"]
    assert set(last["arrays"]["fluid"].data) >= {"x", "y", "u", "v", "p", "rho"}
    res = json.load(open(out / "results.json"))
    assert {"l1_error", "max_u", "max_u_exact"} <= set(res)


def test_second_run_compiles_nothing(tmp_path, tmp_cache):
    tg(["--tf", "0.002", "-d", str(tmp_path / "a"), "--disable-output"])
    tg(["--tf", "0.002", "-d", str(tmp_path / "b"), "--disable-output"])
    first = json.load(open(tmp_path / "a" / "info.json"))
    second = json.load(open(tmp_path / "b" / "info.json"))
    assert first["compile_time"] > 0.5
    assert second["compile_time"] == 0.0


def test_restart_continues_the_same_run(tmp_path):
    full = tmp_path / "full"
    tg(["--tf", "0.03", "--pfreq", "10", "-d", str(full), "--no-openmp"])
    files = io.output_files(full)
    mid = [f for f in files if io.load(f)["solver_data"]["step"] == 10][0]
    part = tmp_path / "part"
    tg(["--tf", "0.03", "--pfreq", "10", "-d", str(part), "--restart", mid, "--no-openmp"])
    a = io.load(io.output_files(full)[-1])
    b = io.load(io.output_files(part)[-1])
    assert a["solver_data"]["step"] == b["solver_data"]["step"]
    for p in ("x", "y", "u", "v", "p"):
        np.testing.assert_allclose(b["arrays"]["fluid"].data[p], a["arrays"]["fluid"].data[p],
                                   rtol=0, atol=1e-10)


def test_blow_up_stops_with_where_and_keeps_last_good_state(tmp_path):
    out = tmp_path / "boom"
    with pytest.raises(BlowUpError) as e:
        tg(["--tf", "100", "--dt", "0.2", "-d", str(out), "--disable-output", "--allow-unstable",
            "--debug"])
    msg = str(e.value)
    # the first bound crossed names array, property (or speed) and particle
    assert re.search(r"fluid\.\w+ .*at particle \d+|of fluid particle \d+", msg), msg
    assert "step" in msg and "t=" in msg
    assert "last good state" in msg
    good = io.load(str(out / "taylor_green_last_good.h5"))
    for name, arr in good["arrays"]["fluid"].data.items():
        assert np.all(np.isfinite(arr)), name
    info = json.load(open(out / "info.json"))
    assert info["completed"] is False and "fluid" in info["error"] and "particle" in info["error"]
    assert info["stopped"] is True     # the guard stopped it: automan counts the case done


def test_non_finite_value_stops_at_once_naming_array_property_particle(tmp_path):
    from sphgen.integrators import IntegratorStep, PEC
    from sphgen.scene import Scene
    from sphgen.solver import Solver
    from conftest import lattice_cloud

    class Poison(IntegratorStep):
        def stage1(self, d_idx, d_x, d_p, dt):
            d_x[d_idx] += 0.0
            if d_idx == 7:
                d_p[d_idx] = d_p[d_idx] * 1e200   # 0.1, 1e199, inf

        def stage2(self, d_idx, d_x, dt):
            d_x[d_idx] += 0.0

    pa = lattice_cloud(nx=4)
    pa.add_property("p", data=np.full(pa.n, 0.1))
    integ = PEC(fluid=Poison())
    sc = Scene([pa], [], steppers=integ.steppers, dim=2, outputs={"fluid": ["p"]})
    solver = Solver(sc, integ, dt=0.1, tf=10.0, outdir=str(tmp_path), prefix="poison", progress=False)
    with pytest.raises(BlowUpError) as e:
        solver.run()
    assert str(e.value).startswith("non-finite fluid.p at particle")
    good = io.load(str(tmp_path / "poison_last_good.h5"))
    assert np.all(np.isfinite(good["arrays"]["fluid"].data["p"]))
    assert good["solver_data"]["step"] == solver.step


def test_show_plan_prints_plan_and_exits(tmp_path, capsys):
    assert main(["run", "taylor_green", "--nx", "16", "--show-plan", "-d", str(tmp_path)]) == 0
    text = capsys.readouterr().out
    assert "prune Vorticity2D[fluid<-fluid]" in text and "properties allocated:" in text
    assert not os.path.exists(tmp_path / "info.json")


def test_sphgen_list_names_taylor_green(capsys):
    assert main(["list"]) == 0
    assert "taylor_green" in capsys.readouterr().out.split()




def _pairs_of_set(app, k):
    """Pair visits of one run of equation set k on the current lists, counted from the plan."""
    rows = app.scene.plan.group_plans
    total = 0
    for gp in rows[k] if len(rows) > 1 else rows[0]:
        for dest, npass in gp.passes.items():
            for loop in npass.sources:
                off, _ = (app.scene.nnps.reference_neighbours(dest, loop.source) if gp.group.reference
                          else app.scene.nnps.neighbours(dest, loop.source))
                total += int(off[-1]) * max(1, gp.group.iterations)
    return total


def test_pair_count_follows_the_evaluations_the_integrator_ran(tmp_path):
    """info.json's pairs per step: each equation set as often as the integrator ran it per step
    (EDAC's kick-drift-kick: sets 0 and 1 every step, set 1 once more before the first;
    SHTC: sets 0 and 1 every step, its start-up set 2 once)."""
    app = tg(["--tf", "0.02", "-d", str(tmp_path / "a"), "--disable-output", "--no-openmp"])
    integ = app.solver.integrator
    steps = integ.steps_taken
    assert steps == app.solver.step > 5 and integ.set_runs == {0: steps, 1: steps + 1}
    expected = _pairs_of_set(app, 0) + _pairs_of_set(app, 1) * (steps + 1) / steps
    assert app.neighbour_pairs_per_step() == round(expected)

    plate = load_application("beryllium_plate")()
    plate.run(["-d", str(tmp_path / "p"), "--disable-output", "--no-progress", "--threads", "1",
               "--nw", "8", "--tf", "1e-6"])
    integ = plate.solver.integrator
    steps = integ.steps_taken
    assert steps > 5 and integ.set_runs == {0: steps, 1: steps + 1, 2: 1}
    one = [_pairs_of_set(plate, k) for k in range(3)]
    assert one[2] > 0
    assert plate.neighbour_pairs_per_step() == round(one[0] + one[1] * (steps + 1) / steps + one[2] / steps)


def test_sphgen_list_into_a_closed_pipe_is_no_traceback():
    """``sphgen list | head -1``: the reader leaves early; sphgen exits 0 and prints nothing."""
    p = subprocess.Popen([sys.executable, "-m", "sphgen", "list"], stdout=subprocess.PIPE,
                         stderr=subprocess.PIPE,
                         cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    p.stdout.close()              # before the child has started writing
    err = p.stderr.read().decode()
    p.stderr.close()
    assert p.wait() == 0 and err == ""


def test_a_run_into_a_closed_pipe_writes_its_results_and_no_traceback(tmp_path):
    """``sphgen run ... | head -1``: the reader leaves early (here before the first line);
    the run still post-processes (results.json, figures) and exits 0 without a traceback."""
    out = tmp_path / "db"
    p = subprocess.Popen([sys.executable, "-m", "sphgen", "run", "dam_break_2d", "--tf", "0.002",
                          "--no-progress", "--threads", "1", "--disable-output", "-d", str(out)],
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         cwd=os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
    p.stdout.close()
    err = p.stderr.read().decode()
    p.stderr.close()
    assert p.wait() == 0 and "Traceback" not in err, err
    assert (out / "results.json").exists() and (out / "toe.png").exists()
    assert json.load(open(out / "info.json"))["completed"]


@pytest.mark.parametrize("name", ["dam_break_variational", "shtc_impulse_of_shear", "uniaxial_compression"])
def test_a_short_run_without_output_still_writes_its_results(name, tmp_path, capsys):
    """Three steps with --disable-output: no output file to read back and (the shear
    layer) no snapshot reached; post_process uses the state in memory.  Both raised an
    IndexError before.  The compression fitted a slope through one late sample (a
    RankWarning and a meaningless number): now None."""
    out = tmp_path / name
    load_application(name)().run(["--max-steps", "3", "--disable-output", "--no-progress", "--no-openmp",
                                  "-d", str(out)])
    results = json.load(open(out / "results.json"))
    assert results["t"] > 0
    if name == "dam_break_variational":
        assert results["ejected_final"] == 0
    elif name == "uniaxial_compression":
        assert results["von_mises_slope_over_estimate"] is None
    else:
        assert np.isfinite(results["profile_error"]) and results["profile_error"] < 1e-3


def test_zero_steps_is_one_clear_line_or_a_result(tmp_path, capsys):
    """--tf 0 (and one step): the shear wave has no decay to fit (one line, exit 2; it raised
    IndexError, and fitted a line through one point);
    the heated disk writes its checks, those that need two samples as n/a (it raised
    TypeError formatting None)."""
    with pytest.raises(SystemExit) as e:
        load_application("shtc_shear_wave")().run(["--tf", "0", "--no-progress", "-d", str(tmp_path / "w")])
    assert e.value.code == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "sphgen: shtc_shear_wave: the decay needs two samples of the amplitude or more (run at least two steps)"]
    with pytest.raises(SystemExit) as e:
        load_application("shtc_shear_wave")().run(["--max-steps", "1", "--no-progress", "-d", str(tmp_path / "w1")])
    assert e.value.code == 2 and "run at least two steps" in capsys.readouterr().err
    load_application("thermo_disk")().run(["--tf", "0", "--no-progress", "-d", str(tmp_path / "d")])
    assert "|dA|/|A| n/a" in capsys.readouterr().out
    assert json.load(open(tmp_path / "d" / "results.json"))["A_drift"] is None


def test_the_reversibility_run_refuses_a_restart_in_one_line(tmp_path, capsys):
    """shtc_reversibility measures a forward-and-back run from its start; a restart used to
    end in ZeroDivisionError (found by a restart sweep of every application)."""
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as e:
        load_application("shtc_reversibility")().run(["--restart", str(tmp_path / "any.h5"), "-d", str(out)])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--restart cannot continue the forward-and-back run" in err[0]
    assert not out.exists()


def test_show_plan_of_a_study_without_a_scene_is_one_line_and_writes_nothing(tmp_path, capsys):
    """shtc_kernel_convergence has no compiled scene; --show-plan used to run the whole
    study and write its folder (found by a --show-plan sweep of every application)."""
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as e:
        load_application("shtc_kernel_convergence")().run(["--show-plan", "-d", str(out)])
    assert e.value.code == 2
    assert capsys.readouterr().err.strip().splitlines() == [
        "sphgen: shtc_kernel_convergence compiles no scene (a quadrature on a lattice, no particles): "
        "there is no plan to show"]
    assert not out.exists()
