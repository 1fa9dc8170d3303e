"""Pass: for each source loop, the pair symbols its ``loop`` methods ask for, with their inputs."""
from .. import pair_symbols


def choose_pair_symbols(plan):
    """Compute per pair only what some ``loop`` of the pass asks for (and what that needs)."""
    notes = []
    for p in plan.neighbour_passes():
        for loop in p.sources:
            asked = {a for ep in loop.calls("loop") for a in ep.methods["loop"].pair_symbols}
            loop.symbols = pair_symbols.closure(asked)
            if loop.symbols:
                notes.append(f"{p.label} <- {loop.source}: {', '.join(loop.symbols)} "
                             f"(~{pair_symbols.cost(asked)} flops per pair)")
    return notes
