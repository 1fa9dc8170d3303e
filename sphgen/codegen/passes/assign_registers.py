"""Pass: destination accumulators of the pair loops live in registers.

A double property of the destination that the pair loops of a pass write, and only
ever as ``d_X[d_idx]``, is loaded into a local before the neighbour loops and stored
after them; the loop methods get its address and index it with 0.
"""
from ...equation import PAIR_METHODS
from ..plan import is_property
from ..translate import in_registers, indexed_only_by_d_idx


def register_candidates(plan, p):
    """Destination doubles the pair loops of a pass write, always as ``d_X[d_idx]``."""
    writes, bad = set(), set()
    for loop in p.sources:
        for ep in loop.equations:
            for sp in (ep.methods[m] for m in PAIR_METHODS if m in ep.methods):
                bad |= {a for a in sp.args if is_property(a, "d_")} - indexed_only_by_d_idx(sp)
                writes |= {a for a in sp.writes if a.startswith("d_")}
    return {a[2:] for a in writes - bad if plan.dtype(p.dest, a[2:]) == "double"}


def assign_registers(plan):
    """Decide each pass's registers and the register form of its pair methods."""
    notes = []
    for p in plan.neighbour_passes():
        regs = register_candidates(plan, p)
        p.registers = tuple(sorted(regs))
        if not regs:
            continue
        names = {f"d_{x}" for x in regs}
        p.pair_specs = {(ep.index, m): in_registers(sp, names & set(sp.args))
                        for ep in p.equations for m, sp in ep.methods.items() if m in PAIR_METHODS}
        notes.append(f"{p.label}: {', '.join(p.registers)} accumulated in registers")
    return notes
