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


def nonzero_switches(obj):
    """The float switches that are not zero: their value stays a run-time parameter, but
    a test ``self.k != 0`` is folded to True (and ``== 0`` to False), so that a pair loop
    is not cut by a branch around the only loads of a property, which gcc does not
    vectorise (a switched-on artificial viscosity or delta-SPH term)."""
    return {k for k in getattr(obj, "switches", ())
            if not isinstance(getattr(obj, k), (bool, int)) and getattr(obj, k) != 0}


def switch_states(obj):
    """{switch: value folded, or 'non-zero'}: what the generated code assumes of ``obj``."""
    nonzero = nonzero_switches(obj)
    return {k: ("non-zero" if k in nonzero else getattr(obj, k)) for k in getattr(obj, "switches", ())}


def _why_empty(ep):
    if ep.dead_stores:
        return "nothing reads what it writes (" + ", ".join(sorted(d[2:] for d in ep.dead_stores)) + ")"
    sw = ", ".join(f"{k}={getattr(ep.eq, k)!r}" for k in ep.eq.switches)
    return f"switched off ({sw})" if sw else "has no work"


def specialise_equation(ep, dim):
    """(Re)specialise the methods of one equation, without its dead stores."""
    ep.kept, ep.reason, ep.methods = True, "", {}
    consts, nonzero = folded_switches(ep.eq), nonzero_switches(ep.eq)
    for m in ep.eq.methods():
        try:
            sp = specialise_method(ep.eq, m, consts, ep.prefix, dim=dim, dead=ep.dead_stores, nonzero=nonzero)
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


def check_switches(plan):
    """Refuse to run a module whose switches have changed since it was generated (a
    folded value, or a non-zero one that became zero): a new scene is needed."""
    for owner, states in plan.switches:
        now = switch_states(owner)
        for k, was in states.items():
            if now[k] != was:
                raise SceneError(f"{type(owner).__name__}.{k} is {getattr(owner, k)!r}, but the scene was "
                                 f"generated for {k} = {was!r}; build a new Scene after changing a switch")


def specialise(plan):
    """Specialise every equation and stage method; an equation left with nothing is dropped."""
    notes = []
    plan.switches = [(o, switch_states(o)) for o in [ep.eq for ep in plan.eqplans] +
                     [st.stepper for st in plan.steppers] if getattr(o, "switches", ())]
    for ep in plan.eqplans:
        specialise_equation(ep, plan.dim)
        if not ep.kept:
            notes.append(f"drop {ep.name}: {ep.reason}")
    for st in plan.steppers:
        consts, nonzero = folded_switches(st.stepper), nonzero_switches(st.stepper)
        specs = {m: specialise_method(st.stepper, m, consts, st.prefix, dim=plan.dim, nonzero=nonzero)
                 for m in st.stepper.stage_methods()}
        st.stages = {m: sp for m, sp in specs.items() if not sp.empty}
    n = sum(len(ep.methods) for ep in plan.eqplans) + sum(len(st.stages) for st in plan.steppers)
    return [f"{n} methods specialised for dim={plan.dim}"] + notes
