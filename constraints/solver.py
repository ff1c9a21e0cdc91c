"""Running cvxpy problems without silently accepting a failed solve."""

from __future__ import annotations

from ._cvxpy import cvxpy as cp
from .errors import SolverError

__all__ = ["solve"]

_DEFAULT_SOLVER = "CLARABEL"


def solve(
    problem: cp.Problem,
    solver: str | None = None,
    *,
    allow_inaccurate: bool = False,
    **options,
) -> float:
    """Solve a cvxpy problem and insist on an optimal status.

    Parameters
    ----------
    problem : cvxpy.Problem
        The problem to solve (its variables receive the solution).
    solver : str, optional
        cvxpy solver name; defaults to CLARABEL when installed, else cvxpy's choice.
    allow_inaccurate : bool, optional
        Accept ``"optimal_inaccurate"`` (rejected by default).
    **options
        Forwarded to :meth:`cvxpy.Problem.solve`.

    Returns
    -------
    float
        The optimal objective value.

    Raises
    ------
    SolverError
        If the solver fails, or the status is anything but ``"optimal"`` (or
        ``"optimal_inaccurate"`` when allowed); the message and ``.status`` carry the status.
    """
    if solver is None and _DEFAULT_SOLVER in cp.installed_solvers():
        solver = _DEFAULT_SOLVER
    try:
        value = problem.solve(solver=solver, **options)
    except cp.error.SolverError as exc:
        raise SolverError(
            f"solver {solver or 'default'} failed (status 'solver_error'): {exc}",
            status="solver_error",
            solver=solver,
        ) from exc
    accepted = {cp.OPTIMAL} | ({cp.OPTIMAL_INACCURATE} if allow_inaccurate else set())
    status = str(problem.status)
    if status not in accepted:
        raise SolverError(
            f"cvxpy problem ended with status '{status}' (solver {solver or 'default'}); "
            "no solution is returned",
            status=status,
            solver=solver,
        )
    return float(value)
