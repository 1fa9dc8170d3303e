"""Pass: prune equations nothing needs, then stores nothing reads, until neither changes.

A property is *needed* if it is a root (read by an integrator stage, an output, a
position or ``h``) or read by a live equation; an equation is live if it writes a
needed property, has ``reduce``/``converged``, or has ``keep = True``.  A live
equation's stores to properties nobody needs are removed and it is specialised again,
which can drop reads and so make more equations and stores dead.
"""
from .check_exist import stage_args
from .specialise import specialise_equation

POSITION = ("x", "y", "z")


def roots(plan):
    """(array, prop) needed whatever the equations do."""
    needed = set()
    for st in plan.steppers:
        needed |= stage_args(st)
    for arr, props in plan.outputs.items():
        needed |= {(arr, p) for p in props}
    for name in plan.arrays:
        needed |= {(name, p) for p in POSITION[:plan.dim] + ("h",)}
    return needed


def liveness(plan):
    """Mark each equation kept or pruned; return the needed (array, prop) (a fixed point)."""
    needed = roots(plan)
    candidates = [ep for ep in plan.eqplans if ep.has_work]
    live = {ep.index for ep in candidates if ep.python_hooks or ep.eq.keep}
    changed = True
    while changed:
        changed = False
        for ep in candidates:
            if ep.index in live or ep.writes() & needed:
                changed |= ep.index not in live
                live.add(ep.index)
                new = (ep.reads() | ep.python_reads) - needed
                changed |= bool(new)
                needed |= new
    for ep in candidates:
        ep.kept = ep.index in live
        if not ep.kept:
            w = ", ".join(sorted(p for _, p in ep.writes()))
            ep.reason = (f"nothing reads what it writes ({w}): no later equation, integrator "
                         "stage, output or diagnostic")
    return needed


def dead_stores(plan):
    """{EqPlan: new "d_X" stores} of kept equations to properties nothing needs."""
    out = {}
    for ep in plan.eqplans:
        if ep.kept and not ep.eq.keep:
            d = {f"d_{p}" for a, p in ep.writes() if (a, p) not in plan.needed} - ep.dead_stores
            if d:
                out[ep] = d
    return out


def prune(plan):
    """Alternate liveness and dead-store removal until neither changes anything."""
    removed = []
    while True:
        plan.needed = liveness(plan)
        new = dead_stores(plan)
        if not new:
            break
        for ep, stores in new.items():
            ep.dead_stores |= stores
            specialise_equation(ep, plan.dim)
            removed.append(f"{ep.name}: removed the stores to {', '.join(sorted(s[2:] for s in stores))}")
    pruned = [f"prune {ep.name}: {ep.reason}" for ep in plan.eqplans if ep.has_work and not ep.kept]
    gone = [f"prune {ep.name}: {ep.reason}" for ep in plan.eqplans if ep.dead_stores and not ep.has_work]
    return _counted(pruned + gone + removed)


def _counted(notes):
    """The notes in order, each once; one that several uses of an equation (in several
    groups or equation sets) gave alike says how many."""
    counts = {}
    for n in notes:
        counts[n] = counts.get(n, 0) + 1
    return [n if k == 1 else f"{n} (in {k} places)" for n, k in counts.items()]
