"""Equation, Group and helper functions: the user-facing physics API.

An equation is a small class whose methods are restricted Python::

    class SummationDensity(Equation):
        def initialize(self, d_idx, d_rho):
            d_rho[d_idx] = 0.0

        def loop(self, d_idx, d_rho, s_idx, s_m, WIJ):
            d_rho[d_idx] += s_m[s_idx] * WIJ

Properties are named by argument: ``d_rho`` is property ``rho`` of the destination,
``s_m`` of the source.  Pair symbols (``XIJ, RIJ, WIJ, DWIJ``, ...: the table in
:mod:`sphgen.codegen.pair_symbols`) are computed only when a ``loop`` asks for them.
Pair loops write only ``d_*[d_idx]`` (gather-only), which keeps the OpenMP loops
race-free.
"""
import ast
import difflib
import inspect
import math
import textwrap

from compyle.api import declare  # noqa: F401  (re-exported: ``from sphgen.equation import declare``)

from .errors import SphgenError

PAIR_METHODS = ("loop", "loop_all")
COMPILED_METHODS = ("initialize", "loop", "loop_all", "post_loop")


class ParameterError(SphgenError, ValueError):
    """An equation parameter is negative, non-finite or unknown."""


def helper(func):
    """Mark a plain restricted-Python function as callable from equations.

    Its arguments are typed by their defaults (``x=1.0`` is a double, ``a=[0.0]`` a
    ``double*``); the generator translates it once into a ``noexcept nogil`` function.
    """
    func.__sphgen_helper__ = True
    return func


_KNOWN = {}


def known_parameters(cls):
    """Parameter names an equation class uses: ``self.<name>`` in its methods' source.

    Empty when a class's source cannot be read (e.g. typed at a prompt): then any
    keyword is accepted.
    """
    if cls not in _KNOWN:
        names = set()
        for klass in cls.__mro__:
            if klass in (Equation, object):
                continue
            try:
                tree = ast.parse(textwrap.dedent(inspect.getsource(klass)))
            except (OSError, TypeError, SyntaxError):
                _KNOWN[cls] = set()
                return _KNOWN[cls]
            names |= {n.attr for n in ast.walk(tree) if isinstance(n, ast.Attribute)
                      and isinstance(n.value, ast.Name) and n.value.id == "self"}
            names |= set(getattr(klass, "switches", ())) | set(getattr(klass, "positive", ()))
            names |= set(getattr(klass, "nonnegative", ()))
        _KNOWN[cls] = names
    return _KNOWN[cls]


class Equation:
    """Base class of all equations: ``Equation(dest, sources, **params)``.

    Class attributes a subclass may set:

    * ``switches``: parameters folded into the generated code as constants, so
      ``if self.alpha != 0.0:`` blocks vanish from the code when ``alpha`` is 0.
    * ``positive`` / ``nonnegative``: parameters checked before compiling.
    * ``keep``: never prune this equation (it has effects outside properties).
    """

    switches = ()
    positive = ()
    nonnegative = ()
    keep = False

    def __init__(self, dest, sources=None, **params):
        self.dest = dest
        if isinstance(sources, str):
            sources = [sources]
        self.sources = list(sources) if sources else []
        known = known_parameters(type(self))
        unknown = sorted(set(params) - known) if known else []
        if unknown:
            close = difflib.get_close_matches(unknown[0], sorted(known), n=1)
            hint = f"; did you mean '{close[0]}'?" if close else ""
            raise ParameterError(f"{type(self).__name__}(dest='{dest}'): unknown parameter "
                                 f"'{unknown[0]}'{hint}")
        for k, v in params.items():
            setattr(self, k, v)
        self.check_parameters()

    # ------------------------------------------------------------------ params
    def parameters(self):
        """Numeric parameters of this instance (everything but dest/sources/private)."""
        return {k: v for k, v in vars(self).items()
                if k not in ("dest", "sources") and not k.startswith("_")}

    def check_parameters(self):
        """Clear error for a non-finite, negative or missing parameter."""
        name = type(self).__name__
        params = self.parameters()
        for k in tuple(self.switches) + tuple(self.positive) + tuple(self.nonnegative):
            if k not in params:
                raise ParameterError(f"{name}(dest='{self.dest}'): parameter '{k}' is not set")
        for k, v in params.items():
            if isinstance(v, bool) or not isinstance(v, (int, float)):
                continue
            if not math.isfinite(v):
                raise ParameterError(f"{name}(dest='{self.dest}'): parameter {k}={v!r} is not finite")
        for k in self.positive:
            if not params[k] > 0:
                raise ParameterError(f"{name}(dest='{self.dest}'): parameter {k}={params[k]!r} must be > 0")
        for k in self.nonnegative:
            if not params[k] >= 0:
                raise ParameterError(f"{name}(dest='{self.dest}'): parameter {k}={params[k]!r} must be >= 0")

    def methods(self):
        """Names of the compiled methods this class defines."""
        return [m for m in COMPILED_METHODS if callable(getattr(type(self), m, None))]

    def __repr__(self):
        return f"{type(self).__name__}(dest={self.dest!r}, sources={self.sources!r})"


class Group:
    """Equations evaluated together; all share one neighbour pass per (dest, source).

    iterate/max_iterations/min_iterations: repeat until every equation's
    ``converged()`` returns > 0 (the count is in ``Group.iterations``).
    condition: ``condition(t, dt) -> bool``; the group is skipped when False.
    update_nnps: rebuild neighbour lists after this group (positions changed).
    reference: use the neighbour lists frozen at t = 0 (Total Lagrangian) and compute
    pair geometry from the reference positions ``x0, y0, z0``.
    real: accepted for PySPH compatibility; sphgen has no ghost copies, so every
    particle is real.
    """

    def __init__(self, equations, iterate=False, max_iterations=1, min_iterations=0,
                 condition=None, update_nnps=False, reference=False, real=True, name=None):
        if not equations:
            raise ValueError("a Group needs at least one equation")
        for eq in equations:
            if not isinstance(eq, Equation):
                raise TypeError(f"Group got {eq!r}, which is not an Equation")
        if iterate and max_iterations < 1:
            raise ValueError("an iterated Group needs max_iterations >= 1")
        if min_iterations > max_iterations:
            raise ValueError("min_iterations must not exceed max_iterations")
        if iterate and not any(callable(getattr(e, "converged", None)) for e in equations):
            raise ValueError("an iterated Group needs an equation with converged()")
        self.equations = list(equations)
        self.iterate = iterate
        self.max_iterations = max_iterations if iterate else 1
        self.min_iterations = min_iterations
        self.condition = condition
        self.update_nnps = update_nnps
        self.reference = reference
        self.real = real
        self.name = name
        self.iterations = 0

    def __repr__(self):
        return f"Group({self.equations!r})"
