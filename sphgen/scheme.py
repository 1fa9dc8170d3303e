"""Scheme: a bundle of equations, integrator and time-step rule with its options."""
from dataclasses import dataclass

from .errors import StabilityError


@dataclass(frozen=True)
class Bound:
    """A documented stability bound: ``value`` must stay below (``upper``) or above ``limit``."""

    option: str      # what the user sets, as on the command line (e.g. '--dt')
    value: float
    limit: float
    upper: bool      # True: value <= limit; False: value >= limit
    rule: str        # the bound as a formula, with its source

    def violated(self, rtol=1e-9):
        if self.upper:
            return self.value > self.limit * (1.0 + rtol)
        return self.value < self.limit * (1.0 - rtol)

    def message(self, scheme):
        side = "above" if self.upper else "below"
        return (f"{self.option} {self.value:.4g} is {side} the {scheme} stability bound "
                f"{self.limit:.4g} ({self.rule})")


class Scheme:
    """Base class of the schemes in ``sphgen.schemes``.

    A scheme declares the properties it needs (``setup_properties``), returns its
    equation sets (``get_equations``: a list of Groups, or one list per integrator
    evaluation), its integrator (``get_integrator``) and a stable time step
    (``get_timestep``).  ``output_props`` are written for viewing and are roots of
    the generator's pruning: an equation whose results reach neither an output nor
    an integrator stage is dropped.  ``stability_bounds(dt)`` lists the bounds the
    scheme documents; a run outside them is refused before it starts.
    The blow-up guard checks two more bounds every step: ``speed_limit`` (the largest
    particle speed) and ``density_bounds()`` ({array: (min, max) of ``rho``}).
    """

    output_props = ("x", "y", "u", "v", "p", "rho", "m", "h")
    speed_limit = None
    # (dt_props, cfl): the application steps adaptively, cfl * min over the particles of
    # the properties dt_props (written by the scheme's equations), capped at get_timestep()
    adaptive_dt = None

    def density_bounds(self):
        """{array name: (lowest, highest) density} the guard enforces (none by default)."""
        return {}

    def setup_properties(self, arrays):
        raise NotImplementedError

    def get_equations(self):
        raise NotImplementedError

    def get_integrator(self):
        raise NotImplementedError

    def get_timestep(self):
        raise NotImplementedError

    def output_properties(self, pa):
        """The properties of array ``pa`` written to the output files (roots of pruning).

        A wall at rest (in ``walls`` but not ``moving_walls``) writes no velocities, so it
        carries none unless an equation reads them.
        """
        props = [p for p in self.output_props if pa.has(p)]
        if pa.name in getattr(self, "walls", ()) and pa.name not in getattr(self, "moving_walls", ()):
            props = [p for p in props if p not in ("u", "v", "w")]
        return props

    def stability_bounds(self, dt):
        """[Bound] for a run with time step ``dt`` (none by default)."""
        return []

    def check_stability(self, dt, allow_unstable=False):
        """Raise StabilityError for the first violated bound; with ``allow_unstable``
        return the messages instead (to be printed as warnings)."""
        bad = [b.message(type(self).__name__) for b in self.stability_bounds(dt) if b.violated()]
        if bad and not allow_unstable:
            raise StabilityError(f"{bad[0]}; pass --allow-unstable to run anyway")
        return bad

    def parameters(self):
        """The scheme's scalar settings (numbers, strings, flags): its part of a run's identity."""
        out = {}
        for k, v in sorted(vars(self).items()):
            if k.startswith("_"):
                continue
            if isinstance(v, (bool, int, float, str)) or (
                    isinstance(v, (list, tuple)) and all(isinstance(x, (str, int, float)) for x in v)):
                out[k] = list(v) if isinstance(v, tuple) else v
        return out
