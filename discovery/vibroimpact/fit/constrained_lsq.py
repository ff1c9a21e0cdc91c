"""Certified least squares on a support: the scaled problem of one library and box, its
unconstrained, precise and constrained fits (with the solver fallback), and its scores."""

import math
from dataclasses import dataclass

import numpy as np

from constraints import constraint_rows, normalized_rows, scale_factors, solve
from constraints import cvxpy as cp
from constraints.errors import SolverError

from ...errors import InputError

_RSS_FLOOR = 1e-14  # relative to mean square force: data are never more exact than this
_INFEASIBLE = ("infeasible", "infeasible_inaccurate")


class _InfeasibleSupport(SolverError):
    """No coefficients on this support satisfy the constraints (not a solver failure)."""

    def __init__(self, message):
        super().__init__(message, status="infeasible")


@dataclass(frozen=True)
class _Constraints:
    """The certified constraints a fit holds to (see :func:`constraints.constraint_rows`).

    Attributes
    ----------
    box : constraints.Box
        Where they hold: ``0 <= zeta <= Z``, ``0 <= dzeta <= V``.
    margin : float
        Dissipativity strictness margin [N s/m] (0 = certified >= 0).
    monotone : bool
        Also a monotone elastic branch ``dF/dzeta(zeta, 0) >= 0``.
    signs : None, int or sequence of int
        Coefficient signs (+1, -1, 0 = free) per library term.
    elevation : int
        Bernstein degree elevation.
    """

    box: object
    margin: float
    monotone: bool
    signs: object
    elevation: int


class _Problem:
    """Scaled least squares with the certified constraints for one library and box.

    Parameters
    ----------
    library : Library
    constraints : _Constraints
    X : ndarray of shape (n_samples, 2)
        ``zeta`` [m], ``dzeta`` [m/s].
    y : ndarray of shape (n_samples,)
        Force [N].
    w : ndarray of shape (n_samples,)
        Sample weights.
    solver : str
        cvxpy solver (the other of CLARABEL/OSQP is the fallback).
    """

    def __init__(self, library, constraints, X, y, w, *, solver):
        box, signs = constraints.box, constraints.signs
        self.library, self.box = library, box
        exps = library.exponents
        self.scale = scale_factors(exps, box)  # Z^a V^b: each term's value at the far corner
        theta = library.transform(X)
        self.fscale = float(np.sqrt(np.average(y**2, weights=w))) or 1.0
        sw = np.sqrt(w)
        self.A = theta / self.scale * sw[:, None]  # features scaled to [0, 1], weighted
        self.b = y / self.fscale * sw
        self.n = float(np.sum(w))
        self.G = self.A.T @ self.A
        self.h = self.A.T @ self.b
        self.yy = float(self.b @ self.b)
        if signs is not None:
            signs = np.broadcast_to(np.asarray(signs, dtype=float), (len(library),))
        # the rows of the cvxpy builders (constraints.builders), as one system M x + off >= 0
        # in units of fscale newtons (offsets come from the dissipativity margin)
        self.M, self.off = constraint_rows(
            exps,
            box,
            margin=constraints.margin,
            monotone=constraints.monotone,
            signs=signs,
            elevation=constraints.elevation,
            force_unit=self.fscale,
        )
        self.solver = solver
        self.n_solves = 0
        self.fallbacks = []  # (support, failed solver, its status, solver that succeeded)
        self.infeasible = {}  # support -> reason
        self._solved = {}  # support -> (x, rss, solver)

    def feasible(self, idx, x, tol=1e-10):
        return bool(np.all(self.M[:, idx] @ x + self.off >= -tol))

    def unconstrained(self, idx):
        G = self.G[np.ix_(idx, idx)]
        try:
            x = np.linalg.solve(G, self.h[idx])
        except np.linalg.LinAlgError:
            x = np.linalg.lstsq(G, self.h[idx], rcond=None)[0]
        rss = max(self.yy - 2 * self.h[idx] @ x + x @ G @ x, 0.0)
        return x, rss

    def precise(self, idx):
        """Least squares on the (weighted, scaled) data by QR: full precision."""
        x = np.linalg.lstsq(self.A[:, idx], self.b, rcond=None)[0]
        r = self.A[:, idx] @ x - self.b
        return x, float(r @ r)

    def constrained(self, idx):
        """Certified least squares on a support: ``(x, rss, solver)``.

        The data enter through a QR of the support's columns, so the cvxpy problem has
        k x k data whatever n is.  Raises :class:`_InfeasibleSupport` when no coefficients
        on the support satisfy the constraints, :class:`SolverError` when both solvers fail.
        """
        key = tuple(idx)
        if key in self._solved:
            return self._solved[key]
        if key in self.infeasible:
            raise _InfeasibleSupport(self.infeasible[key])
        # rows that vanish on this support are dropped; one with a negative offset (a margin
        # and no term it acts on) cannot hold for any coefficients
        M, off, impossible = normalized_rows(self.M[:, idx], self.off)
        if impossible.size:
            self._infeasible(
                key,
                "a constraint has no term on this support to act on (a "
                "dissipativity margin needs a term zd^b, 0 < b <= 1, without zeta)",
            )
        Q, R = np.linalg.qr(self.A[:, idx])
        qb = Q.T @ self.b
        x = cp.Variable(len(idx))
        cons = [M @ x + off >= 0] if M.shape[0] else []
        prob = cp.Problem(cp.Minimize(cp.sum_squares(R @ x - qb)), cons)
        used = self.solver
        try:
            solve(prob, self.solver)
        except SolverError as first:
            # one more interior/first-order solver before giving up (then it raises)
            used = "OSQP" if self.solver != "OSQP" else "CLARABEL"
            opts = (
                {"eps_abs": 1e-10, "eps_rel": 1e-10, "max_iter": 200000} if used == "OSQP" else {}
            )
            try:
                solve(prob, used, **opts)
            except SolverError as second:
                if first.status in _INFEASIBLE and second.status in _INFEASIBLE:
                    self._infeasible(
                        key,
                        f"{self.solver} and {used} report the constraints "
                        "infeasible on this support",
                    )
                raise SolverError(
                    f"{first}; fallback: {second}", status=second.status, solver=used
                ) from second
            self.fallbacks.append((key, self.solver, first.status, used))
        self.n_solves += 1
        xv = np.asarray(x.value, dtype=float)
        r = self.A[:, idx] @ xv - self.b
        self._solved[key] = (xv, float(r @ r), used)
        return self._solved[key]

    def _infeasible(self, key, reason):
        self.infeasible[key] = reason
        raise _InfeasibleSupport(reason)

    def fit_support(self, idx):
        """(x, rss, constrained?, solver) of the best certified fit on a support."""
        x, rss = self.precise(idx)
        if self.feasible(idx, x):
            return x, rss, False, "lstsq"
        x, rss, used = self.constrained(idx)
        return x, rss, True, used

    def physical(self, idx, x):
        c = np.zeros(len(self.library))
        c[idx] = x * self.fscale / self.scale[idx]
        return c

    def scores(self, rss, k):
        mse = max(rss / self.n, _RSS_FLOOR * self.yy / self.n)
        ll = self.n * math.log(mse)
        return ll + k * math.log(self.n), ll + 2 * k


def _weights_and_groups(n, sample_weight, groups):
    """Validated ``(weights, groups)`` for ``n`` samples (defaults: ones, one group each)."""
    w = np.ones(n) if sample_weight is None else np.asarray(sample_weight, dtype=float)
    if w.shape != (n,) or not np.all(np.isfinite(w)) or np.any(w < 0) or not w.sum() > 0:
        raise InputError(
            f"sample_weight must be {n} finite values >= 0, not all zero; got shape {w.shape}"
        )
    groups = np.arange(n) if groups is None else np.asarray(groups)
    if groups.shape != (n,):
        raise InputError(
            f"groups must give the impact of each of the {n} samples; got shape {groups.shape}"
        )
    return w, groups
