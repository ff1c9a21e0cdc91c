"""The error of a regression used before it is fitted: a ``VidiError`` and scikit-learn's
``NotFittedError`` (imported only here, and only where one is raised or the estimator used)."""

from sklearn.exceptions import NotFittedError as SkNotFittedError

from ...errors import VidiError

__all__ = ["NotFittedError", "SkNotFittedError"]


class NotFittedError(VidiError, SkNotFittedError):
    """The estimator is used before :meth:`ConstrainedSparseRegressor.fit` (a ``VidiError``
    and scikit-learn's ``NotFittedError``)."""
