#!/usr/bin/env python
"""Work-precision: L1 error of |u| (Adepu & Ramachandran (2024) eq. 66) against wall time, Taylor-Green EDAC.

For nx in 25, 50, 100 (Re=100, tf=0.5) runs sphgen (2 threads) and, where a PySPH venv
is found, PySPH 1.0b2's EDAC, both from the same start: the square lattice moved by a
uniform random ``--perturb`` dx (default 0.1, sphgen's default; ``--perturb 0`` for the
plain lattice, PySPH's default); prints a table and writes a log-log plot.  Both the
final-time L1 and, for sphgen, its time average over the run are reported: the
final-time value carries acoustic oscillations of period L/c0.

    python benchmarks/work_precision.py [--out outputs/work_precision] [--no-pysph] [--perturb 0.1]
        [--pysph-scheme edac --pysph-scheme gtvf] [--write-reference]

``--write-reference`` stores PySPH's points (one series per ``--pysph-scheme``) in
``sphgen/tools/reference/pysph_taylor_green.json``, which ``sphgen precision taylor_green
--error l1_error --tf 0.5`` plots beside sphgen's runs.
"""
import argparse
import json
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pysph_baseline import find_pysph_python, run_pysph  # noqa: E402

NXS = (25, 50, 100)
REFERENCE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "sphgen", "tools", "reference",
                         "pysph_taylor_green.json")


def reference_points(by_scheme, tf, perturb):
    """The reference file of ``sphgen precision`` from {scheme: [{nx, wall_s, l1}]} of PySPH runs."""
    series = {f"PySPH 1.0b2 {scheme.upper()}": [{"label": r["nx"], "wall_time": r["wall_s"], "error": r["l1"]}
                                                for r in rows if r.get("wall_s") and r.get("l1")]
              for scheme, rows in by_scheme.items()}
    flag = f" --perturb {perturb:g}" if perturb else ""
    return {"source": f"PySPH 1.0b2, `pysph run taylor_green --scheme S --nx N --re 100 --tf {tf:g}{flag}`, "
            "2 threads, output every 50 steps; `python benchmarks/work_precision.py --write-reference"
            f"{flag}`. Wall time is PySPH's 'Run took'.", "error_key": "l1_error", "tf": tf,
            "perturb": perturb, "series": series}


def sphgen_case(nx, tf, out, perturb, threads=2):
    d = os.path.join(out, f"sphgen_nx{nx}")
    exe = os.path.join(os.path.dirname(sys.executable), "sphgen")
    subprocess.run([exe, "run", "taylor_green", "--nx", str(nx), "--tf", str(tf), "--disable-output",
                    "--no-progress", "--threads", str(threads), "--perturb", str(perturb), "-d", d, "--overwrite"],
                   check=True,
                   stdout=subprocess.DEVNULL)
    info = json.load(open(os.path.join(d, "info.json")))
    res = json.load(open(os.path.join(d, "results.json")))
    return {"nx": nx, "wall_s": info["wall_time"], "l1": res["l1_error"],
            "l1_mean": res["l1_error_mean"], "max_u_rel": res["max_u_rel_error"]}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", default="outputs/work_precision")
    p.add_argument("--tf", type=float, default=0.5)
    p.add_argument("--no-pysph", action="store_true")
    p.add_argument("--perturb", type=float, default=0.1,
                   help="random lattice perturbation in dx, the same for both codes (default 0.1)")
    p.add_argument("--pysph-scheme", action="append", choices=("edac", "gtvf"), default=None,
                   help="PySPH scheme(s) to run (default edac)")
    p.add_argument("--write-reference", action="store_true",
                   help="store PySPH's points as the reference of `sphgen precision taylor_green`")
    o = p.parse_args(argv)
    os.makedirs(o.out, exist_ok=True)
    rows = {"sphgen": [sphgen_case(nx, o.tf, o.out, o.perturb) for nx in NXS]}
    py = None if o.no_pysph else find_pysph_python()
    pysph = {}
    for scheme in (o.pysph_scheme or ["edac"]) if py else []:
        code = "pysph" if scheme == "edac" else f"pysph_{scheme}"
        rows[code] = pysph[scheme] = []
        for nx in NXS:
            r = run_pysph(py, nx=nx, tf=o.tf, openmp=True, threads=2, with_error=True, scheme=scheme,
                          workdir=os.path.join(o.out, f"{code}_nx{nx}"),
                          extra_args=["--perturb", str(o.perturb)] if o.perturb else None)
            e = r.get("error") or {}
            pysph[scheme].append({"nx": nx, "wall_s": r.get("run_s"), "l1": e.get("l1"),
                                  "max_u_rel": (e["decay"] / e["decay_ex"] - 1) if e.get("decay") else None})
    if o.write_reference and pysph:
        with open(REFERENCE, "w") as f:
            json.dump(reference_points(pysph, o.tf, o.perturb), f, indent=1)
    with open(os.path.join(o.out, "work_precision.json"), "w") as f:
        json.dump(rows, f, indent=1)
    print(f"{'code':8s}{'nx':>5s}{'wall s':>9s}{'L1(tf)':>9s}{'L1 mean':>9s}{'max|u| err':>12s}")
    for code, rs in rows.items():
        for r in rs:
            mean = f"{r['l1_mean']:9.4f}" if "l1_mean" in r else f"{'':9s}"
            mu = f"{100 * r['max_u_rel']:+11.2f}%" if r.get("max_u_rel") is not None else ""
            print(f"{code:8s}{r['nx']:5d}{r['wall_s']:9.2f}{r['l1']:9.4f}{mean}{mu}")
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(5, 4))
    for code, rs in rows.items():
        ok = [r for r in rs if r["wall_s"] and r["l1"]]
        ax.loglog([r["wall_s"] for r in ok], [r["l1"] for r in ok], "o-", label=f"{code} L1(tf)")
        for r in ok:
            ax.annotate(f"{r['nx']}", (r["wall_s"], r["l1"]), fontsize=8)
        if code == "sphgen":
            ax.loglog([r["wall_s"] for r in ok], [r["l1_mean"] for r in ok], "s--",
                      label="sphgen L1 time mean")
    ax.set_xlabel("wall time of the time loop [s] (2 threads)")
    ax.set_ylabel("$L_1$ error of |u|, Taylor-Green Re=100, t=0.5")
    ax.legend()
    fig.tight_layout()
    path = os.path.join(o.out, "work_precision.png")
    fig.savefig(path, dpi=120)
    print(f"table: {os.path.join(o.out, 'work_precision.json')}\nplot:  {path}")


if __name__ == "__main__":
    main()
