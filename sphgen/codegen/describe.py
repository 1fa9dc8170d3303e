"""``--show-plan``: the plan as text, then what each pass removed or decided; the plan's
estimated floating-point work per neighbour pair (for the benchmarks' roofline line)."""
import ast

from . import pair_symbols

_ARITHMETIC = (ast.Add, ast.Sub, ast.Mult, ast.Div)


def _arithmetic_ops(fdef):
    """+, -, *, / in a specialised method (augmented assignments included; calls of
    helpers and math functions not counted)."""
    return sum(isinstance(n, (ast.BinOp, ast.AugAssign)) and isinstance(n.op, _ARITHMETIC)
               for n in ast.walk(fdef))


def loop_flops(npass, loop):
    """Estimated flops per pair of one source loop of a neighbour pass: its pair symbols
    (the table's costs) plus the arithmetic of the loop methods it calls."""
    return pair_symbols.cost(loop.symbols) + sum(
        _arithmetic_ops(npass.spec(ep, "loop").fdef) for ep in loop.calls("loop"))


def _flags(group):
    on = [f for f, v in (("iterate", group.iterate), ("update_nnps", group.update_nnps),
                         ("reference", group.reference), ("condition", group.condition)) if v]
    return f" [{', '.join(on)}]" if on else ""


def _evaluations(plan):
    lines = []
    for i, row in enumerate(plan.group_plans):
        lines.append(f"evaluation {i}:")
        if i in plan.dropped:
            lines.append("  never evaluated by the integrator; nothing generated")
        for gp in row:
            lines.append(f"  group {gp.index}{_flags(gp.group)}:")
            for dest, eps in gp.dests.items():
                srcs = gp.sources(dest)
                lines.append(f"    dest {dest}: one pass, neighbour sources: "
                             f"{', '.join(srcs) if srcs else 'none'}")
                lines += [f"      keep  {ep.name}: {', '.join(ep.methods)}" for ep in eps]
            lines += [f"      prune {ep.name}: {ep.reason}" for ep in gp.eqplans if not ep.kept]
    return lines


def _allocation(plan):
    lines = ["properties allocated:"]
    for name, props in plan.allocation.items():
        pa = plan.arrays[name]
        lines.append(f"  {name} ({pa.n} particles): {', '.join(sorted(props))}")
        declared = sorted(set(pa.props) - set(props))
        if declared:
            lines.append(f"    declared, not allocated: {', '.join(declared)}")
    return lines


def _passes(plan):
    """One line per pass: its note, 'ok' without one, or its notes indented below it."""
    lines = ["passes:"]
    for name, notes in plan.log:
        if len(notes) <= 1:
            lines.append(f"  {name}: {notes[0] if notes else 'ok'}")
        else:
            lines += [f"  {name}:"] + [f"    {n}" for n in notes]
    return lines


def describe(plan):
    """Human-readable plan: evaluations, stages, allocation, then the passes' notes."""
    dom = plan.domain
    lines = [f"sphgen plan: dim={plan.dim}, kernel={type(plan.kernel).__name__}, "
             f"periodic={tuple(dom.periodic) if dom else (False,) * 3}"]
    lines += _evaluations(plan)
    lines.append("integrator stages:")
    lines += [f"  {st.array}: {type(st.stepper).__name__} {', '.join(st.stages)}" for st in plan.steppers]
    lines += _allocation(plan) + _passes(plan)
    return "\n".join(lines)
