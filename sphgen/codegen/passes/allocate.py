"""Pass: give memory to what the kept scene touches, and nothing else."""
from ..plan import is_property


def allocate(plan):
    """Allocate user data, needed properties and everything a kept method names."""
    alloc = {name: set(pa.data) for name, pa in plan.arrays.items()}
    for arr, prop in plan.needed:
        alloc[arr].add(prop)
    for ep in plan.eqplans:
        if ep.kept:
            for arr, prop in ep.touched():
                alloc[arr].add(prop)
    for st in plan.steppers:
        for sp in st.stages.values():
            alloc[st.array] |= {a[2:] for a in sp.args if is_property(a, "d_")}
    plan.allocation = {name: props - set(plan.arrays[name].constants) for name, props in alloc.items()}
    notes = []
    for name, props in plan.allocation.items():
        spare = sorted(set(plan.arrays[name].props) - set(props))
        notes.append(f"{name}: {len(props)} properties" + (f"; not allocated: {', '.join(spare)}" if spare else ""))
    return notes
