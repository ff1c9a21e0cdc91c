"""cvxpy constraint builders enforcing the physical conditions on the whole box.

Convention
----------
Every builder takes ``x``, a cvxpy expression of shape ``(n_terms,)`` holding the **scaled**
coefficients in units of ``force_unit`` newtons::

    x_i = c_i * Z**a_i * V**b_i / force_unit

(``force_unit = 1`` by default, i.e. ``x`` in N). Fit with the scaled features
``(zeta/Z)**a (zd/V)**b`` (:func:`constraints.library.features` with ``box``) and recover the
physical law with ``c = force_unit * to_physical(x.value, library, box)``. Because the
conditions are homogeneous in ``x``, ``force_unit`` only matters for the dissipativity margin.

Each Bernstein constraint row is divided by its largest absolute entry (rows are then
``<= 1`` in max-norm with one entry equal to 1); identically-zero rows are dropped. This keeps
the constraints well conditioned for any box and coefficient magnitude.

The rows themselves are plain numpy: :func:`normalized_rows` (the normalisation above),
:func:`sign_rows` (coefficient signs) and :func:`constraint_rows` (the whole set of
:func:`physical` as one system ``rows @ x + rhs >= 0``) are shared by the cvxpy builders here
and by any caller assembling its own problem (e.g. :mod:`discovery.vibroimpact.fit.regression`).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ._cvxpy import cvxpy as cp
from .bernstein import bernstein_map, check_margin
from .domain import Box
from .errors import InputError
from .library import Library, exponents

__all__ = [
    "coefficient_signs",
    "constraint_rows",
    "dissipativity",
    "monotone_elastic",
    "non_adhesion",
    "normalized_rows",
    "physical",
    "sign_rows",
]


def _check_variable(x: cp.Expression, n_terms: int) -> None:
    if tuple(x.shape) != (n_terms,):
        raise InputError(
            f"x must have shape ({n_terms},) to match the library, got {tuple(x.shape)}"
        )


def _check_unit(force_unit: float) -> float:
    value = float(force_unit)
    if not math.isfinite(value) or value <= 0.0:
        raise InputError(f"force_unit must be a positive finite number [N], got {force_unit!r}")
    return value


def normalized_rows(
    matrix: np.ndarray, offset: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Affine constraints ``matrix @ x + offset >= 0`` with rows of unit max-norm.

    Each row (and its offset) is divided by its largest absolute entry; rows identically zero
    in ``x`` are dropped: they hold for every ``x`` when their offset is ``>= 0`` and for no
    ``x`` otherwise.

    Parameters
    ----------
    matrix : ndarray, shape (n_rows, n_terms)
    offset : ndarray, shape (n_rows,)

    Returns
    -------
    rows : ndarray, shape (n_kept, n_terms)
    rhs : ndarray, shape (n_kept,)
    impossible : ndarray of int
        Indices (into ``matrix``) of the dropped rows with a negative offset; when not empty
        no ``x`` satisfies the constraints.
    """
    matrix = np.asarray(matrix, dtype=float)
    offset = np.asarray(offset, dtype=float)
    norms = np.max(np.abs(matrix), axis=1) if matrix.shape[1] else np.zeros(matrix.shape[0])
    empty = norms == 0.0
    impossible = np.flatnonzero(empty & (offset < 0.0))
    keep = ~empty
    return matrix[keep] / norms[keep, None], offset[keep] / norms[keep], impossible


def sign_rows(signs: float | Sequence[float], n_terms: int) -> np.ndarray:
    """Rows ``s_i e_i`` (one per constrained term) of the sign constraints ``rows @ x >= 0``.

    Parameters
    ----------
    signs : {1, -1, 0} or sequence of them, length n_terms
        ``+1``: ``c_i >= 0``; ``-1``: ``c_i <= 0``; ``0``: free. A scalar applies to all terms.
    n_terms : int

    Returns
    -------
    ndarray, shape (n_constrained, n_terms)
    """
    try:
        vector = np.asarray(signs, dtype=float)
    except (TypeError, ValueError):
        vector = np.empty(0)
    if vector.ndim == 0:
        vector = np.full(n_terms, float(vector))
    if vector.shape != (n_terms,) or not np.all(np.isin(vector, (-1.0, 0.0, 1.0))):
        raise InputError(
            f"signs must be one of -1, 0, +1 or a sequence of them of length {n_terms}, "
            f"got {signs!r}"
        )
    constrained = np.flatnonzero(vector != 0.0)
    rows = np.zeros((constrained.size, n_terms))
    rows[np.arange(constrained.size), constrained] = vector[constrained]
    return rows


def _condition_rows(
    library: Library,
    box: Box,
    condition: str,
    *,
    elevation: int,
    margin: float = 0.0,
    force_unit: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """Normalised rows of one Bernstein condition; raises if no coefficients can meet it."""
    exps = exponents(library)
    unit = _check_unit(force_unit)
    bmap = bernstein_map(exps, box, condition, elevation=elevation, margin=margin)
    rows, rhs, impossible = normalized_rows(bmap.matrix, np.asarray(bmap.offset) / unit)
    if impossible.size:
        zeta, zd = bmap.control_point(int(impossible[0]))
        raise InputError(
            f"{condition} is impossible for library {[tuple(map(float, e)) for e in exps]}: "
            f"no term can offset the margin near zeta={zeta:.3g} m, zd={zd:.3g} m/s"
        )
    return rows, rhs


def _bernstein_constraints(
    x: cp.Expression,
    library: Library,
    box: Box,
    condition: str,
    *,
    elevation: int,
    margin: float = 0.0,
    force_unit: float = 1.0,
) -> list[cp.Constraint]:
    _check_variable(x, exponents(library).shape[0])
    rows, rhs = _condition_rows(
        library, box, condition, elevation=elevation, margin=margin, force_unit=force_unit
    )
    if rows.shape[0] == 0:
        return []
    if np.any(rhs != 0.0):
        return [rows @ x + rhs >= 0]
    return [rows @ x >= 0]


def constraint_rows(
    library: Library,
    box: Box,
    *,
    margin: float = 0.0,
    monotone: bool = False,
    signs: float | Sequence[float] | None = None,
    elevation: int = 2,
    force_unit: float = 1.0,
) -> tuple[np.ndarray, np.ndarray]:
    """The constraint set of :func:`physical` as one system ``rows @ x + rhs >= 0``.

    Same rows as the builders (Bernstein rows normalised to unit max-norm, vanishing rows
    dropped, then one row per sign constraint), for callers that assemble their own problem.

    Parameters
    ----------
    library : sequence of (float, float), length n_terms
    box : Box
    margin, monotone, signs, elevation, force_unit
        As for :func:`physical`.

    Returns
    -------
    rows : ndarray, shape (n_rows, n_terms)
    rhs : ndarray, shape (n_rows,)
        In units of ``force_unit`` N, like ``x``.

    Raises
    ------
    InputError
        If a condition cannot hold for any coefficients of this library (a margin without a
        term it acts on) or the signs are malformed.
    """
    n_terms = exponents(library).shape[0]
    parts = [
        _condition_rows(library, box, "non_adhesion", elevation=elevation),
        _condition_rows(
            library,
            box,
            "dissipativity",
            elevation=elevation,
            margin=margin,
            force_unit=force_unit,
        ),
    ]
    if monotone:
        parts.append(_condition_rows(library, box, "monotone_elastic", elevation=elevation))
    if signs is not None:
        srows = sign_rows(signs, n_terms)
        parts.append((srows, np.zeros(srows.shape[0])))
    rows = np.vstack([p[0] for p in parts]).reshape(-1, n_terms)
    rhs = np.concatenate([p[1] for p in parts])
    return rows, rhs


def non_adhesion(
    x: cp.Expression, library: Library, box: Box, *, elevation: int = 2
) -> list[cp.Constraint]:
    """Non-adhesion ``P(zeta, zd) >= 0`` on the whole box (Bernstein certificate).

    Parameters
    ----------
    x : cvxpy.Expression, shape (n_terms,)
        Scaled coefficients (see module docstring).
    library : sequence of (float, float), length n_terms
        Exponent pairs ``(a_i, b_i)``.
    box : Box
        Domain ``[0, Z] x [0, V]``.
    elevation : int, optional
        Bernstein degree elevation (tighter but more rows when larger).

    Returns
    -------
    list of cvxpy.Constraint
    """
    return _bernstein_constraints(x, library, box, "non_adhesion", elevation=elevation)


def dissipativity(
    x: cp.Expression,
    library: Library,
    box: Box,
    *,
    margin: float = 0.0,
    elevation: int = 2,
    force_unit: float = 1.0,
) -> list[cp.Constraint]:
    """Dissipativity ``P(zeta, zd) - P(zeta, 0) >= margin * zd`` on the whole box.

    With ``margin = 0`` this certifies ``P(zeta, zd) - P(zeta, 0) >= 0``; with ``margin > 0``
    it is equivalent (for ``zd > 0``) to ``Q = sum_{b_i > 0} c_i zeta**a_i zd**(b_i - 1) >=
    margin``. A Hunt–Crossley term ``zeta**1.5 * zd`` makes ``Q`` vanish at ``zeta = 0``, so
    ``margin > 0`` needs a term with ``a = 0`` and ``0 < b <= 1`` (e.g. viscous ``(0, 1)``).

    Parameters
    ----------
    x : cvxpy.Expression, shape (n_terms,)
        Scaled coefficients in units of ``force_unit`` N.
    library : sequence of (float, float), length n_terms
    box : Box
    margin : float, optional
        Strictness margin on ``Q`` [N s/m], >= 0.
    elevation : int, optional
    force_unit : float, optional
        Force unit of ``x`` [N].

    Returns
    -------
    list of cvxpy.Constraint
        Empty when no term depends on ``zd`` and ``margin = 0``.

    Raises
    ------
    ValueError
        If ``margin > 0`` cannot be met by any coefficients of this library.
    """
    check_margin(library, margin)
    return _bernstein_constraints(
        x,
        library,
        box,
        "dissipativity",
        elevation=elevation,
        margin=margin,
        force_unit=force_unit,
    )


def monotone_elastic(
    x: cp.Expression, library: Library, box: Box, *, elevation: int = 2
) -> list[cp.Constraint]:
    """Monotone elastic branch ``dP/dzeta(zeta, 0) >= 0`` on ``[0, Z]``.

    Certified in the form ``zeta * dP/dzeta(zeta, 0) = sum_{b_i = 0} a_i c_i zeta**a_i >= 0``
    (equivalent for ``zeta > 0``).

    Parameters
    ----------
    x : cvxpy.Expression, shape (n_terms,)
        Scaled coefficients.
    library : sequence of (float, float), length n_terms
    box : Box
    elevation : int, optional

    Returns
    -------
    list of cvxpy.Constraint
        Empty when the library has no ``b = 0`` term.
    """
    return _bernstein_constraints(x, library, box, "monotone_elastic", elevation=elevation)


def coefficient_signs(
    x: cp.Expression,
    library: Library,
    box: Box | None = None,
    *,
    signs: float | Sequence[float] = 1,
) -> list[cp.Constraint]:
    """Sign constraints on the coefficients.

    Scaling factors ``Z**a V**b`` are positive, so the signs of scaled and physical
    coefficients coincide and ``box`` is not needed (accepted for a uniform signature).

    Parameters
    ----------
    x : cvxpy.Expression, shape (n_terms,)
    library : sequence of (float, float), length n_terms
    box : Box, optional
        Unused.
    signs : {1, -1, 0} or sequence of them, length n_terms
        ``+1``: ``c_i >= 0``; ``-1``: ``c_i <= 0``; ``0``: free. A scalar applies to all terms
        (default: all coefficients non-negative).

    Returns
    -------
    list of cvxpy.Constraint
    """
    n_terms = exponents(library).shape[0]
    _check_variable(x, n_terms)
    rows = sign_rows(signs, n_terms)
    if rows.shape[0] == 0:
        return []
    return [rows @ x >= 0]


def physical(
    x: cp.Expression,
    library: Library,
    box: Box,
    *,
    margin: float = 0.0,
    monotone: bool = False,
    signs: float | Sequence[float] | None = None,
    elevation: int = 2,
    force_unit: float = 1.0,
) -> list[cp.Constraint]:
    """Standard physical constraint set: non-adhesion and dissipativity, plus options.

    Parameters
    ----------
    x : cvxpy.Expression, shape (n_terms,)
        Scaled coefficients in units of ``force_unit`` N.
    library : sequence of (float, float), length n_terms
    box : Box
    margin : float, optional
        Dissipativity margin [N s/m].
    monotone : bool, optional
        Also require a monotone elastic branch.
    signs : {1, -1, 0}, sequence of them, or None, optional
        Coefficient sign constraints (:func:`coefficient_signs`); ``None`` adds none.
    elevation : int, optional
        Bernstein degree elevation.
    force_unit : float, optional
        Force unit of ``x`` [N].

    Returns
    -------
    list of cvxpy.Constraint
    """
    constraints = non_adhesion(x, library, box, elevation=elevation)
    constraints += dissipativity(
        x, library, box, margin=margin, elevation=elevation, force_unit=force_unit
    )
    if monotone:
        constraints += monotone_elastic(x, library, box, elevation=elevation)
    if signs is not None:
        constraints += coefficient_signs(x, library, box, signs=signs)
    return constraints
