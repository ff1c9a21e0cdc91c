"""The optimisers of an output-error fit over a :class:`~.problem._Objective`: the paper's
coordinate descent, scipy's Nelder-Mead and trust-region least squares, restarts from the best
point, and the settings they check.
"""

from typing import NamedTuple

import numpy as np
from scipy.optimize import least_squares, minimize

from ...errors import InputError, IntegrationError, VidiTypeError
from ..model.law import ForceLaw
from .problem import _Budget, _NotFinite
from .records import as_records

__all__ = ["METHODS", "RESTART_FACTORS"]

METHODS = ("coordinate-descent", "nelder-mead", "least-squares")


def _coordinate_descent(obj, x0, xtol, step0=0.1):
    x = np.array(x0, dtype=float)
    fx = obj(x)
    steps = np.full(x.size, step0)
    while np.any(steps > xtol):
        for i in range(x.size):
            if steps[i] <= xtol:
                continue
            improved = False
            for direction in (1.0, -1.0):
                trial = x.copy()
                trial[i] += direction * steps[i]
                ft = obj(trial)
                if ft < fx:
                    x, fx, improved = trial, ft, True
                    # accelerate: keep going and double the step while it pays
                    while True:
                        steps[i] *= 2.0
                        trial = x.copy()
                        trial[i] += direction * steps[i]
                        ft = obj(trial)
                        if ft >= fx:
                            steps[i] *= 0.5
                            break
                        x, fx = trial, ft
                    break
            if not improved:
                steps[i] *= 0.5
    return x


def _checked(scenario, reference, start, *, max_simulations):
    """The arguments :func:`identify` checks beyond its settings' fields (the start, and
    the budget against the records: two simulations per record); returns the records."""
    if isinstance(start, str):
        raise VidiTypeError(
            f"identify: start must be a ForceLaw or a Model (parse text with "
            f"ForceLaw.parse({start[:30]!r})); got str"
        )
    if any(c == 0 for c in start.coefficients):
        raise InputError("every start coefficient must be non-zero (they set the scale)")
    records = as_records(scenario, reference)
    if not (isinstance(max_simulations, int | np.integer) and max_simulations >= 2 * len(records)):
        raise InputError(
            f"the simulation budget must be an integer of at least "
            f"{2 * len(records)} (two per record); got {max_simulations!r}"
        )
    return records


def _x_bounds(model):
    """Bounds of the least-squares variables ``x = c / c_start``: an observation model's
    parameter (a sensor's time constant) within its physical bounds, so the trust region
    does not step beyond a bound the model clips to (a step to ``tau < 0`` is clipped to no
    filter, where the fit stalls).  Everything else is unbounded, the model clipping those
    parameters itself: scipy's trust region scales every bounded variable by its distance
    to the bound, which stops a fit near a bound short of the optimum."""
    c0 = np.asarray(model.coefficients, dtype=float)
    lo, hi = np.full(c0.size, -np.inf), np.full(c0.size, np.inf)
    if isinstance(model, ForceLaw):
        return lo, hi
    n = len(model.law.coefficients)
    for i, e in enumerate(model.free_effects(), start=n):
        if e.target == "observation":
            a, b = (v / c0[i] for v in e.parameters[0].bounds)
            lo[i], hi[i] = min(a, b), max(a, b)
    return lo, hi


#: iterations a least-squares fit may stay at the edge of its model's domain before it stops
EDGE_ITERATIONS = 3

#: iterations in a row a least-squares fit above the give-up screen may lower its sum of
#: squares by less than :data:`SCREEN_PROGRESS` before it stops
SCREEN_ITERATIONS = 2
SCREEN_PROGRESS = 0.1
#: how the optimiser's message begins when a fit stopped above the screen
SCREEN_STOP = "stopped above the screen"


def _above_screen(obj, give_up_above):
    """Whether ``obj``'s best criterion so far is above the screen ``give_up_above``."""
    return give_up_above is not None and obj.best[0] > give_up_above


class _StopRules:
    """A least-squares callback that stops a fit which is no result:

    * after :data:`EDGE_ITERATIONS` iterations in a row at the edge of its model's domain
      (a named contact model's stiffness clipped to its floor: its Jacobian column is then
      zero, so no step leaves it; on the README's record such fits were 70 % of the named
      models' time);
    * with ``give_up_above`` (the shortlist's screen of hopeless laws), after
      :data:`SCREEN_ITERATIONS` iterations in a row whose criterion stays above it and
      whose step lowers the sum of squares by less than :data:`SCREEN_PROGRESS`: its force
      histories differ from the record's by more than half the force and the fit only
      polishes that.  On the README's 12-period record a damping-only law walked its damper
      to 300 times the regression's in 39 simulations (2.3 s, each slower than the last: a
      contact time constant ``m / c`` of 30 ns), its criterion 0.93 -> 0.928.

    ``why``: the reason it stopped, or ``""``."""

    def __init__(self, obj, give_up_above=None):
        self.obj, self.give_up_above = obj, give_up_above
        self.run, self.slow, self.cost, self.why = 0, 0, None, ""

    def __call__(self, intermediate_result):
        edges = getattr(self.obj.law(intermediate_result.x), "edges", list)()
        self.run = self.run + 1 if edges else 0
        if self.run >= EDGE_ITERATIONS:
            self.why = f"stopped at the edge of the model's domain ({'; '.join(edges)})"
            raise StopIteration
        cost, before = float(intermediate_result.cost), self.cost
        self.cost = cost
        if self.give_up_above is None or before is None:
            return
        hopeless = _above_screen(self.obj, self.give_up_above)
        self.slow = self.slow + 1 if hopeless and cost > (1 - SCREEN_PROGRESS) * before else 0
        if self.slow >= SCREEN_ITERATIONS:
            self.why = (
                f"{SCREEN_STOP}: {self.obj.name} {self.obj.best[0]:.3g} above "
                f"{self.give_up_above:.3g}, the sum of squares lowered by less than "
                f"{SCREEN_PROGRESS:.0%} in {SCREEN_ITERATIONS} iterations"
            )
            raise StopIteration


#: Nelder-Mead stops when its best criterion has fallen by less than this share of itself over
#: the last :data:`PLATEAU_ITERATIONS` iterations: a hundredth of a percent, far below any
#: criterion's noise.  With only scipy's absolute ``fatol`` and ``xatol`` the simplex went on
#: shrinking: the bench record's start fit (explain from the linear start) reached I2
#: 0.049104 in 40 of its 120 simulations and 0.049101 in the other 80 (CHANGELOG)
PLATEAU_PROGRESS = 1e-4
PLATEAU_ITERATIONS = 10


class _Plateau:
    """A Nelder-Mead callback that stops the simplex once its best criterion has fallen by
    less than :data:`PLATEAU_PROGRESS` of itself over :data:`PLATEAU_ITERATIONS`
    iterations (the best point met is kept by the objective).  ``why``: the reason, or
    ``""``."""

    def __init__(self):
        self.best, self.why = [], ""

    def __call__(self, intermediate_result):
        best = min(float(intermediate_result.fun), self.best[-1] if self.best else np.inf)
        self.best.append(best)
        if len(self.best) <= PLATEAU_ITERATIONS:
            return
        before = self.best[-1 - PLATEAU_ITERATIONS]
        if np.isfinite(before) and before - best <= PLATEAU_PROGRESS * abs(before):
            self.why = (
                f"the criterion fell by less than {PLATEAU_PROGRESS:.2%} of itself in "
                f"{PLATEAU_ITERATIONS} iterations"
            )
            raise StopIteration


#: a least-squares fit stops when its step lowers the sum of squares by less than this share
#: of the residual variance ``s^2 = cost / dof`` (the scale of the standard errors): the
#: estimate then moves by a few hundredths of a standard error at most.  With scipy's fixed
#: ``ftol`` of 1e-12 the fits of the bench record went on for as many iterations again after
#: that point (each one a simulation and its sensitivities per record): CHANGELOG.
FTOL_VARIANCE = 1e-3


def _ftol(obj):
    """scipy's relative ``ftol`` for :data:`FTOL_VARIANCE` (``dF < ftol * F`` with ``F``
    the sum of squares, about ``s^2 * dof``)."""
    return max(FTOL_VARIANCE / obj.dof, 1e-12)


def _optimise(obj, x0, method, xtol, max_simulations, *, give_up_above=None):
    """Run ``method`` on the objective from ``x0``; returns the optimiser's message.  A
    least-squares fit stops early at the edge of its model's domain, or above
    ``give_up_above`` without progress (:class:`_StopRules`)."""
    try:
        if method == "coordinate-descent":
            _coordinate_descent(obj, x0, xtol)
            return "steps below xtol"
        if method == "nelder-mead":
            simplex = np.vstack([x0] + [x0 + 0.1 * np.eye(x0.size)[i] for i in range(x0.size)])
            plateau = _Plateau()
            res = minimize(
                obj,
                x0,
                method="Nelder-Mead",
                callback=plateau,
                options={
                    "xatol": xtol,
                    "fatol": 1e-12,
                    "maxfev": max_simulations,
                    "initial_simplex": simplex,
                },
            )
            return plateau.why or str(res.message)
        # the law's coefficients' columns exact when they can be (one run per record
        # with the variational equations), else scipy's forward differences
        watch = _StopRules(obj, give_up_above)
        res = least_squares(
            obj.residuals,
            x0,
            jac=obj.jacobian if obj.exact_columns[1] else "2-point",
            bounds=_x_bounds(obj.start),
            method="trf",
            x_scale=1.0,
            diff_step=1e-6,
            xtol=xtol * 1e-2,
            ftol=_ftol(obj),
            gtol=1e-12,
            callback=watch,
        )
        if watch.why:
            return watch.why
        return str(res.message)
    except _Budget:
        return f"simulation budget of {max_simulations} used"
    except _NotFinite:
        return "stopped: the optimiser's step was not finite (the best point met is kept)"


class Screens(NamedTuple):
    """The criterion values that cut a fit short (either None: no such cut):
    ``give_up_above``, the shortlist's screen of hopeless laws (:class:`_StopRules`; no
    restart above it), and ``restart_above``, the records' noise floor (no restart at or
    below it): :func:`_restarted`."""

    give_up_above: float | None = None
    restart_above: float | None = None


_NO_SCREENS = Screens()

RESTART_FACTORS = (1.25, 0.8)
"""After the first optimisation, it is started again from its best point with every
parameter scaled by each factor, while the budget allows, and the best point is kept (by the
sum of squares for least squares, else by the criterion).  A law refitted from a start 20 %
off can stop in a basin whose spring is too soft (another contact sequence along the
record's transient); a restart from a stiffer and a softer point often leaves such a basin
(the rates: CHANGELOG)."""


def _restarted(obj, method, xtol, max_simulations, message, *, screens=_NO_SCREENS):
    """:data:`RESTART_FACTORS` restarts from the best point (see there); the message says
    which improved it.  A fit whose criterion is still above ``give_up_above`` (the
    shortlist's screen of hopeless laws, :class:`_StopRules`) is not restarted: a restart
    leaves a wrong basin of a law that can match the record, and this one's force histories
    still differ by more than half the force (the README's damping-only law was restarted
    where each simulation took a quarter of a second: 9.8 s of the fit's 14.9 s).  A
    restart whose point is still at the edge of its model's domain (a named contact model's
    stiffness clipped to its floor, scaled, stays clipped) is not made: the clipped
    parameter's Jacobian column is zero there, so the fit would stay at the edge, which is
    no result (such restarts were 57 % of the named models' fit time on the README's
    record).  A fit whose criterion is at or below ``restart_above`` (the shortlist's
    smallest noise floor over the records: what the true law itself reaches on records this
    noisy) is not restarted either: it matches every record as well as the truth would, so
    a lower sum of squares elsewhere would be fitted noise.  Within the consistency limit
    (about twice the floor) is not enough: on the fit-sheet survey's draw 6 a first fit
    stopped at I2 0.054, within its limit 0.075, its spring 3 % stiff, and the restart from
    0.8 times it reached the floor, 0.035, and the spring within 0.5 % (``screens``:
    :class:`Screens`)."""
    give_up_above, restart_above = screens
    if _above_screen(obj, give_up_above):
        return message + (
            f"; not restarted: {obj.name} {obj.best[0]:.3g} above the screen {give_up_above:.3g}"
        )
    if restart_above is not None and obj.best[0] <= restart_above:
        return message + (
            f"; not restarted: {obj.name} {obj.best[0]:.3g} at every record's noise floor "
            f"({restart_above:.3g} or more)"
        )
    lo, hi = _x_bounds(obj.start)
    squares = method == "least-squares"
    for f in RESTART_FACTORS:
        x_best = obj.estimate(method)
        if x_best is None or obj.n + 4 * len(obj.records) > obj.max_sim:
            break
        before = obj.best_squares[0] if squares else obj.best[0]
        x = np.clip(x_best * f, np.nextafter(lo, np.inf), np.nextafter(hi, -np.inf))
        edges = getattr(obj.law(x), "edges", list)()
        if edges:
            message += f"; not restarted x {f:g}: {'; '.join(edges)}"
            continue
        _optimise(obj, x, method, xtol, max_simulations)
        after = obj.best_squares[0] if squares else obj.best[0]
        if after < before:
            what = "sum of squares" if squares else obj.name
            message += (
                f"; restarted from the best point x {f:g}: {what} {before:.3g} -> {after:.3g}"
            )
    return message


def _fitted(obj, method, xtol, max_simulations, *, restarts=True, screens=_NO_SCREENS):
    """Optimise ``obj`` from its start (``x = 1``), then restart from the best point
    (:func:`_restarted`; not with ``restarts=False``, nor when the criterion is still above
    ``screens.give_up_above`` or at most ``screens.restart_above``: :class:`Screens`):
    ``(the fitted x, the optimiser's message)``.

    Raises
    ------
    IntegrationError
        The start cannot be compared with the records.
    """
    x0 = np.ones(len(obj.start.coefficients))
    if obj.evaluations(x0) is None:
        f = obj.failures[-1]
        raise IntegrationError(
            f"the start law {obj.start} cannot be compared with the record: "
            f"{f['status']} ({f['message']}); give start values closer to "
            "the record (e.g. from vidi fit)"
        )
    message = _optimise(obj, x0, method, xtol, max_simulations, give_up_above=screens.give_up_above)
    if obj.best[1] is None:  # least squares evaluates residuals, which record the path
        obj(x0)
    if restarts:
        message = _restarted(obj, method, xtol, max_simulations, message, screens=screens)
    return obj.estimate(method), message
