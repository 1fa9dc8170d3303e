"""The exception types sphgen raises for things a user can get wrong.

Every error a user can cause is a :class:`SphgenError`: its message is one line that
names the offending thing (option, path, array, property, particle, step) and what was
expected.  ``sphgen run`` and :meth:`sphgen.app.Application.run` print that line to
stderr and exit non-zero; the traceback is shown only with ``--debug`` or
``SPHGEN_DEBUG=1``.  Anything else that escapes is a bug in sphgen, and is shown with its
traceback.
"""


class SphgenError(Exception):
    """Base class: a user-facing error whose message is one clear line."""

    exit_code = 2


class InputError(SphgenError, ValueError):
    """A command-line option, path, parameter or input file is not acceptable."""


class StabilityError(InputError):
    """A parameter lies outside the scheme's documented stability bound."""


class RestartError(InputError):
    """A restart file is missing, unreadable, or belongs to another scene."""


class OutputError(SphgenError):
    """The output folder cannot be used as asked (another run's files, not writable)."""


class BlowUpError(SphgenError, RuntimeError):
    """A run became non-finite or left its scheme's bounds; the last good state is on disk."""

    exit_code = 3


def debug_requested(argv=()):
    """True if ``--debug`` is among the arguments or ``SPHGEN_DEBUG`` is set (not 0)."""
    import os
    return "--debug" in argv or os.environ.get("SPHGEN_DEBUG", "0") not in ("", "0")


def one_line(message, limit=300):
    """The message as one line of at most ``limit`` characters."""
    text = " ".join(str(message).split())
    return text if len(text) <= limit else text[: limit - 3] + "..."
