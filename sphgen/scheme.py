"""Scheme: a bundle of equations, integrator and time-step rule with its options."""


class Scheme:
    """Base class of the schemes in ``sphgen.schemes``.

    A scheme declares the properties it needs (``setup_properties``), returns its
    equation sets (``get_equations``: a list of Groups, or one list per integrator
    evaluation), its integrator (``get_integrator``) and a stable time step
    (``get_timestep``).  ``output_props`` are written for viewing and are roots of
    the generator's pruning: an equation whose results reach neither an output nor
    an integrator stage is dropped.
    """

    output_props = ("x", "y", "u", "v", "p", "rho", "m", "h")

    def add_user_options(self, parser):
        """Add this scheme's command-line options to an argparse group."""

    def consume_user_options(self, options):
        """Read the parsed options back."""

    def setup_properties(self, arrays):
        raise NotImplementedError

    def get_equations(self):
        raise NotImplementedError

    def get_integrator(self):
        raise NotImplementedError

    def get_timestep(self):
        raise NotImplementedError
