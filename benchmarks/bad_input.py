"""Try bad inputs as a user would and report how sphgen answers each.

For every case: the exit status, whether a traceback was printed, the message (the last
line on stderr), its length, and whether any file that existed before changed.  A case
passes when it exits non-zero (or is a documented clean success), prints no traceback,
says one line of at most 300 characters that names the offending thing, and damages
nothing.  ``--markdown`` prints the table for docs/reliability.md.

    python benchmarks/bad_input.py [--markdown] [--workdir DIR]
"""
import argparse
import hashlib
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
EXAMPLE = os.path.join(HERE, "..", "docs", "examples", "my_case.py")
SPHGEN = os.path.join(os.path.dirname(sys.executable), "sphgen")
TG = [SPHGEN, "run", "taylor_green", "--no-progress", "--nx", "16"]


def digest(root):
    """{path: sha1} of every file below root."""
    out = {}
    for d, _, files in os.walk(root):
        for f in files:
            p = os.path.join(d, f)
            with open(p, "rb") as fh:
                out[p] = hashlib.sha1(fh.read()).hexdigest()
    return out


def user_script(work, name, *edits):
    """A copy of the docs example with one mistake put in (pairs ``old, new``)."""
    with open(EXAMPLE) as f:
        text = f.read()
    for old, new in zip(edits[::2], edits[1::2]):
        assert old in text, old
        text = text.replace(old, new, 1)
    path = os.path.join(work, f"{name}.py")
    with open(path, "w") as f:
        f.write(text)
    return [sys.executable, path, "--no-progress", "--nx", "8"]


def setup(work):
    """A finished reference run and assorted bad files; returns {name: path}."""
    ref = os.path.join(work, "ref")
    subprocess.run(TG + ["--tf", "0.02", "--pfreq", "5", "-d", ref], check=True, capture_output=True)
    files = {"ref": ref, "mid": os.path.join(ref, "taylor_green_000005.h5")}
    last = sorted(f for f in os.listdir(ref) if f.startswith("taylor_green_0"))[-1]
    files["last"] = os.path.join(ref, last)
    files["notes"] = os.path.join(work, "notes.txt")
    with open(files["notes"], "w") as f:
        f.write("not an output file\n")
    files["truncated"] = os.path.join(work, "truncated.h5")
    with open(files["mid"], "rb") as src, open(files["truncated"], "wb") as dst:
        dst.write(src.read()[:3000])
    import h5py
    files["plain"] = os.path.join(work, "plain.h5")
    with h5py.File(files["plain"], "w") as f:
        f["x"] = [1.0, 2.0]
    return files


def cases(work, f):
    """(name, command, expect_success) for every bad input."""
    new = lambda n: ["-d", os.path.join(work, n)]  # noqa: E731  (a fresh folder)
    return [
        ("negative --tf", TG + ["--tf", "-1"] + new("a1"), False),
        ("--tf nan", TG + ["--tf", "nan"] + new("a2"), False),
        ("--dt 0", TG + ["--dt", "0"] + new("a3"), False),
        ("--dt not a number", TG + ["--dt", "abc"] + new("a4"), False),
        ("--nx too small", TG[:-1] + ["2"] + new("a5"), False),
        ("--re 0", TG + ["--re", "0"] + new("a6"), False),
        ("--re inf", TG + ["--re", "inf"] + new("a7"), False),
        ("--perturb too large", TG + ["--perturb", "0.7"] + new("a8"), False),
        ("--pst unknown choice", TG + ["--pst", "bogus"] + new("a9"), False),
        ("misspelt option --nxx", TG + ["--nxx", "10"] + new("a10"), False),
        ("--threads 0", TG + ["--threads", "0"] + new("a11"), False),
        ("--pfreq 0", TG + ["--pfreq", "0"] + new("a12"), False),
        ("--hdx negative", TG + ["--hdx", "-1"] + new("a13"), False),
        ("-d is a regular file", TG + ["--tf", "0.01", "-d", f["notes"]], False),
        ("-d below a regular file", TG + ["--tf", "0.01", "-d", os.path.join(f["notes"], "sub")], False),
        ("-d holds another run", TG + ["--tf", "0.01", "-d", f["ref"]], False),
        ("--restart missing file", TG + ["--restart", os.path.join(work, "nope.h5")] + new("b1"), False),
        ("--restart text file", TG + ["--restart", f["notes"]] + new("b2"), False),
        ("--restart truncated HDF5", TG + ["--restart", f["truncated"]] + new("b3"), False),
        ("--restart HDF5 not sphgen", TG + ["--restart", f["plain"]] + new("b4"), False),
        ("--restart other resolution", TG[:-1] + ["20", "--restart", f["mid"]] + new("b5"), False),
        ("--restart other --re", TG + ["--re", "1000", "--restart", f["mid"]] + new("b6"), False),
        ("--restart past --tf", TG + ["--tf", "0.01", "--restart", f["last"]] + new("b7"), False),
        ("--dt above stable step", TG + ["--dt", "0.01"] + new("c1"), False),
        ("--c0 below 10 U", TG + ["--c0", "0.5"] + new("c2"), False),
        ("--c0 1.5 (below 10 U)", TG + ["--c0", "1.5"] + new("c3"), False),
        ("unknown application", [SPHGEN, "run", "taylor_gren"], False),
        ("unknown command", [SPHGEN, "frobnicate"], False),
        ("user Equation: misspelt property",
         user_script(work, "typo", "s_idx, s_T, s_m, s_rho, XIJ", "s_idx, s_Tt, s_m, s_rho, XIJ",
                     "(d_T[d_idx] - s_T[s_idx])", "(d_T[d_idx] - s_Tt[s_idx])")
         + new("d1"), False),
        ("user Equation: unknown keyword",
         user_script(work, "kw", "HeatEquation(a, [a], D=self.D,", "HeatEquation(a, [a], DD=self.D, D=self.D,")
         + new("d2"), False),
        ("user Equation: negative parameter", user_script(work, "neg", "D=self.D,", "D=-self.D,")
         + new("d3"), False),
        ("--tf 0 (documented: a clean run of zero steps)", TG + ["--tf", "0"] + new("e1"), True),
    ]


def run_case(name, cmd, expect_success, work):
    before = digest(work)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=600, cwd=work)
    after = digest(work)
    changed = sorted(k for k in before if after.get(k) != before[k])
    lines = [ln for ln in p.stderr.splitlines() if ln.strip()]
    message = lines[-1] if lines else ""
    traceback = "Traceback (most recent call last)" in p.stderr
    ok = (not traceback and not changed and
          ((p.returncode == 0) if expect_success else (p.returncode != 0 and 0 < len(message) <= 300
                                                       and len(lines) == 1)))
    return {"case": name, "exit": p.returncode, "traceback": traceback, "message": message,
            "length": len(message), "changed": changed, "ok": ok}


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--markdown", action="store_true", help="print a Markdown table")
    ap.add_argument("--workdir", default=None, help="keep the files here (default: a temp folder)")
    a = ap.parse_args()
    work = a.workdir or tempfile.mkdtemp(prefix="sphgen_bad_input_")
    os.makedirs(work, exist_ok=True)
    files = setup(work)
    rows = [run_case(n, c, s, work) for n, c, s in cases(work, files)]
    if a.markdown:
        print("| # | case | exit | traceback | message (stderr) | chars | files changed | ok |")
        print("|---|---|---|---|---|---|---|---|")
        for i, r in enumerate(rows, 1):
            msg = r["message"].replace(work, "$W").replace("|", "\\|")
            print(f"| {i} | {r['case']} | {r['exit']} | {'yes' if r['traceback'] else 'no'} | {msg} | "
                  f"{r['length']} | {len(r['changed'])} | {'yes' if r['ok'] else '**NO**'} |")
    else:
        for i, r in enumerate(rows, 1):
            print(f"{i:2d} {'ok ' if r['ok'] else 'BAD'} exit={r['exit']} tb={r['traceback']} "
                  f"changed={len(r['changed'])} {r['case']}: {r['message']}")
    bad = sum(not r["ok"] for r in rows)
    print(f"\n{len(rows)} cases, {len(rows) - bad} ok, {bad} not ok")
    if not a.workdir:
        shutil.rmtree(work, ignore_errors=True)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
