"""Lyapunov exponents of Ueda's oscillators: the variational equations (Benettin) and two
nearby trajectories, with batch-means standard errors (compiled kernels, frozen results).

Exponents are per unit time.
"""

from dataclasses import dataclass, field

import numpy as np

from .._api._printing import fmt, readable
from .._api._result import Result
from .._api._validate import Array, Real, params
from ..numerics.tolerances import Tolerances
from . import _kernel as UK
from ._runs import Integration
from ._runs import check as _check
from .strobe import state_after
from .system import UedaSystem

__all__ = ["Lyapunov", "lyapunov", "lyapunov_two_trajectory", "batch_stats", "variational_run"]

METHOD = "variational equations, Gram-Schmidt (QR) every period"


@readable
@dataclass(frozen=True, eq=False)
class Lyapunov(Result):
    """The two Lyapunov exponents [1/unit time] of one trajectory.

    Attributes
    ----------
    value, second : float
        Largest and second exponent (Benettin: variational equations, Gram-Schmidt (QR)
        at every strobe time).
    stderr, second_stderr : float
        Standard errors from batch means (``batches`` consecutive batches of periods).
    sum : float
        ``value + second``.
    trace_mean : float
        Time average of the Jacobian's trace ``mu (1 - gamma x^2) - k`` along the same
        trajectory (integrated with it); equals ``sum`` up to the integration error.
    n_periods, batches : int
    rtol : float
    method : str
    batch_values : ndarray of shape (batches,)
        Largest exponent of each batch.
    """

    KIND = "ueda-lyapunov"
    _LOAD = {"batch_values": lambda d: np.array(d.get("batch_values", []), float)}

    value: float
    stderr: float
    second: float
    second_stderr: float
    sum: float
    trace_mean: float
    n_periods: int
    batches: int
    rtol: float
    method: str
    batch_values: np.ndarray = field(repr=False)

    @classmethod
    def from_logs(cls, logs, trace, period, *, batches, rtol):
        """The exponents of a variational run (:func:`variational_run`).

        Parameters
        ----------
        logs : ndarray of shape (m, 2)
            Logarithmic growth of the two tangent directions over each of ``m`` periods.
        trace : ndarray of shape (m,)
            Integral of the Jacobian's trace over each period.
        period : float
            The forcing period ``T``.
        batches : int
            Batches for the standard errors (:func:`batch_stats`).
        rtol : float
            The run's relative tolerance (recorded).

        Returns
        -------
        Lyapunov
        """
        n = logs.shape[0]
        bv, se = batch_stats(logs, period, batches)
        lam = logs.sum(axis=0) / (n * period)
        return cls(
            value=float(lam[0]),
            stderr=float(se[0]),
            second=float(lam[1]),
            second_stderr=float(se[1]),
            sum=float(lam.sum()),
            trace_mean=float(trace.sum() / (n * period)),
            n_periods=n,
            batches=int(bv.shape[0]),
            rtol=rtol,
            method=METHOD,
            batch_values=bv[:, 0].copy(),
        )

    def as_dict(self):
        return {
            "value": self.value,
            "stderr": self.stderr,
            "second": self.second,
            "second_stderr": self.second_stderr,
            "sum": self.sum,
            "trace_mean": self.trace_mean,
            "sum_minus_trace": self.sum - self.trace_mean,
            "n_periods": self.n_periods,
            "batches": self.batches,
            "rtol": self.rtol,
            "method": self.method,
            "units": "per unit time",
        }

    def _lines(self):
        return [
            f"Lyapunov exponents {fmt(self.value, 4)} +- {fmt(self.stderr, 2)} and "
            f"{fmt(self.second, 4)} +- {fmt(self.second_stderr, 2)} per unit time",
            f"  sum {fmt(self.sum, 4)} against the mean trace {fmt(self.trace_mean, 4)}; "
            f"{self.n_periods} periods in {self.batches} batches, rtol {fmt(self.rtol, 2)} "
            f"({self.method})",
        ]


def batch_stats(per_period, T, batches):
    """Batch means of per-period values and their standard errors.

    Parameters
    ----------
    per_period : ndarray of shape (m, ...)
        A value per forcing period (logarithmic growths).
    T : float
        The forcing period.
    batches : int
        Batches wanted (at least 2, at most one per period).

    Returns
    -------
    means : ndarray of shape (n_batches, ...)
        Each batch's sum divided by its duration.
    stderr : ndarray of shape (...)
        Standard error of the mean over the batches.
    """
    n = per_period.shape[0]
    nb = max(2, min(int(batches), n))
    m = n // nb
    b = per_period[: nb * m].reshape(nb, m, *per_period.shape[1:]).sum(axis=1) / (m * T)
    return b, b.std(axis=0, ddof=1) / np.sqrt(nb)


def variational_run(run, y, periods, *, t0=0.0):
    """The state and its variational equations over ``periods`` forcing periods.

    Parameters
    ----------
    run : Integration
        The system's integration (:class:`~discovery.ueda._runs.Integration`).
    y : ndarray of shape (2,)
        The state at ``t0``.
    periods : int
    t0 : float

    Returns
    -------
    logs : ndarray of shape (periods, 2)
        Logarithmic growth of the two tangent directions over each period (QR every
        period).
    trace : ndarray of shape (periods,)
        Integral of the Jacobian's trace over each period.
    strobe : ndarray of shape (periods, 2)
        The state at the end of each period.
    y_final : ndarray of shape (2,)
    """
    n = int(periods)
    logs, trace, strobe = np.empty((n, 2)), np.empty(n), np.empty((n, 2))
    status, t, yf, _ = UK.variational_run(
        float(t0),
        y,
        run.params,
        run.period,
        n,
        run.control(n),
        run.tol.atol_variational,
        (logs, trace, strobe),
    )
    _check(status, t, "the variational equations")
    return logs, trace, strobe, yf


@params(
    system=UedaSystem,
    y0=(None, Array(1)),
    transient=Real(0, integer=True),
    periods=Real(1, integer=True),
    batches=Real(1, integer=True),
    tolerances=(Tolerances, None),
)
def lyapunov(system, y0=None, *, transient=200, periods=4000, batches=20, tolerances=None):
    """The largest two Lyapunov exponents by the variational equations (Benettin).

    Parameters
    ----------
    system : UedaSystem
    y0 : (x, v), optional
        Initial state (default ``(0.1, 0)``); the transient is discarded.
    transient, periods : int
        Drive periods discarded, then averaged over.
    batches : int
        Batches for the standard error (batch means; the batches must be longer than
        the correlation time of the local stretching rates).
    tolerances : Tolerances, optional

    Returns
    -------
    Lyapunov
    """
    run = Integration.of(system, tolerances)
    y = state_after(system, y0, transient, run.tol)
    logs, trace, _, _ = variational_run(run, y, periods)
    return Lyapunov.from_logs(logs, trace, run.period, batches=batches, rtol=run.tol.rtol)


def lyapunov_two_trajectory(
    system, y0=None, *, transient=200, periods=4000, batches=20, d0=1e-7, tolerances=None
):
    """The largest exponent from two trajectories ``d0`` apart (relative to the scale),
    renormalised every period (Benettin/Wolf): ``(value, stderr)`` per unit time."""
    run = Integration.of(system, tolerances)
    T = run.period
    y = state_after(system, y0, transient, run.tol)
    n = int(periods)
    logs = np.empty(n)
    d = float(d0) * float(system.scales()[0])
    status, t, _, _ = UK.pair_run(0.0, y, run.params, T, n, d, run.control(n), logs)
    _check(status, t, "the two-trajectory run")
    _, se = batch_stats(logs, T, batches)
    return float(logs.sum() / (n * T)), float(se)
