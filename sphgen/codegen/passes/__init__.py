"""The plan as a sequence of small named passes over a :class:`~sphgen.codegen.plan.Plan`.

Each pass is a function of the plan: it checks it (raising ``SceneError`` or
``TranslationError`` with the equation, array and property named) or fills in a
decision, and returns notes on what it removed or decided, which ``--show-plan``
prints.  The checks and decisions up to ``allocate`` shape what the scene computes;
the passes after it lower the plan to what the compiled module needs (the Python
evaluator runs the same plan and ignores those).
"""
from ..plan import new_plan
from .allocate import allocate
from .assign_registers import assign_registers
from .check_arrays import check_arrays
from .check_exist import check_exist
from .check_properties import check_properties
from .check_races import check_races
from .choose_pair_symbols import choose_pair_symbols
from .collect_functions import collect_functions
from .collect_helpers import collect_helpers
from .drop_unevaluated import drop_unevaluated
from .fuse import fuse
from .prune import prune
from .specialise import specialise
from .type_arguments import type_arguments

PASSES = (drop_unevaluated, check_arrays, specialise, check_exist, prune, check_properties, fuse, check_races,
          allocate, choose_pair_symbols, assign_registers, collect_functions, type_arguments,
          collect_helpers)


def run(plan, passes=PASSES):
    """Apply the passes in order, logging each one's notes in ``plan.log``."""
    for p in passes:
        plan.log.append((p.__name__, list(p(plan))))
    return plan


def until(name):
    """The passes before the one called ``name`` (for tests of that pass)."""
    names = [p.__name__ for p in PASSES]
    return PASSES[:names.index(name)]


def plan_scene(arrays, equations, steppers, kernel, dim, domain=None, outputs=None, evaluated=None):
    """The finished plan of a scene: :func:`~sphgen.codegen.plan.new_plan`, then every pass."""
    return run(new_plan(arrays, equations, steppers, kernel, dim, domain, outputs, evaluated))
