"""Pass: every property any equation or stage names exists (pruned or not)."""
import difflib

from ..plan import SceneError, is_property


def stage_args(st, which="args"):
    """{(array, prop)} of a stepper's stage methods: all ``d_*`` arguments, or those read."""
    return {(st.array, a[2:]) for sp in st.stages.values() for a in getattr(sp, which)
            if is_property(a, "d_")}


def check_exist(plan):
    """Refuse a property an equation or stage names but its array does not declare."""
    users = [(ep.name, ep.touched()) for ep in plan.eqplans]
    users += [(st.name, stage_args(st)) for st in plan.steppers]
    for who, touched in users:
        for arr, prop in sorted(touched):
            pa = plan.arrays[arr]
            if not pa.has(prop):
                close = difflib.get_close_matches(prop, sorted(set(pa.props) | set(pa.constants)), n=1)
                hint = f"; did you mean '{close[0]}'?" if close else ""
                raise SceneError(f"{who} uses property '{prop}' of array '{arr}', which has no such "
                                 f"property{hint}")
    return []
