"""Pass: the functions the compiled module defines, in order, and their run-time parameters."""
from ..plan import FunctionPlan
from ..translate import specialise


def _module_globals(fp):
    """{module global: (object, attribute)} for the parameters a function reads."""
    sp = fp.spec
    prefix = sp.fdef.name[: -len(sp.method) - 1]
    return {f"{prefix}_{p}": (fp.owner, p) for p in sorted(sp.params_used)}


def collect_functions(plan):
    """Kernel methods; then each pass's methods (first use wins); then the stage methods."""
    kernel = plan.kernel
    plan.kernel_functions = [specialise(kernel, m, kernel.constants(), "kernel", keep_defaults=True)
                             for m in kernel.methods]
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
