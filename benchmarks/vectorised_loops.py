"""Which pair loops of a scene gcc vectorises: one line per neighbour loop of each pass.

Runs ``sphgen run APP ARGS --show-plan`` (which generates and compiles the scene's module,
or finds it in the cache), compiles the module's C once more with the flags of
``sphgen.codegen.build`` and ``-fopt-info-vec``, and reports for each pair loop whether
gcc vectorised it, and if not the first reason it gives.  A pair loop that does not
vectorise runs at scalar speed: on the machines measured here that is 2-3x slower
(docs/performance.md, "Vectorised neighbour loops").

    python benchmarks/vectorised_loops.py [APP ARGS ...]   (default: every benchmark case)
"""
import os
import re
import subprocess
import sys
import sysconfig
import tempfile

import numpy

from sphgen.codegen.build import CFLAGS, INCLUDE, openmp_flags

SPHGEN = os.path.join(os.path.dirname(sys.executable), "sphgen")
CASES = [["taylor_green", "--nx", "50"], ["taylor_green", "--nx", "50", "--scheme", "ctvf"],
         ["dam_break_2d"], ["dam_break_2d", "--delta", "0", "--kernel", "wendland", "--hdx", "1.3"],
         ["rings", "--dx", "0.0005", "--one-body"], ["beryllium_plate"],
         ["shtc_cavity", "--nx", "80", "--cs", "10", "--dt", "2e-4"]]

_PASS = re.compile(r"^static void __pyx_f_\w+?__pass_(\w+)\(long __pyx_v_d_idx")
_PAIR = re.compile(r"^\s*__pyx_v__k = __pyx_t_\d+;")
_SOURCE = re.compile(r"^ \*     # source (\w+)")


def generated_source(app_args):
    """The .pyx of the scene of ``sphgen run APP ARGS`` (compiled by --show-plan if need be)."""
    p = subprocess.run([SPHGEN, "run", *app_args, "--show-plan"], capture_output=True, text=True, check=True)
    m = re.search(r"generated source: (\S+\.pyx)", p.stdout)
    if m is None:
        raise SystemExit(f"no generated source in the plan of {' '.join(app_args)}")
    return m.group(1)


def pair_loops(c_path):
    """[(pass, source array, line of the loop header)] in the generated C."""
    out, current, source = [], None, None
    with open(c_path) as f:
        lines = f.readlines()
    for i, line in enumerate(lines):
        m = _PASS.match(line)
        if m:
            current, source = m.group(1), None
        s = _SOURCE.match(line)
        if s:
            source = s.group(1)
        if current and _PAIR.match(line):
            out.append((current, source, i))     # the for statement is the line before (1-based i)
    return out


def report(c_path):
    """{line: 'vectorised' or the reason gcc gives} for every loop, from -fopt-info-vec-all."""
    inc = [sysconfig.get_paths()["include"], numpy.get_include(), INCLUDE]
    with tempfile.TemporaryDirectory() as tmp:
        p = subprocess.run(["gcc", "-c", "-fPIC", *CFLAGS, *openmp_flags(), *[f"-I{d}" for d in inc], c_path,
                            "-o", os.path.join(tmp, "m.o"), "-fopt-info-vec-all"],
                           capture_output=True, text=True)
    name = os.path.basename(c_path)
    verdict = {}
    for line in p.stderr.splitlines():
        m = re.match(r"(?:.*/)?" + re.escape(name) + r":(\d+):\d+: (optimized|missed): (.*)", line)
        if not m:
            continue
        n, kind, text = int(m.group(1)), m.group(2), m.group(3)
        if kind == "optimized" and text.startswith("loop vectorized"):
            verdict[n] = "vectorised"
        elif text.startswith("couldn't vectorize loop"):
            verdict.setdefault(n, "not vectorised")
    return verdict


def main():
    cases = [sys.argv[1:]] if len(sys.argv) > 1 else CASES
    total = bad = 0
    for args in cases:
        c_path = generated_source(args)[:-4] + ".c"
        verdict = report(c_path)
        print(" ".join(args))
        for name, source, line in pair_loops(c_path):
            v = verdict.get(line, "not vectorised (no report)")
            total += 1
            bad += v != "vectorised"
            print(f"  pass {name:14s} <- {source or '?':10s} {v}")
    print(f"{total - bad} of {total} pair loops vectorised")


if __name__ == "__main__":
    main()
