"""The generator: pruning, switches, dead stores, dimension folding, cache, no GIL."""
import re

import numpy as np

from sphgen.equation import Equation, Group
from sphgen.integrators import IntegratorStep
from sphgen.scene import Scene
from sphgen.equations.basic import SummationDensity, Vorticity2D
from sphgen.equations.momentum import ArtificialViscosity, PressureGradient

from conftest import lattice_cloud, periodic_box


class Kick(IntegratorStep):
    def stage1(self, d_idx, d_u, d_v, d_au, d_av, dt):
        d_u[d_idx] += dt * d_au[d_idx]
        d_v[d_idx] += dt * d_av[d_idx]


def _fluid():
    pa = lattice_cloud(nx=8)
    for p in ("au", "av", "aw", "omega", "pavg"):
        pa.add_property(p)
    pa.add_property("p", data=np.ones(pa.n))
    return pa


def _scene(outputs, alpha=0.0, tmp=None):
    pa = _fluid()
    eqs = [Group([SummationDensity("fluid", ["fluid"])]),
           Group([PressureGradient("fluid", ["fluid"], bql=False),
                  ArtificialViscosity("fluid", ["fluid"], alpha=alpha, c0=10.0),
                  Vorticity2D("fluid", ["fluid"])])]
    return Scene([pa], eqs, steppers={"fluid": Kick()}, dim=2, domain=periodic_box(2),
                 outputs={"fluid": outputs})


def test_equation_nobody_reads_is_pruned_from_plan_and_source():
    sc = _scene(["x", "y", "u", "v"])
    plan = sc.describe()
    assert re.search(r"prune Vorticity2D\[fluid<-fluid\]: nothing reads what it writes \(omega\)", plan)
    assert "Vorticity2D" not in sc.source
    assert "omega" not in sc.plan.allocation["fluid"]
    assert "omega" not in sc.by_name["fluid"].data
    # asked for in the output, the same equation is compiled and its property allocated
    sc2 = _scene(["x", "y", "u", "v", "omega"])
    assert "keep  Vorticity2D" in sc2.describe()
    assert "Vorticity2D_" in sc2.source and "omega" in sc2.by_name["fluid"].data


def test_zero_switch_removes_the_term_from_the_code():
    off = _scene(["u"], alpha=0.0)
    assert "ArtificialViscosity" not in off.source
    assert "prune ArtificialViscosity[fluid<-fluid]: switched off (alpha=0.0)" in off.describe()
    on = _scene(["u"], alpha=0.5)
    assert "ArtificialViscosity_" in on.source
    # a non-zero float switch stays a run-time parameter: no literal 0.5 in the code
    assert "ArtificialViscosity_2_alpha" in on.source


def test_dimension_folding_and_dead_stores_drop_the_third_component():
    sc = _scene(["u"])
    # 2D: aw is declared and initialised by PressureGradient but nothing reads it
    assert "aw" not in sc.plan.allocation["fluid"]
    assert "DWIJ[2] = _f" not in sc.source and "fluid_aw" not in sc.source
    assert "z" not in sc.by_name["fluid"].data


def test_properties_nobody_touches_are_never_allocated():
    sc = _scene(["u"])
    pa = sc.by_name["fluid"]
    assert "pavg" in pa.props and "pavg" not in pa.data
    assert "declared, not allocated: aw, omega, pavg, w, z" in sc.describe()


def test_second_scene_build_compiles_nothing(tmp_cache):
    first = _scene(["u"], alpha=0.25)
    assert first.compile_time > 0
    second = _scene(["u"], alpha=0.25)
    assert second.compile_time == 0.0
    # a different run-time parameter value reuses the same module
    third = _scene(["u"], alpha=0.75)
    assert third.compile_time == 0.0 and third.source == first.source


def test_no_gil_acquisition_inside_parallel_loops():
    sc = _scene(["u", "omega"], alpha=0.5)
    csrc = open(sc.source_path[:-4] + ".c").read()
    checked = 0
    for m in re.finditer(r"^static [^;{]*?(__pyx_\w+)\(([^)]*)\) \{$", csrc, re.M):
        name = m.group(1)
        if not re.search(r"_pass_|stage_|_loop$|_initialize$|_post_loop$|kernel_", name):
            continue
        body = csrc[m.end():csrc.find("\n}\n", m.end())]
        for s in ("PyGILState_Ensure", "ErrOccurredWithGIL", "__pyx_gilstate_save"):
            assert s not in body, f"{name} acquires the GIL ({s})"
        checked += 1
    assert checked >= 8, f"only {checked} generated functions found"


def test_loop_counters_are_declared_int_and_helpers_translate():
    from sphgen.equation import declare
    from sphgen.linalg import det3

    class Det(Equation):
        def initialize(self, d_idx, d_d, d_A):
            a = declare("matrix(9)")
            for i in range(9):            # the break keeps the loop (it would be unrolled)
                a[i] = d_A[9 * d_idx + i]
                if a[i] > 1e300:
                    break
            d_d[d_idx] = det3(a)

    res = {}
    for backend in ("cython", "python"):
        pa = lattice_cloud(nx=5)
        rng = np.random.default_rng(0)
        pa.add_property("A", stride=9, data=rng.uniform(-1, 1, 9 * pa.n))
        pa.add_property("d")
        sc = Scene([pa], [Det("fluid")], dim=2, outputs={"fluid": ["d"]}, backend=backend)
        sc.compute(0, 0.0, 0.1)
        res[backend] = pa.d.copy()
        if backend == "cython":
            assert "cdef int i" in sc.source and "det3(" in sc.source
    expect = np.linalg.det(pa.A.reshape(-1, 3, 3))
    assert np.allclose(res["cython"], expect, rtol=1e-12, atol=1e-14)
    assert np.allclose(res["python"], expect, rtol=1e-12, atol=1e-14)


def test_pair_loop_accumulators_live_in_registers():
    """d_au[d_idx] += ... over the neighbours accumulates in a local, stored once."""
    sc = _scene(["u", "omega"], alpha=0.5)
    src = sc.source
    assert "_r_au = fluid_au[d_idx]" in src and "fluid_au[d_idx] = _r_au" in src
    assert "&_p_au" in src and "d_au[0] +=" in src and "_r_au += _p_au" in src   # summed per pair


def test_show_plan_reports_every_pass_in_order():
    from sphgen.codegen.passes import PASSES
    text = _scene(["u", "omega"], alpha=0.5).describe()
    lines = text[text.index("\npasses:\n"):].splitlines()
    names = [ln.split(":")[0].strip() for ln in lines if ln.startswith("  ") and not ln.startswith("    ")]
    assert names == [p.__name__ for p in PASSES]
    assert "    g1_fluid: au, av, omega accumulated in registers" in text
    assert "    g0_fluid <- fluid: XIJ, R2IJ, RIJ, HIJ, WIJ (~50 flops per pair)" in text


def test_a_pass_over_other_arrays_only_is_scheduled_in_dynamic_chunks():
    """A wall that only sees the fluid gets dynamic chunks (most wall particles may have no
    neighbour); a pass whose destination is among its sources runs the array's thread parts,
    each thread its own first, CLAIM particles at a time, then what is left of the others'."""
    from sphgen.codegen.render import render
    fluid, wall = lattice_cloud("fluid", nx=6), lattice_cloud("wall", nx=6, seed=1)
    sc = Scene([fluid, wall], [Group([SummationDensity("wall", ["fluid"])]),
                               Group([SummationDensity("fluid", ["fluid", "wall"])])],
               dim=2, domain=periodic_box(2), backend="python",
               outputs={"fluid": ["rho"], "wall": ["rho"]})
    src = render(sc.plan).source
    loops = dict(re.findall(r"prange\((\w+)_n, num_threads=_nthreads, (schedule=[^)]*)\):\n\s+_pass", src))
    assert loops == {"wall": "schedule='dynamic', chunksize=64"}
    assert re.search(r"_claim\[8 \* k\] = _part_fluid\[k\]", src)
    assert re.search(r"end = _part_fluid\[owner \+ 1\]\n\s+lo = sphgen_claim\(&_claim\[8 \* owner\], CLAIM\)", src)
    assert re.search(r"for d_idx in range\(lo, hi\):\n\s+_pass_\w+_fluid\(d_idx, t, dt\)", src)
