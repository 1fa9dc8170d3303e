"""``sphgen precision`` and ``sphgen stress``: many runs of one application, one table, one plot.

Both take the application's own options and pass them through; an option given several
values (``--nx 25 50 100``, ``--scheme ctvf edac``) is a sweep axis, and the runs are
the product of the axes.  Each run is ``sphgen run NAME ... -d DIR/<case>`` in its own
process (a blow-up or crash stops that run only), reading ``info.json`` and
``results.json`` afterwards.  Runs are serial unless ``--jobs`` asks for more.
"""
import argparse
import itertools
import json
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

from . import io
from .errors import InputError

_NUMBER = re.compile(r"^-?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$")


def split_sweep(args):
    """(axes [(option, [values])], fixed [args]) from an application's argument list."""
    groups, axes, fixed = [], [], []
    for a in args:
        if a.startswith("-") and not _NUMBER.match(a):
            groups.append([a])
        elif groups:
            groups[-1].append(a)
        else:
            raise InputError(f"value {a!r} does not follow an option")
    for opt, *vals in groups:
        if len(vals) > 1:
            axes.append((opt, vals))
        else:
            fixed += [opt, *vals]
    return axes, fixed


def cases(axes):
    """[(label, args)] for every combination of the axes' values."""
    out = []
    for combo in itertools.product(*[vals for _, vals in axes]):
        args = [x for (opt, _), v in zip(axes, combo) for x in (opt, v)]
        label = "_".join(f"{opt.lstrip('-')}{v}" for (opt, _), v in zip(axes, combo)) or "run"
        out.append((re.sub(r"[^\w.+-]", "_", label), args))
    return out


def run_one(name, args, outdir):
    """One ``sphgen run``; returns its options, exit status, message, info and results."""
    exe = os.path.join(os.path.dirname(sys.executable), "sphgen")
    cmd = [exe, "run", name, *args, "-d", outdir, "--no-progress", "--overwrite"]
    p = subprocess.run(cmd, capture_output=True, text=True)
    lines = [ln for ln in p.stderr.splitlines() if ln.startswith("sphgen:")]
    row = {"args": args, "exit": p.returncode, "message": lines[-1] if lines else "",
           "info": _read(os.path.join(outdir, "info.json")),
           "results": _read(os.path.join(outdir, "results.json"))}
    return row


def _read(path):
    try:
        with open(path) as f:
            return json.load(f)
    except (OSError, ValueError):
        return {}


def check_runs(name, todo, what):
    """Every run's options parsed by the application before any run starts (and before the
    study's folder is made): a wrong option is one line, not a table of failed runs."""
    from .app import load_application
    parser = load_application(name)().parser()
    for label, args in todo:
        try:
            parser.parse_args(list(args) + ["-d", os.devnull])
        except InputError as e:
            raise InputError(f"{what} {name}, run {label}: {e}") from None


def run_all(name, todo, directory, jobs, what):
    """Run [(label, args)] into ``directory/<label>``, ``jobs`` at a time, with a progress bar."""
    from tqdm import tqdm
    check_runs(name, todo, what)
    os.makedirs(directory, exist_ok=True)
    with ThreadPoolExecutor(max_workers=max(1, jobs)) as pool:
        futures = [pool.submit(run_one, name, args, os.path.join(directory, label)) for label, args in todo]
        rows = []
        for (label, _), fut in zip(todo, tqdm(futures, desc=f"sphgen {what} {name}", unit="run")):
            row = fut.result()
            row["case"] = label
            rows.append(row)
    return rows


def _parser(what, description):
    # no abbreviations: an application's option (e.g. --re) must not be taken for one of
    # these (--reference)
    p = argparse.ArgumentParser(prog=f"sphgen {what} NAME", description=description, allow_abbrev=False)
    p.add_argument("name", help="the application")
    p.add_argument("-d", "--directory", default=None, help=f"output folder (default NAME_{what})")
    p.add_argument("--jobs", type=int, default=1, help="runs at a time (default 1: serial)")
    return p


def _parse(p, argv):
    known, rest = p.parse_known_args(argv)
    from .app import list_applications, unknown_application
    if known.name not in list_applications():
        raise InputError(unknown_application(known.name))
    known.directory = known.directory or f"{known.name}_{p.prog.split()[1]}"
    return known, rest


def _table(path, header, rows):
    """A Markdown table, written atomically; returns its text."""
    lines = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    text = "\n".join(lines) + "\n"
    io._write_text(path, text)
    return text


def _plt():
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


# ---------------------------------------------------------------- precision
def precision(argv):
    """``sphgen precision NAME [--error KEY] [--reference FILE] [app options, lists sweep]``."""
    p = _parser("precision", "Error against run time over resolutions (and schemes, dt factors).")
    p.add_argument("--error", default=None, help="results.json key of the error (default: the "
                   "application's error_key)")
    p.add_argument("--reference", default=None, help="JSON of other codes' points to plot beside ours "
                   "(default: sphgen/tools/reference/pysph_NAME.json if it exists)")
    p.add_argument("--repeat", type=int, default=1, help="rounds of every run (default 1); the run time "
                   "is the fastest round's, the error must be the same in every round")
    o, rest = _parse(p, argv)
    if o.repeat < 1:
        raise InputError(f"--repeat must be at least 1, not {o.repeat}")
    from .app import load_application
    key = o.error or getattr(load_application(o.name), "error_key", None)
    if key is None:
        raise InputError(f"application '{o.name}' names no error measure: pass --error KEY")
    axes, fixed = split_sweep(rest)
    todo = [(label, args + fixed) for label, args in cases(axes)]
    rows = fastest_round([run_all(o.name, todo, o.directory, o.jobs, "precision") for _ in range(o.repeat)], key)
    table = [[r["case"], r["info"].get("n_particles", ""), _fmt(r["info"].get("wall_time")),
              _fmt(r["results"].get(key)), "yes" if r["info"].get("completed") else r["message"]]
             for r in rows]
    io.write_json(os.path.join(o.directory, "precision.json"), {"error_key": key, "runs": rows})
    text = _table(os.path.join(o.directory, "precision.md"),
                  ["case", "particles", "wall time [s]", key, "completed"], table)
    ref = _reference(o.reference, o.name)
    if ref is not None and (ref.get("error_key") != key or not _same_tf(ref, rows)):
        print(f"reference points not plotted: they measure {ref.get('error_key')} at t={ref.get('tf')}; "
              f"pass --error {ref.get('error_key')} --tf {ref.get('tf')} to compare")
        ref = None
    if ref is not None and not _same_start(ref, rows):
        print(f"reference points not plotted: they start from a lattice perturbed by {ref.get('perturb', 0):g} dx; "
              f"pass --perturb {ref.get('perturb', 0):g} to compare")
        ref = None
    _plot_precision(os.path.join(o.directory, "precision.png"), axes, rows, key, ref)
    print(text + f"table: {os.path.join(o.directory, 'precision.md')}\n"
          f"plot:  {os.path.join(o.directory, 'precision.png')}")
    return 0 if all(r["exit"] == 0 for r in rows) else 1


def fastest_round(rounds, key):
    """The rows of the first round, each with the fastest round's wall time (the least
    disturbed, as ``timeit`` takes it) and every round's in ``wall_times``.  Rounds are run
    one after the other over all cases, so a slow spell of the machine hits every case
    alike.  A run is deterministic: an error that differs between rounds, or a round that
    did not complete, marks the row as failed."""
    rows = rounds[0]
    for i, row in enumerate(rows):
        same = [r[i] for r in rounds]
        times = [r["info"].get("wall_time") for r in same]
        if len(rounds) == 1 or any(t is None for t in times):
            continue
        row["info"] = dict(row["info"], wall_time=min(times), wall_times=times)
        errors = {r["results"].get(key) for r in same}
        if len(errors) > 1 or any(r["exit"] != row["exit"] for r in same):
            row["exit"] = row["exit"] or 1
            row["message"] = f"sphgen: the rounds differ: {key} {sorted(map(str, errors))}, exit {[r['exit'] for r in same]}"
            row["info"]["completed"] = False
    return rows


def _fmt(v):
    return f"{v:.4g}" if isinstance(v, (int, float)) else "—"


def _reference(path, name):
    if path is None:
        path = os.path.join(os.path.dirname(__file__), "tools", "reference", f"pysph_{name}.json")
        if not os.path.exists(path):
            return None
    with open(path) as f:
        return json.load(f)


def _same_tf(ref, rows):
    return all(abs(r["info"].get("t", -1) - ref.get("tf", -2)) < 1e-9 for r in rows if r["info"])


def _same_start(ref, rows):
    """The runs start as the reference's did (its ``perturb``, 0 if it names none), where
    the application has a ``--perturb`` option."""
    want = float(ref.get("perturb", 0.0))
    return all(abs(float(r["info"]["options"]["perturb"]) - want) < 1e-12 for r in rows
               if r["info"] and "perturb" in r["info"].get("options", {}))


def _line_axis(axes):
    """The numeric axis with the most values runs along a line; the others group lines."""
    numeric = [i for i, (_, vals) in enumerate(axes) if all(_NUMBER.match(v) for v in vals)]
    return max(numeric, key=lambda i: len(axes[i][1])) if numeric else None


def _plot_precision(path, axes, rows, key, ref):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 4.5))
    along = _line_axis(axes)
    groups = {}
    for r in rows:
        pairs = list(zip(r["args"][::2], r["args"][1::2]))[:len(axes)]
        label = ", ".join(f"{o} {v}" for i, (o, v) in enumerate(pairs) if i != along)
        groups.setdefault(label, []).append((r, pairs[along][1] if along is not None else ""))
    for label, members in groups.items():
        ok = [(m["info"]["wall_time"], m["results"][key], v) for m, v in members
              if m["results"].get(key) is not None and m["info"].get("wall_time")]
        if ok:
            ax.loglog([a for a, _, _ in ok], [b for _, b, _ in ok], "o-", label=f"sphgen {label}".strip())
            for a, b, v in ok:
                ax.annotate(str(v), (a, b), fontsize=8)
    for label, pts in (ref or {}).get("series", {}).items():
        ax.loglog([q["wall_time"] for q in pts], [q["error"] for q in pts], "s--", label=label)
        for q in pts:
            ax.annotate(str(q.get("label", "")), (q["wall_time"], q["error"]), fontsize=8)
    ax.set_xlabel("wall time of the time loop [s]")
    ax.set_ylabel(key)
    ax.legend(fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# ---------------------------------------------------------------- stress
def stress(argv):
    """``sphgen stress NAME [--runs N] [--perturb P] [--dt-factor F ...] [app options]``."""
    p = _parser("stress", "Perturbed runs at several time-step factors: which complete, which blow up.")
    p.add_argument("--runs", type=int, default=10, help="runs (seeds) per combination (default 10)")
    p.add_argument("--perturb", type=float, default=0.2, help="initial perturbation in dx (default 0.2)")
    p.add_argument("--stable-factor", type=float, default=1.0,
                   help="dt factor up to which the scheme documents stability (default 1)")
    o, rest = _parse(p, argv)
    from .app import load_application
    known = load_application(o.name)().parser()._option_string_actions
    missing = [opt for opt in ("--perturb", "--seed") if opt not in known]
    if missing:
        raise InputError(f"stress {o.name}: the application has no {' or '.join(missing)} option; "
                         "sphgen stress starts every run from a lattice perturbed at random")
    axes, fixed = split_sweep(rest)
    todo = []
    for label, args in cases(axes):
        for seed in range(o.runs):
            todo.append((f"{label}_seed{seed}", args + fixed + ["--perturb", str(o.perturb), "--seed", str(seed),
                                                               "--allow-unstable"]))
    rows = run_all(o.name, todo, o.directory, o.jobs, "stress")
    table, failures = [], 0
    for r in rows:
        factor = _dt_factor(r["args"])
        blew = r["exit"] != 0
        failures += blew and factor <= o.stable_factor * (1 + 1e-9)
        res = r["results"]
        table.append([r["case"], factor, "blew up: " + r["message"][8:] if blew else "completed",
                      _fmt(res.get("energy_error")), _fmt(res.get("max_density_error")),
                      _fmt(r["info"].get("wall_time"))])
    io.write_json(os.path.join(o.directory, "stress.json"), {"runs": rows, "stable_factor": o.stable_factor})
    text = _table(os.path.join(o.directory, "stress.md"),
                  ["run", "dt factor", "outcome", "energy error", "max density error", "wall time [s]"], table)
    _plot_stress(os.path.join(o.directory, "stress.png"), rows)
    print(text + f"{failures} run(s) blew up at or below the documented stable dt factor {o.stable_factor}")
    return 1 if failures else 0


def _dt_factor(args):
    for opt, v in zip(args, args[1:]):
        if opt == "--dt-factor":
            return float(v)
    return 1.0


def _plot_stress(path, rows):
    plt = _plt()
    fig, ax = plt.subplots(figsize=(6, 4))
    for k, r in enumerate(rows):
        ok = r["exit"] == 0
        t = r["info"].get("t", 0.0)
        ax.plot(_dt_factor(r["args"]) + 0.01 * (k % 10), t, "o" if ok else "x",
                color="tab:green" if ok else "tab:red")
    ax.set_xlabel("dt factor (runs jittered sideways)")
    ax.set_ylabel("time reached")
    ax.set_title("o completed, x blew up")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main(what, argv):
    return {"precision": precision, "stress": stress}[what](argv)


__all__ = ["precision", "stress", "split_sweep", "cases"]
