"""Reference baseline: run PySPH's Taylor-Green EDAC example and parse it.

PySPH is *not* a dependency of sphgen.  It lives in a separate virtualenv
(see :func:`find_pysph_python`) and is driven purely as a subprocess, the
same way a user would run::

    pysph run taylor_green --scheme edac --nx 50 --tf 0.5 --disable-output

Only the standard library and numpy are used here (numpy to read the
``results.npz`` that the example's ``post_process`` writes).

Typical use::

    from benchmarks.pysph_baseline import find_pysph_python, run_pysph
    py = find_pysph_python()
    if py is not None:
        r = run_pysph(py, nx=50, tf=0.5, openmp=True, threads=2,
                      workdir="/tmp/pysph_runs")
        print(r["run_s"], r["us_per_real_particle_step"])
"""

from __future__ import annotations

import csv
import os
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO_ROOT = Path(__file__).resolve().parents[1]
DEFAULT_VENV_PYTHON = Path("/work/pysph-venv/bin/python")

_RE_SETUP = re.compile(r"Setup took:\s*([0-9.eE+-]+)\s*secs")
_RE_RUN = re.compile(r"Run took:\s*([0-9.eE+-]+)\s*secs")
_RE_NFLUID = re.compile(r"nfluid\s*=\s*(\d+),\s*dt\s*=\s*([0-9.eE+-]+)")
_RE_NARRAY = re.compile(r"No of particles:\s*\n\s*fluid:\s*(\d+)")
_RE_EDAC_NU = re.compile(r"viscosity for EDAC with nu\s*=\s*([0-9.eE+-]+)")
_RE_COMPILING = re.compile(r"Compiling code at")


def find_pysph_python(repo_root: str | os.PathLike | None = None) -> str | None:
    """Return the python executable of a PySPH virtualenv, or None.

    Looked up in order: the ``PYSPH_PYTHON`` environment variable,
    ``/work/pysph-venv/bin/python``, ``<repo>/.pysph-venv/bin/python``.
    A candidate is accepted only if it exists and is executable.
    """
    root = Path(repo_root) if repo_root is not None else REPO_ROOT
    candidates = []
    env = os.environ.get("PYSPH_PYTHON")
    if env:
        candidates.append(Path(env))
    candidates.append(DEFAULT_VENV_PYTHON)
    candidates.append(root / ".pysph-venv" / "bin" / "python")
    for c in candidates:
        if c.is_file() and os.access(c, os.X_OK):
            return str(c)
    return None


def _read_text(path: Path) -> str:
    try:
        return path.read_text(errors="replace")
    except OSError:
        return ""


def _loadavg() -> float | None:
    """1-minute load average (the machine may be shared), or None."""
    try:
        return os.getloadavg()[0]
    except (AttributeError, OSError):
        return None


def _busy_cpu_seconds() -> float | None:
    """Machine-wide busy CPU seconds so far (Linux /proc/stat), or None."""
    try:
        with open("/proc/stat") as f:
            fields = f.readline().split()[1:]
        ticks = [int(v) for v in fields]
        idle = ticks[3] + (ticks[4] if len(ticks) > 4 else 0)  # idle + iowait
        busy = sum(ticks[:8]) - idle  # guest time is already in user
        return busy / os.sysconf("SC_CLK_TCK")
    except (OSError, ValueError, IndexError):
        return None


def _read_profile(path: Path) -> dict:
    """Parse PySPH's ``profile_info.csv``: {function: (calls, seconds)}."""
    prof = {}
    try:
        with open(path, newline="") as f:
            for row in csv.DictReader(f):
                prof[row["function"]] = (int(row["calls"]), float(row["time"]))
    except (OSError, KeyError, ValueError):
        pass
    return prof


def _read_results(path: Path) -> dict | None:
    """Final-time values from the example's ``results.npz`` (or None)."""
    if not path.is_file():
        return None
    import numpy as np

    with np.load(path) as data:
        arrays = {k: np.asarray(data[k]) for k in data.files}
    if "t" not in arrays or arrays["t"].size == 0:
        return None
    i = int(np.argmax(arrays["t"]))
    out = {k: float(v[i]) for k, v in arrays.items() if v.ndim == 1 and v.size > i}
    out["keys"] = sorted(arrays)
    out["n_outputs"] = int(arrays["t"].size)
    return out


def run_pysph(
    python_exe: str,
    nx: int = 50,
    tf: float = 0.5,
    openmp: bool = False,
    threads: int | None = None,
    workdir: str | os.PathLike | None = None,
    *,
    with_error: bool = False,
    pfreq: int = 50,
    fresh_cache: bool = False,
    scheme: str = "edac",
    extra_args: list[str] | None = None,
    timeout: float | None = None,
) -> dict:
    """Run PySPH's ``taylor_green`` example once and return parsed results.

    Parameters
    ----------
    python_exe : python of a virtualenv with PySPH installed.
    nx, tf : resolution (nx*nx fluid particles on [0,1]^2) and final time.
    openmp : pass ``--openmp`` to PySPH.
    threads : if given, ``OMP_NUM_THREADS`` for the child process.
    workdir : directory for the output folder (a temp dir if None).
    with_error : run with output (every ``pfreq`` steps) so that the
        example's post_process writes ``results.npz``; its final-time
        L1 error, max|u| etc. are returned under ``"error"``.
    fresh_cache : compile into a private, empty cache (HOME points into
        the output dir), so ``setup_s`` includes the full Cython compile.
    timeout : seconds before the child is killed (subprocess.TimeoutExpired).

    Returns a dict with keys: ``cmd``, ``returncode``, ``wall_s``,
    ``setup_s`` (PySPH "Setup took", includes code generation and compile
    when not cached), ``run_s`` (PySPH "Run took", the time loop only),
    ``cpu_user_s``/``cpu_sys_s`` (child CPU time, whole process),
    ``load_before``/``load_after`` (1-min load average; the machine may be
    shared, so compare timings only at similar load), ``other_cpu_s``
    (CPU seconds used by *other* processes on the machine during the run:
    a direct contention measure; ~0 means the timing is clean),
    ``compiled`` (True if this run compiled its extension), ``n_real``
    (fluid particles), ``n_array`` (fluid + periodic ghosts in the array),
    ``dt``, ``steps``, ``accel_evals``, ``edac_nu``, ``profile`` (dict of
    PySPH's profile: function -> (calls, seconds)),
    ``us_per_real_particle_step``, ``us_per_array_particle_step``,
    ``output_dir``, ``stdout_tail`` and, with ``with_error``, ``error``
    (final-time values from results.npz: t, l1, linf, p_l1, decay,
    decay_ex, ke, ke_ex).
    """
    if workdir is None:
        workdir = tempfile.mkdtemp(prefix="pysph_run_")
    workdir = Path(workdir).resolve()
    workdir.mkdir(parents=True, exist_ok=True)
    tag = "tg_%s_nx%d_tf%g_%s%s" % (
        scheme, nx, tf, "omp" if openmp else "serial",
        "" if threads is None else str(threads),
    )
    out_dir = workdir / tag
    out_dir.mkdir(parents=True, exist_ok=True)
    for stale in ("taylor_green.log", "profile_info.csv", "results.npz"):
        (out_dir / stale).unlink(missing_ok=True)

    cmd = [
        str(python_exe), "-m", "pysph.examples.run", "taylor_green",
        "--scheme", scheme, "--nx", str(nx), "--tf", repr(float(tf)),
        "-d", str(out_dir),
    ]
    if with_error:
        cmd += ["--pfreq", str(int(pfreq))]
    else:
        cmd += ["--disable-output"]
    if openmp:
        cmd += ["--openmp"]
    if extra_args:
        cmd += list(extra_args)

    env = dict(os.environ)
    if threads is not None:
        env["OMP_NUM_THREADS"] = str(int(threads))
    if fresh_cache:
        home = out_dir / "home"
        home.mkdir(exist_ok=True)
        env["HOME"] = str(home)

    load_before = _loadavg()
    ru0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    busy0 = _busy_cpu_seconds()
    t0 = time.perf_counter()
    proc = subprocess.run(
        cmd, cwd=str(workdir), env=env, capture_output=True, text=True,
        timeout=timeout,
    )
    wall = time.perf_counter() - t0
    ru1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    busy1 = _busy_cpu_seconds()
    cpu_user = ru1.ru_utime - ru0.ru_utime
    cpu_sys = ru1.ru_stime - ru0.ru_stime
    other_cpu = None
    if busy0 is not None and busy1 is not None:
        other_cpu = max(0.0, (busy1 - busy0) - cpu_user - cpu_sys)
    text = proc.stdout + "\n" + proc.stderr
    log = _read_text(out_dir / "taylor_green.log")
    both = text + "\n" + log

    def grab(rx, conv=float, src=both):
        m = rx.search(src)
        return conv(m.group(1)) if m else None

    m = _RE_NFLUID.search(both)
    n_real = int(m.group(1)) if m else None
    dt = float(m.group(2)) if m else None
    prof = _read_profile(out_dir / "profile_info.csv")
    steps = prof.get("Integrator.stage2", (None, None))[0]
    if steps is None and dt:
        steps = int(round(tf / dt))
    accel = prof.get("acceleration_eval_0", (None, None))[0]
    if accel is not None and "Integrator.initial_acceleration" in prof:
        accel += prof["Integrator.initial_acceleration"][0]

    result = {
        "cmd": cmd,
        "returncode": proc.returncode,
        "wall_s": wall,
        "cpu_user_s": cpu_user,
        "cpu_sys_s": cpu_sys,
        "other_cpu_s": other_cpu,
        "load_before": load_before,
        "load_after": _loadavg(),
        "setup_s": grab(_RE_SETUP),
        "run_s": grab(_RE_RUN),
        "compiled": bool(_RE_COMPILING.search(both)),
        "nx": nx,
        "tf": tf,
        "openmp": openmp,
        "threads": threads,
        "n_real": n_real,
        "n_array": grab(_RE_NARRAY, int),
        "dt": dt,
        "steps": steps,
        "accel_evals": accel,
        "edac_nu": grab(_RE_EDAC_NU),
        "profile": prof,
        "output_dir": str(out_dir),
        "stdout_tail": text[-2000:],
    }
    run_s = result["run_s"]
    if run_s and steps:
        for key, n in (("us_per_real_particle_step", n_real),
                       ("us_per_array_particle_step", result["n_array"])):
            result[key] = 1e6 * run_s / (steps * n) if n else None
    if with_error:
        # The example's post_process saves results.npz *before* it imports
        # matplotlib for plots, so a missing matplotlib only loses the PNGs.
        result["error"] = _read_results(out_dir / "results.npz")
    return result


def main(argv: list[str] | None = None) -> int:
    import argparse
    import json

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--python", default=None, help="PySPH venv python")
    p.add_argument("--nx", type=int, default=50)
    p.add_argument("--tf", type=float, default=0.5)
    p.add_argument("--openmp", action="store_true")
    p.add_argument("--threads", type=int, default=None)
    p.add_argument("--workdir", default=None)
    p.add_argument("--with-error", action="store_true")
    p.add_argument("--fresh-cache", action="store_true")
    a = p.parse_args(argv)
    py = a.python or find_pysph_python()
    if py is None:
        print("no PySPH python found (set PYSPH_PYTHON)", file=sys.stderr)
        return 2
    r = run_pysph(py, a.nx, a.tf, a.openmp, a.threads, a.workdir,
                  with_error=a.with_error, fresh_cache=a.fresh_cache)
    r.pop("stdout_tail")
    print(json.dumps(r, indent=1, default=str))
    return 0 if r["returncode"] == 0 or r.get("error") else 1


if __name__ == "__main__":
    sys.exit(main())
