"""Render a :class:`Plan` into the Cython source of one scene module (mako)."""
import ast
import inspect
import os
import types

from mako.template import Template

from ..equation import PAIR_METHODS
from .translate import TranslationError, in_registers, indexed_only_by_d_idx, specialise, to_cython

_TEMPLATE = os.path.join(os.path.dirname(__file__), "scene.pyx.mako")
VERSION = "0.1"


class _Obj:
    def __init__(self, **kw):
        self.__dict__.update(kw)


def _ctype(dtype):
    return "double" if dtype == "double" else "int"


def pair_symbols_needed(syms):
    """The requested pair symbols and everything they are computed from."""
    need = set(syms)
    if need & {"DWIJ"}:
        need |= {"WDASHIJ", "RIJ", "XIJ"}
    if need & {"WIJ", "WDASHIJ", "GHIJ"}:
        need |= {"RIJ", "HIJ"}
    if "EPS" in need:
        need.add("HIJ")
    if "RIJ" in need:
        need.add("R2IJ")
    if "R2IJ" in need:
        need.add("XIJ")
    return need


def pair_symbol_code(syms, dest, src, dim, domain, reference):
    """Lines computing the requested pair symbols (with their dependencies)."""
    need = pair_symbols_needed(syms)
    pos = ("x0", "y0", "z0") if reference else ("x", "y", "z")
    lines = []
    if "XIJ" in need:
        for k in range(3):
            if k < dim:
                lines.append(f"XIJ[{k}] = {dest}_{pos[k]}[d_idx] - {src}_{pos[k]}[s_idx]")
                if domain is not None and domain.periodic[k] and not reference:
                    L = repr(float(domain.length[k]))
                    half = repr(0.5 * float(domain.length[k]))
                    lines += [f"if XIJ[{k}] > {half}:", f"    XIJ[{k}] -= {L}",
                              f"elif XIJ[{k}] < -{half}:", f"    XIJ[{k}] += {L}"]

    if "R2IJ" in need:
        lines.append("R2IJ = " + " + ".join(f"XIJ[{k}] * XIJ[{k}]" for k in range(dim)))
    if "RIJ" in need:
        lines.append("RIJ = sqrt(R2IJ)")
    if "HIJ" in need:
        lines.append(f"HIJ = 0.5 * ({dest}_h[d_idx] + {src}_h[s_idx])")
    if "EPS" in need:
        lines.append("EPS = 0.01 * HIJ * HIJ")
    if "VIJ" in need:
        for k, u in enumerate(("u", "v", "w")[:dim]):
            lines.append(f"VIJ[{k}] = {dest}_{u}[d_idx] - {src}_{u}[s_idx]")
    if "WIJ" in need:
        lines.append("WIJ = kernel_w(RIJ, HIJ)")
    if "WDASHIJ" in need:
        lines.append("WDASHIJ = kernel_dwdr(RIJ, HIJ)")
    if "GHIJ" in need:
        lines.append("GHIJ = kernel_gradh(RIJ, HIJ)")
    if "DWIJ" in need:
        lines.append("_f = WDASHIJ / RIJ if RIJ > 1e-12 else 0.0")
        lines += [f"DWIJ[{k}] = _f * XIJ[{k}]" for k in range(dim)]
    return lines


def nbr_key(dest, src, reference):
    return f"{'rnb' if reference else 'nb'}_{dest}_{src}"


def register_accumulators(plan, dest, sources):
    """Destination doubles the pair loops of a pass write, always as ``d_X[d_idx]``."""
    writes, bad = set(), set()
    for lps in sources.values():
        for ep in lps:
            for m in PAIR_METHODS:
                sp = ep.methods.get(m)
                if sp is None:
                    continue
                d_args = {a for a in sp.args if a.startswith("d_") and a != "d_idx"}
                good = indexed_only_by_d_idx(sp)
                bad |= d_args - good
                writes |= {a for a in sp.writes if a.startswith("d_")}
    return {a[2:] for a in writes - bad if plan.dtype(dest, a[2:]) == "double"}


def _call(sp, dest, src=None, key=None, regs=()):
    args = []
    for a in sp.args:
        if a.startswith("d_") and a != "d_idx" and a[2:] in regs:
            args.append(f"&_r_{a[2:]}")
        elif a.startswith("d_") and a != "d_idx":
            args.append(f"{dest}_{a[2:]}")
        elif a.startswith("s_") and a != "s_idx":
            args.append(f"{src}_{a[2:]}")
        elif a == "NBRS":
            args.append(f"&{key}_idx[{key}_off[d_idx]]")
        elif a == "N_NBRS":
            args.append(f"{key}_off[d_idx + 1] - {key}_off[d_idx]")
        else:
            args.append(a)
    return f"{sp.fdef.name}({', '.join(args)})"


_COMPYLE_BUILTINS = ("declare", "cast", "address", "atomic_inc", "atomic_dec")


def _helpers_called(spec, owner_func, seen):
    """Helper functions (``@helper``) called by a specialised body, recursively."""
    out = []
    glb = dict(getattr(owner_func, "__globals__", {}))
    try:
        glb.update(inspect.getclosurevars(owner_func).nonlocals)
    except (TypeError, ValueError):
        pass
    for node in ast.walk(spec.fdef):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            f = glb.get(node.func.id)
            if isinstance(f, types.FunctionType) and node.func.id not in _COMPYLE_BUILTINS:
                if not getattr(f, "__sphgen_helper__", False):
                    raise TranslationError(
                        f"{node.func.id}() is a Python function, not a sphgen helper: decorate it "
                        "with @sphgen.equation.helper so it can be translated")
                if f.__name__ not in seen:
                    seen.add(f.__name__)
                    hs = specialise(f, f.__name__, {}, None, keep_defaults=True)
                    out += _helpers_called(hs, f, seen) + [(f, hs)]
    return out


def render(plan):
    """(source, param_values, line_origins) of the scene module."""
    kernel = plan.kernel
    kernel_code = [to_cython(specialise(kernel, m, kernel.constants(), "kernel", keep_defaults=True),
                             helper=True) for m in kernel.methods]
    method_code, params, helpers, seen, emitted = [], {}, [], set(), set()

    def emit(owner, sp, dtypes):
        if sp.fdef.name in emitted:
            return
        emitted.add(sp.fdef.name)
        for p in sorted(sp.params_used):
            params[f"{_prefix(sp)}_{p}"] = (owner, p)
        try:
            helpers.extend(_helpers_called(sp, getattr(type(owner), sp.method), seen))
            method_code.append(to_cython(sp, dtypes))
        except TranslationError as e:
            raise TranslationError(f"{type(owner).__name__}.{sp.method}: {e}") from None

    def _prefix(sp):
        return sp.fdef.name[: -len(sp.method) - 1]

    passes, nbr_keys = [], []
    pair_specs = {}   # (equation, method) -> the version with register accumulators

    def pair(ep, m):
        return pair_specs.get((id(ep.eq), m), ep.methods[m])
    for row in plan.group_plans:
        for gp in row:
            for dest, eps in gp.dests.items():
                regs = register_accumulators(plan, dest, gp.sources(dest))
                for ep in eps:
                    for m, sp in ep.methods.items():
                        if m in PAIR_METHODS and regs:
                            sp = in_registers(sp, {f"d_{x}" for x in regs} & set(sp.args))
                            pair_specs[(id(ep.eq), m)] = sp
                        dt = {}
                        for a in sp.args:
                            if a.startswith("d_") and a != "d_idx":
                                dt[a] = plan.dtype(dest, a[2:])
                            elif a.startswith("s_") and a != "s_idx":
                                kinds = {plan.dtype(s, a[2:]) for s in ep.eq.sources}
                                if len(kinds) > 1:
                                    raise TranslationError(
                                        f"{ep.name}: property '{a[2:]}' has different types across sources")
                                dt[a] = kinds.pop()
                        emit(ep.eq, sp, dt)
                p = _Obj(name=f"g{gp.index}_{dest}", dest=dest, initialize=[], post_loop=[], sources=[])
                p.initialize = [_call(ep.methods["initialize"], dest) for ep in eps if "initialize" in ep.methods]
                p.post_loop = [_call(ep.methods["post_loop"], dest) for ep in eps if "post_loop" in ep.methods]
                p.registers = [(x, f"{dest}_{x}") for x in sorted(regs)]
                syms_all = set()
                for src, lps in gp.sources(dest).items():
                    key = nbr_key(dest, src, gp.group.reference)
                    if key not in nbr_keys:
                        nbr_keys.append(key)
                    syms = {a for ep in lps for m in PAIR_METHODS if m in ep.methods
                            for a in ep.methods[m].pair_symbols}
                    calls = [_call(pair(ep, "loop"), dest, src, key, regs) for ep in lps if "loop" in ep.methods]
                    alls = [_call(pair(ep, "loop_all"), dest, src, key, regs) for ep in lps
                            if "loop_all" in ep.methods]
                    symbols = pair_symbol_code(syms, dest, src, plan.dim, plan.domain, gp.group.reference) \
                        if calls else []
                    if calls:
                        syms_all |= pair_symbols_needed(syms)
                    p.sources.append(_Obj(name=src, key=key, symbols=symbols, calls=calls, loop_all=alls))
                decls = ["cdef long s_idx = 0", "cdef long _k = 0", "cdef double _f = 0.0"]
                decls += [f"cdef double _r_{x} = 0.0" for x, _ in p.registers]
                for s in ("XIJ", "VIJ", "DWIJ"):
                    if s in syms_all:
                        # components past the dimension are zero (set once, never recomputed)
                        decls.append(f"cdef double {s}[3]")
                        decls += [f"{s}[{k}] = 0.0" for k in range(plan.dim, 3)]
                scal = [s for s in ("RIJ", "R2IJ", "HIJ", "EPS", "WIJ", "WDASHIJ", "GHIJ") if s in syms_all]
                decls += [f"cdef double {s} = 0.0" for s in scal]
                p.decls = decls
                passes.append(p)
    stages = []
    for st in plan.steppers:
        for m, sp in st.stages.items():
            emit(st.stepper, sp, {a: plan.dtype(st.array, a[2:]) for a in sp.args
                                  if a.startswith("d_") and a != "d_idx"})
            stages.append(_Obj(name=f"{st.array}_{m}", array=st.array, call=_call(sp, st.array)))
    helper_code = [to_cython(hs, helper=True) for _, hs in helpers]
    allocation = [(name, [(p, _ctype(plan.dtype(name, p))) for p in sorted(props)])
                  for name, props in plan.allocation.items()]
    constants = [(name, sorted(pa.constants)) for name, pa in plan.arrays.items() if pa.constants]
    guarded = [(name, [(p, plan.arrays[name].props[p].stride) for p in sorted(props)
                       if plan.dtype(name, p) == "double"])
               for name, props in plan.allocation.items()]
    src = Template(filename=_TEMPLATE).render(
        version=VERSION, allocation=allocation, constants=constants, nbr_keys=nbr_keys,
        param_globals=sorted(params), kernel_name=type(kernel).__name__, dim=plan.dim,
        kernel_code=kernel_code, helper_code=helper_code, method_code=method_code,
        passes=passes, stages=stages, guarded=guarded,
        moving=[(name, [u for u in ("u", "v", "w")[:plan.dim] if u in props])
                for name, props in plan.allocation.items() if "u" in props])
    return src, params
