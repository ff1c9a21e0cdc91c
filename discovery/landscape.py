"""Criteria landscapes over a grid of two coefficients (the paper's Figs. 4-5).

Every grid point is an independent full computation (steady state from the
scenario's initial state, exact impulse, all criteria against the reference), so
points are computed in parallel processes and the result does not depend on the
order of evaluation.
"""

import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from multiprocessing import get_context

import numpy as np

from .criteria import CRITERIA, evaluate_criteria
from .errors import InputError, IntegrationError
from .response import response

__all__ = ["Landscape", "landscape", "parse_grid"]


@dataclass(frozen=True)
class Landscape:
    """Criteria over ``axes[0] x axes[1]`` coefficient values.

    Attributes
    ----------
    terms : tuple of str
        The two varied terms.
    axes : tuple of ndarray
        Values of the first and the second coefficient.
    values : dict
        ``name -> ndarray of shape (len(axes[0]), len(axes[1]))``; NaN where the
        point has no periodic steady state with contact.
    regime : ndarray of shape (len(axes[0]), len(axes[1])), dtype object
        ``"P1"``, ``"P2"``, ... or ``"nonperiodic"`` (``"no-contact"`` if periodic
        but without impact).
    seconds : float
        Wall time.
    workers : int
    """

    terms: tuple
    axes: tuple
    values: dict
    regime: np.ndarray
    seconds: float
    workers: int

    def argmin(self, name):
        """Index ``(i, j)`` of the smallest value of criterion ``name``."""
        v = np.where(np.isnan(self.values[name]), np.inf, self.values[name])
        return np.unravel_index(int(np.argmin(v)), v.shape)


def parse_grid(text):
    """``'41x41'`` -> ``(41, 41)``."""
    try:
        a, b = (int(v) for v in str(text).lower().split("x"))
    except ValueError:
        raise InputError(f"grid {text!r} must look like 41x41") from None
    if a < 2 or b < 2 or a * b > 250_000:
        raise InputError(f"grid {text!r} needs at least 2 points per axis and at most 250000 "
                         "points in all")
    return a, b


_CTX = {}


def _init(scenario, law, reference, tolerances):
    _CTX.update(scenario=scenario, law=law, reference=reference, tolerances=tolerances)


def _row(args):
    i, v0, axis1 = args
    sc, law, ref = _CTX["scenario"], _CTX["law"], _CTX["reference"]
    out = []
    for v1 in axis1:
        coefs = list(law.coefficients)
        coefs[0], coefs[1] = v0, v1
        try:
            r = response(sc, law.with_coefficients(coefs), tolerances=_CTX["tolerances"])
        except IntegrationError:
            out.append(("nonperiodic", None))
            continue
        if r.impulse is None:
            out.append((r.regime if not r.steady.periodic else "no-contact", None))
            continue
        out.append((r.regime, evaluate_criteria(ref, r.impulse)))
    return i, out


def landscape(scenario, law, axis0, axis1, reference=None, *, workers=None, tolerances=None):
    """Compute all criteria over a grid of the first two coefficients of ``law``.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
        Template law; its first two coefficients are varied (others kept).
    axis0, axis1 : array_like
        Values of the first and second coefficient.
    reference : Impulse, optional
        ``F_E``; default the exact impulse of ``scenario.law``.
    workers : int, optional
        Processes (default: all cores).
    tolerances : Tolerances, optional

    Returns
    -------
    Landscape
    """
    if len(law.terms) < 2:
        raise InputError("a landscape varies two coefficients; the law needs two terms")
    axis0 = np.asarray(axis0, dtype=float)
    axis1 = np.asarray(axis1, dtype=float)
    t_start = time.perf_counter()
    if reference is None:
        if scenario.law is None:
            raise InputError(f"scenario {scenario.name!r} has no reference law; add [law] text")
        reference = response(scenario, scenario.law, tolerances=tolerances).impulse
        if reference is None:
            raise InputError("the reference law has no periodic steady state with contact")
    workers = workers or os.cpu_count() or 1
    regime = np.empty((axis0.size, axis1.size), dtype=object)
    values = {n: np.full((axis0.size, axis1.size), np.nan) for n in CRITERIA}
    jobs = [(i, v0, axis1) for i, v0 in enumerate(axis0)]
    init = (scenario, law, reference, tolerances)
    if workers == 1:
        _init(*init)
        results = map(_row, jobs)
        pool = None
    else:
        pool = ProcessPoolExecutor(workers, mp_context=get_context("fork"), initializer=_init,
                                   initargs=init)
        results = pool.map(_row, jobs)
    try:
        for i, row in results:
            for j, (reg, crit) in enumerate(row):
                regime[i, j] = reg
                if crit is not None:
                    for n, v in crit.items():
                        values[n][i, j] = v
    finally:
        if pool is not None:
            pool.shutdown()
    return Landscape(terms=tuple(law.names[:2]), axes=(axis0, axis1), values=values,
                     regime=regime, seconds=time.perf_counter() - t_start, workers=workers)
