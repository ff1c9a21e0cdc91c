"""Identification by simulation: minimise a criterion over a law's coefficients.

Every objective evaluation is a full simulation to the periodic steady state and a
comparison of its impulse with the measured one.  Coefficients are optimised in
units of the start values (``x_i = c_i / c_i^start``) so all methods see a
well-scaled problem.  Methods:

``coordinate-descent``
    The paper's accelerated coordinate descent: along each coefficient in turn
    try a step, double it while it keeps improving, else try the other direction,
    else halve it; stop when every step is below ``xtol``.
``nelder-mead``
    scipy's Nelder–Mead simplex (derivative-free).
``least-squares``
    scipy's trust-region least squares on the residual vector
    ``(F_N - F_E)`` weighted so that its squared norm is ``I3^2`` (a smooth
    surrogate, Gauss–Newton fast); the chosen criterion is reported.
"""

import time
from dataclasses import dataclass, field

import numpy as np
from scipy.optimize import least_squares, minimize

from .criteria import compare, criterion, evaluate_criteria
from .errors import InputError, IntegrationError
from .response import response

__all__ = ["IdentificationResult", "identify", "METHODS"]

METHODS = ("coordinate-descent", "nelder-mead", "least-squares")
_PENALTY = 10.0


@dataclass(frozen=True)
class IdentificationResult:
    """Outcome of :func:`identify`.

    Attributes
    ----------
    law : ForceLaw
        Identified law.
    criterion : str
        The criterion minimised (reported for every method).
    value : float
        Its final value.
    criteria : dict
        All criteria ``I0..I4`` at the identified law.
    method : str
    n_simulations : int
        Steady-state simulations used.
    iterations : list of dict
        Every iterate: ``coefficients`` {term: value}, ``value``, ``n_simulations``.
    seconds : float
    message : str
    """

    law: object
    criterion: str
    value: float
    criteria: dict
    method: str
    n_simulations: int
    iterations: list = field(default_factory=list)
    seconds: float = 0.0
    message: str = ""

    @property
    def coefficients(self):
        return self.law.as_dict()


class _Objective:
    """Counts simulations, caches them, and records the best-so-far path."""

    def __init__(self, scenario, start, measured, name, sampled, tolerances):
        self.scenario, self.start, self.measured = scenario, start, measured
        self.name, self.sampled, self.tol = name, sampled, tolerances
        self.func = criterion(name)
        self.c0 = np.array(start.coefficients)
        self.n = 0
        self.cache = {}
        self.best = (np.inf, None)
        self.path = []
        # residual weights: trapezoid-like sample spacing, normalised so that the sum
        # of squared residuals is I3^2
        E = measured
        self.w = np.sqrt(np.gradient(E.t) / max(np.trapezoid(E.F**2, E.t), 1e-300))

    def law(self, x):
        return self.start.with_coefficients(self.c0 * np.asarray(x))

    def impulse(self, x):
        key = tuple(np.round(np.asarray(x, dtype=float), 14))
        if key not in self.cache:
            self.n += 1
            try:
                r = response(self.scenario, self.law(x), tolerances=self.tol)
                imp = r.impulse
                if imp is not None and self.sampled:
                    imp = imp.resampled_like(self.measured)
            except IntegrationError:
                imp = None
            self.cache[key] = imp
        return self.cache[key]

    def __call__(self, x):
        imp = self.impulse(x)
        if imp is None:
            return _PENALTY
        v = float(self.func(compare(self.measured, imp)))
        if v < self.best[0]:
            self.best = (v, np.array(x, dtype=float))
            self.path.append({"coefficients": self.law(x).as_dict(), "value": v,
                              "n_simulations": self.n})
        return v

    def residuals(self, x):
        imp = self.impulse(x)
        E, w = self.measured, self.w
        if imp is None:
            return (np.full(E.t.size, _PENALTY) * w * max(np.max(np.abs(E.F)), 1.0))[1:]
        self(x)  # records the path with the requested criterion
        fn = imp.evaluate(E.t, "left")
        # the onset value F_E(0+) is extrapolated from samples: it is left out so the
        # fit is not biased by the extrapolation error at the jump
        return ((fn - E.F) * w)[1:]


def _coordinate_descent(obj, x0, xtol, max_sim, step0=0.1):
    x = np.array(x0, dtype=float)
    fx = obj(x)
    steps = np.full(x.size, step0)
    while np.any(steps > xtol) and obj.n < max_sim:
        for i in range(x.size):
            if steps[i] <= xtol or obj.n >= max_sim:
                continue
            improved = False
            for direction in (1.0, -1.0):
                trial = x.copy()
                trial[i] += direction * steps[i]
                ft = obj(trial)
                if ft < fx:
                    x, fx, improved = trial, ft, True
                    # accelerate: keep going and double the step while it pays
                    while obj.n < max_sim:
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


def identify(scenario, measured, start, *, criterion="I2", method="coordinate-descent",
             xtol=1e-5, max_simulations=600, sampled=True, tolerances=None):
    """Identify the coefficients of ``start`` from a measured impulse by simulation.

    Parameters
    ----------
    scenario : Scenario
        The known part of the machine.
    measured : Impulse
        ``F_E`` (e.g. :meth:`Measurement.impulse`).
    start : ForceLaw
        Terms to identify and their start values (all non-zero).
    criterion : str
        Criterion to minimise (``I0``..``I4``).
    method : str
        One of :data:`METHODS`.
    xtol : float
        Relative coefficient tolerance.
    max_simulations : int
        Simulation budget.
    sampled : bool
        Compare ``F_N`` sampled like the measurement (default) or exact.
    tolerances : Tolerances, optional

    Returns
    -------
    IdentificationResult
    """
    if method not in METHODS:
        raise InputError(f"unknown method {method!r}; valid methods: {', '.join(METHODS)}")
    if any(c == 0 for c in start.coefficients):
        raise InputError("every start coefficient must be non-zero (they set the scale)")
    t0 = time.perf_counter()
    obj = _Objective(scenario, start, measured, criterion, sampled, tolerances)
    x0 = np.ones(len(start.coefficients))
    if method == "coordinate-descent":
        _coordinate_descent(obj, x0, xtol, max_simulations)
        message = "steps below xtol" if obj.n < max_simulations else "simulation budget used"
    elif method == "nelder-mead":
        simplex = np.vstack([x0] + [x0 + 0.1 * np.eye(x0.size)[i] for i in range(x0.size)])
        res = minimize(obj, x0, method="Nelder-Mead",
                       options={"xatol": xtol, "fatol": 1e-12, "maxfev": max_simulations,
                                "initial_simplex": simplex})
        message = res.message
    else:
        res = least_squares(obj.residuals, x0, method="trf", x_scale=1.0, diff_step=1e-6,
                            xtol=xtol * 1e-2, ftol=1e-12, gtol=1e-12,
                            max_nfev=max_simulations)
        message = res.message
    x_best = obj.best[1] if obj.best[1] is not None else x0
    law = obj.law(x_best)
    imp = obj.impulse(x_best)
    crit = evaluate_criteria(measured, imp) if imp is not None else {}
    return IdentificationResult(
        law=law, criterion=criterion, value=float(obj.best[0]), criteria=crit, method=method,
        n_simulations=obj.n, iterations=obj.path, seconds=time.perf_counter() - t0,
        message=str(message))
