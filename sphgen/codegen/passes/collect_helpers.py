"""Pass: the ``@helper`` functions the module's functions call, each specialised once."""
import ast
import inspect
import types

from ..translate import TranslationError, specialise

COMPYLE_BUILTINS = ("declare", "cast", "address", "atomic_inc", "atomic_dec")


def _callees(spec, func):
    """Plain Python functions a specialised body calls, found through ``func``'s namespace."""
    names = dict(getattr(func, "__globals__", {}))
    try:
        names.update(inspect.getclosurevars(func).nonlocals)
    except (TypeError, ValueError):
        pass
    for node in ast.walk(spec.fdef):
        if isinstance(node, ast.Call) and isinstance(node.func, ast.Name):
            f = names.get(node.func.id)
            if isinstance(f, types.FunctionType) and node.func.id not in COMPYLE_BUILTINS:
                yield node.func.id, f


def helpers_called(spec, func, seen):
    """Specialised helpers called by ``spec``, recursively, callees before callers."""
    out = []
    for name, f in _callees(spec, func):
        if not getattr(f, "__sphgen_helper__", False):
            raise TranslationError(f"{name}() is a Python function, not a sphgen helper: decorate it "
                                   "with @sphgen.equation.helper so it can be translated")
        if f.__name__ not in seen:
            seen.add(f.__name__)
            hs = specialise(f, f.__name__, {}, None, keep_defaults=True)
            out += helpers_called(hs, f, seen) + [hs]
    return out


def collect_helpers(plan):
    """Every helper the module's functions call, in order of first use."""
    seen = set()
    plan.helpers = []
    for fp in plan.functions:
        try:
            plan.helpers += helpers_called(fp.spec, getattr(type(fp.owner), fp.spec.method), seen)
        except TranslationError as e:
            raise TranslationError(f"{fp.origin}: {e}") from None
    return [f"helpers: {', '.join(h.fdef.name for h in plan.helpers)}"] if plan.helpers else []
