"""Candidate term libraries ``Theta(zeta, zd)`` for force-law discovery.

A :class:`Library` is an ordered set of :class:`~discovery.vibroimpact.model.law.Term` and a
scikit-learn style transformer: ``transform(X)`` with ``X[:, 0] = zeta`` [m] and
``X[:, 1] = dzeta`` [m/s] returns ``Theta`` with one column per term, evaluated
at ``zd = max(dzeta, 0)``.  Libraries combine with ``+``.

Specifications (``Library.parse``)::

    poly:3            every zeta^a zd^b with 1 <= a + b <= 3 (no constant)
    hc                Hunt-Crossley terms z^1.5, z^1.5*zd
    z,zd,z*zd,z^1.5   an explicit list of term names
    poly:2+hc         a sum of specifications
"""

import difflib
import re
from dataclasses import dataclass

import numpy as np

from ..._api._validate import check
from ...errors import InputError
from .law import ForceLaw, Term

__all__ = ["Library"]


def _reason(exc):
    """The part of a term error after the quoted law text: the reason alone."""
    text = str(exc)
    if "cannot read" in text:  # a syntax error: the hint after it says what a term looks like
        return ""
    text = text.split(": ", 1)[1] if text.startswith("force law ") and ": " in text else text
    return f" ({text.split(';')[0]})"


@dataclass(frozen=True)
class Library:
    """An ordered set of candidate terms.

    Parameters
    ----------
    terms : tuple of Term
        Distinct terms.
    """

    terms: tuple

    def __post_init__(self):
        check("Library: terms", self.terms, (tuple, list))
        for term in self.terms:
            check("Library: each term", term, Term)
        terms = tuple(self.terms)
        if not terms:
            raise InputError("a library needs at least one term")
        if len(set(terms)) != len(terms):
            raise InputError("a library lists the same term twice")
        object.__setattr__(self, "terms", terms)

    # ----------------------------------------------------------- construction
    @classmethod
    def polynomial(cls, degree):
        """Every ``zeta^a zd^b`` with integer ``1 <= a + b <= degree``."""
        if not (isinstance(degree, int | np.integer) and 1 <= degree <= 8):
            raise InputError(f"polynomial degree must be an integer in 1..8, got {degree!r}")
        return cls(tuple(Term(a, d - a) for d in range(1, degree + 1) for a in range(d, -1, -1)))

    @classmethod
    def hunt_crossley(cls):
        """``z^1.5`` and ``z^1.5*zd``: the Hunt-Crossley contact."""
        return cls((Term(1.5, 0), Term(1.5, 1)))

    @classmethod
    def parse(cls, spec):
        """Library from a specification (see the module docstring)."""
        if isinstance(spec, Library):
            return spec
        if hasattr(spec, "powers_") or type(spec).__module__.startswith("pysindy"):
            return cls.from_pysindy(spec)
        if not isinstance(spec, str) or not spec.strip():
            raise InputError("library must be text like 'poly:3', 'hc' or 'z,zd,z*zd'")
        out = None
        for part in _split_plus(spec):
            part = part.strip()
            if part.startswith("poly:"):
                try:
                    lib = cls.polynomial(int(part[5:]))
                except ValueError:
                    raise InputError(f"library {part!r}: write poly:N with N = 1..8") from None
            elif part == "hc":
                lib = cls.hunt_crossley()
            else:
                terms = []
                for name in part.split(","):
                    try:
                        terms.append(Term.parse(name.strip()))
                    except InputError as exc:
                        raise InputError(
                            f"library {spec!r}: {name.strip()!r} is not a term{_reason(exc)}"
                            f"{_did_you_mean(name.strip())}; use poly:N, hc or names like z, "
                            "zd, z*zd, z^1.5, z^2*zd (fit also takes 'contact-models': the "
                            "named contact models)"
                        ) from None
                lib = cls(tuple(terms))
            out = lib if out is None else out + lib
        if out is None:
            raise InputError(
                f"library {spec!r} names no terms; write e.g. 'poly:2', 'hc' or 'z,zd,z*zd'"
            )
        return out

    @classmethod
    def from_pysindy(cls, feature_library, feature_names=("z", "zd")):
        """Terms of a pysindy polynomial library on the inputs ``(z, zd)``.

        Parameters
        ----------
        feature_library : pysindy.PolynomialLibrary
            On two inputs (``zeta``, ``zd``); fitted here if it is not yet.
        feature_names : (str, str)
            Names pysindy should use for the two inputs.
        """
        powers = getattr(feature_library, "powers_", None)
        if powers is None:
            try:  # not fitted yet: only the number of inputs matters for the terms
                feature_library.fit(np.ones((4, 2)))
            except Exception as exc:  # noqa: BLE001 - any pysindy failure is a user error here
                raise InputError(f"cannot use pysindy library {feature_library!r}: {exc}") from None
            powers = getattr(feature_library, "powers_", None)
        if powers is None:
            raise InputError("only pysindy polynomial libraries (with powers_) can be converted")
        powers = np.asarray(powers)
        if powers.ndim != 2 or powers.shape[1] != 2:
            raise InputError("the pysindy library must be fitted on exactly two inputs (z, zd)")
        terms = [Term(float(a), float(b)) for a, b in powers if a + b > 0]
        return cls(tuple(dict.fromkeys(terms)))

    def __add__(self, other):
        other = Library.parse(other)
        return Library(tuple(dict.fromkeys(self.terms + other.terms)))

    # ------------------------------------------------------------ properties
    def __len__(self):
        return len(self.terms)

    def __iter__(self):
        return iter(self.terms)

    @property
    def names(self):
        return [t.name for t in self.terms]

    @property
    def exponents(self):
        """ndarray of shape (n_terms, 2): ``(a, b)`` per term (the constraints' library)."""
        return np.array([(t.a, t.b) for t in self.terms], dtype=float)

    def get_feature_names_out(self, input_features=None):
        return np.array(self.names, dtype=object)

    def subset(self, support):
        """Library of the terms where ``support`` (bool array) is true."""
        return Library(tuple(t for t, s in zip(self.terms, support, strict=True) if s))

    def law(self, coef):
        """:class:`ForceLaw` with these terms and coefficients (zeros dropped)."""
        keep = [(t, float(c)) for t, c in zip(self.terms, coef, strict=True) if c != 0.0]
        if not keep:
            raise InputError("all coefficients are zero: no law")
        return ForceLaw(tuple(t for t, _ in keep), tuple(c for _, c in keep))

    # ----------------------------------------------------- sklearn transformer
    def fit(self, X=None, y=None):
        return self

    def transform(self, X):
        """``Theta`` of shape (n_samples, n_terms) from ``X[:, 0] = zeta``, ``X[:, 1] = dzeta``."""
        X = np.asarray(X, dtype=float)
        if X.ndim != 2 or X.shape[1] != 2:
            raise InputError(f"X must have shape (n_samples, 2) = (zeta, dzeta); got {X.shape}")
        zeta = np.maximum(X[:, 0], 0.0)
        zd = np.maximum(X[:, 1], 0.0)
        return np.column_stack([t(zeta, zd) for t in self.terms])

    def fit_transform(self, X, y=None):
        return self.transform(X)


def _did_you_mean(word):
    """``" (did you mean 'poly:2'?)"`` for a library word close to one (``poly2``,
    ``contact-model``), else ``""``."""
    m = re.fullmatch(r"poly\s*[-_ ]?\s*(\d)", word.lower())
    if m:
        return f" (did you mean 'poly:{m.group(1)}'?)"
    close = difflib.get_close_matches(word.lower(), ("contact-models", "hc"), n=1, cutoff=0.7)
    return f" (did you mean {close[0]!r}?)" if close else ""


def _split_plus(spec):
    """Split on '+' between specifications (term names never contain '+')."""
    return [p for p in spec.split("+") if p.strip()]
