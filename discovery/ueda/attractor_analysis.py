"""One attractor of Ueda's oscillators, reached from one initial state: its stroboscopic
points, Lyapunov exponents, regime and a stretch of trajectory (a frozen result).

The pieces are in :mod:`.strobe` (the stroboscopic map, trajectories), :mod:`.exponents`
(Lyapunov exponents) and :mod:`.regimes` (the classification); coexisting attractors
from a grid of initial states are in :mod:`.coexisting`.
"""

import time
from dataclasses import dataclass, field

import numpy as np

from .._api._printing import generic_lines, readable
from .._api._result import Result, part
from .._api._validate import Array, Real, params
from ..numerics.tolerances import Tolerances
from ._runs import Integration
from ._runs import initial_state as _y0
from .exponents import Lyapunov, variational_run
from .periodic import UedaMap
from .regimes import Regime, classify_points
from .strobe import state_after, trajectory
from .system import UedaSystem

__all__ = ["Attractor", "attractor"]


@readable
@dataclass(frozen=True, eq=False)
class Attractor(Result):
    """An attractor reached from one initial state.

    Attributes
    ----------
    system : UedaSystem
    regime : Regime
    lyapunov : Lyapunov
    strobe : ndarray of shape (n, 2)
        Stroboscopic points ``(x, x')`` at ``t = 2 pi k / nu`` after the transient.
    t, x, v : ndarray
        A stretch of trajectory on the attractor (for the phase-plane figure).
    y0 : ndarray of shape (2,)
        The initial state.
    transient : int
    seconds : float
    """

    KIND = "ueda-attractor"
    _LOAD = {
        "system": lambda d: UedaSystem.from_dict(d["system"]),
        "lyapunov": lambda d: part(Lyapunov, d["lyapunov"]),
        "regime": lambda d: Regime.from_dict(d["classification"]),
        "strobe": lambda d: None,
        "t": lambda d: None,
        "x": lambda d: None,
        "v": lambda d: None,
        "y0": lambda d: np.array(d["y0"], float),
        "transient": lambda d: d["transient_periods"],
    }

    system: UedaSystem
    regime: Regime
    lyapunov: Lyapunov
    strobe: np.ndarray = field(repr=False)
    t: np.ndarray = field(repr=False)
    x: np.ndarray = field(repr=False)
    v: np.ndarray = field(repr=False)
    y0: np.ndarray
    transient: int
    seconds: float

    @property
    def n_points(self):
        return int(self.strobe.shape[0])

    def as_dict(self):
        s = self.strobe
        return {
            "system": self.system.as_dict(),
            "regime": self.regime.regime,
            "classification": self.regime.as_dict(),
            "lyapunov": self.lyapunov.as_dict(),
            "strobe_x_range": [float(s[:, 0].min()), float(s[:, 0].max())],
            "strobe_y_range": [float(s[:, 1].min()), float(s[:, 1].max())],
            "n_points": self.n_points,
            "y0": [float(v) for v in self.y0],
            "transient_periods": self.transient,
            "seconds": self.seconds,
        }

    def _lines(self):
        return generic_lines(self)


@params(
    system=UedaSystem,
    y0=(None, Array(1)),
    transient=Real(0, integer=True),
    periods=Real(1, integer=True),
    batches=Real(1, integer=True),
    trajectory_periods=Real(0, integer=True),
    tolerances=(Tolerances, None),
)
def attractor(
    system,
    y0=None,
    *,
    transient=500,
    periods=5000,
    batches=20,
    trajectory_periods=30,
    tolerances=None,
):
    """The attractor reached from ``y0``: strobe points, exponents, regime, a trajectory.

    The strobe points are those of the Lyapunov run (one trajectory, ``periods``
    points).

    Parameters
    ----------
    system : UedaSystem
    y0 : (x, v), optional
        Initial state (default ``(0.1, 0)``).
    transient, periods : int
        Drive periods discarded, then observed (strobe points and exponents).
    batches : int
        Batches for the exponents' standard errors.
    trajectory_periods : int
        Periods of the trajectory kept for the phase-plane figure.
    tolerances : Tolerances, optional

    Returns
    -------
    Attractor
    """
    t_start = time.perf_counter()
    run = Integration.of(system, tolerances)
    tol, T = run.tol, run.period
    y_init = _y0(y0)
    y = state_after(system, y_init, transient, tol)
    logs, trace, strobe, yf = variational_run(run, y, periods)
    lyap = Lyapunov.from_logs(logs, trace, T, batches=batches, rtol=tol.rtol)
    # a recurring orbit is polished by shooting: its Floquet multipliers are the evidence
    reg = classify_points(
        strobe, system.scales(), lyap.value, lyap.stderr, period_map=UedaMap(system, tol)
    )
    n_tr = int(trajectory_periods)
    t, x, v = trajectory(system, yf, (0.0, n_tr * T), n_samples=200 * n_tr, tolerances=tol)
    return Attractor(
        system=system,
        regime=reg,
        lyapunov=lyap,
        strobe=strobe,
        t=t,
        x=x,
        v=v,
        y0=y_init,
        transient=int(transient),
        seconds=time.perf_counter() - t_start,
    )
