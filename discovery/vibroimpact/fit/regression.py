"""Sparse regression of contact-force laws under certified physical conditions.

:class:`ConstrainedSparseRegressor` follows scikit-learn's estimator contract
(``__init__`` stores its arguments; ``fit`` validates and learns ``coef_``,
``support_``, ...; ``predict``, ``score``, ``get_params``/``set_params``).

Every fitted law satisfies the paper's conditions on the whole box
``D = [0, zeta_max] x [0, zd_max]`` (from the data, with a margin): non-adhesion (4)
and dissipativity (6), optionally a monotone elastic branch and coefficient signs.
They are imposed through Bernstein certificates (:mod:`constraints`) as linear
constraints of a cvxpy problem, and every selected law is verified independently on
a dense grid.  A solver failure raises with the solver's status; nothing is zeroed.
A support on which the constraints cannot hold at all (e.g. a dissipativity margin with no
``zd`` term to meet it) is infeasible: it is skipped and recorded in ``infeasible_``; only when
no proposed support is feasible does the fit raise.  When the requested solver fails on a
support, the other of CLARABEL/OSQP is tried once; every such fallback is recorded in
``fallbacks_`` and in the candidate's ``extra["solver"]``.

Selection methods
    ``best-subset``  exact best subset of each size under the constraints
                     (branch and bound: a constrained residual is never below the
                     unconstrained one, so most subsets need no cvxpy solve);
    ``l1-path``      constrained lasso path (one cvxpy problem, re-solved over lambda);
    ``stlsq``, ``sr3``  pysindy's optimizers propose supports;
    ``constrained-sr3`` pysindy's ConstrainedSR3 with the conditions at the samples.
Every support a method proposes is re-fitted under the certified constraints and
scored by BIC and AIC; K-fold cross-validation over whole impacts is computed when
``scoring="cv"`` or ``cv_report=True`` (``cv_error`` is ``nan`` otherwise).
"""

import time
from dataclasses import dataclass, field

import numpy as np
from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.exceptions import NotFittedError as SkNotFittedError
from sklearn.utils.validation import check_is_fitted

from constraints import Box, certify, require

from ..._api._printing import coefficient_lines, fmt, readable
from ..._api._validate import Array, check
from ...errors import InputError, VidiError
from ..model.library import Library
from .constrained_lsq import _Constraints, _InfeasibleSupport, _Problem, _weights_and_groups
from .proposals import _best_subsets, _l1_path, _pysindy_supports

__all__ = ["ConstrainedSparseRegressor", "Candidate", "SELECTIONS", "SCORES"]

SELECTIONS = ("best-subset", "l1-path", "stlsq", "sr3", "constrained-sr3")
SCORES = ("bic", "aic", "cv")


class NotFittedError(VidiError, SkNotFittedError):
    """The estimator is used before :meth:`ConstrainedSparseRegressor.fit` (a ``VidiError``
    and scikit-learn's ``NotFittedError``)."""


@readable
@dataclass(frozen=True)
class Candidate:
    """One fitted support.

    Attributes
    ----------
    terms : tuple of str
    coefficients : dict
        ``{term: value}`` in SI units.
    rss : float
        Weighted residual sum of squares [N^2].
    bic, aic : float
    cv_error : float
        Cross-validated relative RMS error (``nan`` when not computed).
    constrained : bool
        Whether any physical constraint was active at the solution.
    extra : dict
        ``"solver"``: what produced the coefficients (``"lstsq"`` when no constraint is
        active, else the cvxpy solver that succeeded, the fallback one if the requested
        solver failed).
    """

    terms: tuple
    coefficients: dict
    rss: float
    bic: float
    aic: float
    cv_error: float = float("nan")
    constrained: bool = False
    extra: dict = field(default_factory=dict)

    @property
    def size(self):
        return len(self.terms)

    def as_dict(self):
        return {
            "terms": list(self.terms),
            "coefficients": self.coefficients,
            "rss": self.rss,
            "bic": self.bic,
            "aic": self.aic,
            "cv_error": self.cv_error,
            "constrained": self.constrained,
            **self.extra,
        }

    def _lines(self):
        cv = "" if np.isnan(self.cv_error) else f", cross-validated error {fmt(self.cv_error, 3)}"
        return [
            f"support {' + '.join(self.terms) or '(none)'}: rss {fmt(self.rss, 4)} N², BIC "
            f"{fmt(self.bic, 6)}, AIC {fmt(self.aic, 6)}{cv}"
            + (", a constraint active" if self.constrained else ""),
            *coefficient_lines(self.coefficients),
        ]


class ConstrainedSparseRegressor(RegressorMixin, BaseEstimator):
    """Sparse, physically certified regression of ``F`` on a term library.

    Parameters
    ----------
    library : str or Library
        Candidate terms, e.g. ``"poly:2"``, ``"poly:3+hc"``, ``"z,zd,z*zd"``.
    selection : str
        One of :data:`SELECTIONS`.
    scoring : {"bic", "aic", "cv"}
        How the final support is chosen among the candidates.
    max_terms : int
        Largest support considered by ``best-subset``.
    cv : int
        Folds of the cross-validation over impacts.
    margin : float
        Dissipativity strictness margin [N s/m] (0 = certified >= 0).
    monotone : bool
        Also require a monotone elastic branch ``dF/dzeta(zeta, 0) >= 0``.
    signs : None, int or sequence of int
        Coefficient signs (+1, -1, 0 = free) per library term.
    box_margin : float
        The box is the data's range enlarged by this fraction.
    elevation : int
        Bernstein degree elevation (tighter certificates when larger).
    threshold : float
        Threshold of the pysindy optimizers (scaled units).
    n_lambdas : int
        Points on the ``l1-path``.
    solver : str
        cvxpy solver (when it fails on a support, the other of CLARABEL/OSQP is tried).
    grid : int
        Points per axis of the independent verification grid.
    cv_report : bool
        Compute the cross-validation error of every candidate even when ``scoring`` is not
        ``"cv"`` (it costs ``cv`` refits of every candidate).

    Attributes
    ----------
    library_ : Library
    box_ : constraints.Box
    coef_ : ndarray of shape (n_terms,)
        Physical coefficients (zeros off the support).
    support_ : ndarray of shape (n_terms,), bool
    law_ : ForceLaw
    candidates_ : list of Candidate
        One per feasible proposed support, best first by ``scoring``.
    infeasible_ : list of dict
        Proposed supports skipped because no coefficients on them satisfy the constraints:
        ``{"support": terms, "reason": str}``.
    fallbacks_ : list of dict
        Solves where ``solver`` failed and the fallback succeeded: ``{"support": terms,
        "solver": fallback solver, "failed": requested solver, "status": its status,
        "stage": "fit" or "cv"}``.
    certificate_ : constraints.Certificate
    n_features_in_ : int
        2 (``zeta``, ``dzeta``).
    n_solves_ : int
        cvxpy solves used.
    fit_seconds_ : float
    """

    def __init__(
        self,
        library="poly:2",
        *,
        selection="best-subset",
        scoring="bic",
        max_terms=4,
        cv=5,
        margin=0.0,
        monotone=False,
        signs=None,
        box_margin=0.1,
        elevation=2,
        threshold=0.05,
        n_lambdas=30,
        solver="CLARABEL",
        grid=1001,
        cv_report=False,
    ):
        self.library = library
        self.selection = selection
        self.scoring = scoring
        self.max_terms = max_terms
        self.cv = cv
        self.margin = margin
        self.monotone = monotone
        self.signs = signs
        self.box_margin = box_margin
        self.elevation = elevation
        self.threshold = threshold
        self.n_lambdas = n_lambdas
        self.solver = solver
        self.grid = grid
        self.cv_report = cv_report

    # ------------------------------------------------------------------ fit
    def fit(self, X, y, groups=None, sample_weight=None):
        """Fit on ``X[:, 0] = zeta`` [m], ``X[:, 1] = dzeta`` [m/s], ``y = F`` [N].

        Parameters
        ----------
        X : array_like of shape (n_samples, 2)
        y : array_like of shape (n_samples,)
        groups : array_like of shape (n_samples,), optional
            Impact index of each sample (cross-validation folds keep impacts whole);
            default: every sample its own group.
        sample_weight : array_like of shape (n_samples,), optional

        Returns
        -------
        self
        """
        check("ConstrainedSparseRegressor.fit: X", X, Array(2))
        check("ConstrainedSparseRegressor.fit: y", y, Array())
        t0 = time.perf_counter()
        self._validate()
        X = np.asarray(X, dtype=float)
        y = np.asarray(y, dtype=float).ravel()
        if X.ndim != 2 or X.shape[1] != 2 or X.shape[0] != y.size or y.size < 3:
            raise InputError(
                f"X must be (n_samples, 2) = (zeta, dzeta) and y (n_samples,); got "
                f"{X.shape} and {y.shape}"
            )
        if not (np.all(np.isfinite(X)) and np.all(np.isfinite(y))):
            raise InputError("X and y must be finite")
        w, groups = _weights_and_groups(y.size, sample_weight, groups)
        self.library_ = Library.parse(self.library)
        if self.signs is not None:
            sg = np.atleast_1d(np.asarray(self.signs))
            if sg.size not in (1, len(self.library_)) or not np.all(np.isin(sg, (-1, 0, 1))):
                raise InputError(
                    f"signs must be one of -1, 0, +1 or one per library term "
                    f"({len(self.library_)}); got {self.signs!r}"
                )
        zp = np.maximum(X[:, 0], 0.0)
        vp = np.maximum(X[:, 1], 0.0)
        if not (zp.max() > 0 and vp.max() > 0):
            raise InputError("the data need samples with zeta > 0 and dzeta > 0 (loading)")
        self.box_ = Box(zp.max() * (1 + self.box_margin), vp.max() * (1 + self.box_margin))
        self.n_features_in_ = 2
        prob = self._problem(X, y, w)
        supports = self._propose(prob)
        cands = []
        for idx in supports:
            try:
                x, rss, active, used = prob.fit_support(list(idx))
            except _InfeasibleSupport:
                continue  # recorded in prob.infeasible
            bic, aic = prob.scores(rss, len(idx))
            c = prob.physical(list(idx), x)
            cands.append((idx, c, rss * prob.fscale**2, bic, aic, active, used))
        self.infeasible_ = [
            {"support": self._names(k), "reason": r} for k, r in prob.infeasible.items()
        ]
        self.fallbacks_ = [
            {
                "support": self._names(k),
                "solver": alt,
                "failed": failed,
                "status": status,
                "stage": "fit",
            }
            for k, failed, status, alt in prob.fallbacks
        ]
        if not cands:
            self._no_feasible_support()
        # cross-validation over impacts (only when it is used or asked for)
        if self.scoring == "cv" or self.cv_report:
            cv_err = self._cross_validate(X, y, w, groups, [c[0] for c in cands])
        else:
            cv_err = [float("nan")] * len(cands)
        self.candidates_ = []
        for (idx, c, rss, bic, aic, active, used), e in zip(cands, cv_err, strict=True):
            names = self._names(idx)
            self.candidates_.append(
                Candidate(
                    terms=names,
                    coefficients={n: float(c[i]) for n, i in zip(names, idx, strict=True)},
                    rss=float(rss),
                    bic=float(bic),
                    aic=float(aic),
                    cv_error=float(e),
                    constrained=bool(active),
                    extra={"solver": used},
                )
            )
        key = {"bic": lambda c: c.bic, "aic": lambda c: c.aic, "cv": lambda c: c.cv_error}
        self.candidates_.sort(key=key[self.scoring])
        best = self.candidates_[0]
        self.coef_ = np.array([best.coefficients.get(t.name, 0.0) for t in self.library_.terms])
        self.support_ = self.coef_ != 0
        self.law_ = self.library_.law(self.coef_)
        # a law that breaks a condition anywhere in the box is an error, never a warning
        self.certificate_ = require(self.certify(self.coef_))
        self.n_solves_ = prob.n_solves
        self.fit_seconds_ = time.perf_counter() - t0
        return self

    def _names(self, idx):
        return tuple(self.library_.terms[i].name for i in idx)

    def _no_feasible_support(self):
        by_reason = {}
        for rec in self.infeasible_:
            by_reason.setdefault(rec["reason"], []).append(" + ".join(rec["support"]))
        why = (
            "; ".join(f"{', '.join(sup)}: {r}" for r, sup in by_reason.items())
            or "no support was proposed"
        )
        opts = (
            f"margin {self.margin:g} N s/m"
            + (", monotone" if self.monotone else "")
            + ("" if self.signs is None else f", signs {self.signs!r}")
        )
        raise InputError(
            f"no proposed support of library {self.library!r} can satisfy the "
            f"physical constraints ({opts}): {why}; add a term they act on, raise "
            "max_terms or relax the margin/signs"
        )

    def rescore(
        self, coef, X, y, sample_weight=None, groups=None, *, constrained=False, extra=None
    ):
        """A :class:`Candidate` for given physical coefficients (e.g. refined by simulation):
        its rss, BIC and AIC on ``(X, y)`` computed exactly as for the fitted candidates, and
        the cross-validated error of its support when the estimator computes one."""
        coef = np.asarray(coef, dtype=float)
        X, y = np.asarray(X, dtype=float), np.asarray(y, dtype=float)
        w, groups = _weights_and_groups(y.size, sample_weight, groups)
        prob = self._problem(X, y, w)
        r = self.library_.transform(X) @ coef - y
        rss = float(np.sum(w * r**2))
        idx = np.flatnonzero(coef != 0)
        bic, aic = prob.scores(rss / prob.fscale**2, idx.size)
        names = self._names(idx)
        cv = float("nan")
        if self.scoring == "cv" or self.cv_report:
            cv = float(self._cross_validate(X, y, w, groups, [tuple(idx)])[0])
        return Candidate(
            terms=names,
            coefficients={n: float(coef[i]) for n, i in zip(names, idx, strict=True)},
            rss=rss,
            bic=float(bic),
            aic=float(aic),
            cv_error=cv,
            constrained=constrained,
            extra=dict(extra or {}),
        )

    def certify(self, coef):
        """Independent certificate of physical coefficients on ``box_`` (Bernstein + grid)."""
        conditions = ["non_adhesion", "dissipativity"] + (
            ["monotone_elastic"] if self.monotone else []
        )
        sup = np.asarray(coef) != 0
        lib = self.library_.subset(sup)
        return certify(
            np.asarray(coef)[sup],
            lib.exponents,
            self.box_,
            conditions,
            elevation=self.elevation,
            grid=self.grid,
            margin=self.margin,
        )

    def _validate(self):
        if self.selection not in SELECTIONS:
            raise InputError(
                f"selection must be one of {', '.join(SELECTIONS)}; got {self.selection!r}"
            )
        if self.scoring not in SCORES:
            raise InputError(f"scoring must be one of {', '.join(SCORES)}; got {self.scoring!r}")
        if not (isinstance(self.max_terms, int | np.integer) and self.max_terms >= 1):
            raise InputError(f"max_terms must be a positive integer; got {self.max_terms!r}")
        if not (isinstance(self.cv, int | np.integer) and self.cv >= 2):
            raise InputError(f"cv must be an integer >= 2; got {self.cv!r}")
        if not (isinstance(self.margin, int | float | np.number) and self.margin >= 0):
            raise InputError(f"margin must be a number >= 0 (N s/m); got {self.margin!r}")
        if not (isinstance(self.box_margin, int | float | np.number) and self.box_margin >= 0):
            raise InputError(
                f"box_margin must be a number >= 0 (the box must contain the "
                f"data); got {self.box_margin!r}"
            )
        if not (isinstance(self.elevation, int | np.integer) and self.elevation >= 0):
            raise InputError(f"elevation must be an integer >= 0; got {self.elevation!r}")

    def _problem(self, X, y, w):
        constraints = _Constraints(
            box=self.box_,
            margin=self.margin,
            monotone=self.monotone,
            signs=self.signs,
            elevation=self.elevation,
        )
        return _Problem(self.library_, constraints, X, y, w, solver=self.solver)

    # ------------------------------------------------------- support proposal
    def _propose(self, prob):
        """The supports the selection method proposes (:mod:`.proposals`)."""
        if self.selection == "best-subset":
            out = _best_subsets(prob, len(self.library_), self.max_terms)
            if not out:
                self.infeasible_ = [
                    {"support": self._names(k), "reason": r} for k, r in prob.infeasible.items()
                ]
                self._no_feasible_support()
            return out
        if self.selection == "l1-path":
            return _l1_path(prob, self.max_terms, self.n_lambdas, self.solver)
        return _pysindy_supports(prob, self.selection, self.threshold)

    def _cross_validate(self, X, y, w, groups, supports):
        ug = np.unique(groups)
        k = min(self.cv, ug.size)
        if k < 2:
            return [float("nan")] * len(supports)
        rng = np.random.default_rng(0)
        fold_of = dict(zip(rng.permutation(ug), np.arange(ug.size) % k, strict=True))
        fold = np.array([fold_of[g] for g in groups])
        errs = np.zeros(len(supports))
        den = 0.0
        for f in range(k):
            tr, te = fold != f, fold == f
            sub = self._problem(X[tr], y[tr], w[tr])
            theta = self.library_.transform(X[te])
            for j, idx in enumerate(supports):
                x, _, _, _ = sub.fit_support(list(idx))
                c = sub.physical(list(idx), x)
                r = theta @ c - y[te]
                errs[j] += float(np.sum(w[te] * r * r))
            den += float(np.sum(w[te] * y[te] ** 2))
            self.fallbacks_ += [
                {
                    "support": self._names(key),
                    "solver": alt,
                    "failed": failed,
                    "status": status,
                    "stage": "cv",
                }
                for key, failed, status, alt in sub.fallbacks
            ]
        return list(np.sqrt(errs / den))

    # --------------------------------------------------------------- predict
    def predict(self, X):
        """Contact force [N] at ``X`` (conditions (3)-(5) applied)."""
        try:
            check_is_fitted(self)
        except SkNotFittedError as exc:
            raise NotFittedError(str(exc)) from None
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != self.n_features_in_:
            raise InputError(
                f"X has shape {X.shape}; the estimator is expecting "
                f"{self.n_features_in_} features (zeta, dzeta)"
            )
        return self.law_(X[:, 0], X[:, 1])

    def stability(self, X, y, groups, *, n_resamples=50, random_state=0, sample_weight=None):
        """How often each term is selected over bootstrap resamples of whole impacts.

        Each resample draws impacts (those of non-zero total weight) with replacement and
        refits with their samples' weights; an impact drawn twice enters as two distinct
        impacts (its own group id each time), so the refit's cross-validation never splits
        or merges them.

        Parameters
        ----------
        X, y, groups
            As for :meth:`fit` (``groups`` required: impacts are what is resampled).
        n_resamples : int
        random_state : int
        sample_weight : array_like of shape (n_samples,), optional

        Returns
        -------
        dict
            ``{term: frequency in [0, 1]}`` for every library term.
        """
        X = np.asarray(X, dtype=float)
        y = np.asarray(y, dtype=float).ravel()
        if groups is None:
            raise InputError("stability needs the impact of every sample (groups)")
        w, groups = _weights_and_groups(y.size, sample_weight, groups)
        rng = np.random.default_rng(random_state)
        ug = np.unique(groups[w > 0])  # an impact of zero weight is no data: never drawn
        members = [np.flatnonzero(groups == g) for g in ug]
        lib = Library.parse(self.library)
        counts = np.zeros(len(lib))
        for _ in range(n_resamples):
            pick = rng.choice(ug.size, size=ug.size, replace=True)
            rows = np.concatenate([members[g] for g in pick])
            # a duplicated impact is a new impact: group id = its position in the draw
            new_groups = np.repeat(np.arange(pick.size), [members[g].size for g in pick])
            est = ConstrainedSparseRegressor(
                **{**self.get_params(), "cv": 2, "grid": 101, "cv_report": False}
            )
            est.fit(X[rows], y[rows], groups=new_groups, sample_weight=w[rows])
            counts += est.support_
        return {t.name: float(c / n_resamples) for t, c in zip(lib.terms, counts, strict=True)}
