"""Would float32 pay?  The scene's generated module with every ``double`` made ``float``,
its pair passes timed against the float64 module on the same state (issue 14's float32
direction, measured before building it into the generator).

The application runs a few steps (``sphgen run APP ARGS``, serial); its generated source
is then rewritten: ``double`` -> ``float``, ``np.float64`` -> ``np.float32``, the libm
calls to their ``f`` forms (``sqrtf``, ``rintf``, ...), compiled with the generated
modules' flags plus ``-fsingle-precision-constant`` (so that literals do not promote the
arithmetic back to double).  Both modules are bound to the same neighbour rows and to
the same particle data (a float32 copy for the second), each pass is called ``--calls``
times, serial, and the best time of each is printed with the ratio, followed by the
largest relative difference between the two modules' particle data after each pass
(one call each, in order, from the same state: the inputs' rounding to float32 included).

    python benchmarks/float32_passes.py taylor_green --nx 50 --tf 0.01
    python benchmarks/float32_passes.py dam_break_2d --tf 0.002
"""
import argparse
import os
import re
import sys
import time

import numpy as np

MATH = ("sqrt", "rint", "fabs", "exp", "pow", "floor", "fmax", "fmin", "cbrt", "log", "sin", "cos",
        "tanh", "atan2", "copysign")


def float32_source(source):
    """The generated module's source with float in place of double throughout."""
    out = source.replace("double", "float").replace("np.float64", "np.float32")
    for fn in MATH:
        out = re.sub(rf"\b{fn}\(", f"{fn}f(", out)
    return out


def best_ms(fn, calls):
    best = float("inf")
    for _ in range(calls):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return 1e3 * best


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("app")
    p.add_argument("--calls", type=int, default=60, help="calls of each pass (best is kept)")
    opts, app_args = p.parse_known_args(argv)
    os.environ["SPHGEN_TUNE_THREADS"] = "0"
    from sphgen.app import load_application
    from sphgen.codegen import build

    app = load_application(opts.app)()
    app.run(["--disable-output", "--no-progress", "--overwrite", "-d", f"/tmp/float32_{opts.app}",
             "--no-openmp"] + app_args)
    scene, engine = app.scene, app.scene.engine
    m64 = engine.module
    build.CFLAGS = build.CFLAGS + ["-fsingle-precision-constant"]
    m32, _ = build.load_or_build(float32_source(open(m64.__sphgen_source__).read()))
    data32 = {pa.name: {k: (v.astype(np.float32) if v.dtype == np.float64 else v.copy())
                        for k, v in {**pa.data, **pa.constants}.items()} for pa in scene.arrays}
    m32.bind_arrays({pa.name: (pa.n, data32[pa.name]) for pa in scene.arrays})
    m32.set_parameters({g: float(getattr(o, a)) for g, (o, a) in engine.rendered.parameters.items()})
    engine._bound_lists = None
    engine.bind_neighbours()
    m32.bind_neighbours(engine._bound_lists)
    m64.set_threads(1)
    m32.set_threads(1)
    print(f"{opts.app}: {sum(pa.n for pa in scene.arrays)} particles, serial, best of {opts.calls} calls")
    total64 = total32 = 0.0
    for name in sorted(k for k in dir(m64) if k.startswith("pass_")):
        f64, f32 = getattr(m64, name), getattr(m32, name)
        f64(0.0, 1e-6)
        f32(0.0, 1e-6)
        worst = 0.0
        for pa in scene.arrays:
            for k, v in pa.data.items():
                if v.dtype != np.float64 or not v.size:
                    continue
                scale = float(np.abs(v).max()) or 1.0
                worst = max(worst, float(np.abs(data32[pa.name][k] - v).max()) / scale)
        t64, t32 = best_ms(lambda: f64(0.0, 1e-6), opts.calls), best_ms(lambda: f32(0.0, 1e-6), opts.calls)
        total64, total32 = total64 + t64, total32 + t32
        print(f"{name:22s} float64 {t64:8.4f} ms   float32 {t32:8.4f} ms   float64/float32 {t64 / t32:5.2f}"
              f"   float32 - float64 after it: {worst:.1e} (largest, relative to the property's largest value)")
    print(f"{'all passes':22s} float64 {total64:8.4f} ms   float32 {total32:8.4f} ms   float64/float32 "
          f"{total64 / total32:5.2f}")


if __name__ == "__main__":
    sys.exit(main())
