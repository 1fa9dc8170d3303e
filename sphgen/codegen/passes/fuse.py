"""Pass: fuse each group's kept equations into one neighbour pass per destination."""
from ...equation import PAIR_METHODS
from ..plan import GroupPlan, NeighbourPass, SourceLoop


def neighbour_pass(gp, dest, eps):
    """The pass of one group over one destination: its sources in order of first use."""
    loops = {}
    for ep in eps:
        if any(m in ep.methods for m in PAIR_METHODS):
            for s in ep.eq.sources:
                loop = loops.setdefault(s, SourceLoop(s, []))
                if ep not in loop.equations:
                    loop.equations.append(ep)
    return NeighbourPass(f"g{gp.index}_{dest}", dest, gp.group.reference, eps, list(loops.values()))


def group_plan(group, index, eqplans):
    gp = GroupPlan(group, index, eqplans)
    dests = {}
    for ep in eqplans:
        if ep.kept:
            dests.setdefault(ep.eq.dest, []).append(ep)
    gp.passes = {dest: neighbour_pass(gp, dest, eps) for dest, eps in dests.items()}
    return gp


def fuse(plan):
    """One parallel loop per group and destination, in the order the groups run; a group
    that several equation sets share is planned (and compiled) once."""
    notes, planned = [], {}
    plan.group_plans = []
    for evaluation in plan.evaluations:
        row = []
        for group, eqplans in evaluation:
            if id(group) not in planned:
                planned[id(group)] = group_plan(group, len(planned), eqplans)
            row.append(planned[id(group)])
        plan.group_plans.append(row)
    for p in plan.neighbour_passes():
        srcs = ", ".join(loop.source for loop in p.sources) or "no neighbours"
        notes.append(f"{p.label}: {len(p.equations)} equation(s) in one pass over {srcs}")
    return notes
