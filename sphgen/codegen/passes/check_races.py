"""Pass: no pass reads through ``s_*`` a property of its own destination that its group writes."""
from ...equation import PAIR_METHODS
from ..plan import SceneError


def check_races(plan):
    """Refuse a pair loop that reads s_X of the destination array while the group writes X."""
    for p in plan.neighbour_passes():
        written = {prop for ep in p.equations for _, prop in ep.writes()}
        for loop in p.sources:
            if loop.source != p.dest:
                continue
            for ep in loop.equations:
                for m in PAIR_METHODS:
                    sp = ep.methods.get(m)
                    bad = sorted(sp.props("s_") & written) if sp else []
                    if bad:
                        raise SceneError(
                            f"{ep.name}.{m} reads s_{bad[0]} of '{loop.source}' while this group writes "
                            f"'{bad[0]}' of '{p.dest}': split them into two Groups")
    return []
