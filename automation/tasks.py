"""automan glue: a task is done when its sphgen run wrote info.json with completed (or stopped): true."""
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
        try:
            with open(os.path.join(self.output_dir, "info.json")) as f:
                return json.load(f)
        except (OSError, ValueError):
            return {}

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


class SphgenProblem(Problem):
    """A Problem whose cases are sphgen runs (``Simulation(root, 'sphgen run NAME', ...)``)."""

    task_cls = SphgenTask

    @staticmethod
    def sphgen(app):
        exe = os.path.join(os.path.dirname(sys.executable), "sphgen")
        return f"{exe} run {app}"

    @staticmethod
    def results(case):
        with open(case.input_path("results.json")) as f:
            return json.load(f)

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


__all__ = ["SphgenProblem", "SphgenTask", "Simulation", "paper_and_quick"]
