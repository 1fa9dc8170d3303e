"""automan glue: a task is done when its sphgen run wrote info.json with completed: true."""
import json
import os
import sys

from automan.api import CommandTask, Problem, Simulation


class SphgenTask(CommandTask):
    """Runs ``sphgen run ...`` with ``-d <output_dir>``."""

    def __init__(self, command, output_dir, job_info=None, depends=None):
        if isinstance(command, str):
            command = command + " -d $output_dir --no-progress --overwrite"
        super().__init__(command, output_dir, job_info, depends)

    def _is_done(self):
        info = os.path.join(self.output_dir, "info.json")
        try:
            with open(info) as f:
                return bool(json.load(f).get("completed"))
        except (OSError, ValueError):
            return False


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
