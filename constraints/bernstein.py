"""Bernstein-polynomial certificates of non-negativity on the box ``D = [0, Z] x [0, V]``.

Method
------
Exponents may be rational. Let ``q`` (``r``) be the smallest integer ``<= 8`` making every
``q * a_i`` (``r * b_i``) an integer. The substitution ``zeta = Z s**q``, ``zd = V u**r`` maps
the unit square ``[0, 1]**2`` bijectively onto ``D`` and turns each term into a monomial::

    c_i zeta**a_i zd**b_i = x_i * s**(q a_i) * u**(r b_i),   x_i = c_i Z**a_i V**b_i  [N].

The polynomial is written in the tensor-product Bernstein basis of degree
``(n_s, n_u) = (deg_s + elevation, deg_u + elevation)``; the monomial ``s**i`` has Bernstein
coefficients ``C(k, i) / C(n, i)`` for ``k >= i`` and 0 otherwise. If every Bernstein coefficient
is ``>= 0`` the polynomial is ``>= 0`` on the square, hence on ``D``. This is a sufficient
condition; it becomes necessary as the elevation grows only for polynomials *strictly* positive
on the closed square. Every law vanishes at ``zeta = zd = 0``, and the coefficients next to that
corner are governed by the lowest-order monomials, so non-negativity that relies on a
cancellation between lowest-order terms (e.g. ``s**2 - s*u + u**2``) is never certified at any
elevation: the certificate (and the fit constrained by it) is conservative there.

Scaling convention
------------------
The linear map is written on the **scaled** coefficients ``x`` (newtons), not on the physical
``c``. Its entries are then products of ratios of binomials, all in ``[0, 1]`` whatever the
magnitudes of ``Z``, ``V`` and ``c``, and each column reaches exactly 1 at the far corner.
Bernstein coefficients are in newtons. (The cvxpy builders additionally normalise each row to
unit max-norm, see :mod:`constraints.builders`.)

Conditions
----------
``"non_adhesion"``
    ``P(zeta, zd) >= 0``.
``"dissipativity"``
    ``P(zeta, zd) - P(zeta, 0) - margin * zd >= 0``: the terms with ``b > 0``, minus the
    margin term. For ``zd > 0`` this is equivalent to ``Q(zeta, zd) >= margin`` with
    ``Q = sum_{b_i > 0} c_i zeta**a_i zd**(b_i - 1)`` [N s/m], and stays polynomial even when
    some ``0 < b_i < 1``. ``margin = 0`` certifies ``>= 0``.
``"monotone_elastic"``
    ``zeta * dP/dzeta(zeta, 0) = sum_{b_i = 0} a_i c_i zeta**a_i >= 0`` on ``[0, Z]``
    (univariate in ``s``); for ``zeta > 0`` this is ``dP/dzeta(zeta, 0) >= 0``, and it stays
    polynomial when some ``0 < a_i < 1``.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

from .domain import Box
from .errors import InputError
from .library import Library, exponents, to_scaled

__all__ = [
    "CONDITIONS",
    "MAX_LATTICE",
    "BernsteinMap",
    "bernstein_basis",
    "bernstein_coefficients",
    "bernstein_map",
    "check_margin",
    "evaluate_bernstein",
    "lattice_factor",
    "monomial_bernstein",
]

CONDITIONS = ("non_adhesion", "dissipativity", "monotone_elastic")
"""Names of the box conditions understood by :func:`bernstein_map` and the verifier."""

MAX_LATTICE = 8
"""Largest denominator accepted for rational exponents (``q, r <= 8``)."""

_LATTICE_TOL = 1e-9


def lattice_factor(values: Sequence[float] | np.ndarray, max_factor: int = MAX_LATTICE) -> int:
    """Smallest integer ``q`` in ``[1, max_factor]`` making every ``q * value`` an integer.

    Parameters
    ----------
    values : sequence of float, shape (n,)
        Non-negative exponents (may be empty, then ``q = 1``).
    max_factor : int, optional
        Largest allowed factor.

    Returns
    -------
    int

    Raises
    ------
    ValueError
        If no factor ``<= max_factor`` works (exponent not a simple rational).
    """
    vals = np.asarray(values, dtype=float).ravel()
    for q in range(1, max_factor + 1):
        scaled = q * vals
        if np.all(np.abs(scaled - np.round(scaled)) <= _LATTICE_TOL * np.maximum(1.0, scaled)):
            return q
    bad = [
        float(v)
        for v in vals
        if all(abs(q * v - round(q * v)) > _LATTICE_TOL for q in range(1, max_factor + 1))
    ]
    raise InputError(
        f"exponents {bad or list(vals)} are not rationals with denominator <= {max_factor} "
        "(jointly); the Bernstein certificate needs q * exponent integer for some q <= "
        f"{max_factor}"
    )


def monomial_bernstein(power: int, degree: int) -> np.ndarray:
    """Bernstein coefficients of ``t**power`` in the basis of degree ``degree`` on ``[0, 1]``.

    Parameters
    ----------
    power : int
        Monomial power ``i >= 0``.
    degree : int
        Basis degree ``n >= i``.

    Returns
    -------
    ndarray, shape (degree + 1,)
        ``C(k, i) / C(n, i)`` for ``k >= i``, else 0 (exact binomials, rounded once).
    """
    if power < 0 or degree < power:
        raise InputError(f"need 0 <= power <= degree, got power={power}, degree={degree}")
    denominator = math.comb(degree, power)
    return np.array(
        [math.comb(k, power) / denominator if k >= power else 0.0 for k in range(degree + 1)]
    )


def bernstein_basis(degree: int, t: ArrayLike) -> np.ndarray:
    """Bernstein basis ``C(n, k) t**k (1 - t)**(n - k)`` evaluated at points.

    Parameters
    ----------
    degree : int
        Degree ``n >= 0``.
    t : array_like, shape (n_points,)
        Points in ``[0, 1]``.

    Returns
    -------
    ndarray, shape (n_points, degree + 1)
    """
    tt = np.asarray(t, dtype=float).ravel()[:, None]
    k = np.arange(degree + 1)[None, :]
    binom = np.array([math.comb(degree, j) for j in range(degree + 1)], dtype=float)[None, :]
    return binom * tt**k * (1.0 - tt) ** (degree - k)


def evaluate_bernstein(coefficients: ArrayLike, s: ArrayLike, u: ArrayLike | None = None):
    """Evaluate a univariate or tensor-product Bernstein form.

    Parameters
    ----------
    coefficients : array_like, shape (n_s + 1,) or (n_s + 1, n_u + 1)
        Bernstein coefficients.
    s : array_like, shape (n_points,)
        First coordinate in ``[0, 1]``.
    u : array_like, shape (n_points,), optional
        Second coordinate in ``[0, 1]`` (required for a bivariate form).

    Returns
    -------
    ndarray, shape (n_points,)
    """
    coef = np.asarray(coefficients, dtype=float)
    bs = bernstein_basis(coef.shape[0] - 1, s)
    if coef.ndim == 1:
        return bs @ coef
    if u is None:
        raise InputError("a bivariate Bernstein form needs both s and u")
    bu = bernstein_basis(coef.shape[1] - 1, u)
    return np.einsum("pk,kl,pl->p", bs, coef, bu)


@dataclass(frozen=True, eq=False)
class BernsteinMap:
    """Affine map from scaled coefficients ``x`` [N] to Bernstein coefficients [N].

    ``bernstein = matrix @ x + offset``; the row index ``k * (n_u + 1) + l`` corresponds to the
    control point ``(s, u) = (k / n_s, l / n_u)``, i.e. ``(zeta, zd) = (Z (k/n_s)**q,
    V (l/n_u)**r)``.

    Attributes
    ----------
    condition : str
        One of :data:`CONDITIONS`.
    matrix : ndarray, shape (n_bernstein, n_terms)
        Entries in ``[0, 1]`` (times ``a_i`` for ``"monotone_elastic"``).
    offset : ndarray, shape (n_bernstein,)
        Constant part [N] (non-zero only for a dissipativity margin).
    degrees : tuple of int
        ``(n_s, n_u)``, or ``(n_s,)`` for the univariate ``"monotone_elastic"``.
    lattice : tuple of int
        ``(q, r)``: ``zeta = Z s**q``, ``zd = V u**r``.
    box : Box
        The domain.
    """

    condition: str
    matrix: np.ndarray
    offset: np.ndarray
    degrees: tuple[int, ...]
    lattice: tuple[int, int]
    box: Box

    def coefficients(self, x: ArrayLike) -> np.ndarray:
        """Bernstein coefficients [N] for numeric scaled coefficients.

        Parameters
        ----------
        x : array_like, shape (n_terms,)
            Scaled coefficients [N].

        Returns
        -------
        ndarray, shape (n_s + 1, n_u + 1) or (n_s + 1,)
        """
        values = self.matrix @ np.asarray(x, dtype=float) + self.offset
        return values.reshape(tuple(d + 1 for d in self.degrees))

    def control_point(self, row: int) -> tuple[float, float]:
        """Physical location ``(zeta [m], zd [m/s])`` of the control point of a row."""
        q, r = self.lattice
        if len(self.degrees) == 1:
            return (self.box.zeta_max * (row / self.degrees[0]) ** q, 0.0)
        n_s, n_u = self.degrees
        k, l = divmod(row, n_u + 1)
        return (self.box.zeta_max * (k / n_s) ** q, self.box.zd_max * (l / n_u) ** r)


def check_margin(library: Library | np.ndarray, margin: float) -> float:
    """Validate a dissipativity margin against a library.

    ``Q(zeta, zd) >= margin > 0`` at ``zeta = 0`` and ``zd -> 0`` needs a term with ``a = 0``
    and ``0 < b <= 1`` (e.g. the viscous term ``(0, 1)``): a Hunt–Crossley term
    ``zeta**1.5 * zd`` makes ``Q`` vanish at ``zeta = 0``, so such libraries need
    ``margin = 0``.

    Parameters
    ----------
    library : sequence of (float, float)
    margin : float
        Required lower bound of ``Q`` [N s/m], >= 0.

    Returns
    -------
    float
        The margin as a float.

    Raises
    ------
    ValueError
        If the margin is negative or not finite, or if it is positive and no library term can
        make ``Q`` reach it at ``zeta = 0``.
    """
    value = float(margin)
    if not math.isfinite(value) or value < 0.0:
        raise InputError(f"margin must be a finite number >= 0 [N s/m], got {margin!r}")
    if value > 0.0:
        exps = exponents(library)
        if not np.any((exps[:, 0] == 0.0) & (exps[:, 1] > 0.0) & (exps[:, 1] <= 1.0)):
            raise InputError(
                f"dissipativity margin {value:g} N s/m is impossible for library "
                f"{[tuple(map(float, e)) for e in exps]}: Q(zeta, zd) = sum_(b>0) c zeta^a "
                "zd^(b-1) vanishes at zeta = 0 (zd -> 0) unless a term has a = 0 and "
                "0 < b <= 1 (e.g. the viscous term (0, 1)); use margin = 0"
            )
    return value


def _check_condition(condition: str) -> None:
    if condition not in CONDITIONS:
        raise InputError(f"unknown condition {condition!r}; expected one of {CONDITIONS}")


def _check_elevation(elevation: int) -> int:
    if isinstance(elevation, bool) or int(elevation) != elevation or elevation < 0:
        raise InputError(f"elevation must be an integer >= 0, got {elevation!r}")
    return int(elevation)


def bernstein_map(
    library: Library | np.ndarray,
    box: Box,
    condition: str = "non_adhesion",
    *,
    elevation: int = 2,
    margin: float = 0.0,
) -> BernsteinMap:
    """Build the affine map from scaled coefficients to Bernstein coefficients of a condition.

    Parameters
    ----------
    library : sequence of (float, float), length n_terms
        Exponent pairs ``(a_i, b_i)``.
    box : Box
        Domain ``[0, Z] x [0, V]``.
    condition : {"non_adhesion", "dissipativity", "monotone_elastic"}
        Which polynomial to certify (see the module docstring).
    elevation : int, optional
        Degree elevation added to the natural degree in each variable; larger is tighter.
    margin : float, optional
        Dissipativity margin [N s/m] (only for ``"dissipativity"``).

    Returns
    -------
    BernsteinMap

    Raises
    ------
    ValueError
        Unknown condition, bad elevation, exponents needing a lattice factor > 8, or an
        impossible margin (see :func:`check_margin`).
    """
    _check_condition(condition)
    elevation = _check_elevation(elevation)
    exps = exponents(library)
    a, b = exps[:, 0], exps[:, 1]
    margin = check_margin(exps, margin) if condition == "dissipativity" else float(margin)
    if condition != "dissipativity" and margin != 0.0:
        raise InputError(f"margin applies to dissipativity only, got margin={margin!r}")

    if condition == "monotone_elastic":
        active = b == 0.0
        weights = np.where(active, a, 0.0)
        q = lattice_factor(a[active])
        powers = np.rint(q * a).astype(int)
        n_s = int(powers[active].max(initial=0)) + elevation
        matrix = np.zeros((n_s + 1, exps.shape[0]))
        for i in np.flatnonzero(active):
            matrix[:, i] = weights[i] * monomial_bernstein(int(powers[i]), n_s)
        return _freeze(BernsteinMap(condition, matrix, np.zeros(n_s + 1), (n_s,), (q, 1), box))

    active = np.ones_like(a, dtype=bool) if condition == "non_adhesion" else b > 0.0
    q = lattice_factor(a[active])
    r = lattice_factor(b[active])
    ps = np.rint(q * a).astype(int)
    pu = np.rint(r * b).astype(int)
    n_s = int(ps[active].max(initial=0)) + elevation
    top_u = int(pu[active].max(initial=0))
    if margin > 0.0:
        top_u = max(top_u, r)
    n_u = top_u + elevation
    matrix = np.zeros(((n_s + 1) * (n_u + 1), exps.shape[0]))
    for i in np.flatnonzero(active):
        column = np.outer(monomial_bernstein(int(ps[i]), n_s), monomial_bernstein(int(pu[i]), n_u))
        matrix[:, i] = column.ravel()
    offset = np.zeros(matrix.shape[0])
    if margin > 0.0:
        # - margin * zd = - margin * V * u**r, constant in s (all-ones Bernstein coefficients)
        offset = -margin * box.zd_max * np.outer(np.ones(n_s + 1), monomial_bernstein(r, n_u))
        offset = offset.ravel()
    return _freeze(BernsteinMap(condition, matrix, offset, (n_s, n_u), (q, r), box))


def _freeze(bmap: BernsteinMap) -> BernsteinMap:
    """The map with its arrays read-only."""
    bmap.matrix.setflags(write=False)
    bmap.offset.setflags(write=False)
    return bmap


def bernstein_coefficients(
    coef: ArrayLike,
    library: Library | np.ndarray,
    box: Box,
    condition: str = "non_adhesion",
    *,
    elevation: int = 2,
    margin: float = 0.0,
) -> np.ndarray:
    """Bernstein coefficients [N] of a condition polynomial for a numeric law.

    The minimum of the returned array is the certificate margin: ``>= 0`` proves the
    condition on the whole box.

    Parameters
    ----------
    coef : array_like, shape (n_terms,)
        **Physical** coefficients ``c``.
    library : sequence of (float, float)
    box : Box
    condition : {"non_adhesion", "dissipativity", "monotone_elastic"}
    elevation : int, optional
    margin : float, optional
        Dissipativity margin [N s/m].

    Returns
    -------
    ndarray, shape (n_s + 1, n_u + 1), or (n_s + 1,) for ``"monotone_elastic"``
    """
    bmap = bernstein_map(library, box, condition, elevation=elevation, margin=margin)
    return bmap.coefficients(to_scaled(coef, library, box))
