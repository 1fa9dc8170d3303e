"""Options shared by the CTVF/GTVF solid applications (rings, uniaxial compression): the
scheme, its homogenisation and corrections, and the checks of positive numbers."""
import math

from sphgen.errors import InputError

from ..equations.shifting import SHIFTINGS

SCHEMES = ("ctvf", "gtvf")


def add_solid_scheme_options(group):
    """``--scheme`` (ctvf or gtvf), ``--shifting``, ``--no-corrections``, ``--alpha``."""
    group.add_argument("--scheme", choices=SCHEMES, default="ctvf", help="CTVF or GTVF (default ctvf)")
    group.add_argument("--shifting", choices=SHIFTINGS, default=None,
                       help="homogenisation (default: spst for ctvf, gtvf for gtvf)")
    group.add_argument("--no-corrections", action="store_true", help="ctvf: no correction terms")
    group.add_argument("--alpha", type=float, default=1.0, help="artificial viscosity (paper: 1)")


def check_solid_scheme_options(o, positive=()):
    """Refuse non-positive ``positive`` options and --no-corrections without ctvf; the
    shifting to use (spst for ctvf, gtvf for gtvf unless given)."""
    for name in positive:
        v = getattr(o, name)
        if not (math.isfinite(v) and v > 0):
            raise InputError(f"--{name.replace('_', '-')} must be a positive number, got {v}")
    if o.no_corrections and o.scheme != "ctvf":
        raise InputError("--no-corrections applies to --scheme ctvf only")
    return o.shifting or ("spst" if o.scheme == "ctvf" else "gtvf")
