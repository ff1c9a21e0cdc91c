"""The supports a selection method proposes to the certified regression: the exact best
subset of each size, the constrained lasso path, pysindy's optimizers over a threshold
path."""

import itertools
import math

import numpy as np

from constraints import cvxpy as cp
from constraints import solve

from ...errors import InputError
from .constrained_lsq import _InfeasibleSupport


def _best_subsets(prob, n, max_terms):
    """Exact best certified subset of each size up to ``max_terms`` of a library of ``n``
    terms (branch and bound on the RSS); empty when no subset is feasible."""
    if n > 16:
        raise InputError(
            f"best-subset handles libraries up to 16 terms (got {n}); use l1-path or stlsq"
        )
    out = []
    for k in range(1, min(max_terms, n) + 1):
        subsets = [list(s) for s in itertools.combinations(range(n), k)]
        unc = []
        for idx in subsets:
            x, rss = prob.unconstrained(idx)
            unc.append((rss, idx, x))
        unc.sort(key=lambda r: r[0])
        best_rss, best_idx = math.inf, None
        for rss, idx, x in unc:
            if rss >= best_rss * (1 + 1e-9) + 1e-300:
                break  # no later subset can beat the best constrained fit
            if prob.feasible(idx, x):
                if rss < best_rss:
                    best_rss, best_idx = rss, idx
                break  # feasible and smallest remaining unconstrained RSS
            try:
                _, crss, _ = prob.constrained(idx)  # a solver failure raises
            except _InfeasibleSupport:
                continue  # no coefficients on this subset are physical: recorded, skipped
            if crss < best_rss:
                best_rss, best_idx = crss, idx
        if best_idx is not None:
            out.append(tuple(best_idx))
    return out


def _l1_path(prob, max_terms, n_lambdas, solver):
    """The supports of ``n_lambdas`` points of the constrained lasso path (at most
    ``max_terms`` terms each)."""
    n = len(prob.library)
    x = cp.Variable(n)
    lam = cp.Parameter(nonneg=True)
    Q, R = np.linalg.qr(prob.A)  # k x k data in the cvxpy problem, whatever n is
    obj = cp.sum_squares(R @ x - Q.T @ prob.b) + lam * cp.norm1(x)
    problem = cp.Problem(cp.Minimize(obj), [prob.M @ x + prob.off >= 0])
    lam_max = 2 * float(np.max(np.abs(prob.h)))
    supports = []
    for value in np.geomspace(lam_max, lam_max * 1e-6, n_lambdas):
        lam.value = value
        solve(problem, solver)
        prob.n_solves += 1
        xv = np.asarray(x.value)
        idx = tuple(np.flatnonzero(np.abs(xv) > 1e-6 * max(np.max(np.abs(xv)), 1e-300)))
        if idx and idx not in supports and len(idx) <= max_terms:
            supports.append(idx)
    if not supports:
        raise InputError("the l1 path selected no term; lower box_margin or check the data")
    return supports


def _pysindy_supports(prob, selection, threshold):
    """Supports proposed by a pysindy optimizer (``selection``) over a threshold path.

    pysindy's ConstrainedSR3 returns no exact zeros, so a term counts as proposed
    when ``|x_i| > 1e-3 max |x|`` (scaled units) for every pysindy method.
    """
    import warnings

    import pysindy as ps

    supports = []
    for thr in threshold * np.geomspace(0.1, 10.0, 9):
        if selection == "stlsq":
            opt = ps.STLSQ(threshold=thr, alpha=1e-8)
        elif selection == "sr3":
            opt = ps.SR3(reg_weight_lam=thr**2 / 2, regularizer="L0")
        else:
            opt = _pysindy_constrained(prob, thr)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            opt.fit(prob.A, prob.b)
        coef = np.asarray(opt.coef_).ravel()
        big = np.max(np.abs(coef)) if coef.size else 0.0
        idx = tuple(np.flatnonzero(np.abs(coef) > 1e-3 * big)) if big > 0 else ()
        if idx and idx not in supports:
            supports.append(idx)
    if not supports:
        raise InputError(
            f"pysindy's {selection} selected no term at any threshold "
            f"around {threshold}; change threshold"
        )
    return supports


def _pysindy_constrained(prob, thr):
    """pysindy ConstrainedSR3 with the Bernstein rows as (sample-free) inequalities."""
    import pysindy as ps

    return ps.ConstrainedSR3(
        reg_weight_lam=thr,
        regularizer="L1",
        constraint_lhs=-prob.M,
        constraint_rhs=prob.off,
        constraint_order="feature",
        inequality_constraints=True,
    )
