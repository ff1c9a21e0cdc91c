"""Exceptions raised for bad input and failed numerics.

Every error message is one line naming the problem and the fix; the CLI turns
:class:`VidiError` subclasses into exit code 2 without a traceback.
"""

__all__ = ["VidiError", "InputError", "LawSyntaxError", "IntegrationError"]


class VidiError(Exception):
    """Base class of the errors the CLI reports as a one-line message (exit code 2)."""


class InputError(VidiError, ValueError):
    """A user-supplied value, file or option is invalid."""


class LawSyntaxError(InputError):
    """A force-law text does not follow the law grammar."""


class IntegrationError(VidiError, RuntimeError):
    """A simulation failed (blow-up, step budget exhausted, step size underflow)."""
