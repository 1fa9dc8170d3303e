"""`sphgen precision` and `sphgen stress`: sweep parsing, tables and plots of real runs."""
import json
import os

import pytest

from sphgen.app import main
from sphgen.errors import InputError
from sphgen.studies import cases, split_sweep


def test_options_with_several_values_are_sweep_axes():
    axes, fixed = split_sweep(["--nx", "25", "50", "--tf", "0.1", "--scheme", "a", "b", "--no-openmp",
                               "--shift", "-1"])
    assert axes == [("--nx", ["25", "50"]), ("--scheme", ["a", "b"])]
    assert fixed == ["--tf", "0.1", "--no-openmp", "--shift", "-1"]
    assert [label for label, _ in cases(axes)] == ["nx25_schemea", "nx25_schemeb", "nx50_schemea",
                                                   "nx50_schemeb"]
    assert cases([]) == [("run", [])]
    with pytest.raises(InputError):
        split_sweep(["25", "--nx"])


def test_precision_and_stress_write_tables_and_plots(tmp_path, capsys):
    d = tmp_path / "prec"
    assert main(["precision", "taylor_green", "--nx", "12", "16", "--tf", "0.02", "--no-openmp",
                 "-d", str(d)]) == 0
    data = json.load(open(d / "precision.json"))
    assert data["error_key"] == "l1_error_mean" and len(data["runs"]) == 2
    assert all(r["info"]["completed"] and r["results"]["l1_error_mean"] > 0 for r in data["runs"])
    assert [r["info"]["n_particles"] for r in data["runs"]] == [144, 256]
    assert os.path.getsize(d / "precision.png") > 1000 and "| nx12 |" in open(d / "precision.md").read()
    s = tmp_path / "stress"
    # dt factor 40 at nx=12 blows up; it is above the documented factor 1, so the study passes
    code = main(["stress", "taylor_green", "--runs", "1", "--nx", "12", "--tf", "0.3", "--no-openmp",
                 "--dt-factor", "1", "40", "-d", str(s)])
    rows = json.load(open(s / "stress.json"))["runs"]
    outcome = {r["case"]: r["exit"] for r in rows}
    assert outcome["dt-factor1_seed0"] == 0 and outcome["dt-factor40_seed0"] == 3
    assert code == 0 and "blew up" in open(s / "stress.md").read()
    assert os.path.getsize(s / "stress.png") > 1000


def test_precision_repeat_takes_the_fastest_round_and_checks_the_errors(tmp_path):
    d = tmp_path / "prec"
    assert main(["precision", "taylor_green", "--nx", "12", "--tf", "0.02", "--no-openmp", "--repeat", "3",
                 "-d", str(d)]) == 0
    (run,) = json.load(open(d / "precision.json"))["runs"]
    times = run["info"]["wall_times"]
    assert len(times) == 3 and run["info"]["wall_time"] == min(times) and run["info"]["completed"]
    # rounds whose errors differ fail the row (a run is deterministic)
    from sphgen.studies import fastest_round
    rounds = [[{"exit": 0, "message": "", "info": {"wall_time": t, "completed": True},
                "results": {"e": e}}] for t, e in ((2.0, 0.1), (1.0, 0.1), (1.5, 0.2))]
    (row,) = fastest_round(rounds, "e")
    assert row["info"]["wall_time"] == 1.0 and row["exit"] == 1 and not row["info"]["completed"]
    assert "rounds differ" in row["message"]
    with pytest.raises(SystemExit):
        main(["precision", "taylor_green", "--repeat", "0", "-d", str(tmp_path / "x")])


def test_stress_fails_when_a_run_blows_up_within_the_stable_factor(tmp_path):
    code = main(["stress", "taylor_green", "--runs", "1", "--nx", "12", "--tf", "0.3", "--no-openmp",
                 "--dt-factor", "40", "--stable-factor", "50", "-d", str(tmp_path)])
    assert code == 1


def test_an_application_option_is_not_taken_for_an_abbreviated_study_option():
    """`--re 2` (taylor_couette's Reynolds number) once became `--reference 2` of precision."""
    from sphgen.studies import _parse, _parser
    p = _parser("precision", "")
    p.add_argument("--reference", default=None)
    known, rest = _parse(p, ["taylor_couette", "--re", "2", "--nr", "10", "20"])
    assert known.reference is None and rest == ["--re", "2", "--nr", "10", "20"]


def test_pysph_reference_file_has_one_series_per_scheme(tmp_path):
    """benchmarks/work_precision.py --write-reference: the file `sphgen precision` plots."""
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "benchmarks"))
    from work_precision import reference_points
    from sphgen.studies import _reference
    ref = reference_points({"edac": [{"nx": 25, "wall_s": 3.0, "l1": 0.02}, {"nx": 50, "wall_s": None, "l1": 0.1}],
                            "gtvf": [{"nx": 25, "wall_s": 4.0, "l1": 0.03}]}, 0.5, 0.1)
    path = tmp_path / "ref.json"
    path.write_text(json.dumps(ref))
    back = _reference(str(path), "taylor_green")
    assert back["error_key"] == "l1_error" and back["tf"] == 0.5 and back["perturb"] == 0.1
    assert "--perturb 0.1" in back["source"]
    assert back["series"] == {"PySPH 1.0b2 EDAC": [{"label": 25, "wall_time": 3.0, "error": 0.02}],
                              "PySPH 1.0b2 GTVF": [{"label": 25, "wall_time": 4.0, "error": 0.03}]}


def test_reference_points_from_another_start_are_not_plotted():
    """PySPH's points from the plain lattice are not compared with runs from a perturbed one."""
    from sphgen.studies import _same_start
    runs = [{"info": {"options": {"perturb": 0.1}}}, {"info": {"options": {"perturb": 0.1}}}]
    assert _same_start({"perturb": 0.1}, runs)
    assert not _same_start({}, runs)                    # an older file: the plain lattice
    assert _same_start({}, [{"info": {"options": {"nr": 10}}}])   # no --perturb option: nothing to compare


@pytest.mark.parametrize("argv, words", [
    (["stress", "couette", "--runs", "1"], "stress couette: the application has no --perturb or --seed option"),
    (["stress", "taylor_green", "--runs", "1", "--nx", "12", "--frobnicate", "3"],
     "stress taylor_green, run run_seed0: unrecognized arguments: --frobnicate 3"),
    (["precision", "taylor_green", "--nx", "12", "16", "--frobnicate", "3"],
     "precision taylor_green, run nx12: unrecognized arguments: --frobnicate 3"),
])
def test_a_study_with_options_its_application_lacks_is_one_line_before_any_run(argv, words, tmp_path):
    """Each such run used to be reported as blown up ("blew up: unrecognized arguments"),
    after running the others: found by a stress sweep of every application."""
    d = tmp_path / "study"
    with pytest.raises(SystemExit) as e:
        main(argv + ["-d", str(d)])
    assert str(e.value).startswith("sphgen: " + words) and "\n" not in str(e.value)
    assert not d.exists()
