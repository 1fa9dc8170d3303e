#!/usr/bin/env python
"""Taylor-Green (nx=50, Re=100, tf=0.5): sphgen against PySPH in the same run.

Prints, as medians of ``--repeat`` runs: time per particle-step (serial and 2 threads),
neighbour pairs per second, the 1 -> 2 thread speed-up, the first-run compile time, and
the ratio against PySPH 1.0b2's closest case when a PySPH venv is found
(``PYSPH_PYTHON``; see ``pysph_baseline.find_pysph_python``).  ``--scheme`` picks
sphgen's scheme and, from :data:`PYSPH_CLOSEST`, PySPH's: EDAC against
``pysph run taylor_green --scheme edac``; CTVF and GTVF against ``--scheme gtvf``
(PySPH 1.0b2 has no CTVF; its GTVF has the same two evaluations per kick-drift-kick
step, docs/performance.md).  The machine may be shared: each row also reports the CPU
seconds other processes used during the runs (0 means a clean timing).

    python benchmarks/bench_taylor_green.py [--scheme edac|ctvf|gtvf] [--nx 50] [--tf 0.5] [--repeat 3]
"""
import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from pysph_baseline import _busy_cpu_seconds, find_pysph_python, run_pysph  # noqa: E402
from roofline import host_line, peak_gflops, roofline_line  # noqa: E402

# sphgen's scheme -> PySPH 1.0b2's closest Taylor-Green scheme (docs/performance.md)
PYSPH_CLOSEST = {"edac": "edac", "ctvf": "gtvf", "gtvf": "gtvf"}


def run_sphgen(nx, tf, threads, workdir, cache=None, scheme="edac"):
    """One sphgen run as a subprocess; returns its info.json plus contention."""
    out = os.path.join(workdir, f"sphgen_{scheme}_nx{nx}_t{threads}_{time.time_ns()}")
    exe = os.path.join(os.path.dirname(sys.executable), "sphgen")
    # the plain lattice, as PySPH's case starts (sphgen's default start is perturbed)
    cmd = [exe, "run", "taylor_green", "--scheme", scheme, "--nx", str(nx), "--tf", str(tf), "--perturb", "0", "--disable-output",
           "--no-progress", "-d", out]
    cmd += ["--no-openmp"] if threads == 1 else ["--threads", str(threads)]
    env = dict(os.environ)
    if cache:
        env["SPHGEN_CACHE"] = cache
    busy0, t0 = _busy_cpu_seconds(), time.perf_counter()
    r0 = os.times()
    subprocess.run(cmd, check=True, env=env, stdout=subprocess.DEVNULL)
    r1 = os.times()
    wall = time.perf_counter() - t0
    busy1 = _busy_cpu_seconds()
    with open(os.path.join(out, "info.json")) as f:
        info = json.load(f)
    own = (r1.children_user - r0.children_user) + (r1.children_system - r0.children_system)
    info["other_cpu_s"] = (busy1 - busy0 - own) if busy0 is not None else None
    info["process_wall_s"] = wall
    return info


def summarise_sphgen(runs):
    n = runs[0]["n_particles"]
    steps = runs[0]["steps"]
    pairs = runs[0]["neighbour_pairs_per_step"]
    walls = [r["wall_time"] for r in runs]
    med = statistics.median(walls)
    return {"wall_s": med, "us_per_particle_step": 1e6 * med / (n * steps),
            "pairs_per_s": pairs * steps / med, "steps": steps, "n": n,
            "other_cpu_s": [round(r["other_cpu_s"] or 0, 2) for r in runs], "walls": walls}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--scheme", choices=sorted(PYSPH_CLOSEST), default="edac",
                   help="sphgen's scheme (default %(default)s); PySPH runs its closest: %(choices)s -> "
                        + ", ".join(f"{k}: {v}" for k, v in sorted(PYSPH_CLOSEST.items())))
    p.add_argument("--nx", type=int, default=50)
    p.add_argument("--tf", type=float, default=0.5)
    p.add_argument("--repeat", type=int, default=3)
    p.add_argument("--no-pysph", action="store_true")
    p.add_argument("--json", default=None, help="write the results here")
    o = p.parse_args(argv)
    work = tempfile.mkdtemp(prefix="sphgen_bench_")
    pysph_scheme = PYSPH_CLOSEST[o.scheme]
    res = {"scheme": o.scheme, "pysph_scheme": pysph_scheme, "nx": o.nx, "tf": o.tf, "repeat": o.repeat,
           "load_start": os.getloadavg()[0], "host_start": host_line()}

    cold = run_sphgen(o.nx, o.tf, 2, work, cache=os.path.join(work, "cache"), scheme=o.scheme)
    res["sphgen_compile_s"] = cold["compile_time"]
    py = None if o.no_pysph else find_pysph_python()
    # interleave the codes so a drift in machine speed hits both alike
    ours = {1: [], 2: []}
    theirs = {1: [], 2: []}
    for _ in range(o.repeat):
        for threads in (1, 2):
            ours[threads].append(run_sphgen(o.nx, o.tf, threads, work, scheme=o.scheme))
            if py:
                theirs[threads].append(run_pysph(py, nx=o.nx, tf=o.tf, openmp=threads > 1,
                                                 threads=threads if threads > 1 else None, scheme=pysph_scheme,
                                                 workdir=os.path.join(work, f"pysph_{threads}")))
    for threads in (1, 2):
        res[f"sphgen_{threads}"] = summarise_sphgen(ours[threads])
    s1, s2 = res["sphgen_1"], res["sphgen_2"]
    res["sphgen_speedup_1_to_2"] = s1["wall_s"] / s2["wall_s"]
    for t in (1, 2) if py else ():
        ok = [r for r in theirs[t] if r["returncode"] == 0 and r.get("us_per_real_particle_step")]
        if not ok:
            res[f"pysph_{t}"] = {"error": theirs[t][0].get("stdout_tail", "")[-500:]}
            continue
        res[f"pysph_{t}"] = {"run_s": statistics.median(r["run_s"] for r in ok),
                             "us_per_particle_step": statistics.median(r["us_per_real_particle_step"] for r in ok),
                             "steps": ok[0]["steps"], "n_real": ok[0]["n_real"], "n_array": ok[0]["n_array"],
                             "other_cpu_s": [round(r["other_cpu_s"] or 0, 2) for r in ok]}
        res[f"ratio_{t}"] = res[f"pysph_{t}"]["us_per_particle_step"] / res[f"sphgen_{t}"]["us_per_particle_step"]
    res["load_end"] = os.getloadavg()[0]
    res["host_end"] = host_line()
    peak = peak_gflops()
    res["roofline"] = [roofline_line(sorted(ours[t], key=lambda r: r["wall_time"])[len(ours[t]) // 2], peak,
                                     f"sphgen {t} thread(s)") for t in (1, 2)]

    print(f"Taylor-Green sphgen {o.scheme.upper()} against PySPH {pysph_scheme.upper()}, nx={o.nx} "
          f"({o.nx * o.nx} particles), tf={o.tf}, medians of {o.repeat}")
    print(f"{'':24s}{'us/particle-step':>18s}{'pairs/s':>12s}{'wall s':>9s}  other-CPU s")
    for t in (1, 2):
        s = res[f"sphgen_{t}"]
        print(f"sphgen {t} thread(s){'':6s}{s['us_per_particle_step']:18.3f}{s['pairs_per_s']:12.3g}"
              f"{s['wall_s']:9.2f}  {s['other_cpu_s']}")
    for t in (1, 2):
        s = res.get(f"pysph_{t}")
        if s and "us_per_particle_step" in s:
            print(f"PySPH  {t} thread(s){'':6s}{s['us_per_particle_step']:18.3f}{'':12s}{s['run_s']:9.2f}"
                  f"  {s['other_cpu_s']}")
    counts = {res[f"pysph_{t}"]["n_real"] for t in (1, 2) if "n_real" in res.get(f"pysph_{t}", {})}
    if counts:
        print(f"particles: sphgen {s1['n']}, PySPH {', '.join(map(str, sorted(counts)))}"
              + ("" if counts == {s1["n"]} else "  (NOT the same count: the ratio is not comparable)"))
    print(f"sphgen speed-up 1 -> 2 threads: {res['sphgen_speedup_1_to_2']:.2f}x")
    for t in (1, 2):
        if f"ratio_{t}" in res:
            print(f"PySPH {pysph_scheme.upper()} / sphgen {o.scheme.upper()} time per particle-step, "
                  f"{t} thread(s): {res[f'ratio_{t}']:.2f}x")
    print(f"sphgen first-run compile time: {res['sphgen_compile_s']:.2f} s")
    for line in res["roofline"]:
        print(line)
    print(f"load average: {res['load_start']:.2f} at start, {res['load_end']:.2f} at end")
    print(f"at start, {res['host_start']}")
    print(f"at end, {res['host_end']}")
    if o.json:
        with open(o.json, "w") as f:
            json.dump(res, f, indent=1)
    return res


if __name__ == "__main__":
    main()
