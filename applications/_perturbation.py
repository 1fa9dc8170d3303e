"""``--perturb`` and ``--seed``: the randomly moved initial positions that ``sphgen stress`` asks
every application for (shared by the SHTC-SPH applications)."""
import math

from sphgen.errors import InputError
from sphgen.geometry import perturb


def add_perturbation_options(group):
    """Add ``--perturb`` (amplitude in units of the spacing) and ``--seed``."""
    group.add_argument("--perturb", type=float, default=0.0,
                       help="random perturbation of the initial positions in units of dr (default 0; "
                       "`sphgen stress` sets it)")
    group.add_argument("--seed", type=int, default=1, help="seed of the perturbation (default 1)")


def check_perturbation(o):
    """Refuse a perturbation outside [0, 0.5) spacings."""
    if not (math.isfinite(o.perturb) and 0 <= o.perturb < 0.5):
        raise InputError(f"--perturb must be in [0, 0.5), got {o.perturb}")


def perturbed(points, dr, o):
    """The points moved by uniform(-perturb dr, perturb dr) per coordinate (unchanged at 0)."""
    if o.perturb == 0:
        return tuple(points)
    return perturb(points, o.perturb * dr, o.seed)
