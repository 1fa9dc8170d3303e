"""The run-time choice of the Verlet skin (sphgen/nnps/skin_tuner.py): its cost model, its
bookkeeping of generations, and that a run with it gives the same results as without."""
import numpy as np
import pytest

from sphgen.app import load_application
from sphgen.nnps import NeighbourSearch
from sphgen.nnps.skin_tuner import SkinTuner, best_skin

from test_nnps import _drift, assert_same_lists, domain_for, make_array


def upkeep(x, b0, c0, kappa, dim):
    """The modelled neighbour upkeep per update with the skin x."""
    return (1.0 + x) ** dim * (c0 + b0 / (kappa * x))


@pytest.mark.parametrize("dim", [1, 2, 3])
@pytest.mark.parametrize("b0, c0, kappa", [(0.65, 0.12, 77.0), (0.55, 0.08, 53.0), (5.0, 0.1, 20.0),
                                            (0.01, 1.0, 100.0)])
def test_best_skin_is_the_minimum_of_the_upkeep(dim, b0, c0, kappa):
    xs = np.linspace(1e-4, 3.0, 300001)
    brute = xs[np.argmin(upkeep(xs, b0, c0, kappa, dim))]
    assert best_skin(b0, c0, kappa, dim) == pytest.approx(brute, rel=1e-3, abs=2e-5)


def test_best_skin_limits():
    assert best_skin(0.0, 1.0, 10.0, 2) == 0.0          # free rebuilds: no skin
    assert best_skin(1.0, 0.0, 10.0, 2) == float("inf")  # free cuts: the widest


def feed(tuner, generations, b0, c0, kappa, dim, noise=None):
    """Updates timed as the model says, generation after generation, with the tuner's skin."""
    rng = np.random.default_rng(3)
    for _ in range(generations):
        s = tuner.skin
        grow = (1.0 + s) ** dim
        length = max(2, int(round(kappa * s)))
        jitter = (lambda: 1.0 + noise * rng.standard_normal()) if noise else (lambda: 1.0)
        tuner.record((b0 + c0) * grow * jitter(), True, s)
        for _ in range(length - 1):
            tuner.record(c0 * grow * jitter(), False, s)
    tuner.record(0.0, True, tuner.skin)       # closes the last generation


@pytest.mark.parametrize("dim", [2, 3])
@pytest.mark.parametrize("b0, c0, kappa", [(0.65, 0.12, 77.0), (0.55, 0.08, 53.0), (0.4, 0.5, 90.0)])
def test_the_tuner_settles_on_the_cheapest_skin(dim, b0, c0, kappa):
    best = best_skin(b0, c0, kappa, dim)
    tuner = SkinTuner(0.1, dim, lowest=0.01, highest=0.9)
    feed(tuner, 40, b0, c0, kappa, dim, noise=0.05)
    assert tuner.choices                                   # it moved from 0.1
    # within the 5 % it tolerates, and as cheap as the best to 1 %
    assert tuner.skin == pytest.approx(best, rel=0.12)
    assert upkeep(tuner.skin, b0, c0, kappa, dim) <= 1.01 * upkeep(best, b0, c0, kappa, dim)


def test_the_tuner_stays_within_its_bounds_and_needs_three_generations():
    tuner = SkinTuner(0.1, 2, lowest=0.05, highest=0.2)
    feed(tuner, 2, 50.0, 0.01, 50.0, 2)       # rebuilds dear: the widest skin, once it has seen 3
    assert tuner.skin == 0.1 and tuner.n_generations == 2
    feed(tuner, 1, 50.0, 0.01, 50.0, 2)
    assert tuner.skin == 0.2
    feed(tuner, 5, 0.0, 1.0, 50.0, 2)         # rebuilds free: the narrowest
    assert tuner.skin == 0.05
    with pytest.raises(ValueError, match="lowest <= skin <= highest"):
        SkinTuner(0.6, 2, highest=0.5)


def test_a_generation_cut_short_by_a_sort_is_not_counted():
    tuner = SkinTuner(0.1, 2)
    tuner.record(10.0, True, 0.1)
    for _ in range(4):
        tuner.record(1.0, False, 0.1)
    tuner.interrupt()                          # a sort rebuilt the lists
    tuner.record(1.0, False, 0.1)              # not counted: no generation is open
    tuner.record(10.0, True, 0.1)
    assert tuner.n_generations == 0 and tuner._open == [0.1, 10.0, []]
    for _ in range(3):
        tuner.record(1.0, False, 0.1)
    tuner.record(10.0, True, 0.1)
    assert tuner.n_generations == 1
    b0, c0, kappa = tuner.samples[0]
    assert (b0, c0, kappa) == pytest.approx((9.0 / 1.21, 1.0 / 1.21, 4 / 0.1))


@pytest.mark.parametrize("periodic", [False, True])
def test_rows_stay_exact_when_the_skin_changes_at_every_rebuild(periodic):
    """The tuner changes ``skin`` between rebuilds: the rows still equal a fresh build."""
    rng = np.random.default_rng(8)
    dom = domain_for((periodic, periodic))
    pa = make_array("f", 500, 2, rng, h=0.04, hvar=0.2)
    fresh_pa = make_array("f", 500, 2, np.random.default_rng(8), h=0.04, hvar=0.2)
    skinned = NeighbourSearch([pa], 2, 2.0, dom, sort=False, skin=0.1)
    fresh = NeighbourSearch([fresh_pa], 2, 2.0, dom, sort=False)
    skins = iter([0.3, 0.05, 0.5, 0.025, 0.2] * 20)
    for step in range(60):
        for p in (pa, fresh_pa):
            _drift(p, 2, step, 0.002)
        builds = skinned.n_builds
        skinned.update()
        fresh.update()
        if skinned.n_builds != builds:
            skinned.skin = next(skins)         # taken at the next rebuild
        assert_same_lists(skinned.neighbours("f", "f"), fresh.neighbours("f", "f"))
    assert skinned.n_builds >= 6


def test_a_run_with_the_skin_tuned_gives_the_same_results(tmp_path, monkeypatch):
    """Taylor-Green with --tune-skin (its clock made to say rebuilds are dear, so the skin
    surely moves) ends bit for bit where the run with the fixed skin does."""
    import types

    import sphgen.scene

    finals = {}
    for tuned in (False, True):
        if tuned:       # each timed update takes one tick, each rebuild 100 more
            now = [0.0]

            def tick():
                now[0] += 1.0
                return now[0]
            build = NeighbourSearch._build

            def dear_build(self):
                now[0] += 100.0
                return build(self)
            monkeypatch.setattr(sphgen.scene, "time", types.SimpleNamespace(perf_counter=tick))
            monkeypatch.setattr(NeighbourSearch, "_build", dear_build)
        app = load_application("taylor_green")()
        app.run(["--nx", "30", "--skin", "0.03", "--max-steps", "150", "--no-openmp", "--no-progress", "--disable-output",
                 "-d", str(tmp_path / f"run{tuned}")] + (["--tune-skin"] if tuned else []))
        f = app.scene.by_name["fluid"]
        finals[tuned] = {p: f.get(p).copy() for p in ("x", "y", "u", "v", "rho", "p")}
        assert app.scene.nnps.n_builds > 20
        if tuned:
            tuner = app.scene.skin_tuner
            assert tuner.choices and tuner.skin == 0.5          # the widest: rebuilds are dear
            assert app.scene.nnps.skin == 0.5
    for p in finals[False]:
        np.testing.assert_array_equal(finals[True][p], finals[False][p])


def test_tuning_without_a_skin_is_one_clear_line(tmp_path, capsys):
    out = tmp_path / "run"
    with pytest.raises(SystemExit) as e:
        load_application("taylor_green")().run(["--skin", "0", "--tune-skin", "-d", str(out)])
    assert e.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["sphgen: --tune-skin chooses among skins: give --skin above 0 "
                   "(see sphgen run taylor_green --help)"]
    assert not out.exists()
