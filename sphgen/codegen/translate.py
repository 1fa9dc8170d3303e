"""From a restricted-Python method to a specialised function (an ``ast.FunctionDef``).

1. ``specialise``: parse the method, fold ``self.<switch>`` into literals, turn other
   ``self.<param>`` into module globals, prune branches whose test became a constant,
   auto-declare integer ``range`` loop counters, drop arguments nobody uses.
2. ``_usage``: which ``d_*``/``s_*`` properties the specialised body reads and writes.
3. ``in_registers``: the register-accumulator form of a pair method.

Turning the result into Cython is :mod:`sphgen.codegen.cython`.
"""
import ast
import copy
import inspect
import textwrap
import types
from dataclasses import dataclass

from ..errors import SphgenError
from . import pair_symbols


class TranslationError(SphgenError):
    """A method uses Python the generator cannot translate."""


def _const_value(node):
    return node.value if isinstance(node, ast.Constant) else None


class _Specialiser(ast.NodeTransformer):
    """Fold switches, rename params, prune constant branches."""

    def __init__(self, constants, param_names, prefix, methods=(), dim=3, nonzero=()):
        self.dim = dim
        self.methods = set(methods)
        self.constants = constants
        self.nonzero = set(nonzero)
        self.param_names = param_names
        self.prefix = prefix
        self.globals_used = set()

    def visit_Attribute(self, node):
        self.generic_visit(node)
        if isinstance(node.value, ast.Name) and node.value.id == "self":
            if node.attr in self.constants:
                val = self.constants[node.attr]
                if isinstance(val, bool):
                    val = int(val)
                return ast.copy_location(ast.Constant(val), node)
            if node.attr in self.param_names:
                name = f"{self.prefix}_{node.attr}"
                self.globals_used.add(node.attr)
                return ast.copy_location(ast.Name(id=name, ctx=ast.Load()), node)
            if node.attr in self.methods:
                return ast.copy_location(ast.Name(id=f"{self.prefix}_{node.attr}", ctx=ast.Load()), node)
            raise TranslationError(f"self.{node.attr} is not a parameter of this object")
        return node

    def visit_Subscript(self, node):
        self.generic_visit(node)
        if isinstance(node.slice, ast.Constant) and isinstance(node.slice.value, float) and \
                node.slice.value.is_integer():      # an index folded through ``0 * x`` (0.0)
            node.slice = ast.copy_location(ast.Constant(int(node.slice.value)), node.slice)
        # vector pair symbols have zero components beyond the scene's dimension
        if isinstance(node.value, ast.Name) and pair_symbols.is_vector(node.value.id) and \
                isinstance(node.ctx, ast.Load) and isinstance(node.slice, ast.Constant) and \
                isinstance(node.slice.value, int) and node.slice.value >= self.dim:
            return ast.copy_location(ast.Constant(0.0), node)
        return node

    def visit_AugAssign(self, node):
        self.generic_visit(node)
        if isinstance(node.op, (ast.Add, ast.Sub)) and _const_value(node.value) == 0.0 \
                and isinstance(node.value, ast.Constant):
            return None
        return node

    def visit_UnaryOp(self, node):
        self.generic_visit(node)
        v = _const_value(node.operand)
        if v is not None and not isinstance(v, str):
            try:
                return ast.copy_location(ast.Constant(eval(compile(ast.Expression(node), "", "eval"))), node)
            except Exception:
                return node
        return node

    def visit_BinOp(self, node):
        self.generic_visit(node)
        zero = lambda n: isinstance(n, ast.Constant) and not isinstance(n.value, bool) and n.value == 0  # noqa: E731
        if isinstance(node.op, ast.Mult) and (zero(node.left) or zero(node.right)):
            return ast.copy_location(ast.Constant(0.0), node)
        if isinstance(node.op, (ast.Add, ast.Sub)) and zero(node.right):
            return node.left
        if isinstance(node.op, ast.Add) and zero(node.left):
            return node.right
        if _const_value(node.left) is not None and _const_value(node.right) is not None:
            try:
                return ast.copy_location(ast.Constant(eval(compile(ast.Expression(node), "", "eval"))), node)
            except Exception:
                return node
        return node

    def _nonzero_switch(self, node):
        return (isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name) and node.value.id == "self"
                and node.attr in self.nonzero)

    def visit_Compare(self, node):
        # ``self.k != 0`` of a non-zero switch k is True, ``self.k == 0`` False (k stays a
        # run-time parameter elsewhere)
        if len(node.ops) == 1 and isinstance(node.ops[0], (ast.Eq, ast.NotEq)):
            for a, b in ((node.left, node.comparators[0]), (node.comparators[0], node.left)):
                if self._nonzero_switch(a) and isinstance(b, ast.Constant) and \
                        not isinstance(b.value, bool) and b.value == 0:
                    return ast.copy_location(ast.Constant(isinstance(node.ops[0], ast.NotEq)), node)
        self.generic_visit(node)
        vals = [node.left] + list(node.comparators)
        if all(isinstance(v, ast.Constant) for v in vals):
            return ast.copy_location(ast.Constant(bool(eval(compile(ast.Expression(node), "", "eval")))), node)
        return node

    def visit_BoolOp(self, node):
        self.generic_visit(node)
        consts = [_const_value(v) for v in node.values]
        is_and = isinstance(node.op, ast.And)
        if any(isinstance(v, ast.Constant) and bool(v.value) != is_and for v in node.values):
            return ast.copy_location(ast.Constant(not is_and), node)
        rest = [v for v, c in zip(node.values, consts) if not isinstance(v, ast.Constant)]
        if not rest:
            return ast.copy_location(ast.Constant(is_and), node)
        if len(rest) == 1:
            return rest[0]
        node.values = rest
        return node

    def visit_If(self, node):
        self.generic_visit(node)
        if isinstance(node.test, ast.Constant):
            body = node.body if node.test.value else node.orelse
            return body or None
        if not node.body:
            node.body = [ast.Pass()]
        return node

    def visit_IfExp(self, node):
        self.generic_visit(node)
        if isinstance(node.test, ast.Constant):
            return node.body if node.test.value else node.orelse
        return node


class _DeadStores(ast.NodeTransformer):
    """Remove stores to properties nothing needs (``d_X[...] = ...`` for X in dead)."""

    def __init__(self, dead):
        self.dead = dead

    def _target(self, t):
        return isinstance(t, ast.Subscript) and isinstance(t.value, ast.Name) and t.value.id in self.dead

    def visit_Assign(self, node):
        return None if all(self._target(t) for t in node.targets) else node

    def visit_AugAssign(self, node):
        return None if self._target(node.target) else node

    def visit_If(self, node):
        self.generic_visit(node)
        if not node.body and not node.orelse:
            return None
        if not node.body:
            node.body = [ast.Pass()]
        return node

    def visit_For(self, node):
        self.generic_visit(node)
        return node if node.body else None


class _Unroll(ast.NodeTransformer):
    """``for i in range(n)`` with a constant ``n`` (after switch folding, e.g.
    ``range(self.dim)``) becomes ``n`` copies of its body with ``i`` a literal, when the
    copies stay small and ``i`` is not assigned, nor read after the loop, and there is no
    ``break``/``continue``/``else``.  The components of vector symbols past the dimension
    are then literal indices that fold to 0 (in 2D, ``XIJ[i] * DWIJ[j]`` over 3 x 3 keeps 4
    of its 9 terms); gcc unrolls such loops too, but may not fold ``0.0 * x``."""

    MAX_STATEMENTS = 96      # statements a loop may become

    def __init__(self, fdef):
        # names read outside every loop that binds them: their loops are kept
        inside = {id(x) for f in ast.walk(fdef) if isinstance(f, ast.For) and isinstance(f.target, ast.Name)
                  for st in f.body for x in ast.walk(st) if isinstance(x, ast.Name) and x.id == f.target.id}
        self.read_outside = {n.id for n in ast.walk(fdef) if isinstance(n, ast.Name)
                             and isinstance(n.ctx, ast.Load) and id(n) not in inside}

    def visit_For(self, node):
        self.generic_visit(node)
        if not (isinstance(node.target, ast.Name) and isinstance(node.iter, ast.Call)
                and getattr(node.iter.func, "id", "") == "range" and not node.orelse
                and len(node.iter.args) == 1 and isinstance(node.iter.args[0], ast.Constant)
                and isinstance(node.iter.args[0].value, int)):
            return node
        n, name = node.iter.args[0].value, node.target.id
        inner = [x for st in node.body for x in ast.walk(st)]
        if any(isinstance(x, (ast.Break, ast.Continue, ast.For, ast.While)) for x in inner) or \
                any(isinstance(x, ast.Name) and x.id == name and not isinstance(x.ctx, ast.Load) for x in inner):
            return node
        if name in self.read_outside or n * sum(isinstance(x, ast.stmt) for x in inner) > self.MAX_STATEMENTS:
            return node            # read after the loop, or too large
        out = []
        for k in range(n):
            for st in node.body:
                copy_ = copy.deepcopy(st)
                for x in ast.walk(copy_):
                    for field, value in ast.iter_fields(x):
                        if isinstance(value, ast.Name) and value.id == name:
                            setattr(x, field, ast.copy_location(ast.Constant(k), value))
                        elif isinstance(value, list):
                            value[:] = [ast.copy_location(ast.Constant(k), v) if isinstance(v, ast.Name)
                                        and v.id == name else v for v in value]
                out.append(copy_)
        return out or None


# what a comparison may hold to be evaluated eagerly: no load, call or division (an integer
# division by zero would trap where the short circuit guarded it)
_PLAIN = (ast.Name, ast.Constant, ast.BinOp, ast.UnaryOp, ast.Compare, ast.Load,
          ast.Add, ast.Sub, ast.Mult, ast.unaryop, ast.cmpop)


class _EagerTests(ast.NodeTransformer):
    """``a < b and c > d`` on plain values (names, constants, +, - and *: nothing that
    loads from memory, calls or divides) becomes ``(a < b) & (c > d)`` (``or``: ``|``).  Cython
    writes ``and`` as short-circuit jumps, which gcc does not if-convert, so a pair loop
    with such a test did not vectorise; evaluating both sides of a plain comparison is
    safe and costs a few instructions."""

    @classmethod
    def _plain(cls, node):
        if isinstance(node, ast.BinOp) and isinstance(node.op, (ast.BitAnd, ast.BitOr)):
            return cls._plain(node.left) and cls._plain(node.right)     # an inner test made eager
        return isinstance(node, ast.Compare) and len(node.ops) == 1 and \
            all(isinstance(n, _PLAIN) for n in ast.walk(node))

    def visit_BoolOp(self, node):
        self.generic_visit(node)
        if not all(self._plain(v) for v in node.values):
            return node
        op = ast.BitAnd() if isinstance(node.op, ast.And) else ast.BitOr()
        out = node.values[0]
        for v in node.values[1:]:
            out = ast.BinOp(out, op, v)
        return ast.copy_location(out, node)


def _remove_dead_locals(fdef):
    """Drop assignments to local names that nothing reads (after folding), repeatedly."""
    while True:
        loads = {n.id for n in ast.walk(fdef) if isinstance(n, ast.Name) and isinstance(n.ctx, ast.Load)}
        dead = []
        for node in ast.walk(fdef):
            for field in ("body", "orelse"):
                body = getattr(node, field, None)
                if not isinstance(body, list):
                    continue
                for st in body:
                    if isinstance(st, ast.Assign) and all(isinstance(t, ast.Name) and t.id not in loads
                                                          for t in st.targets) and \
                            not (isinstance(st.value, ast.Call) and getattr(st.value.func, "id", "") == "declare"):
                        dead.append((body, st))
        if not dead:
            return
        for body, st in dead:
            body.remove(st)
        for node in ast.walk(fdef):
            for field in ("body", "orelse"):
                body = getattr(node, field, None)
                if isinstance(body, list) and field == "body" and not body and node is not fdef:
                    body.append(ast.Pass())


def _names(tree):
    return {n.id for n in ast.walk(tree) if isinstance(n, ast.Name)}


def _is_empty(body):
    return all(isinstance(s, (ast.Pass,)) or (isinstance(s, ast.Expr) and isinstance(s.value, ast.Constant))
               for s in body)


@dataclass(eq=False)
class Specialised:
    """A method after specialisation: its AST, arguments, and property usage."""

    owner: object
    method: str
    fdef: ast.FunctionDef
    params_used: set           # parameters read as module globals
    filename: str
    firstline: int

    def __post_init__(self):
        self.args = [a.arg for a in self.fdef.args.args]
        self.reads, self.writes = _usage(self.fdef)

    @property
    def empty(self):
        return _is_empty(self.fdef.body)

    def props(self, prefix):
        """Property names with the given prefix ('d_' or 's_') that the body touches."""
        return {a[2:] for a in self.args if a.startswith(prefix) and a not in ("d_idx", "s_idx")}

    @property
    def pair_symbols(self):
        """The pair symbols among its arguments."""
        return [a for a in self.args if a in pair_symbols.SYMBOLS]


def _is_d_idx(node):
    return isinstance(node, ast.Name) and node.id == "d_idx"


def _terms(node):
    """The terms of a sum ``a + b + ...`` (nested additions flattened)."""
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):
        return _terms(node.left) + _terms(node.right)
    return [node]


def _row_offset(index, stride):
    """``e`` if ``index`` is ``stride * d_idx + e`` (the terms of the sum in any order;
    ``stride * d_idx`` alone gives 0, and a stride of 1 accepts ``d_idx`` only); None
    otherwise."""
    if stride == 1:
        return ast.Constant(0) if _is_d_idx(index) else None

    def scaled(n):
        return isinstance(n, ast.BinOp) and isinstance(n.op, ast.Mult) and any(
            _is_d_idx(a) and isinstance(b, ast.Constant) and b.value == stride
            for a, b in ((n.left, n.right), (n.right, n.left)))
    terms = _terms(index)
    rows = [t for t in terms if scaled(t)]
    rest = [t for t in terms if not scaled(t)]
    if len(rows) != 1 or any(_is_d_idx(n) for t in rest for n in ast.walk(t)):
        return None
    offset = rest[0] if rest else ast.Constant(0)
    for t in rest[1:]:
        offset = ast.BinOp(offset, ast.Add(), t)
    return offset


def indexed_by_row(spec, strides):
    """d_* arguments every access of which is ``d_X[k * d_idx + e]`` with k the stride of X
    (``strides``: argument -> stride; ``d_X[d_idx]`` when it is 1): the row of the
    destination particle, nothing else."""
    ok = {a for a in spec.args if a.startswith("d_") and a != "d_idx"}
    for node in ast.walk(spec.fdef):
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and node.value.id in ok:
            if _row_offset(node.slice, strides.get(node.value.id, 1)) is None:
                ok.discard(node.value.id)
    # a bare use (passing the pointer on) also disqualifies
    subs = {id(n.value) for n in ast.walk(spec.fdef) if isinstance(n, ast.Subscript)}
    for node in ast.walk(spec.fdef):
        if isinstance(node, ast.Name) and node.id in ok and id(node) not in subs:
            ok.discard(node.id)
    return ok


def sums_only(spec, names):
    """The names among ``names`` that ``spec`` only ever adds to: every access is the
    target of ``d_X[...] += ...`` or ``-= ...`` (never read, never assigned)."""
    ok = set(names)
    targets = set()
    for node in ast.walk(spec.fdef):
        if isinstance(node, ast.AugAssign) and isinstance(node.op, (ast.Add, ast.Sub)) \
                and isinstance(node.target, ast.Subscript):
            targets.add(id(node.target))
    for node in ast.walk(spec.fdef):
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and \
                node.value.id in ok and id(node) not in targets:
            ok.discard(node.value.id)
    return ok


class _RegisterForm(ast.NodeTransformer):
    """Index the named arguments by their offset in the destination's row instead."""

    def __init__(self, strides):
        self.strides = strides

    def visit_Subscript(self, node):
        self.generic_visit(node)
        if isinstance(node.value, ast.Name) and node.value.id in self.strides:
            node.slice = ast.copy_location(_row_offset(node.slice, self.strides[node.value.id]), node.slice)
        return node


def in_registers(spec, strides):
    """A copy of ``spec`` where ``d_X[k * d_idx + e]`` reads/writes ``d_X[e]`` for X in
    ``strides`` (argument -> stride k; ``d_X[d_idx]`` becomes ``d_X[0]``).

    The neighbour pass then hands these equations the address of a local accumulator,
    so ``d_au[d_idx] += ...`` over all neighbours stays in a register instead of a
    load-add-store through memory per pair.
    """
    new = copy.copy(spec)
    new.fdef = ast.fix_missing_locations(_RegisterForm(strides).visit(copy.deepcopy(spec.fdef)))
    return new


def _usage(fdef):
    """(reads, writes): sets of argument names read / written through subscripts."""
    reads, writes, stored = set(), set(), set()
    for node in ast.walk(fdef):
        if isinstance(node, ast.Subscript) and isinstance(node.value, ast.Name) and \
                isinstance(node.ctx, ast.Store):
            writes.add(node.value.id)
            stored.add(id(node.value))
    for node in ast.walk(fdef):
        if isinstance(node, ast.Name) and isinstance(node.ctx, ast.Load) and id(node) not in stored:
            reads.add(node.id)
    return reads, writes


def method_source(func):
    """(dedented source, filename, first line) of a function or method."""
    try:
        lines, first = inspect.getsourcelines(func)
    except (OSError, TypeError) as e:
        raise TranslationError(f"cannot read the source of {func.__qualname__}: {e}") from None
    return textwrap.dedent("".join(lines)), inspect.getsourcefile(func) or "<unknown>", first


def specialise(owner, method, constants, prefix, keep_defaults=False, dim=3, dead=(), nonzero=()):
    """Specialise ``owner.method`` into a function named ``<prefix>_<method>``.

    ``constants`` are folded; other numeric attributes become globals ``<prefix>_<name>``;
    a comparison of an attribute in ``nonzero`` with 0 is folded (it is known not to be 0).
    """
    func_name = method if prefix is None else f"{prefix}_{method}"
    func = getattr(type(owner), method) if not isinstance(owner, types.FunctionType) else owner
    src, filename, first = method_source(func)
    tree = ast.parse(src)
    fdef = tree.body[0]
    if not isinstance(fdef, ast.FunctionDef):
        raise TranslationError(f"{func.__qualname__} is not a plain function")
    ast.increment_lineno(tree, first - 1)
    fdef.decorator_list = []
    if fdef.body and isinstance(fdef.body[0], ast.Expr) and isinstance(fdef.body[0].value, ast.Constant):
        fdef.body = fdef.body[1:] or [ast.Pass()]
    params = {} if isinstance(owner, types.FunctionType) else {
        k: v for k, v in vars(owner).items() if not k.startswith("_")}
    if fdef.args.args and fdef.args.args[0].arg == "self":
        fdef.args.args = fdef.args.args[1:]
        fdef.args.defaults = fdef.args.defaults[-len(fdef.args.args):] if fdef.args.args else []
    numeric = {k for k, v in params.items() if isinstance(v, (int, float)) and k not in constants}
    methods = [m for m in dir(type(owner)) if not m.startswith("_") and callable(getattr(type(owner), m))]
    sp = _Specialiser(constants, numeric, prefix, methods, dim, nonzero)
    fdef = sp.visit(fdef)
    fdef = sp.visit(_Unroll(fdef).visit(fdef))     # then fold what the literal indices made constant
    if dead:
        fdef = _DeadStores(set(dead)).visit(fdef)
        fdef = sp.visit(fdef)
    if not fdef.body:
        fdef.body = [ast.Pass()]
    _remove_dead_locals(fdef)
    fdef = _EagerTests().visit(fdef)
    _declare_loop_counters(fdef)
    used = _names(ast.Module(body=fdef.body, type_ignores=[]))
    keep = [a for a in fdef.args.args if a.arg in used]
    if not keep_defaults:
        fdef.args.defaults = []
        fdef.args.args = keep
    fdef.name = func_name
    ast.fix_missing_locations(fdef)
    return Specialised(owner, method, fdef, sp.globals_used, filename, first)


def _declare_loop_counters(fdef):
    """Declare ``for i in range(...)`` counters as int unless the user did."""
    declared = set()
    for node in ast.walk(fdef):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Call) and \
                isinstance(node.value.func, ast.Name) and node.value.func.id == "declare":
            for t in node.targets:
                declared |= _names(t)
    counters = []
    for node in ast.walk(fdef):
        if isinstance(node, ast.For) and isinstance(node.target, ast.Name) and \
                isinstance(node.iter, ast.Call) and getattr(node.iter.func, "id", "") == "range":
            if node.target.id not in declared and node.target.id not in counters:
                counters.append(node.target.id)
    decls = [ast.parse(f"{c} = declare('int')").body[0] for c in counters]
    for d in decls:
        ast.copy_location(d, fdef)
    fdef.body = decls + fdef.body
