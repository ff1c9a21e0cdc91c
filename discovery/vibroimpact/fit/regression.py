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

The estimator wraps :class:`~discovery.vibroimpact.fit.certified_fit.CertifiedSparseFit`,
the regression without scikit-learn, which the commands use (importing scikit-learn costs
0.8 s); this module imports scikit-learn for its base classes and its ``NotFittedError``.
"""

from sklearn.base import BaseEstimator, RegressorMixin
from sklearn.utils.validation import check_is_fitted

from .certified_fit import SCORES, SELECTIONS, Candidate, CertifiedSparseFit, RegressionSettings
from .not_fitted import NotFittedError, SkNotFittedError

__all__ = ["ConstrainedSparseRegressor", "Candidate", "SELECTIONS", "SCORES", "NotFittedError"]


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
    certified_fit_ : CertifiedSparseFit
        The sklearn-free regression that did the fit (what the commands use).
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
        core = self._core()
        core._name = type(self).__name__
        core.fit(X, y, groups=groups, sample_weight=sample_weight)
        for name, value in vars(core).items():
            if name.endswith("_") and not name.startswith("_"):
                setattr(self, name, value)
        self.certified_fit_ = core
        return self

    def _core(self):
        """A :class:`CertifiedSparseFit` with this estimator's parameters."""
        return CertifiedSparseFit(RegressionSettings(**self.get_params()))

    def _checked(self):
        try:
            check_is_fitted(self)
        except SkNotFittedError as exc:
            raise NotFittedError(str(exc)) from None
        return self.certified_fit_

    def rescore(
        self, coef, X, y, sample_weight=None, groups=None, *, constrained=False, extra=None
    ):
        """A :class:`Candidate` for given physical coefficients (e.g. refined by simulation):
        its rss, BIC and AIC on ``(X, y)`` computed exactly as for the fitted candidates, and
        the cross-validated error of its support when the estimator computes one."""
        return self._checked().rescore(
            coef, X, y, sample_weight, groups, constrained=constrained, extra=extra
        )

    def certify(self, coef):
        """Independent certificate of physical coefficients on ``box_`` (Bernstein + grid)."""
        return self._checked().certify(coef)

    def predict(self, X):
        """Contact force [N] at ``X`` (conditions (3)-(5) applied)."""
        return self._checked().predict(X)

    def stability(self, X, y, groups, *, n_resamples=50, random_state=0, sample_weight=None):
        """How often each term is selected over bootstrap resamples of whole impacts
        (:meth:`CertifiedSparseFit.stability`): ``{term: frequency in [0, 1]}``."""
        return self._core().stability(
            X,
            y,
            groups,
            n_resamples=n_resamples,
            random_state=random_state,
            sample_weight=sample_weight,
        )
