"""Shooting and Floquet multipliers, shared by every periodically forced system.

One implementation for the vibro-impact system
(:class:`~discovery.vibroimpact.dynamics.steady_states.
StroboscopicMap`) and Ueda's oscillators (:class:`~discovery.ueda.periodic.UedaMap`):
both are *period maps* ``Phi`` (the state advanced by one forcing period, sampled at a
fixed forcing phase) following the small protocol :class:`PeriodMap`.  On such a map

* :func:`recurrence` measures how closely the strobe points repeat after ``n`` periods;
* :func:`newton_orbit` solves ``Phi^n(y) = y`` by damped Newton (the Jacobian is the
  map's own: the vibro-impact map's from its variational equations with the saltation
  matrix at every event, Ueda's by finite differences);
* :func:`floquet_multipliers` are the eigenvalues of the Jacobian of ``Phi^n`` at the
  orbit (the monodromy matrix);
* :func:`smallest_period` reduces a stable period-``n`` orbit to its smallest period.

Distances are relative to the map's ``scale``: ``max_i |a_i - b_i| / scale_i``.
"""

from typing import Protocol, runtime_checkable

import numpy as np

from ..errors import IntegrationError

__all__ = [
    "PeriodMap",
    "recurrence",
    "newton_orbit",
    "floquet_multipliers",
    "is_stable",
    "smallest_period",
]


@runtime_checkable
class PeriodMap(Protocol):
    """The period map of a periodically forced system (what shooting needs).

    Attributes
    ----------
    n_states : int
        Dimension of the state (the functions here also take it from ``len(y)``, so a map
        may omit it).
    scale : ndarray of shape (n_states,)
        Characteristic size of each state component: distances, residuals and
        finite-difference steps are relative to it.
    n_calls : int, optional
        Map evaluations so far (a counter; reported, never needed).

    Methods
    -------
    advance(y, n=1)
        The state ``n`` forcing periods after ``y`` (``Phi^n(y)``); raises
        :class:`~discovery.errors.IntegrationError` when the integration fails.
    jacobian(y, n=1, fy=None)
        ``d Phi^n / d y`` at ``y``, ndarray of shape ``(n_states, n_states)``; ``fy`` is
        ``Phi^n(y)`` when the caller already has it.
    advance_jacobian(y, n=1), optional
        ``(Phi^n(y), d Phi^n / d y)`` from one run (a map whose Jacobian comes from the
        variational equations integrated with the state); :func:`newton_orbit` then
        takes each full step's state and Jacobian together.
    """

    scale: np.ndarray

    def advance(self, y, n=1): ...

    def jacobian(self, y, n=1, fy=None): ...


def recurrence(strobe, scale, max_period):
    """Smallest relative distance ``|y_{k+n} - y_k|`` over the last strobe points, per n.

    For each ``n <= max_period`` the largest distance over the last (up to) three pairs
    ``(k, k + n)`` ending at the last point: ``{n: distance}``.
    """
    d = {}
    points = np.asarray(strobe)
    last = len(points) - 1
    for n in range(1, max_period + 1):
        k = max(0, last - n - 2)
        d[n] = float(np.max(np.abs(points[k + n :] - points[k : last - n + 1]) / scale))
    return d


def newton_orbit(pm, y, n, *, tol, max_iter, history=None):
    """Damped Newton on ``G(y) = Phi^n(y) - y``.

    Parameters
    ----------
    pm : PeriodMap
    y : ndarray
        Starting state (e.g. the last strobe point of a transient).
    n : int
        Period in forcing periods.
    tol : float
        Convergence when ``max |Phi^n(y) - y| / scale < tol``.
    max_iter : int
        Newton iterations.
    history : list, optional
        The residual of each iteration is appended to it.

    Returns
    -------
    y : ndarray
        The last iterate (the orbit's state when converged).
    residual : float
        ``max |Phi^n(y) - y| / scale`` there.
    J : ndarray or None
        Jacobian of ``Phi^n`` at ``y`` when converged (the monodromy matrix), else the
        last one computed (``None`` if none was).
    converged : bool
    """
    history = [] if history is None else history
    s = pm.scale
    eye = np.eye(len(y))
    both = getattr(pm, "advance_jacobian", None)
    if both is None:
        fy, Jy = pm.advance(y, n), None
    else:
        fy, Jy = both(y, n)
    res = np.max(np.abs(fy - y) / s)
    J = None
    for _ in range(max_iter):
        history.append(res)
        if res < tol:
            break
        J = Jy if Jy is not None else pm.jacobian(y, n, fy)
        try:
            step = np.linalg.solve(J - eye, -(fy - y))
        except np.linalg.LinAlgError:
            return y, res, J, False
        found = _line_search(pm, n, y, step, res)
        if found is None:
            return y, res, J, False
        y, fy, res, Jy = found
    converged = res < tol
    if converged:
        J = Jy if Jy is not None else pm.jacobian(y, n, fy)
    return y, res, J, converged


def _line_search(pm, n, y, step, res):
    """``(y, Phi^n(y), residual, Jacobian or None)`` at the first of ``y + step``,
    ``y + step / 2``, ... (down to 1e-3) that lowers the residual, or None.  The full
    step, the one Newton takes near an orbit, is evaluated with its Jacobian when the map
    gives both from one run (``advance_jacobian``); the damped ones plainly."""
    both = getattr(pm, "advance_jacobian", None)
    lam = 1.0
    while lam > 1e-3:
        y_try = y + lam * step
        try:
            if lam == 1.0 and both is not None:
                f_try, J_try = both(y_try, n)
            else:
                f_try, J_try = pm.advance(y_try, n), None
        except IntegrationError:
            lam *= 0.5
            continue
        r_try = np.max(np.abs(f_try - y_try) / pm.scale)
        if r_try < res:
            return y_try, f_try, r_try, J_try
        lam *= 0.5
    return None


def floquet_multipliers(J, n_states=None):
    """Floquet multipliers: the eigenvalues of the monodromy matrix ``J`` (complex).

    ``J is None`` (no Jacobian) gives ``n_states`` NaNs.
    """
    if J is None:
        return np.full(int(n_states), np.nan + 0j)
    return np.linalg.eigvals(J)


def is_stable(multipliers):
    """All ``|multiplier| < 1`` (an attracting orbit; NaN multipliers are not stable)."""
    return bool(np.all(np.abs(multipliers) < 1.0))


def smallest_period(pm, y_orb, n, tol, max_newton):
    """The smallest period ``m | n`` of a stable period-``n`` orbit through ``y_orb``.

    Each divisor ``m`` is tested by polishing: damped Newton on ``Phi^m(y) = y`` from
    ``y_orb``.  The orbit has period ``m`` when that converges to a *stable* fixed point
    of ``Phi^m`` close to ``y_orb`` (two attracting fixed points of ``Phi^n`` cannot be
    arbitrarily close).  The decision therefore rests on the accuracy Newton reaches at
    each divisor, never on a fixed closure threshold: a period-1 orbit with a Floquet
    multiplier near +1 or -1 closes after one period only to the accuracy that shooting
    at ``n`` reached, which can be far above ``tol``.  Near a period doubling the nearby
    period-``m`` orbit is unstable (a multiplier below -1), so it is not taken.

    Returns ``(m, y, residual, J, newton_history)`` or ``None`` when no proper divisor
    closes the orbit.
    """
    for m in range(1, n):
        if n % m:
            continue
        hist = []
        y_m, res_m, J_m, ok_m = newton_orbit(
            pm, y_orb, m, tol=tol, max_iter=max_newton, history=hist
        )
        if not ok_m:
            continue
        mult = floquet_multipliers(J_m)
        close = np.max(np.abs(y_m - y_orb) / pm.scale) < 1e-3
        if close and is_stable(mult):
            return m, y_m, res_m, J_m, hist
    return None
