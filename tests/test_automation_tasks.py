"""automation.tasks.SphgenTask: a run the blow-up guard stopped is done, not an error.

The jobs are fakes (no process is started): what automan sees of a job is its status, and
what SphgenTask reads is the run folder's info.json.
"""
import json
import os

import pytest
from automan.automation import TaskRunner

from automation.tasks import SphgenTask


class FakeWorker:
    host = "localhost"


class FakeJobProxy:
    """automan's view of a submitted job that has ended with ``status``."""

    worker = FakeWorker()

    def __init__(self, status):
        self._status = status
        self.cleaned = False

    def status(self):
        return self._status

    def copy_output(self, dest):
        return None            # a local job: nothing to copy

    def clean(self, force=False):
        self.cleaned = True

    def get_stderr(self):
        return "sphgen: speed |(u, v)| = 30.1 of fluid particle 226 is above the scheme's limit 10"


def write_info(folder, **info):
    os.makedirs(folder, exist_ok=True)
    with open(os.path.join(folder, "info.json"), "w") as f:
        json.dump(info, f)


def task(folder):
    return SphgenTask("sphgen run taylor_green", str(folder))


STOPPED = dict(completed=False, stopped=True, error="speed ... above the scheme's limit", t=0.12)
INTERRUPTED = dict(completed=False, stopped=False, error="interrupted", t=0.05)
FINISHED = dict(completed=True, stopped=False, error=None, t=0.5)


def test_a_job_the_guard_stopped_is_done_and_not_flagged(tmp_path, capsys):
    t = task(tmp_path / "case")
    write_info(t.output_dir, **STOPPED)
    t.job_proxy = FakeJobProxy("error")
    assert t.complete() is True
    assert t.complete() is True              # asked again: still done
    assert not os.path.exists(t._error_status_file)
    assert t.job_proxy.cleaned
    assert "stopped by the blow-up guard at t=0.12" in capsys.readouterr().out


@pytest.mark.parametrize("info", [INTERRUPTED, None], ids=["ctrl-c", "no-info"])
def test_a_job_that_failed_otherwise_is_still_an_error(tmp_path, info):
    t = task(tmp_path / "case")
    if info is not None:
        write_info(t.output_dir, **info)
    else:
        os.makedirs(t.output_dir)
    t.job_proxy = FakeJobProxy("error")
    with pytest.raises(RuntimeError, match="failed"):
        t.complete()
    assert os.path.exists(t._error_status_file)


def test_a_running_job_is_not_done_yet(tmp_path):
    t = task(tmp_path / "case")
    write_info(t.output_dir, completed=False, stopped=False, error=None, t=0.01)
    t.job_proxy = FakeJobProxy("running")
    assert t.complete() is False


@pytest.mark.parametrize("info,done", [(STOPPED, True), (FINISHED, True), (INTERRUPTED, False),
                                       (None, False)], ids=["stopped", "finished", "ctrl-c", "none"])
def test_an_earlier_run_counts_as_done_when_finished_or_stopped(tmp_path, info, done):
    """A later ``python automate.py`` (no job of its own): only info.json decides."""
    t = task(tmp_path / "case")
    if info is not None:
        write_info(t.output_dir, **info)
    assert t.complete() is done


class FakeScheduler:
    """Submitting a job 'runs' it at once: writes its info.json and returns its proxy."""

    def __init__(self, outcomes):
        self.outcomes = outcomes     # output_dir -> (info, job status)
        self.submitted = []

    def submit(self, job):
        info, status = self.outcomes[job.output_dir]
        write_info(job.output_dir, **info)
        self.submitted.append(job.output_dir)
        return FakeJobProxy(status)


def test_a_preset_goes_on_past_a_stopped_run(tmp_path, capsys):
    """automan's own task runner: the stopped case and the finished one are both done, no errors."""
    stopped, finished = task(tmp_path / "stopped"), task(tmp_path / "finished")
    sched = FakeScheduler({stopped.output_dir: (STOPPED, "error"), finished.output_dir: (FINISHED, "done")})
    runner = TaskRunner([stopped, finished], sched)
    assert runner.run(wait=0) == 0
    assert sorted(sched.submitted) == sorted([stopped.output_dir, finished.output_dir])
    assert runner.task_status[stopped] == runner.task_status[finished] == "done"
    # and a second invocation runs neither again
    again = FakeScheduler({})
    assert TaskRunner([task(tmp_path / "stopped"), task(tmp_path / "finished")], again).run(wait=0) == 0
    assert again.submitted == []
