"""Term libraries ``P(zeta, zd) = sum_i c_i zeta**a_i * zd**b_i``: validation, scaling, evaluation.

A library is a sequence of exponent pairs ``(a_i, b_i)`` (non-negative reals, never
``(0, 0)``). Two coefficient conventions are used throughout the package:

* **physical** coefficients ``c`` (``c_i`` in N m^-a_i (m/s)^-b_i), the law as written;
* **scaled** coefficients ``x_i = c_i * Z**a_i * V**b_i`` [N], the value of term ``i`` at the
  far corner of the box ``D = [0, Z] x [0, V]``. With ``s = zeta / Z`` and ``u = zd / V`` on the
  unit square, ``P = sum_i x_i s**a_i u**b_i``: all numerical work uses this form.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike

from .domain import Box
from .errors import InputError

__all__ = [
    "Library",
    "evaluate",
    "exponents",
    "features",
    "scale_factors",
    "to_physical",
    "to_scaled",
]

Library = Sequence[tuple[float, float]]
"""A sequence of exponent pairs ``(a, b)``: term ``zeta**a * zd**b``."""


def exponents(library: Library | np.ndarray) -> np.ndarray:
    """Validate a library and return its exponents.

    Parameters
    ----------
    library : sequence of (float, float) or ndarray, shape (n_terms, 2)
        Exponent pairs ``(a_i, b_i)``.

    Returns
    -------
    ndarray, shape (n_terms, 2)
        Read-only float array; column 0 holds ``a`` (zeta), column 1 holds ``b`` (zd).

    Raises
    ------
    ValueError
        If the library is empty, an entry is not a pair of finite non-negative numbers, an
        entry is the constant term ``(0, 0)`` (a contact force must vanish without contact),
        or an entry is repeated (the regression would be ill-posed).
    """
    entries = list(library)
    if not entries:
        raise InputError("library is empty; it needs at least one (a, b) term")
    out = np.empty((len(entries), 2))
    seen: dict[tuple[float, float], int] = {}
    for index, entry in enumerate(entries):
        try:
            a, b = (float(v) for v in entry)
        except (TypeError, ValueError):
            raise InputError(
                f"library entry {index} = {entry!r} is not a pair of numbers (a, b)"
            ) from None
        if not (math.isfinite(a) and math.isfinite(b)) or a < 0.0 or b < 0.0:
            raise InputError(
                f"library entry {index} = ({a}, {b}): exponents must be finite and >= 0"
            )
        if a == 0.0 and b == 0.0:
            raise InputError(
                f"library entry {index} = (0, 0) is a constant term, which is never allowed: "
                "a contact force must vanish at zeta = 0, zd = 0"
            )
        if (a, b) in seen:
            raise InputError(f"library entry {index} = ({a}, {b}) repeats entry {seen[(a, b)]}")
        seen[(a, b)] = index
        out[index] = (a, b)
    out.setflags(write=False)
    return out


def scale_factors(library: Library | np.ndarray, box: Box) -> np.ndarray:
    """Per-term scale ``Z**a_i * V**b_i`` linking physical and scaled coefficients.

    Parameters
    ----------
    library : sequence of (float, float)
        Exponent pairs, see :func:`exponents`.
    box : Box
        Domain ``[0, Z] x [0, V]`` (Z in m, V in m/s).

    Returns
    -------
    ndarray, shape (n_terms,)
        ``m**a_i (m/s)**b_i``; ``x = c * scale_factors(...)``.
    """
    exps = exponents(library)
    return box.zeta_max ** exps[:, 0] * box.zd_max ** exps[:, 1]


def _coefficients(coef: ArrayLike, n_terms: int, name: str = "coef") -> np.ndarray:
    values = np.asarray(coef, dtype=float)
    if values.shape != (n_terms,):
        raise InputError(
            f"{name} must have shape ({n_terms},) to match the library, got {values.shape}"
        )
    if not np.all(np.isfinite(values)):
        raise InputError(f"{name} contains non-finite values: {values}")
    return values


def to_scaled(coef: ArrayLike, library: Library | np.ndarray, box: Box) -> np.ndarray:
    """Physical coefficients ``c`` -> scaled coefficients ``x = c * Z**a * V**b`` [N].

    Parameters
    ----------
    coef : array_like, shape (n_terms,)
        Physical coefficients.
    library : sequence of (float, float)
    box : Box

    Returns
    -------
    ndarray, shape (n_terms,)
    """
    factors = scale_factors(library, box)
    return _coefficients(coef, factors.size) * factors


def to_physical(x: ArrayLike, library: Library | np.ndarray, box: Box) -> np.ndarray:
    """Scaled coefficients ``x`` [N] -> physical coefficients ``c = x / (Z**a * V**b)``.

    Parameters
    ----------
    x : array_like, shape (n_terms,)
        Scaled coefficients [N].
    library : sequence of (float, float)
    box : Box

    Returns
    -------
    ndarray, shape (n_terms,)
    """
    factors = scale_factors(library, box)
    return _coefficients(x, factors.size, "x") / factors


def _state(zeta: ArrayLike, zd: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    z = np.asarray(zeta, dtype=float)
    v = np.asarray(zd, dtype=float)
    for name, values in (("zeta", z), ("zd", v)):
        if not np.all(np.isfinite(values)):
            raise InputError(f"{name} contains non-finite values")
        if np.any(values < 0.0):
            raise InputError(
                f"{name} has negative values (min {values.min():.3g}); the law is defined "
                "on zeta >= 0, zd = max(dzeta/dt, 0) >= 0"
            )
    return np.broadcast_arrays(z, v)


def features(
    zeta: ArrayLike, zd: ArrayLike, library: Library | np.ndarray, box: Box | None = None
) -> np.ndarray:
    """Design matrix of the library evaluated at samples.

    Parameters
    ----------
    zeta : array_like, shape (n_samples,)
        Interpenetration [m], >= 0.
    zd : array_like, shape (n_samples,)
        Penetration velocity [m/s], >= 0.
    library : sequence of (float, float)
    box : Box, optional
        If given, return the *scaled* features ``(zeta/Z)**a (zd/V)**b`` (dimensionless),
        to be paired with scaled coefficients ``x`` [N]; otherwise the physical features
        ``zeta**a zd**b`` paired with physical coefficients ``c``.

    Returns
    -------
    ndarray, shape (n_samples, n_terms)
    """
    exps = exponents(library)
    z, v = _state(zeta, zd)
    z = z.ravel()
    v = v.ravel()
    if box is not None:
        z = z / box.zeta_max
        v = v / box.zd_max
    return z[:, None] ** exps[None, :, 0] * v[:, None] ** exps[None, :, 1]


def evaluate(
    coef: ArrayLike, library: Library | np.ndarray, zeta: ArrayLike, zd: ArrayLike
) -> np.ndarray:
    """Evaluate the law ``P(zeta, zd) = sum_i c_i zeta**a_i zd**b_i`` [N].

    Parameters
    ----------
    coef : array_like, shape (n_terms,)
        Physical coefficients.
    library : sequence of (float, float)
    zeta, zd : array_like
        Interpenetration [m] and penetration velocity [m/s], broadcastable, >= 0.

    Returns
    -------
    ndarray
        Force [N], with the broadcast shape of ``zeta`` and ``zd``.
    """
    exps = exponents(library)
    c = _coefficients(coef, exps.shape[0])
    z, v = _state(zeta, zd)
    total = np.zeros(z.shape)
    for ci, (a, b) in zip(c, exps, strict=True):
        total += ci * z**a * v**b
    return total
