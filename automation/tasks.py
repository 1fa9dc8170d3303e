"""automan glue: a task is done when its sphgen run wrote info.json with completed (or stopped): true.

The figure scripts ask :func:`run_state` what became of a run: ``"completed"`` (it reached its
end and wrote results.json), ``"stopped"`` (the blow-up guard ended it: its info.json,
history.json and output files hold the run up to the stop, but there is no results.json) or
``"not run"`` (no info.json, or a run that has not ended).  :func:`state_suffix` is the label
that marks a stopped run's curves and panels; :func:`missing` reports a quantity that only
results.json has."""
import json
import os
import sys

from automan.api import CommandTask, Problem, Simulation


class SphgenTask(CommandTask):
    """Runs ``sphgen run ...`` with ``-d <output_dir>``.

    Done when the run's info.json says ``completed`` or ``stopped`` (the blow-up guard ended
    it: its job exits non-zero, but its data up to the stop is on disk and running it again
    would stop at the same step)."""

    def __init__(self, command, output_dir, job_info=None, depends=None):
        if isinstance(command, str):
            command = command + " -d $output_dir --no-progress --overwrite"
        super().__init__(command, output_dir, job_info, depends)

    def info(self):
        """The run's info.json, or {} if there is none (yet) or it cannot be read."""
        return run_info(self.output_dir)

    def _is_done(self):
        info = self.info()
        return bool(info.get("completed") or info.get("stopped"))

    def _copy_output_and_check_status(self):
        """automan's check of a job it started, except that a job the guard stopped is done."""
        jp = self.job_proxy
        if jp.status() == "error":
            copy = jp.copy_output(".")      # a remote job's folder, as automan fetches it
            if copy is not None:
                copy.wait()
            info = self.info()
            if info.get("stopped"):
                jp.clean()
                self._finished = True
                print(f"\n{self.output_dir}: stopped by the blow-up guard at t={info.get('t')}; "
                      "its data up to the stop is kept")
                return True
        return super()._copy_output_and_check_status()


def _folder(run):
    """The folder of ``run``: an automan case (``Simulation``) or a path."""
    return run.input_path() if hasattr(run, "input_path") else os.fspath(run)


def run_info(run):
    """The run's info.json, or {} if there is none or it cannot be read."""
    try:
        with open(os.path.join(_folder(run), "info.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def run_state(run):
    """"completed", "stopped" (by the blow-up guard) or "not run" (nothing, or not ended)."""
    info = run_info(run)
    if info.get("completed"):
        return "completed"
    return "stopped" if info.get("stopped") else "not run"


def stopped_at(run):
    """"stopped at t = ..." (the time in its info.json) for a stopped run, else None."""
    if run_state(run) != "stopped":
        return None
    t = run_info(run).get("t")
    return "stopped at t = " + ("?" if t is None else f"{t:.4g}")


def state_suffix(run):
    """" (stopped at t = ...)" for a stopped run, "" otherwise: appended to its labels."""
    at = stopped_at(run)
    return f" ({at})" if at else ""


def stopped_marks(runs):
    """" (tag stopped at t = ...; ...)" for the stopped runs of {tag: run}, "" if none: the label
    of a curve drawn from several runs (a convergence line)."""
    marks = [f"{tag} {stopped_at(run)}" for tag, run in runs.items() if stopped_at(run)]
    return f" ({'; '.join(marks)})" if marks else ""


def reached(run, t, last, tol=0.01):
    """False for a time ``t`` that a stopped run did not reach (later than its last output
    ``last`` by more than ``tol`` of it): its panel says "stopped at t = ..." instead of
    repeating the last output."""
    return run_state(run) != "stopped" or t <= last * (1 + tol) + 1e-12


def state_text(run):
    """What an empty panel of ``run`` says: "stopped at t = ..." or "not run"."""
    return stopped_at(run) or "not run"


def missing(run, what, why="only a run that reaches its end writes results.json"):
    """Print that ``what`` of ``run`` is missing (it stopped or did not run) and ``why``; None."""
    print(f"note: {os.path.basename(os.path.normpath(_folder(run)))} {state_text(run)}: {what} missing ({why})")
    return None


def read_results(run, what="its results"):
    """The run's results.json, or None if it has none: with a printed note (:func:`missing`)
    if the run was started (it has an info.json: stopped, or failed), silently if never run."""
    try:
        with open(os.path.join(_folder(run), "results.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return missing(run, what) if run_info(run) else None


def pick(run, res, keys):
    """{key: res[key]} of a run's results (None for any it lacks, every one if ``res`` is
    None), with ``stopped_at`` (the time in info.json) for a stopped run."""
    out = {k: (res or {}).get(k) for k in keys}
    if run_state(run) == "stopped":
        out["stopped_at"] = run_info(run).get("t")
    return out


class SphgenProblem(Problem):
    """A Problem whose cases are sphgen runs (``Simulation(root, 'sphgen run NAME', ...)``)."""

    task_cls = SphgenTask

    @staticmethod
    def sphgen(app):
        exe = os.path.join(os.path.dirname(sys.executable), "sphgen")
        return f"{exe} run {app}"

    @staticmethod
    def results(case, what="its results"):
        """The case's results.json, or None (with a printed note) if it stopped or did not end."""
        return read_results(case, what)

    @staticmethod
    def history(case):
        with open(case.input_path("history.json")) as f:
            return json.load(f)


def paper_and_quick(base, name, doc, module, **attrs):
    """Two subclasses of ``base``: ``name`` (preset "paper") and ``name + "Quick"`` (preset
    "quick"), with the class attributes ``attrs``, documented by ``doc``."""
    paper = type(name, (base,), {**attrs, "__doc__": doc, "__module__": module})
    quick = type(name + "Quick", (paper,), {"preset": "quick", "__doc__": doc + " (quick preset)",
                                             "__module__": module})
    return paper, quick


__all__ = ["SphgenProblem", "SphgenTask", "Simulation", "missing", "paper_and_quick", "pick", "read_results",
           "reached", "run_info", "run_state", "state_suffix", "state_text", "stopped_at", "stopped_marks"]
