"""The certified sparse regression itself, free of scikit-learn: what every command fits.

:class:`CertifiedSparseFit` holds its options in one :class:`RegressionSettings` and learns
what :class:`~discovery.vibroimpact.fit.regression.ConstrainedSparseRegressor` (the
scikit-learn estimator, which wraps it) exposes: ``coef_``, ``support_``, ``law_``,
``candidates_``, ``box_``, ``certificate_``...  The commands use it directly: importing
scikit-learn takes 0.8 s (scipy.stats and pandas come with it), a third of a short fit.
The selection methods, constraints and scores are described in
:mod:`~discovery.vibroimpact.fit.regression`.
"""

import time
from dataclasses import asdict, dataclass, field, replace

import numpy as np

from constraints import Box, certify, require

from ..._api._printing import coefficient_lines, fmt, readable
from ..._api._validate import Array, check
from ...errors import InputError
from ..model.library import Library
from .constrained_lsq import _Constraints, _InfeasibleSupport, _Problem, _weights_and_groups
from .proposals import _best_subsets, _l1_path, _pysindy_supports

__all__ = ["CertifiedSparseFit", "RegressionSettings", "Candidate", "SELECTIONS", "SCORES"]

SELECTIONS = ("best-subset", "l1-path", "stlsq", "sr3", "constrained-sr3")
SCORES = ("bic", "aic", "cv")


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


@dataclass(frozen=True)
class RegressionSettings:
    """The options of one certified sparse regression (the keywords of
    :class:`~discovery.vibroimpact.fit.regression.ConstrainedSparseRegressor`, which
    documents each); checked when a fit starts."""

    library: object = "poly:2"
    selection: str = "best-subset"
    scoring: str = "bic"
    max_terms: int = 4
    cv: int = 5
    margin: float = 0.0
    monotone: bool = False
    signs: object = None
    box_margin: float = 0.1
    elevation: int = 2
    threshold: float = 0.05
    n_lambdas: int = 30
    solver: str = "CLARABEL"
    grid: int = 1001
    cv_report: bool = False


class CertifiedSparseFit:
    """Sparse, physically certified regression of ``F`` on a term library, without
    scikit-learn (its estimator, :class:`ConstrainedSparseRegressor`, wraps this class).

    Parameters
    ----------
    settings : RegressionSettings, optional
        Default: ``RegressionSettings()``.

    Attributes
    ----------
    The fitted attributes of :class:`ConstrainedSparseRegressor` (``library_``, ``box_``,
    ``coef_``, ``support_``, ``law_``, ``candidates_``, ``infeasible_``, ``fallbacks_``,
    ``certificate_``, ``n_features_in_``, ``n_solves_``, ``fit_seconds_``).
    """

    _name = "CertifiedSparseFit"

    def __init__(self, settings=None):
        self.settings = RegressionSettings() if settings is None else settings

    def get_params(self, deep=True):
        """The settings as keywords (those of :class:`ConstrainedSparseRegressor`)."""
        return asdict(self.settings)

    def __repr__(self):
        changed = {
            k: v for k, v in self.get_params().items() if v != getattr(RegressionSettings, k)
        }
        return f"CertifiedSparseFit({', '.join(f'{k}={v!r}' for k, v in changed.items())})"

    def __str__(self):
        """Its settings, then the selected support and how many were fitted (or that it is
        not fitted yet)."""
        if not hasattr(self, "candidates_"):
            return f"{self!r}: not fitted"
        best = self.candidates_[0]
        return "\n".join(
            [
                f"{self!r}: {len(self.candidates_)} feasible supports, "
                f"{len(self.infeasible_)} infeasible, {self.n_solves_} constrained solves",
                *best._lines(),
            ]
        )

    # ------------------------------------------------------------------ fit
    def fit(self, X, y, groups=None, sample_weight=None):
        """Fit on ``X[:, 0] = zeta`` [m], ``X[:, 1] = dzeta`` [m/s], ``y = F`` [N]; the
        parameters are those of :meth:`ConstrainedSparseRegressor.fit`. Returns self."""
        check(f"{self._name}.fit: X", X, Array(2))
        check(f"{self._name}.fit: y", y, Array())
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
        self.library_ = Library.parse(self.settings.library)
        if self.settings.signs is not None:
            sg = np.atleast_1d(np.asarray(self.settings.signs))
            if sg.size not in (1, len(self.library_)) or not np.all(np.isin(sg, (-1, 0, 1))):
                raise InputError(
                    f"signs must be one of -1, 0, +1 or one per library term "
                    f"({len(self.library_)}); got {self.settings.signs!r}"
                )
        zp = np.maximum(X[:, 0], 0.0)
        vp = np.maximum(X[:, 1], 0.0)
        if not (zp.max() > 0 and vp.max() > 0):
            raise InputError("the data need samples with zeta > 0 and dzeta > 0 (loading)")
        self.box_ = Box(
            zp.max() * (1 + self.settings.box_margin), vp.max() * (1 + self.settings.box_margin)
        )
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
        if self.settings.scoring == "cv" or self.settings.cv_report:
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
        self.candidates_.sort(key=key[self.settings.scoring])
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
            f"margin {self.settings.margin:g} N s/m"
            + (", monotone" if self.settings.monotone else "")
            + ("" if self.settings.signs is None else f", signs {self.settings.signs!r}")
        )
        raise InputError(
            f"no proposed support of library {self.settings.library!r} can satisfy the "
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
        if self.settings.scoring == "cv" or self.settings.cv_report:
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
            ["monotone_elastic"] if self.settings.monotone else []
        )
        sup = np.asarray(coef) != 0
        lib = self.library_.subset(sup)
        return certify(
            np.asarray(coef)[sup],
            lib.exponents,
            self.box_,
            conditions,
            elevation=self.settings.elevation,
            grid=self.settings.grid,
            margin=self.settings.margin,
        )

    def _validate(self):
        s = self.settings
        if s.selection not in SELECTIONS:
            raise InputError(
                f"selection must be one of {', '.join(SELECTIONS)}; got {s.selection!r}"
            )
        if s.scoring not in SCORES:
            raise InputError(f"scoring must be one of {', '.join(SCORES)}; got {s.scoring!r}")
        if not (isinstance(s.max_terms, int | np.integer) and s.max_terms >= 1):
            raise InputError(f"max_terms must be a positive integer; got {s.max_terms!r}")
        if not (isinstance(s.cv, int | np.integer) and s.cv >= 2):
            raise InputError(f"cv must be an integer >= 2; got {s.cv!r}")
        if not (isinstance(s.margin, int | float | np.number) and s.margin >= 0):
            raise InputError(f"margin must be a number >= 0 (N s/m); got {s.margin!r}")
        if not (isinstance(s.box_margin, int | float | np.number) and s.box_margin >= 0):
            raise InputError(
                f"box_margin must be a number >= 0 (the box must contain the "
                f"data); got {s.box_margin!r}"
            )
        if not (isinstance(s.elevation, int | np.integer) and s.elevation >= 0):
            raise InputError(f"elevation must be an integer >= 0; got {s.elevation!r}")

    def _problem(self, X, y, w):
        constraints = _Constraints(
            box=self.box_,
            margin=self.settings.margin,
            monotone=self.settings.monotone,
            signs=self.settings.signs,
            elevation=self.settings.elevation,
        )
        return _Problem(self.library_, constraints, X, y, w, solver=self.settings.solver)

    # ------------------------------------------------------- support proposal
    def _propose(self, prob):
        """The supports the selection method proposes (:mod:`.proposals`)."""
        if self.settings.selection == "best-subset":
            out = _best_subsets(prob, len(self.library_), self.settings.max_terms)
            if not out:
                self.infeasible_ = [
                    {"support": self._names(k), "reason": r} for k, r in prob.infeasible.items()
                ]
                self._no_feasible_support()
            return out
        if self.settings.selection == "l1-path":
            return _l1_path(
                prob, self.settings.max_terms, self.settings.n_lambdas, self.settings.solver
            )
        return _pysindy_supports(prob, self.settings.selection, self.settings.threshold)

    def _cross_validate(self, X, y, w, groups, supports):
        ug = np.unique(groups)
        k = min(self.settings.cv, ug.size)
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
        if not hasattr(self, "law_"):
            from .not_fitted import NotFittedError

            raise NotFittedError(
                f"This {self._name} instance is not fitted yet. Call 'fit' with appropriate "
                "arguments before using this estimator."
            )
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != self.n_features_in_:
            raise InputError(
                f"X has shape {X.shape}; the estimator is expecting "
                f"{self.n_features_in_} features (zeta, dzeta)"
            )
        return self.law_(X[:, 0], X[:, 1])

    def score(self, X, y, sample_weight=None):
        """The coefficient of determination R² of :meth:`predict` on ``(X, y)``."""
        y = np.asarray(y, dtype=float).ravel()
        w = np.ones_like(y) if sample_weight is None else np.asarray(sample_weight, float)
        r = y - self.predict(X)
        mean = np.average(y, weights=w)
        return float(1.0 - np.sum(w * r * r) / np.sum(w * (y - mean) ** 2))

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
        lib = Library.parse(self.settings.library)
        counts = np.zeros(len(lib))
        for _ in range(n_resamples):
            pick = rng.choice(ug.size, size=ug.size, replace=True)
            rows = np.concatenate([members[g] for g in pick])
            # a duplicated impact is a new impact: group id = its position in the draw
            new_groups = np.repeat(np.arange(pick.size), [members[g].size for g in pick])
            est = CertifiedSparseFit(replace(self.settings, cv=2, grid=101, cv_report=False))
            est.fit(X[rows], y[rows], groups=new_groups, sample_weight=w[rows])
            counts += est.support_
        return {t.name: float(c / n_resamples) for t, c in zip(lib.terms, counts, strict=True)}
