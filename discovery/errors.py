"""Exceptions raised for bad input and failed numerics.

Every error message is one line naming the problem and the fix; the CLI turns
:class:`VidiError` subclasses into exit code 2 without a traceback.

One hierarchy: :class:`VidiError` and :class:`InputError` are defined in
:mod:`constraints.errors` (the lower-level package, which never imports ``discovery``) and
re-exported here, so the constraints package's :class:`~constraints.errors.SolverError` and
:class:`~constraints.errors.CertificateError` are ``VidiError`` subclasses too.
"""

from constraints.errors import CertificateError, InputError, SolverError, VidiError

__all__ = [
    "VidiError",
    "InputError",
    "VidiTypeError",
    "LawSyntaxError",
    "IntegrationError",
    "NoContactError",
    "CertificateError",
    "SolverError",
]


class LawSyntaxError(InputError):
    """A force-law text does not follow the law grammar."""


class IntegrationError(VidiError, RuntimeError):
    """A simulation failed (blow-up, step budget exhausted, step size underflow)."""


class NoContactError(InputError):
    """A force record (or a noisy replicate of one) has no contact above its threshold."""


class VidiTypeError(VidiError, TypeError):
    """An argument of a public function has the wrong type."""
