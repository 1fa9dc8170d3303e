"""Pass: every array an equation names exists."""
import difflib

from ..plan import SceneError


def check_arrays(plan):
    """Refuse an equation whose destination or a source is not an array of the scene."""
    for ep in plan.eqplans:
        for name in [ep.eq.dest] + ep.eq.sources:
            if name not in plan.arrays:
                close = difflib.get_close_matches(name, list(plan.arrays), n=1)
                hint = f"; did you mean '{close[0]}'?" if close else ""
                raise SceneError(f"{ep.name}: no particle array named '{name}'{hint} "
                                 f"(arrays: {', '.join(plan.arrays)})")
    return []
