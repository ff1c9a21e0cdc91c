"""The stroboscopic map and trajectories of Ueda's oscillators (compiled kernels).

The stroboscopic map samples the state at ``t = 2 pi k / nu`` (the forcing's phase 0).
Integrator settings are :class:`discovery.numerics.tolerances.Tolerances` (``rtol``,
absolute tolerance ``rtol * atol_scale * scale``, ``max_steps``, largest step
``hmax_fraction`` of a period).
"""

import numpy as np

from .._api._validate import Array, Real, params
from ..numerics.tolerances import Tolerances
from . import _kernel as UK
from ._runs import Integration
from ._runs import check as _check
from ._runs import initial_state as _y0
from .system import UedaSystem

__all__ = ["strobe_points", "trajectory", "state_after"]


@params(
    system=UedaSystem,
    y0=(None, Array(1)),
    n=Real(1, integer=True),
    transient=Real(0, integer=True),
    t0=Real(),
    tolerances=(Tolerances, None),
)
def strobe_points(system, y0=None, n=200, *, transient=200, t0=0.0, tolerances=None):
    """The stroboscopic points after a transient.

    Parameters
    ----------
    system : UedaSystem
    y0 : (x, v), optional
        State at ``t0`` (default ``(0.1, 0)``).
    n : int
        Points returned.
    transient : int
        Periods integrated first.
    t0 : float
        Start time (a multiple of the period keeps the strobe phase at 0).
    tolerances : Tolerances, optional

    Returns
    -------
    points : ndarray of shape (n, 2)
    y_final : ndarray of shape (2,)
        The last point (the state at ``t0 + (transient + n) T``).
    """
    run = Integration.of(system, tolerances)
    out = np.empty((int(n), 2))
    status, t, y, _, _ = UK.strobe_run(
        float(t0),
        _y0(y0),
        run.params,
        run.period,
        int(transient),
        int(n),
        run.control(int(n) + int(transient)),
        (np.empty(0), np.empty((2, 0))),
        out,
    )
    _check(status, t, "the stroboscopic map")
    return out, y


def state_after(system, y0, transient, tol):
    """The state after ``transient`` periods from ``y0`` at ``t = 0``.

    Parameters
    ----------
    system : UedaSystem
    y0 : (x, v) or None
        The initial state (default ``(0.1, 0)``).
    transient : int
        Forcing periods integrated (0: ``y0`` itself).
    tol : Tolerances

    Returns
    -------
    ndarray of shape (2,)
    """
    if int(transient) <= 0:
        return _y0(y0)
    return strobe_points(system, y0, 1, transient=int(transient) - 1, tolerances=tol)[1]


@params(
    system=UedaSystem,
    y0=Array(1),
    t_span=Array(1),
    n_samples=Real(2, integer=True),
    tolerances=(Tolerances, None),
)
def trajectory(system, y0, t_span, n_samples=4000, *, tolerances=None):
    """``(t, x, v)`` sampled uniformly on ``t_span`` (dense output, no extra steps)."""
    run = Integration.of(system, tolerances)
    T = run.period
    t0, t1 = float(t_span[0]), float(t_span[1])
    te = np.linspace(t0, t1, int(n_samples))
    out = np.empty((2, te.size))
    n_per = max(1, int(np.ceil((t1 - t0) / T - 1e-9)))
    strobe = np.empty((n_per, 2))
    status, t, _, _, k = UK.strobe_run(
        t0, _y0(y0), run.params, T, 0, n_per, run.control(n_per), (te, out), strobe
    )
    _check(status, t, "the trajectory")
    return te[:k], out[0, :k], out[1, :k]
