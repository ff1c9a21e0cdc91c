"""What every compiled run of Ueda's oscillators needs: the tolerances for a system, the
step budget, the initial state, the status check (shared by the attractor, the period map,
the chart and discovery, so none imports another's private helpers)."""

import numpy as np

from ..errors import InputError, VidiTypeError
from ..numerics.status import check
from ..numerics.tolerances import Tolerances
from .system import UedaSystem

__all__ = ["DEFAULT_Y0", "budget", "check", "setup", "initial_state"]

DEFAULT_Y0 = (0.1, 0.0)


def budget(tol, n_periods):
    """Step budget of a run: ``max_steps`` per 100 periods."""
    return tol.max_steps * (1 + int(n_periods) // 100)


def setup(system, tolerances):
    """``(tolerances, period, atol, largest step)`` of runs of ``system``."""
    if not isinstance(system, UedaSystem):
        raise VidiTypeError("system must be a discovery.ueda.UedaSystem")
    tol = tolerances or Tolerances()
    T = system.period
    return tol, T, tol.atol(system.scales()), T * tol.hmax_fraction


def initial_state(y0):
    """The initial state ``(x, x')`` (default :data:`DEFAULT_Y0`), checked."""
    y = np.array(DEFAULT_Y0 if y0 is None else y0, dtype=float).reshape(-1)
    if y.shape != (2,) or not np.all(np.isfinite(y)):
        raise InputError(f"the initial state must be two finite numbers (x, x'), got {y0!r}")
    return y
