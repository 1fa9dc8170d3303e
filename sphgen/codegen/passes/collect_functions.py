"""Pass: the functions the compiled module defines, in order, and their run-time parameters."""
from .. import pair_symbols
from ..plan import FunctionPlan
from ..translate import TranslationError, specialise


def _module_globals(fp):
    """{module global: (object, attribute)} for the parameters a function reads."""
    sp = fp.spec
    prefix = sp.fdef.name[: -len(sp.method) - 1]
    return {f"{prefix}_{p}": (fp.owner, p) for p in sorted(sp.params_used)}


def collect_functions(plan):
    """Kernel methods (the extra ones if a chosen pair symbol calls one); then each pass's
    methods (first use wins); then the stage methods."""
    kernel = plan.kernel
    asked = pair_symbols.kernel_methods(s for p in plan.neighbour_passes() for loop in p.sources
                                        for s in loop.symbols)
    missing = sorted(asked - set(kernel.extra_methods))
    if missing:
        raise TranslationError(f"a pair symbol of this scene needs the kernel method '{missing[0]}', "
                               f"which {type(kernel).__name__} does not have")
    methods = tuple(kernel.methods) + (tuple(kernel.extra_methods) if asked else ())
    plan.kernel_functions = [specialise(kernel, m, kernel.constants(), "kernel", keep_defaults=True)
                             for m in methods]
    funcs = {}
    for p in plan.neighbour_passes():
        for ep in p.equations:
            for m in ep.methods:
                sp = p.spec(ep, m)
                funcs.setdefault(sp.fdef.name, FunctionPlan(ep.eq, sp, p.dest, ep.eq.sources))
    for st in plan.steppers:
        for sp in st.stages.values():
            funcs.setdefault(sp.fdef.name, FunctionPlan(st.stepper, sp, st.array, []))
    plan.functions = list(funcs.values())
    plan.parameters = {}
    for fp in plan.functions:
        plan.parameters.update(_module_globals(fp))
    return [f"{len(plan.functions)} functions, {len(plan.parameters)} run-time parameters"
            + (f" ({', '.join(sorted(plan.parameters))})" if plan.parameters else "")]
