"""Pass: drop the equation sets the integrator never evaluates.

A scheme gives one equation set per evaluation its integrator *may* ask for; the
integrator of the scene at hand may never ask for some of them (the viscous Verlet run
with nu = 0 never evaluates its dissipative set).  Such a set is emptied before anything
else looks at it: its equations are not specialised, checked, kept or compiled unless
another set also runs them, and :meth:`~sphgen.scene.Scene.compute` refuses it.
"""
from ..plan import SceneError


def drop_unevaluated(plan):
    """Empty every set not in ``plan.evaluated`` (``None``: the integrator runs them all)."""
    n = len(plan.evaluations)
    if plan.evaluated is None or n == 1:    # one set stands for every evaluation
        return []
    unknown = sorted(set(plan.evaluated) - set(range(n)))
    if unknown:
        raise SceneError(f"the integrator evaluates equation set(s) {unknown}, but the scheme gave "
                         f"{n} set(s) (0 to {n - 1})")
    notes = []
    for i in range(n):
        if i not in plan.evaluated:
            plan.dropped.add(i)
            plan.evaluations[i] = []
            notes.append(f"set {i}: never evaluated by the integrator; nothing generated")
    used = {}
    for row in plan.evaluations:
        for group, eqplans in row:
            for ep in eqplans:
                used[ep] = used.get(ep, False) or group.reference
    plan.eqplans = [ep for ep in plan.eqplans if ep in used]
    for ep in plan.eqplans:        # a dropped set's group no longer makes an equation 'reference'
        ep.reference = used[ep]
    return notes
