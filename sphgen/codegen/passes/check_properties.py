"""Pass: every property the kept scene reads has data, a writer or a default; outputs exist."""
from ..plan import SceneError
from .check_exist import stage_args


def _writers(plan):
    out = set()
    for ep in plan.eqplans:
        if ep.kept:
            out |= ep.writes()
    for st in plan.steppers:
        out |= {(st.array, a[2:]) for sp in st.stages.values() for a in sp.writes if a.startswith("d_")}
    return out


def check_properties(plan):
    """Refuse a read of a property nothing sets, and an output that does not exist."""
    writers = _writers(plan)
    users = [(ep.name, ep.reads()) for ep in plan.eqplans if ep.kept]
    users += [(st.name, stage_args(st, "reads")) for st in plan.steppers]
    for who, reads in users:
        for arr, prop in sorted(reads):
            pa = plan.arrays[arr]
            if prop in pa.data or prop in pa.constants or (arr, prop) in writers:
                continue
            if pa.props[prop].explicit_default:
                continue
            raise SceneError(f"{who} reads property '{prop}' of array '{arr}', but nothing sets it: "
                             "give it data, a default (add_property(..., default=...)), or an "
                             "equation that computes it")
    for arr, props in plan.outputs.items():
        for p in props:
            if not plan.arrays[arr].has(p):
                raise SceneError(f"output property '{p}' of array '{arr}' does not exist")
    return []
