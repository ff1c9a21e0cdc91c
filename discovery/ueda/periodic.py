"""Periodic orbits of Ueda's oscillators: the period map, shooting, Floquet multipliers.

:class:`UedaMap` is the oscillator's period map ``Phi`` (the state advanced by ``n``
forcing periods ``2 pi / nu`` on the compiled stroboscopic integrator
:func:`~discovery.ueda._kernel.strobe_run`, from the forcing's phase 0) in the
:class:`~discovery.numerics.shooting.PeriodMap` protocol; :func:`periodic_orbit`
converges a period-``n`` orbit with the shooting shared with the vibro-impact system
(:mod:`discovery.numerics.shooting`) and reports its Floquet multipliers.

The Jacobian of ``Phi^n`` is by central differences (steps ``1e-5`` of the scale; four
map evaluations in two dimensions).  Measured on the entrained orbit ``B = 0.45,
nu = 1.05`` against the monodromy matrix integrated by scipy at ``rtol 1e-13``: central
differences agree to 4e-10 at the default ``rtol 1e-9``, forward differences (steps
``1e-6``, the vibro-impact system's choice, available as ``difference="forward"``) to
4e-7, whatever the tolerance (their truncation error).  The compiled variational run
(:func:`~discovery.ueda._kernel.variational_run`) orthonormalises its tangent
vectors at every strobe time and returns only their log growths, not the monodromy
matrix; it gives the moduli of the multipliers over a long run on the orbit (Lyapunov
exponents ``log|m_i| / (n T)``) and their product (the trace integral, Liouville), which
the tests use as cross-checks.
"""

from dataclasses import dataclass, field

import numpy as np

from .._api._printing import fmt, readable
from .._api._validate import Array, Real, params
from ..errors import InputError
from ..numerics.shooting import floquet_multipliers, is_stable, newton_orbit, smallest_period
from ..numerics.tolerances import Tolerances
from . import _kernel as UK
from ._runs import check as _check
from ._runs import control as _control
from ._runs import initial_state as _y0
from ._runs import setup as _setup
from .system import UedaSystem

__all__ = ["UedaMap", "PeriodicOrbit", "periodic_orbit"]


class UedaMap:
    """The period map of one :class:`~discovery.ueda.UedaSystem` (shooting protocol).

    Parameters
    ----------
    system : UedaSystem
    tolerances : Tolerances, optional
        Integrator settings (as for :func:`~discovery.ueda.strobe_points`).
    difference : {"central", "forward"}
        Finite differences of :meth:`jacobian`.
    fd_step : float, optional
        Their step relative to ``scale`` (default ``1e-5`` central, ``1e-6`` forward).

    Attributes
    ----------
    n_states : int
        2 (``x, x'``).
    scale : ndarray of shape (2,)
        :meth:`UedaSystem.scales`.
    n_calls, n_steps : int
        Map evaluations and integration steps so far.
    """

    n_states = 2

    def __init__(self, system, tolerances=None, difference="central", fd_step=None):
        if difference not in ("central", "forward"):
            raise InputError(f"difference must be 'central' or 'forward', got {difference!r}")
        self.system = system
        self.difference = difference
        self.tol, self._T, self._atol, self._hmax = _setup(system, tolerances)
        self._p = system.params()
        self.scale = system.scales()
        self.fd_step = float(
            fd_step if fd_step is not None else 1e-5 if difference == "central" else 1e-6
        )
        self._te = np.empty(0)
        self._oe = np.empty((2, 0))
        self._out = np.empty((1, 2))
        self.n_calls = 0
        self.n_steps = 0

    @property
    def period(self):
        return self._T

    def advance(self, y, n=1):
        """``Phi^n(y)``: the state ``n`` forcing periods after ``y`` (taken at phase 0)."""
        n = int(n)
        if n < 1:
            raise InputError(f"n must be >= 1, got {n}")
        status, t, yf, steps, _ = UK.strobe_run(
            0.0,
            np.asarray(y, dtype=float),
            self._p,
            self._T,
            n - 1,
            1,
            _control(self.tol, self._atol, self._hmax, n),
            (self._te, self._oe),
            self._out,
        )
        self.n_calls += 1
        self.n_steps += steps
        _check(status, t, "the stroboscopic map")
        return yf

    def jacobian(self, y, n=1, fy=None):
        """Finite-difference Jacobian of ``Phi^n`` at ``y`` (the monodromy matrix on a
        period-``n`` orbit), ndarray of shape (2, 2); ``fy = Phi^n(y)`` if known."""
        central = self.difference == "central"
        if not central and fy is None:
            fy = self.advance(y, n)
        J = np.empty((2, 2))
        for j in range(2):
            d = self.fd_step * self.scale[j]
            yp = np.array(y, dtype=float)
            yp[j] += d
            if central:
                ym = np.array(y, dtype=float)
                ym[j] -= d
                J[:, j] = (self.advance(yp, n) - self.advance(ym, n)) / (2.0 * d)
            else:
                J[:, j] = (self.advance(yp, n) - fy) / d
        return J


@readable
@dataclass(frozen=True)
class PeriodicOrbit:
    """A periodic orbit of the stroboscopic map (or the evidence that shooting failed).

    Attributes
    ----------
    n_periods : int
        Period in forcing periods (after reduction to the smallest period, see
        :func:`~discovery.numerics.shooting.smallest_period`).
    y0 : ndarray of shape (2,)
        The orbit's state at the forcing's phase 0 (the last Newton iterate if not
        converged).
    multipliers : ndarray of shape (2,), complex
        Floquet multipliers (eigenvalues of the Jacobian of ``Phi^n`` at ``y0``); NaN
        when no Jacobian was computed.
    residual : float
        ``max |Phi^n(y0) - y0| / scale``.
    converged, stable : bool
        Newton reached ``tol``; and all ``|multipliers| < 1``.
    newton_residuals : list of float
        The residual of each Newton iteration (at the period first tried).
    reduced_from : int
        The period shooting started with (equal to ``n_periods`` when not reduced).
    n_calls : int
        Period-map evaluations used.
    """

    n_periods: int
    y0: np.ndarray
    multipliers: np.ndarray
    residual: float
    converged: bool
    stable: bool
    newton_residuals: list = field(default_factory=list)
    reduced_from: int = 0
    n_calls: int = 0

    def as_dict(self):
        return {
            "n_periods": self.n_periods,
            "y0": [float(v) for v in self.y0],
            "multipliers_abs": [float(abs(m)) for m in self.multipliers],
            "multipliers": [[float(m.real), float(m.imag)] for m in self.multipliers],
            "residual": float(self.residual),
            "converged": self.converged,
            "stable": self.stable,
            "newton_residuals": [float(r) for r in self.newton_residuals],
            "reduced_from": self.reduced_from,
            "n_calls": self.n_calls,
        }

    def _lines(self):
        mult = np.abs(np.asarray(self.multipliers))
        state = ("stable" if self.stable else "unstable") if self.converged else "NOT converged"
        reduced = (
            f" (reduced from P{self.reduced_from})"
            if self.reduced_from not in (0, self.n_periods)
            else ""
        )
        return [
            f"periodic orbit P{self.n_periods}{reduced}: {state}, |Floquet multipliers| "
            + ", ".join(fmt(m, 3) for m in mult)
            + f", residual {fmt(self.residual, 2)}",
            f"  at phase 0: x {fmt(self.y0[0], 6)}, v {fmt(self.y0[1], 6)}; "
            f"{self.n_calls} period-map evaluations",
        ]


@params(
    system=(UedaSystem, None),
    y0=Array(1),
    n=Real(1, integer=True),
    tol=Real(0, open_low=True),
    max_newton=Real(1, integer=True),
    tolerances=(Tolerances, None),
)
def periodic_orbit(
    system, y0, n=1, *, tol=1e-8, max_newton=12, reduce=True, tolerances=None, period_map=None
):
    """Converge the period-``n`` orbit near ``y0`` by shooting; its Floquet multipliers.

    Parameters
    ----------
    system : UedaSystem
    y0 : (x, v)
        A state at the forcing's phase 0 near the orbit (e.g. the last strobe point).
    n : int
        Period in forcing periods (what the recurrence of the strobe points suggests).
    tol : float
        Newton tolerance on ``max |Phi^n(y) - y| / scale``.
    max_newton : int
        Newton iterations (per period tried).
    reduce : bool
        For a stable orbit with ``n > 1``, look for a smaller period dividing ``n``.
    tolerances : Tolerances, optional
    period_map : UedaMap, optional
        The map to use (its counters keep counting); default a new one.

    Returns
    -------
    PeriodicOrbit
    """
    pm = period_map if period_map is not None else UedaMap(system, tolerances)
    calls0 = pm.n_calls
    n = int(n)
    hist = []
    y, res, J, ok = newton_orbit(pm, _y0(y0), n, tol=tol, max_iter=max_newton, history=hist)
    mult = floquet_multipliers(J, 2)
    stable = bool(ok and is_stable(mult))
    m = n
    if stable and reduce and n > 1:
        red = smallest_period(pm, y, n, tol, max_newton)
        if red is not None:
            m, y, res, J, _ = red
            mult = floquet_multipliers(J)
    return PeriodicOrbit(
        n_periods=m,
        y0=np.asarray(y, dtype=float),
        multipliers=mult,
        residual=float(res),
        converged=bool(ok),
        stable=stable,
        newton_residuals=[float(r) for r in hist],
        reduced_from=n,
        n_calls=pm.n_calls - calls0,
    )
