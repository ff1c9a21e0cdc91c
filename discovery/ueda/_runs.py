"""What every compiled run of Ueda's oscillators needs: the tolerances for a system, the
step budget, the initial state, the status check (shared by the attractor, the period map,
the chart and discovery, so none imports another's private helpers)."""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError, VidiTypeError
from ..numerics.status import check
from ..numerics.tolerances import Tolerances
from .system import UedaSystem

__all__ = ["DEFAULT_Y0", "Integration", "budget", "control", "check", "setup", "initial_state"]

DEFAULT_Y0 = (0.1, 0.0)


def budget(tol, n_periods):
    """Step budget of a run: ``max_steps`` per 100 periods."""
    return tol.max_steps * (1 + int(n_periods) // 100)


def control(tol, atol, hmax, n_periods):
    """The compiled runs' step control ``(rtol, atol, hmax, max_steps)`` for a run of
    ``n_periods`` (:func:`budget` its steps)."""
    return float(tol.rtol), atol, float(hmax), budget(tol, n_periods)


def setup(system, tolerances):
    """``(tolerances, period, atol, largest step)`` of runs of ``system``."""
    if not isinstance(system, UedaSystem):
        raise VidiTypeError("system must be a discovery.ueda.UedaSystem")
    tol = tolerances or Tolerances.default()
    T = system.period
    return tol, T, tol.atol(system.scales()), T * tol.hmax_fraction


@dataclass(frozen=True, eq=False)
class Integration:
    """How the compiled runs of one system integrate (:func:`setup` with the system's
    parameters), handed from function to function as one object.

    Attributes
    ----------
    params : ndarray
        The system's parameters as the kernels take them (:meth:`UedaSystem.params`).
    period : float
        The forcing period ``T``.
    tol : Tolerances
    atol : ndarray of shape (2,)
        Absolute tolerances of ``(x, x')``: ``rtol * atol_scale * scale``.
    hmax : float
        Largest step: ``hmax_fraction`` of the period.
    """

    params: np.ndarray
    period: float
    tol: Tolerances
    atol: np.ndarray
    hmax: float

    @classmethod
    def of(cls, system, tolerances=None):
        """The integration of ``system`` with ``tolerances`` (default :class:`Tolerances`)."""
        tol, T, atol, hmax = setup(system, tolerances)
        return cls(params=system.params(), period=T, tol=tol, atol=atol, hmax=hmax)

    def budget(self, n_periods):
        """Step budget of a run of ``n_periods`` (:func:`budget`)."""
        return budget(self.tol, n_periods)

    def control(self, n_periods):
        """The compiled runs' step control for a run of ``n_periods`` (:func:`control`)."""
        return control(self.tol, self.atol, self.hmax, n_periods)


def initial_state(y0):
    """The initial state ``(x, x')`` (default :data:`DEFAULT_Y0`), checked."""
    y = np.array(DEFAULT_Y0 if y0 is None else y0, dtype=float).reshape(-1)
    if y.shape != (2,) or not np.all(np.isfinite(y)):
        raise InputError(f"the initial state must be two finite numbers (x, x'), got {y0!r}")
    return y
