"""The plan: what one scene computes, as plain data that the passes fill in.

:func:`new_plan` collects the scene (arrays, equation sets, steppers, kernel); the passes
of :mod:`sphgen.codegen.passes` then specialise, check, prune, fuse, allocate and lower
it.  The plan is the generator's single source of truth: the renderer emits exactly
what it keeps, the Python evaluator runs exactly what it keeps, and ``--show-plan``
prints it.
"""
import ast
import inspect
import textwrap
from dataclasses import dataclass, field

from ..equation import Equation, Group
from ..errors import SphgenError
from . import pair_symbols
from .describe import describe
from .pair_symbols import PairGeometry


class SceneError(SphgenError, ValueError):
    """A scene is inconsistent: missing property, bad array name, race, ..."""


def is_property(arg, prefix=("d_", "s_")):
    """True for ``d_X`` / ``s_X`` property arguments (not ``d_idx`` / ``s_idx``)."""
    return arg.startswith(prefix) and arg not in ("d_idx", "s_idx")


def reduce_reads(eq):
    """Properties ``reduce(self, dst, t, dt)`` reads as ``dst.<name>`` (found in its source)."""
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


@dataclass(eq=False)
class EqPlan:
    """One equation instance: its specialised methods and whether it is kept."""

    eq: Equation
    index: int
    dim: int = 3
    reference: bool = False
    methods: dict = field(default_factory=dict)     # method name -> Specialised
    kept: bool = True
    reason: str = ""                                 # why it was pruned
    dead_stores: set = field(default_factory=set)    # "d_X" stores removed as dead

    def __post_init__(self):
        self.python_hooks = [m for m in ("reduce", "converged") if callable(getattr(self.eq, m, None))]
        self.python_reads = reduce_reads(self.eq) if "reduce" in self.python_hooks else set()

    @property
    def prefix(self):
        return f"{type(self.eq).__name__}_{self.index}"

    @property
    def name(self):
        eq = self.eq
        return f"{type(eq).__name__}[{eq.dest}{'<-' + ','.join(eq.sources) if eq.sources else ''}]"

    @property
    def has_work(self):
        """Something to run: a compiled method left after specialisation, or a Python hook."""
        return bool(self.methods or self.python_hooks)

    def _arrays(self):
        return [self.eq.dest] + self.eq.sources

    def implied(self):
        """Properties the requested pair symbols read, on dest and sources."""
        syms = {a for sp in self.methods.values() for a in sp.pair_symbols}
        props = pair_symbols.properties(syms, PairGeometry(self.dim, reference=self.reference))
        return {(a, p) for a in self._arrays() for p in props}

    def _named(self, d_args):
        out = self.implied()
        for sp in self.methods.values():
            out |= {(self.eq.dest, a[2:]) for a in sp.args if a in d_args(sp)}
            out |= {(s, a[2:]) for a in sp.args if is_property(a, "s_") for s in self.eq.sources}
        return out

    def reads(self):
        """{(array, prop)} read by the kept methods."""
        return self._named(lambda sp: {a for a in sp.reads if is_property(a, "d_")})

    def writes(self):
        return {(self.eq.dest, a[2:]) for sp in self.methods.values() for a in sp.writes
                if a.startswith("d_")}

    def touched(self):
        """{(array, prop)} any kept method names."""
        return self._named(lambda sp: {a for a in sp.args if is_property(a, "d_")})


@dataclass(eq=False)
class SourceLoop:
    """The loop over one source's neighbours inside a neighbour pass."""

    source: str
    equations: list                  # EqPlans with a pair method over this source
    symbols: tuple = ()              # pair symbols computed per pair, in table order

    def calls(self, method):
        return [ep for ep in self.equations if method in ep.methods]


@dataclass(eq=False)
class NeighbourPass:
    """One parallel loop over a destination: every kept equation of a group for that dest."""

    label: str                       # "g<group index>_<dest>"
    dest: str
    reference: bool
    equations: list                  # the group's kept EqPlans with this destination
    sources: list = field(default_factory=list)      # SourceLoops, in order of first use
    registers: tuple = ()            # destination doubles accumulated in locals
    sums: tuple = ()                 # registers only added to: summed per pair first
    pair_specs: dict = field(default_factory=dict)   # (eq index, method) -> register form

    def calls(self, method):
        return [ep for ep in self.equations if method in ep.methods]

    def spec(self, ep, method):
        """The version of a method this pass calls (its register form, if any)."""
        return self.pair_specs.get((ep.index, method), ep.methods[method])

    @property
    def symbols(self):
        """Every pair symbol some source loop computes, in table order."""
        used = {s for loop in self.sources for s in loop.symbols}
        return tuple(s for s in pair_symbols.SYMBOLS if s in used)


@dataclass(eq=False)
class GroupPlan:
    """A group of kept equations: per destination, one fused neighbour pass."""

    group: Group
    index: int
    eqplans: list
    passes: dict = field(default_factory=dict)   # dest -> NeighbourPass

    @property
    def dests(self):
        """{dest: [kept EqPlans]}, in order of first appearance."""
        return {dest: p.equations for dest, p in self.passes.items()}

    def sources(self, dest):
        """Ordered sources of a destination with the equations that loop over each."""
        return {loop.source: loop.equations for loop in self.passes[dest].sources}


@dataclass(eq=False)
class StepperPlan:
    """One array's integrator stepper and its specialised stage methods."""

    array: str
    stepper: object
    index: int
    stages: dict = field(default_factory=dict)   # stage name -> Specialised

    @property
    def prefix(self):
        return f"{type(self.stepper).__name__}_{self.index}"

    @property
    def name(self):
        return f"{type(self.stepper).__name__}[{self.array}]"


@dataclass(eq=False)
class FunctionPlan:
    """A function the compiled module defines: a method of an equation or stepper."""

    owner: object
    spec: object                     # Specialised
    dest: str
    sources: list
    arg_types: dict = field(default_factory=dict)   # argument -> C type

    @property
    def origin(self):
        return f"{type(self.owner).__name__}.{self.spec.method}"


@dataclass(eq=False)
class Plan:
    """What a scene computes; the passes fill in everything after ``steppers``."""

    arrays: dict                     # name -> ParticleArray
    evaluations: list                # per equation set: [(Group, [EqPlan])]
    eqplans: list                    # every EqPlan once, in order of first appearance
    steppers: list                   # StepperPlans, by array name
    kernel: object
    dim: int
    domain: object = None
    outputs: dict = field(default_factory=dict)
    evaluated: object = None                          # set indices the integrator runs (None: all)
    dropped: set = field(default_factory=set)         # sets it never runs (nothing generated)
    needed: set = field(default_factory=set)          # (array, prop) something needs
    group_plans: list = field(default_factory=list)   # per evaluation: [GroupPlan]
    allocation: dict = field(default_factory=dict)    # array -> {props given memory}
    kernel_functions: list = field(default_factory=list)
    functions: list = field(default_factory=list)     # FunctionPlans, in emission order
    helpers: list = field(default_factory=list)       # Specialised helpers, callees first
    parameters: dict = field(default_factory=dict)    # module global -> (owner, attribute)
    switches: list = field(default_factory=list)      # (owner, {switch: what the code assumes})
    log: list = field(default_factory=list)           # (pass name, [notes])

    def dtype(self, arr, prop):
        """The element type of a property: 'double' or 'int' (constants are doubles)."""
        pa = self.arrays[arr]
        return "double" if prop in pa.constants else pa.props[prop].dtype

    def neighbour_passes(self):
        """Every neighbour pass once, in the order the evaluations first run them (a group
        shared by several sets is one group plan)."""
        gps = dict.fromkeys(gp for row in self.group_plans for gp in row)
        return [p for gp in gps for p in gp.passes.values()]

    def neighbour_lists(self):
        """(dest, source, reference) of every neighbour list a pass walks, in order."""
        out = [(p.dest, loop.source, p.reference) for p in self.neighbour_passes() for loop in p.sources]
        return list(dict.fromkeys(out))

    def describe(self):
        """Human-readable plan (``--show-plan``)."""
        return describe(self)


def normalise_evaluations(equations):
    """Equations, Groups, or a list of per-evaluation lists -> list of lists of Groups."""
    if not equations:
        return [[]]
    if all(isinstance(e, Equation) for e in equations):
        return [[Group(list(equations))]]
    if all(isinstance(e, Group) for e in equations):
        return [list(equations)]
    if all(isinstance(e, (list, tuple)) for e in equations):
        return [normalise_evaluations(list(s))[0] for s in equations]
    raise SceneError("equations must be a list of Equations, of Groups, or a list of per-evaluation lists")


def new_plan(arrays, equations, steppers, kernel, dim, domain=None, outputs=None, evaluated=None):
    """The plan of a scene before any pass: its groups, equations and steppers collected;
    ``evaluated``: the equation sets the integrator runs (``None``: every one)."""
    by_name = {pa.name: pa for pa in arrays}
    if len(by_name) != len(arrays):
        raise SceneError("two particle arrays have the same name")
    eqplans = {}
    evaluations = []
    for groups in normalise_evaluations(equations):
        row = []
        for g in groups:
            for eq in g.equations:
                if id(eq) not in eqplans:
                    eqplans[id(eq)] = EqPlan(eq, len(eqplans), dim)
                eqplans[id(eq)].reference |= g.reference
            row.append((g, [eqplans[id(eq)] for eq in g.equations]))
        evaluations.append(row)
    stepper_plans = [StepperPlan(a, s, i) for i, (a, s) in enumerate(sorted((steppers or {}).items()))]
    return Plan(by_name, evaluations, list(eqplans.values()), stepper_plans, kernel, dim, domain,
                dict(outputs or {}), None if evaluated is None else set(evaluated))
