"""Pass: the C type of every argument of every function the module defines."""
from .. import pair_symbols
from ..plan import is_property
from ..translate import TranslationError

SPECIAL = {"d_idx": "long", "s_idx": "long", "t": "double", "dt": "double", "NBRS": "int*", "N_NBRS": "long"}


def _property_type(plan, fp, arg):
    if arg.startswith("d_"):
        return plan.dtype(fp.dest, arg[2:]) + "*"
    kinds = {plan.dtype(s, arg[2:]) for s in fp.sources} or {"double"}
    if len(kinds) > 1:
        raise TranslationError(f"{fp.origin}: property '{arg[2:]}' has different types across sources")
    return kinds.pop() + "*"


def argument_type(plan, fp, arg):
    """'double*' for d_rho, 'long' for d_idx, the table's type for a pair symbol, ..."""
    if arg in SPECIAL:
        return SPECIAL[arg]
    if arg in pair_symbols.SYMBOLS:
        return pair_symbols.SYMBOLS[arg].arg_type
    if is_property(arg):
        return _property_type(plan, fp, arg)
    raise TranslationError(
        f"{fp.origin}: argument '{arg}' is neither a property (d_*/s_*), a pair symbol "
        f"({', '.join(pair_symbols.SYMBOLS)}) nor one of {', '.join(SPECIAL)}")


def type_arguments(plan):
    """Type each function's arguments from the arrays' dtypes and the pair-symbol table."""
    for fp in plan.functions:
        fp.arg_types = {a: argument_type(plan, fp, a) for a in fp.spec.args}
    ints = sorted({f"{fp.dest}.{a[2:]}" for fp in plan.functions for a, t in fp.arg_types.items()
                   if t == "int*" and is_property(a)})
    return [f"integer properties: {', '.join(ints)}"] if ints else []
