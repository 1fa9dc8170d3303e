"""OpenMP speed-up on an idle machine and the parallel/serial ratio under load.

Taylor-Green nx=100 (10,000 particles), the same run serial and with 2 threads; then
again while a CPU-bound process runs beside it.  "2 threads fixed" disables the
load-aware thread choice (SPHGEN_TUNE_THREADS=0) to show what it saves.  Medians of
--repeat runs; each time is the solver's stepping wall time from info.json.

    python benchmarks/bench_openmp_load.py [--repeat 3] [--tf 0.05]
"""
import argparse
import json
import multiprocessing as mp
import os
import statistics
import subprocess
import sys
import tempfile

SPHGEN = os.path.join(os.path.dirname(sys.executable), "sphgen")


def burn(stop):
    x = 0
    while not stop.is_set():
        for _ in range(100000):
            x += 1


def run(work, tf, threads, tune=True):
    out = os.path.join(work, f"r{threads}_{tune}")
    cmd = [SPHGEN, "run", "taylor_green", "--nx", "100", "--tf", str(tf), "--disable-output",
           "--no-progress", "--overwrite", "-d", out]
    cmd += ["--no-openmp"] if threads == 1 else ["--threads", str(threads)]
    env = dict(os.environ, SPHGEN_TUNE_THREADS="1" if tune else "0")
    subprocess.run(cmd, check=True, capture_output=True, env=env)
    info = json.load(open(os.path.join(out, "info.json")))
    return info["wall_time"], info["thread_choices"]


def series(work, tf, repeat):
    t = {"serial": [], "2 threads": [], "2 threads fixed": []}
    for _ in range(repeat):
        t["serial"].append(run(work, tf, 1)[0])
        t["2 threads"].append(run(work, tf, 2)[0])
        t["2 threads fixed"].append(run(work, tf, 2, tune=False)[0])
    return {k: statistics.median(v) for k, v in t.items()}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--tf", type=float, default=0.05)
    a = ap.parse_args()
    work = tempfile.mkdtemp(prefix="sphgen_omp_")
    run(work, 0.001, 2)  # compile once
    idle = series(work, a.tf, a.repeat)
    stop = mp.Event()
    hog = mp.Process(target=burn, args=(stop,))
    hog.start()
    try:
        loaded = series(work, a.tf, a.repeat)
    finally:
        stop.set()
        hog.join()
    for name, r in (("idle", idle), ("one CPU-bound process beside", loaded)):
        print(f"{name}: serial {r['serial']:.2f} s, 2 threads {r['2 threads']:.2f} s, "
              f"2 threads fixed {r['2 threads fixed']:.2f} s")
    print(f"speed-up 1 -> 2 threads, idle: {idle['serial'] / idle['2 threads']:.2f}x "
          f"(fixed: {idle['serial'] / idle['2 threads fixed']:.2f}x)")
    print(f"2-thread / serial time under load: {loaded['2 threads'] / loaded['serial']:.2f} "
          f"(fixed: {loaded['2 threads fixed'] / loaded['serial']:.2f})")


if __name__ == "__main__":
    main()
