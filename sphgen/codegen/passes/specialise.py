"""Pass: specialise every method (switches, constants and dimension folded), drop empty ones."""
from ...equation import PAIR_METHODS
from ..plan import SceneError
from ..translate import TranslationError, specialise as specialise_method


def folded_switches(obj):
    """Switches folded into the code: ints/bools always, floats only when zero.

    A non-zero float switch stays a run-time parameter, so a sweep over it (e.g. the
    viscosity of a Reynolds-number study) shares one compiled module.
    """
    out = {}
    for k in getattr(obj, "switches", ()):
        v = getattr(obj, k)
        if isinstance(v, (bool, int)) or v == 0:
            out[k] = v
    return out


def _why_empty(ep):
    if ep.dead_stores:
        return "nothing reads what it writes (" + ", ".join(sorted(d[2:] for d in ep.dead_stores)) + ")"
    sw = ", ".join(f"{k}={getattr(ep.eq, k)!r}" for k in ep.eq.switches)
    return f"switched off ({sw})" if sw else "has no work"


def specialise_equation(ep, dim):
    """(Re)specialise the methods of one equation, without its dead stores."""
    ep.kept, ep.reason, ep.methods = True, "", {}
    consts = folded_switches(ep.eq)
    for m in ep.eq.methods():
        try:
            sp = specialise_method(ep.eq, m, consts, ep.prefix, dim=dim, dead=ep.dead_stores)
        except TranslationError as e:
            raise SceneError(f"{ep.name}.{m}: {e}") from None
        if m in PAIR_METHODS and any(w.startswith("s_") for w in sp.writes):
            bad = sorted(w for w in sp.writes if w.startswith("s_"))
            raise SceneError(f"{ep.name}.{m} writes {', '.join(bad)}: pair loops are gather-only "
                             "(they may write only d_*[d_idx])")
        if not sp.empty:
            ep.methods[m] = sp
    if not ep.has_work:
        ep.kept, ep.reason = False, _why_empty(ep)


def specialise(plan):
    """Specialise every equation and stage method; an equation left with nothing is dropped."""
    notes = []
    for ep in plan.eqplans:
        specialise_equation(ep, plan.dim)
        if not ep.kept:
            notes.append(f"drop {ep.name}: {ep.reason}")
    for st in plan.steppers:
        consts = folded_switches(st.stepper)
        specs = {m: specialise_method(st.stepper, m, consts, st.prefix, dim=plan.dim)
                 for m in st.stepper.stage_methods()}
        st.stages = {m: sp for m, sp in specs.items() if not sp.empty}
    n = sum(len(ep.methods) for ep in plan.eqplans) + sum(len(st.stages) for st in plan.steppers)
    return [f"{n} methods specialised for dim={plan.dim}"] + notes
