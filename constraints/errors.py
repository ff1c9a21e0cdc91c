"""Exceptions of the :mod:`constraints` package.

A law that breaks a physical condition anywhere on the domain, or a solver run that does not
end in an optimal status, is always an error: nothing is downgraded to a warning and no
coefficient is silently zeroed.

:class:`VidiError` is the root of the one error hierarchy of the project: it is defined
here, in the lower-level package, and :mod:`discovery.errors` re-exports it (``constraints``
never imports ``discovery``). Every error of both packages is therefore catchable as
``VidiError`` (the CLI turns it into a one-line message and exit code 2), and as the
builtin it specialises (``ValueError`` for bad input and failed certificates,
``RuntimeError`` for failed solves).
"""

from __future__ import annotations

__all__ = ["VidiError", "InputError", "CertificateError", "SolverError"]


class VidiError(Exception):
    """Base class of the errors the CLI reports as a one-line message (exit code 2)."""


class InputError(VidiError, ValueError):
    """A user-supplied value, file or option is invalid."""


class CertificateError(VidiError, ValueError):
    """A fitted law violates (or could not be certified for) a physical condition.

    Parameters
    ----------
    message : str
        One-line description naming the condition, the location and the size of the violation.
    condition : str
        Name of the failed condition (``"non_adhesion"``, ``"dissipativity"`` or
        ``"monotone_elastic"``).
    location : tuple of float
        ``(zeta [m], zd [m/s])`` of the worst point found.
    violation : float
        Size of the violation relative to the force scale ``max |P|`` on the domain (>= 0).
    """

    def __init__(
        self,
        message: str,
        *,
        condition: str,
        location: tuple[float, float],
        violation: float,
    ) -> None:
        super().__init__(message)
        self.condition = condition
        self.location = location
        self.violation = violation


class SolverError(VidiError, RuntimeError):
    """A cvxpy problem did not end with an accepted status.

    Parameters
    ----------
    message : str
        Human-readable description, always containing the status.
    status : str
        The cvxpy status string (e.g. ``"infeasible"``, ``"optimal_inaccurate"``) or
        ``"solver_error"`` when the solver itself failed.
    solver : str or None
        Name of the solver that was requested, if any.
    """

    def __init__(self, message: str, *, status: str, solver: str | None = None) -> None:
        super().__init__(message)
        self.status = status
        self.solver = solver
