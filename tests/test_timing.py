"""``--timing``: exclusive per-part timers whose rows add up to the time loop."""
import json

import pytest

from sphgen.app import load_application
from sphgen.timing import Timers


class FakeClock:
    """A clock that each timed function advances by a fixed amount."""

    def __init__(self):
        self.now = 0.0

    def __call__(self):
        return self.now


def test_nested_timers_are_exclusive_and_add_up():
    clock = FakeClock()
    timers = Timers()
    timers.clock = clock

    def inner():
        clock.now += 2.0

    timed_inner = timers.wrap(inner, "inner")

    def outer():
        clock.now += 1.0
        timed_inner()
        timed_inner()
        clock.now += 0.5

    timers.wrap(outer, "outer")()
    assert timers.seconds == {"outer": pytest.approx(1.5), "inner": pytest.approx(4.0)}
    assert timers.calls == {"outer": 1, "inner": 2}
    rows, serial = timers.table(loop_seconds=10.0, steps=2)
    by = {r[0]: r for r in rows}
    assert by["inner"][3] == pytest.approx(2000.0)          # ms per step
    assert by["inner"][4] == pytest.approx(1.0)             # calls per step
    other = [r for r in rows if r[0].startswith("other")][0]
    assert other[1] == pytest.approx(10.0 - 5.5)
    assert serial == pytest.approx(1.0)                     # neither label is a threaded part


def test_labels_from_arguments_and_serial_share():
    clock = FakeClock()
    timers = Timers()
    timers.clock = clock

    def run_pass(npass, t, dt):
        clock.now += 3.0

    def guard():
        clock.now += 1.0

    timed = timers.wrap(run_pass, lambda npass, t, dt: f"pass {npass}")
    timed("g0", 0.0, 0.1)
    timed("g1", 0.0, 0.1)
    timers.wrap(guard, "blow-up guard")()
    text, as_dict = timers.report(loop_seconds=8.0, steps=1, threads=1)
    assert set(timers.seconds) == {"pass g0", "pass g1", "blow-up guard"}
    assert as_dict["serial_share"] == pytest.approx(2.0 / 8.0)
    assert "at most 1.60x" in text                         # 1 / (0.25 + 0.75 / 2)


def test_run_with_timing_reports_every_part(tmp_path, capsys):
    out = tmp_path / "run"
    app = load_application("taylor_green")()
    app.run(["--no-progress", "--nx", "16", "--tf", "0.01", "--disable-output", "--timing",
             "--no-openmp", "-d", str(out)])
    printed = capsys.readouterr().out
    info = json.load(open(out / "info.json"))
    timing = info["timing"]
    parts = {r["part"] for r in timing["rows"]}
    assert any(p.startswith("pass ") for p in parts) and any(p.startswith("stage ") for p in parts)
    assert {"neighbours: cells", "neighbours: lists", "blow-up guard"} <= parts
    total = sum(r["seconds"] for r in timing["rows"])
    assert total == pytest.approx(info["wall_time"], rel=1e-6)
    other = [r for r in timing["rows"] if r["part"].startswith("other")][0]
    assert other["seconds"] > 0             # the initial accelerations are not in the loop's rows
    passes = [r for r in timing["rows"] if r["part"].startswith("pass ")]
    assert all(r["calls_per_step"] == pytest.approx(1.0) for r in passes)
    assert timing["steps"] == info["steps"]
    assert "2 threads can make this run at most" in printed
