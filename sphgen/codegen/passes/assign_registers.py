"""Pass: destination accumulators of the pair loops live in registers.

A double property of the destination that the pair loops of a pass write, and only
ever in the destination's own row (``d_X[d_idx]``, or ``d_X[k * d_idx + e]`` for a
property of stride k), is loaded into locals before the neighbour loops and stored
after them; the loop methods get their address and index them with ``e``.

A register the pair methods only ever add to (``+=`` / ``-=``, never read or assigned)
is a *sum*: each pair's contributions go into a per-pair partial that starts at 0 and
is added to the register once per pair.  The loop then carries one reduction per sum
instead of a chain through every equation, which lets the C compiler vectorise the
neighbour loop (several pairs per instruction).
"""
from ...equation import PAIR_METHODS
from ..plan import is_property
from ..translate import in_registers, indexed_by_row, sums_only


def _strides(plan, p, sp):
    return {a: plan.arrays[p.dest].props[a[2:]].stride for a in sp.args
            if is_property(a, "d_") and a[2:] in plan.arrays[p.dest].props}


def register_candidates(plan, p):
    """Destination doubles the pair loops of a pass write, always in the destination's row."""
    writes, bad = set(), set()
    for loop in p.sources:
        for ep in loop.equations:
            for sp in (ep.methods[m] for m in PAIR_METHODS if m in ep.methods):
                bad |= {a for a in sp.args if is_property(a, "d_")} - indexed_by_row(sp, _strides(plan, p, sp))
                writes |= {a for a in sp.writes if a.startswith("d_")}
    return {a[2:] for a in writes - bad if plan.dtype(p.dest, a[2:]) == "double"}


def sum_registers(p, regs):
    """The registers every per-pair (``loop``) method of the pass only adds to."""
    names = {f"d_{x}" for x in regs}
    for loop in p.sources:
        for ep in loop.equations:
            for m in PAIR_METHODS:
                if m in ep.methods:
                    sp = ep.methods[m]
                    used = names & set(sp.args)
                    names -= used - sums_only(sp, used) if m == "loop" else used
    return {a[2:] for a in names}


def assign_registers(plan):
    """Decide each pass's registers, its sums and the register form of its pair methods."""
    notes = []
    for p in plan.neighbour_passes():
        regs = register_candidates(plan, p)
        p.registers = tuple(sorted(regs))
        p.sums = tuple(sorted(sum_registers(p, regs)))
        if not regs:
            continue
        names = {f"d_{x}" for x in regs}
        p.pair_specs = {(ep.index, m): in_registers(sp, {a: k for a, k in _strides(plan, p, sp).items() if a in names})
                        for ep in p.equations for m, sp in ep.methods.items() if m in PAIR_METHODS}
        note = f"{p.label}: {', '.join(p.registers)} accumulated in registers"
        if p.sums:
            note += f" (summed per pair: {', '.join(p.sums)})"
        notes.append(note)
    return notes
