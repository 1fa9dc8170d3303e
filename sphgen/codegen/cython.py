"""From a specialised function to Cython: marked source, then compyle's CythonGenerator.

Every statement of the source handed to compyle carries a ``# @src file:line`` comment,
so a compile error can be traced back to the equation and line that produced it.
"""
import ast
import linecache

from compyle.config import use_config
from compyle.cython_generator import CythonGenerator
from compyle.types import KnownType

from .translate import TranslationError

_UNSUPPORTED = (ast.With, ast.AsyncWith, ast.Try, ast.FunctionDef, ast.AsyncFunctionDef,
                ast.ClassDef, ast.AsyncFor, ast.Match)


def marked_source(fdef, filename):
    """Source of a function with a ``# @src file:line`` comment before every statement."""
    lines = [f"def {fdef.name}({ast.unparse(fdef.args)}):"] + _block(fdef.body, 1, filename)
    return "\n".join(lines) + "\n"


def _block(stmts, depth, filename):
    pad = "    " * depth
    lines = []
    for st in stmts:
        if hasattr(st, "lineno"):
            lines.append(f"{pad}# @src {filename}:{st.lineno}")
        lines += _statement(st, depth, filename)
    return lines


def _statement(st, depth, filename):
    pad = "    " * depth
    if isinstance(st, ast.If):
        return _if_chain(st, depth, filename)
    if isinstance(st, (ast.For, ast.While)):
        if isinstance(st, ast.For):
            target = st.target.elts if isinstance(st.target, ast.Tuple) else [st.target]
            head = f"for {', '.join(ast.unparse(t) for t in target)} in {ast.unparse(st.iter)}:"
        else:
            head = f"while {ast.unparse(st.test)}:"
        lines = [pad + head] + _block(st.body, depth + 1, filename)
        if st.orelse:
            lines += [pad + "else:"] + _block(st.orelse, depth + 1, filename)
        return lines
    if isinstance(st, _UNSUPPORTED):
        raise TranslationError(f"line {st.lineno}: '{type(st).__name__}' statements cannot be translated")
    return [pad + ast.unparse(st)]


def _if_chain(node, depth, filename):
    """``if``/``elif``/``else``: an ``else`` holding only an ``if`` is written as ``elif``."""
    pad = "    " * depth
    lines = [f"{pad}if {ast.unparse(node.test)}:"] + _block(node.body, depth + 1, filename)
    while len(node.orelse) == 1 and isinstance(node.orelse[0], ast.If):
        node = node.orelse[0]
        lines += [f"{pad}elif {ast.unparse(node.test)}:"] + _block(node.body, depth + 1, filename)
    if node.orelse:
        lines += [pad + "else:"] + _block(node.orelse, depth + 1, filename)
    return lines


def to_cython(spec, arg_types=None):
    """Cython source of a specialised function, ``noexcept nogil``.

    ``arg_types`` maps every argument to its C type (the plan's signatures); without
    it (kernels, helpers) compyle types the arguments by their defaults.
    """
    fname = f"<sphgen:{spec.fdef.name}>"
    src = marked_source(spec.fdef, spec.filename)
    linecache.cache[fname] = (len(src), None, src.splitlines(True), fname)
    namespace = {}
    exec(compile(src, fname, "exec"), namespace)
    known = {a: KnownType(t) for a, t in (arg_types or {}).items()}
    with use_config(use_openmp=True):   # compyle then declares the function nogil
        gen = CythonGenerator(known_types=known)
    try:
        gen.parse(namespace[spec.fdef.name])
    except Exception as e:  # compyle raises a variety of errors
        raise TranslationError(str(e)) from None
    return gen.get_code()
