"""Kill a run with SIGKILL at random moments and check that nothing is lost.

For each kill: every output file in the folder loads; the XDMF index resolves every
dataset it names (as ParaView would); a restart from the last output in the same folder
leaves no stray temporary file and reaches the uninterrupted run's final state bit for
bit (serial) or within 1e-10 (2 threads); its history.json and results.json equal the
uninterrupted run's.

    python benchmarks/kill_test.py [--kills 10] [--threads 1] [--seed 0]
"""
import argparse
import json
import os
import random
import shutil
import signal
import subprocess
import sys
import tempfile
import time

import numpy as np

from sphgen import io

SPHGEN = os.path.join(os.path.dirname(sys.executable), "sphgen")
CASE = ["--nx", "20", "--tf", "0.15", "--pfreq", "3", "--no-progress"]


def command(outdir, threads, extra=()):
    par = ["--no-openmp"] if threads == 1 else ["--threads", str(threads)]
    return [SPHGEN, "run", "taylor_green", *CASE, *par, "-d", outdir, *extra]


def final_state(outdir):
    last = io.load(io.output_files(outdir, "taylor_green")[-1])
    return last["solver_data"]["step"], last["arrays"]["fluid"].data


def killed_run(outdir, threads, rng, duration):
    """Start a run, kill it at a random moment after its first output; returns the delay."""
    p = subprocess.Popen(command(outdir, threads), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    start = time.perf_counter()
    while not (os.path.isdir(outdir) and io.output_files(outdir)) and p.poll() is None:
        time.sleep(0.01)
    delay = rng.uniform(0.0, duration)
    time.sleep(delay)
    p.send_signal(signal.SIGKILL)
    p.wait()
    return time.perf_counter() - start


def check_folder(outdir):
    """Every output readable and the XDMF complete; returns (outputs, stray temporaries)."""
    files = io.output_files(outdir, "taylor_green")
    for f in files:
        io.load(f)
    stray = [f for f in os.listdir(outdir) if ".tmp-" in f]
    xdmf = os.path.join(outdir, "taylor_green.xdmf")
    steps, _ = io.verify_xdmf(xdmf)
    # killed between an output and its index update, the index lacks only that output
    if steps not in (len(files), len(files) - 1):
        raise AssertionError(f"{xdmf} indexes {steps} steps, the folder has {len(files)} outputs")
    return files, stray


def restart_and_compare(outdir, files, ref, threads):
    if io.step_of(files[-1]) < io.step_of(io.output_files(ref)[-1]):
        subprocess.run(command(outdir, threads, ["--restart", files[-1]]), check=True, capture_output=True)
    else:  # killed after its last step: a restart is refused (past --tf); post-process again
        subprocess.run(command(outdir, threads, ["--overwrite"]), check=True, capture_output=True)
    stray = [f for f in os.listdir(outdir) if ".tmp-" in f]
    step, data = final_state(outdir)
    ref_step, ref_data = final_state(ref)
    diff = max(float(np.max(np.abs(data[p] - ref_data[p]))) for p in ("x", "y", "u", "v", "p"))
    same_hist = json.load(open(os.path.join(outdir, "history.json"))) == \
        json.load(open(os.path.join(ref, "history.json")))
    same_res = all(json.load(open(os.path.join(outdir, n))) == json.load(open(os.path.join(ref, n)))
                   for n in ("results.json", "diagnostics.json"))
    io.verify_xdmf(os.path.join(outdir, "taylor_green.xdmf"))
    return {"step": step == ref_step, "max_diff": diff, "history": same_hist, "results": same_res,
            "stray_after": stray}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--kills", type=int, default=10)
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--seed", type=int, default=0)
    a = ap.parse_args()
    rng = random.Random(a.seed)
    work = tempfile.mkdtemp(prefix="sphgen_kill_")
    ref = os.path.join(work, "ref")
    t0 = time.perf_counter()
    subprocess.run(command(ref, a.threads), check=True, capture_output=True)
    duration = json.load(open(os.path.join(ref, "info.json")))["wall_time"]
    print(f"uninterrupted run: {time.perf_counter() - t0:.2f} s ({duration:.2f} s stepping)")
    tol = 0.0 if a.threads == 1 else 1e-10
    bad = 0
    for k in range(a.kills):
        out = os.path.join(work, f"kill{k}")
        when = killed_run(out, a.threads, rng, duration)
        files, stray = check_folder(out)
        r = restart_and_compare(out, files, ref, a.threads)
        ok = r["step"] and r["max_diff"] <= tol and r["history"] and r["results"] and not r["stray_after"]
        bad += not ok
        print(f"kill {k}: at {when:.2f} s, {len(files)} outputs readable, XDMF complete, "
              f"{len(stray)} stray temporaries before restart, {len(r['stray_after'])} after; "
              f"restart: max |diff| {r['max_diff']:.1e}, history equal {r['history']}, "
              f"results equal {r['results']} -> {'ok' if ok else 'NOT OK'}")
    shutil.rmtree(work, ignore_errors=True)
    print(f"{a.kills} kills, {a.kills - bad} ok")
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
