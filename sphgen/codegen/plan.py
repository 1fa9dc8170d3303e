"""Scene analysis: specialise every method, prune what nothing needs, check properties.

The plan is the generator's single source of truth: the renderer emits exactly what it
keeps, the Python evaluator runs exactly what it keeps, and ``--show-plan`` prints it.
"""
import difflib

from ..equation import Equation, Group, PAIR_METHODS
from ..errors import SphgenError
from .translate import TranslationError, specialise

POSITION = ("x", "y", "z")


def folded_switches(obj):
    """Switches folded into the code: ints/bools always, floats only when zero.

    A non-zero float switch stays a run-time parameter, so a sweep over it (e.g. the
    viscosity of a Reynolds-number study) shares one compiled module.
    """
    out = {}
    for k in getattr(obj, "switches", ()):
        v = getattr(obj, k)
        if isinstance(v, (bool, int)) or v == 0:
            out[k] = v
    return out


class SceneError(SphgenError, ValueError):
    """A scene is inconsistent: missing property, bad array name, race, ..."""


def _reduce_reads(eq):
    """Properties ``reduce(self, dst, t, dt)`` reads as ``dst.<name>`` (found in its source)."""
    import ast
    import inspect
    import textwrap
    try:
        tree = ast.parse(textwrap.dedent(inspect.getsource(type(eq).reduce)))
    except (OSError, TypeError, SyntaxError):
        return set()
    fdef = tree.body[0]
    args = [a.arg for a in fdef.args.args]
    if len(args) < 2:
        return set()
    dst = args[1]
    return {(eq.dest, n.attr) for n in ast.walk(fdef)
            if isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and n.value.id == dst
            and not n.attr.startswith("_") and n.attr not in ("n", "name", "data", "props", "constants")}


class EqPlan:
    """One equation instance: its specialised methods and whether it is kept."""

    def __init__(self, eq, index, dim=3):
        self.dim = dim
        self.reference = False
        self.eq = eq
        self.index = index
        self.prefix = f"{type(eq).__name__}_{index}"
        self.name = f"{type(eq).__name__}[{eq.dest}{'<-' + ','.join(eq.sources) if eq.sources else ''}]"
        self.methods = {}
        self.kept = True
        self.reason = ""
        self.python_hooks = [m for m in ("reduce", "converged") if callable(getattr(eq, m, None))]
        self.python_reads = _reduce_reads(eq) if "reduce" in self.python_hooks else set()

    def implied(self):
        """Properties the requested pair symbols need, on dest and sources."""
        syms = {a for sp in self.methods.values() for a in sp.args}
        props = set()
        if "VIJ" in syms:
            props |= set(("u", "v", "w")[:self.dim])
        if syms & {"HIJ", "WIJ", "DWIJ", "WDASHIJ", "GHIJ", "EPS"}:
            props.add("h")
        if self.reference and syms & {"XIJ", "RIJ", "R2IJ", "WIJ", "DWIJ", "WDASHIJ", "GHIJ"}:
            props |= set(("x0", "y0", "z0")[:self.dim])
        if not props:
            return set()
        return {(a, p) for a in [self.eq.dest] + self.eq.sources for p in props}

    def reads(self):
        """{(array, prop)} read by the kept methods."""
        out = self.implied()
        for sp in self.methods.values():
            for a in sp.args:
                if a.startswith("d_") and a != "d_idx" and (a in sp.reads):
                    out.add((self.eq.dest, a[2:]))
                elif a.startswith("s_") and a != "s_idx":
                    out.update((s, a[2:]) for s in self.eq.sources)
        return out

    def writes(self):
        return {(self.eq.dest, a[2:]) for sp in self.methods.values() for a in sp.writes
                if a.startswith("d_")}

    def touched(self):
        out = self.implied()
        for sp in self.methods.values():
            for a in sp.args:
                if a.startswith("d_") and a != "d_idx":
                    out.add((self.eq.dest, a[2:]))
                elif a.startswith("s_") and a != "s_idx":
                    out.update((s, a[2:]) for s in self.eq.sources)
        return out


class GroupPlan:
    """A group of kept equations: per destination, one fused pass over all its sources."""

    def __init__(self, group, index, eqplans):
        self.group = group
        self.index = index
        self.eqplans = eqplans
        self.dests = {}
        for ep in eqplans:
            if ep.kept:
                self.dests.setdefault(ep.eq.dest, []).append(ep)

    def sources(self, dest):
        """Ordered sources of a destination with the equations that loop over each."""
        out = {}
        for ep in self.dests[dest]:
            for m in PAIR_METHODS:
                if m in ep.methods:
                    for s in ep.eq.sources:
                        lst = out.setdefault(s, [])
                        if ep not in lst:
                            lst.append(ep)
        return out


class StepperPlan:
    def __init__(self, array, stepper, index):
        self.array = array
        self.stepper = stepper
        self.prefix = f"{type(stepper).__name__}_{index}"
        self.stages = {}


class Plan:
    """What the scene computes: groups per stage, stage kernels, allocations."""

    def __init__(self, arrays, stages, steppers, kernel, dim, domain, outputs):
        self.arrays = {pa.name: pa for pa in arrays}
        if len(self.arrays) != len(arrays):
            raise SceneError("two particle arrays have the same name")
        self.kernel = kernel
        self.dim = dim
        self.domain = domain
        self.outputs = outputs or {}
        self.stages = stages
        self._eqplans = {}
        self.groups = []
        for si, groups in enumerate(stages):
            gps = []
            for g in groups:
                eps = [self._eqplan(eq) for eq in g.equations]
                for ep in eps:
                    ep.reference = ep.reference or g.reference
                gps.append(eps)
            self.groups.append(list(zip(groups, gps)))
        self.steppers = [StepperPlan(a, s, i) for i, (a, s) in enumerate(sorted(steppers.items()))]
        self._specialise({})
        self._check_exist()
        self._prune_to_fixed_point()
        self._check_properties()
        self.group_plans = []
        gi = 0
        for gs in self.groups:
            row = []
            for g, eps in gs:
                gp = GroupPlan(g, gi, eps)
                gi += 1
                self._check_race(gp)
                row.append(gp)
            self.group_plans.append(row)
        self.allocation = self._allocation()

    # ------------------------------------------------------------ building
    def _eqplan(self, eq):
        if id(eq) not in self._eqplans:
            ep = EqPlan(eq, len(self._eqplans), self.dim)
            for name in [eq.dest] + eq.sources:
                if name not in self.arrays:
                    close = difflib.get_close_matches(name, list(self.arrays), n=1)
                    hint = f"; did you mean '{close[0]}'?" if close else ""
                    raise SceneError(f"{ep.name}: no particle array named '{name}'{hint} "
                                     f"(arrays: {', '.join(self.arrays)})")
            self._eqplans[id(eq)] = ep
        return self._eqplans[id(eq)]

    @property
    def eqplans(self):
        return list(self._eqplans.values())

    def _specialise(self, dead):
        for ep in self.eqplans:
            ep.kept, ep.reason, ep.methods = True, "", {}
            consts = folded_switches(ep.eq)
            for m in ep.eq.methods():
                try:
                    sp = specialise(ep.eq, m, consts, ep.prefix, dim=self.dim, dead=dead.get(id(ep.eq), ()))
                except TranslationError as e:
                    raise SceneError(f"{ep.name}.{m}: {e}") from None
                if m in PAIR_METHODS and any(w.startswith("s_") for w in sp.writes):
                    bad = sorted(w for w in sp.writes if w.startswith("s_"))
                    raise SceneError(f"{ep.name}.{m} writes {', '.join(bad)}: pair loops are gather-only "
                                     "(they may write only d_*[d_idx])")
                if not sp.empty:
                    ep.methods[m] = sp
            if not ep.methods and not ep.python_hooks:
                ep.kept = False
                sw = ", ".join(f"{k}={getattr(ep.eq, k)!r}" for k in ep.eq.switches)
                if dead.get(id(ep.eq)):
                    ep.reason = ("nothing reads what it writes (" +
                                 ", ".join(sorted(d[2:] for d in dead[id(ep.eq)])) + ")")
                else:
                    ep.reason = f"switched off ({sw})" if sw else "has no work"
        for st in self.steppers:
            st.stages = {}
            consts = folded_switches(st.stepper)
            for m in st.stepper.stage_methods():
                sp = specialise(st.stepper, m, consts, st.prefix, dim=self.dim)
                if not sp.empty:
                    st.stages[m] = sp

    def _prune_to_fixed_point(self):
        """Prune equations, then stores nothing reads, until neither changes.

        Removing a dead store can make an equation's other reads unneeded, which can
        make another equation dead, and so on.
        """
        dead = {}
        while True:
            self._prune()
            new = {}
            for ep in self.eqplans:
                if ep.kept and not ep.eq.keep:
                    d = {f"d_{p}" for a, p in ep.writes() if (a, p) not in self.needed}
                    if d:
                        new[id(ep.eq)] = d | dead.get(id(ep.eq), set())
            if all(new.get(k, set()) <= dead.get(k, set()) for k in new):
                return
            for k, v in new.items():
                dead[k] = dead.get(k, set()) | v
            self._specialise(dead)

    def _prune(self):
        """Keep an equation only if something needs what it writes (fixed point)."""
        needed = set()
        for st in self.steppers:
            for sp in st.stages.values():
                needed |= {(st.array, a[2:]) for a in sp.args if a.startswith("d_") and a != "d_idx"}
        for arr, props in self.outputs.items():
            needed |= {(arr, p) for p in props}
        for name in self.arrays:
            needed |= {(name, p) for p in POSITION[:self.dim] + ("h",)}
        live = {id(ep.eq) for ep in self.eqplans if ep.kept and (ep.python_hooks or ep.eq.keep)}
        changed = True
        while changed:
            changed = False
            for ep in self.eqplans:
                if not ep.kept:
                    continue
                if id(ep.eq) in live or ep.writes() & needed:
                    if id(ep.eq) not in live:
                        live.add(id(ep.eq))
                        changed = True
                    new = (ep.reads() | ep.python_reads) - needed
                    if new:
                        needed |= new
                        changed = True
        for ep in self.eqplans:
            if ep.kept and id(ep.eq) not in live:
                ep.kept = False
                w = ", ".join(sorted(p for _, p in ep.writes()))
                ep.reason = (f"nothing reads what it writes ({w}): no later equation, integrator "
                             "stage, output or diagnostic")
        self.needed = needed

    def _check_properties(self):
        writers = set()
        for ep in self.eqplans:
            if ep.kept:
                writers |= ep.writes()
        for st in self.steppers:
            writers |= {(st.array, a[2:]) for sp in st.stages.values() for a in sp.writes if a.startswith("d_")}
        users = [(ep.name, ep.reads()) for ep in self.eqplans if ep.kept]
        for st in self.steppers:
            r = {(st.array, a[2:]) for sp in st.stages.values() for a in sp.reads
                 if a.startswith("d_") and a != "d_idx"}
            users.append((f"{type(st.stepper).__name__}[{st.array}]", r))
        for who, reads in users:
            for arr, prop in sorted(reads):
                pa = self.arrays[arr]
                if prop in pa.data or prop in pa.constants or (arr, prop) in writers:
                    continue
                if pa.props[prop].explicit_default:
                    continue
                raise SceneError(f"{who} reads property '{prop}' of array '{arr}', but nothing sets it: "
                                 "give it data, a default (add_property(..., default=...)), or an "
                                 "equation that computes it")
        for arr, props in self.outputs.items():
            for p in props:
                if not self.arrays[arr].has(p):
                    raise SceneError(f"output property '{p}' of array '{arr}' does not exist")

    def _check_exist(self):
        """Every property any equation or stage names must exist (pruned or not)."""
        users = [(ep.name, ep.touched()) for ep in self.eqplans]
        for st in self.steppers:
            users.append((f"{type(st.stepper).__name__}[{st.array}]",
                          {(st.array, a[2:]) for sp in st.stages.values() for a in sp.args
                           if a.startswith("d_") and a != "d_idx"}))
        for who, touched in users:
            for arr, prop in sorted(touched):
                pa = self.arrays[arr]
                if not pa.has(prop):
                    close = difflib.get_close_matches(prop, sorted(set(pa.props) | set(pa.constants)), n=1)
                    hint = f"; did you mean '{close[0]}'?" if close else ""
                    raise SceneError(f"{who} uses property '{prop}' of array '{arr}', which has no such "
                                     f"property{hint}")

    def _check_race(self, gp):
        for dest, eps in gp.dests.items():
            written = set()
            for ep in eps:
                written |= {p for _, p in ep.writes()}
            for src, lps in gp.sources(dest).items():
                if src != dest:
                    continue
                for ep in lps:
                    for m in PAIR_METHODS:
                        sp = ep.methods.get(m)
                        if sp is None:
                            continue
                        bad = sorted(sp.props("s_") & written)
                        if bad:
                            raise SceneError(
                                f"{ep.name}.{m} reads s_{bad[0]} of '{src}' while this group writes "
                                f"'{bad[0]}' of '{dest}': split them into two Groups")

    def _allocation(self):
        alloc = {name: set(pa.data) for name, pa in self.arrays.items()}
        for arr, prop in self.needed:
            alloc[arr].add(prop)
        for ep in self.eqplans:
            if ep.kept:
                for arr, prop in ep.touched():
                    alloc[arr].add(prop)
        for st in self.steppers:
            for sp in st.stages.values():
                alloc[st.array] |= {a[2:] for a in sp.args if a.startswith("d_") and a != "d_idx"}
        for name, pa in self.arrays.items():
            alloc[name] = {p for p in alloc[name] if p not in pa.constants}
        return alloc

    # ------------------------------------------------------------ output
    def dtype(self, arr, prop):
        pa = self.arrays[arr]
        if prop in pa.constants:
            return "double"
        return pa.props[prop].dtype

    def describe(self):
        """Human-readable plan (``--show-plan``)."""
        lines = [f"sphgen plan: dim={self.dim}, kernel={type(self.kernel).__name__}, "
                 f"periodic={tuple(self.domain.periodic) if self.domain else (False,) * 3}"]
        for si, row in enumerate(self.group_plans):
            lines.append(f"stage evaluation {si}:")
            for gp in row:
                g = gp.group
                flags = [f for f, on in (("iterate", g.iterate), ("update_nnps", g.update_nnps),
                                         ("reference", g.reference), ("condition", g.condition)) if on]
                lines.append(f"  group {gp.index}{' [' + ', '.join(flags) + ']' if flags else ''}:")
                for dest, eps in gp.dests.items():
                    srcs = gp.sources(dest)
                    lines.append(f"    dest {dest}: one pass, neighbour sources: "
                                 f"{', '.join(srcs) if srcs else 'none'}")
                    for ep in eps:
                        lines.append(f"      keep  {ep.name}: {', '.join(ep.methods)}")
                for ep in gp.eqplans:
                    if not ep.kept:
                        lines.append(f"      prune {ep.name}: {ep.reason}")
        lines.append("integrator stages:")
        for st in self.steppers:
            lines.append(f"  {st.array}: {type(st.stepper).__name__} {', '.join(st.stages)}")
        lines.append("properties allocated:")
        for name, props in self.allocation.items():
            declared = set(self.arrays[name].props) - props
            lines.append(f"  {name} ({self.arrays[name].n} particles): {', '.join(sorted(props))}")
            if declared:
                lines.append(f"    declared, not allocated: {', '.join(sorted(declared))}")
        return "\n".join(lines)


def normalise_stages(equations):
    """Equations, Groups, or a list of per-stage lists -> list of lists of Groups."""
    if not equations:
        return [[]]
    if all(isinstance(e, Equation) for e in equations):
        return [[Group(list(equations))]]
    if all(isinstance(e, Group) for e in equations):
        return [list(equations)]
    if all(isinstance(e, (list, tuple)) for e in equations):
        return [normalise_stages(list(s))[0] for s in equations]
    raise SceneError("equations must be a list of Equations, of Groups, or a list of per-stage lists")
