"""The output folder of a run and restarts into it: checked first, changed last.

Policy (docs/reliability.md): a run writes into a folder that holds no other run, or
continues the run it restarts from (``--restart`` of a file in that folder).  A folder
holding another run's files is refused, naming them, unless ``--overwrite`` asks to
clear them.  Temporaries of a dead writer are removed by the next run in the folder.
Every check here runs before anything is compiled or written.
"""
import json
import os

from . import io
from .errors import OutputError, RestartError


def same_folder(restart, outdir):
    """True if the restart file lives in ``outdir`` (the run continues in place)."""
    if not restart or not os.path.isdir(outdir):
        return False
    return os.path.samefile(os.path.dirname(os.path.abspath(restart)), outdir)


def check_output_folder(outdir, overwrite=False, restart=None):
    """Refuse a path that cannot be a folder, or a folder holding another run."""
    path = os.path.abspath(outdir)
    if os.path.exists(path) and not os.path.isdir(path):
        raise OutputError(f"-d {outdir} is a file, not a folder")
    parent = path
    while not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if not os.path.isdir(parent):
        raise OutputError(f"-d {outdir}: {parent} is a file, so no folder can be made below it")
    if not os.access(parent, os.W_OK | os.X_OK):
        raise OutputError(f"-d {outdir}: {parent} is not writable")
    found = io.run_files(path)
    if found and not overwrite and not same_folder(restart, path):
        shown = ", ".join(found[:3]) + (f" and {len(found) - 3} more" if len(found) > 3 else "")
        raise OutputError(f"-d {outdir} already holds a run ({shown}); pass --overwrite to replace "
                          "it, or choose another folder")


def prepare_output_folder(outdir, overwrite=False, restart=None):
    """Create the folder, remove dead temporaries and (``overwrite``) another run's files."""
    os.makedirs(outdir, exist_ok=True)
    removed = io.remove_stray_temporaries(outdir)
    if overwrite and not same_folder(restart, outdir):
        for fname in io.run_files(outdir):
            os.remove(os.path.join(outdir, fname))
            removed.append(fname)
    return removed


def read_restart(path):
    """The solver data of a restart file, or a RestartError naming what is wrong with it."""
    try:
        return io.read_solver_data(path)
    except FileNotFoundError:
        raise RestartError(f"--restart {path}: no such file") from None
    except (OSError, ValueError, KeyError) as e:
        raise RestartError(f"--restart: {e}") from None


def _flatten(d, prefix=""):
    out = {}
    for k, v in d.items():
        if isinstance(v, dict):
            out.update(_flatten(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def check_restart(path, data, signature, tf):
    """Refuse a restart file of another scene, or one at or past ``tf``."""
    stored = data.get("signature")
    if stored is None:
        raise RestartError(f"--restart {path} carries no record of the scene that wrote it, so "
                           "it cannot be checked against this run")
    now = _flatten(json.loads(json.dumps(signature)))
    then = _flatten(stored)
    diff = [f"{k} = {then.get(k)!r} there, {now.get(k)!r} now"
            for k in sorted(set(now) | set(then)) if then.get(k) != now.get(k)]
    if diff:
        more = f" (and {len(diff) - 3} more)" if len(diff) > 3 else ""
        raise RestartError(f"--restart {path} was written by another scene: "
                           + "; ".join(diff[:3]) + more)
    t = float(data["t"])
    if t >= tf - 1e-12 * max(1.0, tf):
        raise RestartError(f"--restart {path} is at t={t:.6g}, at or past --tf {tf:.6g}: nothing "
                           "to run; raise --tf to continue")


def restart_notes(data, dt, tf):
    """What a restart changes that it may change (said in the log)."""
    notes = []
    if "tf" in data and float(data["tf"]) != tf:
        notes.append(f"continuing to --tf {tf:.6g} (the run that wrote the file aimed at {float(data['tf']):.6g})")
    if float(data["dt"]) != dt:
        notes.append(f"time step {dt:.6g} (the run that wrote the file used {float(data['dt']):.6g})")
    return notes


def earlier_history(restart, t, name="history.json"):
    """The rows (first column t) of a time series of the restarted run up to time ``t``."""
    path = os.path.join(os.path.dirname(os.path.abspath(restart)), name)
    try:
        with open(path) as f:
            hist = json.load(f)
    except (OSError, ValueError):
        return None
    eps = 1e-12 * max(1.0, abs(t))
    hist["rows"] = [r for r in hist.get("rows", []) if r[0] <= t + eps]
    return hist


def earlier_info(outdir):
    """The info.json of a run in ``outdir`` (or {})."""
    try:
        with open(os.path.join(outdir, "info.json")) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}
