"""Render a finished :class:`~sphgen.codegen.plan.Plan` into the Cython source of one module.

Everything here follows from decisions the passes took; this module only names things
(module globals, neighbour lists, entry points), writes the calls and the pair-symbol
lines, and fills ``scene.pyx.mako``, which holds no logic.
"""
import os
from dataclasses import dataclass

from mako.template import Template

from . import pair_symbols
from .cython import to_cython
from .pair_symbols import CythonPair
from .plan import is_property
from .translate import TranslationError

_TEMPLATE = os.path.join(os.path.dirname(__file__), "scene.pyx.mako")
VERSION = "0.1"
_NUMPY = {"double": "np.float64", "int": "np.int32"}


@dataclass(frozen=True)
class Rendered:
    """The module source and the names the backend needs to drive it."""

    source: str
    parameters: dict        # module global -> (object, attribute) whose value it takes
    pass_entries: dict      # neighbour pass label -> entry point ("pass_g0_fluid")
    stage_entries: dict     # (array, stage) -> entry point ("stage_fluid_stage1")
    neighbour_lists: dict   # module name of a list ("nb_fluid_fluid") -> (dest, source, reference)
    registers: dict         # neighbour pass label -> properties accumulated in registers
    helpers: tuple          # names of the helper functions translated
    origin: dict            # generated function -> "Class.method" (for compile errors)


@dataclass(frozen=True)
class SourceView:
    name: str
    key: str
    symbols: list
    calls: list
    loop_all: list
    zero_partials: list     # per pair, before the calls: the partials of the sums set to 0
    add_partials: list      # per pair, after the calls: each partial added to its register


@dataclass(frozen=True)
class PassView:
    name: str
    dest: str
    decls: list
    initialize: list
    load_registers: list
    sources: list
    store_registers: list
    post_loop: list
    schedule: str = "parts"   # "parts", or the prange's schedule (see pass_schedule)


@dataclass(frozen=True)
class StageView:
    name: str
    array: str
    call: str


def nbr_key(dest, src, reference):
    """Module name of a neighbour list."""
    return f"{'rnb' if reference else 'nb'}_{dest}_{src}"


def call(sp, dest, src=None, key=None, regs=None, sums=()):
    """The call of a generated method inside a loop over ``d_idx`` (and ``s_idx``).

    ``regs`` (register -> stride): these go by address, the per-pair partial for those
    in ``sums``; a strided register is a local array."""
    regs = regs or {}
    args = []
    for a in sp.args:
        if is_property(a, "d_"):
            x = a[2:]
            if x in regs:
                args.append(("" if regs[x] > 1 else "&") + ("_p_" if x in sums else "_r_") + x)
            else:
                args.append(f"{dest}_{x}")
        elif is_property(a, "s_"):
            args.append(f"{src}_{a[2:]}")
        elif a == "NBRS":
            args.append(f"&{key}_idx[{key}_off[d_idx]]")
        elif a == "N_NBRS":
            args.append(f"{key}_off[d_idx + 1] - {key}_off[d_idx]")
        else:
            args.append(a)
    return f"{sp.fdef.name}({', '.join(args)})"


def declarations(plan, p):
    """Locals of a neighbour pass: loop indices, scratch, registers, then pair symbols."""
    rows = [pair_symbols.SYMBOLS[s] for s in p.symbols]
    scratch = dict.fromkeys(s for row in rows for s in row.scratch)
    decls = ["cdef long s_idx = 0", "cdef long _k = 0"]
    decls += [f"cdef double {s} = 0.0" for s in scratch]
    strides = register_strides(plan, p)
    for pre, names in (("_r_", p.registers), ("_p_", p.sums)):
        decls += [f"cdef double {pre}{x}[{strides[x]}]" if strides[x] > 1 else f"cdef double {pre}{x} = 0.0"
                  for x in names]
    for row in sorted(rows, key=lambda r: not r.vector):   # arrays first, then scalars
        decls += row.declaration(plan.dim)
    return decls


def register_strides(plan, p):
    """{register: stride of its property}."""
    return {x: plan.arrays[p.dest].props[x].stride for x in p.registers}


def _rows(x, k):
    """The local names of register x's row (stride k)."""
    return [x] if k == 1 else [f"{x}[{i}]" for i in range(k)]


def source_view(plan, p, loop):
    key = nbr_key(p.dest, loop.source, p.reference)
    pair = CythonPair(p.dest, loop.source, plan.dim, plan.domain, p.reference)
    symbols = [line for s in loop.symbols for line in pair_symbols.SYMBOLS[s].cython(pair)]
    strides = register_strides(plan, p)
    calls = {m: [call(p.spec(ep, m), p.dest, loop.source, key, strides, p.sums if m == "loop" else ())
                 for ep in loop.calls(m)]
             for m in ("loop", "loop_all")}
    used = {a[2:] for ep in loop.calls("loop") for a in p.spec(ep, "loop").args if is_property(a, "d_")}
    rows = [r for x in p.sums if x in used for r in _rows(x, strides[x])]
    return SourceView(loop.source, key, symbols, calls["loop"], calls["loop_all"],
                      [f"_p_{r} = 0.0" for r in rows], [f"_r_{r} += _p_{r}" for r in rows])


def pass_view(plan, p):
    strides = register_strides(plan, p)
    pairs = [(f"_r_{r}", f"{p.dest}_{x}[{k} * d_idx + {i}]" if k > 1 else f"{p.dest}_{x}[d_idx]")
             for x, k in strides.items() for i, r in enumerate(_rows(x, k))]
    return PassView(
        p.label, p.dest, declarations(plan, p),
        [call(ep.methods["initialize"], p.dest) for ep in p.calls("initialize")],
        [f"{r} = {m}" for r, m in pairs],
        [source_view(plan, p, loop) for loop in p.sources],
        [f"{m} = {r}" for r, m in pairs],
        [call(ep.methods["post_loop"], p.dest) for ep in p.calls("post_loop")],
        pass_schedule(p))


def pass_schedule(p):
    """The array's thread parts (``"parts"``: one per thread, cut by the neighbour candidates,
    the same in every loop over the array) for a pass whose destination is among its
    sources (every particle has neighbours); dynamic chunks when it visits only other arrays (a wall
    next to the fluid: most of its particles may have no neighbour, and static halves
    leave one thread the work)."""
    if not p.sources or any(loop.source == p.dest for loop in p.sources):
        return "parts"
    return "schedule='dynamic', chunksize=64"


def _method_code(fp):
    try:
        return to_cython(fp.spec, fp.arg_types)
    except TranslationError as e:
        raise TranslationError(f"{fp.origin}: {e}") from None


def _array_tables(plan):
    """What the module's data, guard and speed sections list, array by array."""
    alloc = [(name, {p: plan.dtype(name, p) for p in sorted(props)}) for name, props in plan.allocation.items()]
    speed = {name: [u for u in ("u", "v", "w")[:plan.dim] if u in props] for name, props in alloc
             if "u" in props}
    return dict(
        allocation=[(name, [(p, t, _NUMPY[t]) for p, t in props.items()]) for name, props in alloc],
        constants=[(name, sorted(pa.constants)) for name, pa in plan.arrays.items() if pa.constants],
        guarded=[(name, [(p, plan.arrays[name].props[p].stride) for p, t in props.items() if t == "double"])
                 for name, props in alloc],
        scanned=[(name, " + ".join(f"{name}_{u}[i] * {name}_{u}[i]" for u in speed.get(name, ())),
                  props.get("rho") == "double") for name, props in alloc
                 if name in speed or props.get("rho") == "double"],
        swept=_swept_table(plan, alloc, speed))


def _swept_table(plan, alloc, speed):
    """(array, [(stride, non-finite count of value i of the properties of that stride)],
    its |u|^2 expression or "", whether it has a double rho) per allocated array: what the
    guard's sweep looks at (stride 1 first, where the speed and density checks join it)."""
    out = []
    for name, props in alloc:
        by_stride = {}
        for p, t in props.items():
            if t == "double":
                by_stride.setdefault(plan.arrays[name].props[p].stride, []).append(p)
        by_stride.setdefault(1, [])
        counts = [(st, " + ".join(f"(not isfinite({name}_{p}[i]))" for p in by_stride[st]) or "0")
                  for st in sorted(by_stride)]
        out.append((name, counts, " + ".join(f"{name}_{u}[i] * {name}_{u}[i]" for u in speed.get(name, ())),
                    props.get("rho") == "double"))
    return out


def _parts_table(plan, lists):
    """(array, the keys of the neighbour lists of which it is the destination): each array's
    particles are cut into one part per thread, balanced by the candidates of these lists."""
    return [(name, [k for k, (dest, _, _) in lists.items() if dest == name]) for name in plan.allocation]


def render(plan):
    """The :class:`Rendered` module of a finished plan."""
    stages = [StageView(f"{st.array}_{m}", st.array, call(sp, st.array))
              for st in plan.steppers for m, sp in st.stages.items()]
    lists = {nbr_key(*nl): nl for nl in plan.neighbour_lists()}
    passes = [pass_view(plan, p) for p in plan.neighbour_passes()]
    source = Template(filename=_TEMPLATE).render(
        version=VERSION, nbr_keys=list(lists), param_globals=sorted(plan.parameters),
        kernel_name=type(plan.kernel).__name__, dim=plan.dim,
        kernel_code=[to_cython(sp) for sp in plan.kernel_functions],
        helper_code=[to_cython(sp) for sp in plan.helpers],
        method_code=[_method_code(fp) for fp in plan.functions],
        passes=passes, stages=stages, parts=_parts_table(plan, lists), **_array_tables(plan))
    return Rendered(
        source=source, parameters=dict(plan.parameters),
        pass_entries={p.name: f"pass_{p.name}" for p in passes},
        stage_entries={(st.array, m): f"stage_{st.array}_{m}" for st in plan.steppers for m in st.stages},
        neighbour_lists=lists,
        registers={p.label: p.registers for p in plan.neighbour_passes()},
        helpers=tuple(h.fdef.name for h in plan.helpers),
        origin={fp.spec.fdef.name: fp.origin for fp in plan.functions})
