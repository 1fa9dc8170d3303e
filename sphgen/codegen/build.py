"""Compile a generated module once and cache it by a hash of its source.

The cache lives in ``$SPHGEN_CACHE`` (default ``~/.cache/sphgen``).  A second run of
the same scene finds ``m_<hash>.so`` and compiles nothing.  Concurrent runs of the
same scene (automan runs several cases at once) serialise on a file lock.
"""
import fcntl
import hashlib
import importlib.util
import io
import os
import platform
import re
import sys
import sysconfig
import time
from contextlib import redirect_stderr, redirect_stdout

import numpy

from ..errors import SphgenError


class CompileError(SphgenError, RuntimeError):
    """The generated code did not compile; the message names the equation and line."""


def cache_dir():
    d = os.environ.get("SPHGEN_CACHE") or os.path.join(os.path.expanduser("~"), ".cache", "sphgen")
    os.makedirs(d, exist_ok=True)
    return d


def _cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith(("model name", "flags")):
                    return line
    except OSError:
        pass
    return platform.processor()


_OMP = None


def openmp_flags():
    """['-fopenmp'] if the C compiler supports OpenMP, else []."""
    global _OMP
    if _OMP is None:
        from setuptools._distutils.ccompiler import new_compiler
        from setuptools._distutils.sysconfig import customize_compiler
        import tempfile
        cc = new_compiler()
        customize_compiler(cc)
        with tempfile.TemporaryDirectory() as tmp:
            src = os.path.join(tmp, "p.c")
            with open(src, "w") as f:
                f.write("#include <omp.h>\nint main(void){return omp_get_max_threads() < 1;}\n")
            try:
                with redirect_stdout(io.StringIO()), redirect_stderr(io.StringIO()):
                    objs = cc.compile([src], output_dir=tmp, extra_postargs=["-fopenmp"])
                    cc.link_executable(objs, os.path.join(tmp, "p"), extra_postargs=["-fopenmp"])
                _OMP = ["-fopenmp"]
            except Exception:
                _OMP = []
    return _OMP


# No -ffast-math: the blow-up guard needs NaN and inf to behave (no -ffinite-math-only).
# The relaxations below change results only at round-off: no errno, no FP traps, FMA
# contraction, x/y as x*(1/y), and re-associated sums (-fassociative-math with
# -fno-signed-zeros), which lets gcc vectorise the neighbour loops' reductions over
# several pairs per instruction (docs/performance.md).
# -g0 undoes the -g of Python's own CFLAGS (sysconfig), which setuptools puts first: debug
# information for a generated module costs most of its compile time (SHTC's Taylor-Couette
# scene, 59 k lines of C: gcc 39 s with -g, 6.5 s without) and changes no instruction.
CFLAGS = ["-O3", "-march=native", "-fno-math-errno", "-fno-trapping-math", "-ffp-contract=fast",
          "-freciprocal-math", "-fassociative-math", "-fno-signed-zeros", "-g0",
          "-Wno-unused-function",
          "-Wno-unreachable-code", "-Wno-maybe-uninitialized"]


_SRC_PATH = re.compile(r"^(\s*# @src ).*?([^/\\]+:\d+)$", re.M)


INCLUDE = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "nnps")


def _header_text():
    """The C header the generated modules include (sphgen/nnps/sphgen_claim.h)."""
    with open(os.path.join(INCLUDE, "sphgen_claim.h")) as f:
        return f.read()


def module_hash(source):
    """Hash of what the module is: the source with the ``# @src`` comments reduced to
    ``file:line`` (two clones of the project share cached modules), compiler flags and
    the versions the build depends on."""
    import Cython
    key = "\n".join([_SRC_PATH.sub(r"\1\2", source), " ".join(CFLAGS + openmp_flags()), Cython.__version__, numpy.__version__,
                     sys.version, platform.machine(), _cpu_model(), _header_text()])
    return hashlib.sha256(key.encode()).hexdigest()[:20]


def load_or_build(source, origin=None):
    """(module, compile_seconds): compile_seconds is 0.0 when the cache had it."""
    name = f"m_{module_hash(source)}"
    d = cache_dir()
    so = os.path.join(d, name + sysconfig.get_config_var("EXT_SUFFIX"))
    t0 = time.perf_counter()
    built = False
    if not os.path.exists(so):
        with open(os.path.join(d, name + ".lock"), "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if not os.path.exists(so):
                _build(name, source, d, origin)
                built = True
    spec = importlib.util.spec_from_file_location(name, so)
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    mod.__sphgen_source__ = os.path.join(d, name + ".pyx")
    return mod, (time.perf_counter() - t0) if built else 0.0


def _build(name, source, d, origin):
    from Cython.Build import cythonize
    from setuptools import Distribution, Extension
    from setuptools.command.build_ext import build_ext

    pyx = os.path.join(d, name + ".pyx")
    tmp = pyx + f".tmp{os.getpid()}"
    with open(tmp, "w") as f:
        f.write(source)
    os.replace(tmp, pyx)
    omp = openmp_flags()
    ext = Extension(name, [pyx], include_dirs=[numpy.get_include(), INCLUDE],
                    extra_compile_args=CFLAGS + omp, extra_link_args=omp,
                    define_macros=[("NPY_NO_DEPRECATED_API", "NPY_1_7_API_VERSION")])
    out = io.StringIO()
    try:
        with redirect_stdout(out), redirect_stderr(out):
            exts = cythonize([ext], quiet=True, language_level=3, force=True)
            dist = Distribution({"ext_modules": exts, "script_args": ["build_ext"]})
            cmd = build_ext(dist)
            cmd.build_lib = d
            cmd.build_temp = os.path.join(d, "build", name)
            cmd.inplace = False
            cmd.ensure_finalized()
            cmd.run()
    except BaseException as e:  # Cython raises CompileError, gcc SystemExit/DistutilsError
        log = out.getvalue() + f"\n{type(e).__name__}: {e}"
        raise CompileError(explain_failure(log, pyx, origin)) from None


_PYX_ERR = re.compile(r"m_[0-9a-f]+\.pyx:(\d+):(\d+): (.*)")
_C_ERR = re.compile(r"m_[0-9a-f]+\.c:(\d+):\d+: error: (.*)")


def _origin_of_pyx_line(lines, lineno):
    """(function name, '# @src file:line') nearest above a pyx line."""
    src, func = None, None
    for i in range(min(lineno, len(lines)) - 1, -1, -1):
        ln = lines[i].strip()
        if src is None and ln.startswith("# @src "):
            src = ln[len("# @src "):]
        m = re.match(r"(?:cdef (?:inline )?\w+\*? |def )(\w+)\(", ln)
        if m:
            func = m.group(1)
            break
    return func, src


def explain_failure(log, pyx, origin=None):
    """Turn a Cython/gcc failure into 'Equation.method (file:line): message'."""
    try:
        with open(pyx) as f:
            lines = f.read().splitlines()
    except OSError:
        lines = []
    msgs = []
    for m in _PYX_ERR.finditer(log):
        func, src = _origin_of_pyx_line(lines, int(m.group(1)))
        msgs.append(_describe(func, src, origin, m.group(3), pyx, m.group(1)))
    if not msgs:
        cfile = pyx[:-4] + ".c"
        try:
            with open(cfile) as f:
                clines = f.read().splitlines()
        except OSError:
            clines = []
        for m in _C_ERR.finditer(log):
            n = int(m.group(1))
            pyx_line = None
            for i in range(min(n, len(clines)) - 1, -1, -1):
                mm = re.search(r'/\* ".*?\.pyx":(\d+)', clines[i])
                if mm:
                    pyx_line = int(mm.group(1))
                    break
            func, src = _origin_of_pyx_line(lines, pyx_line) if pyx_line else (None, None)
            msgs.append(_describe(func, src, origin, "C compiler: " + m.group(2), pyx, pyx_line))
    if not msgs:
        msgs.append("the generated module failed to build:\n" + log[-3000:])
    return "\n".join(dict.fromkeys(msgs))


def _describe(func, src, origin, message, pyx, line):
    who = (origin or {}).get(func, func or "generated code")
    where = f" ({src})" if src else ""
    return f"{who}{where}: {message}  [generated: {pyx}:{line}]"
