"""Independent verification of a fitted law: Bernstein certificate plus a dense grid.

The grid check does not use the Bernstein machinery: it evaluates the condition with the
original real exponents at ``n_zeta x n_zd`` points uniformly spaced in ``zeta`` and ``zd``,
box edges included (default ``1001 x 1001``, about 1e6 points), in row chunks to bound memory.

All condition quantities are forces [N] (see :mod:`constraints.bernstein`), and relative values
are divided by the force scale ``max |P|`` over the grid. A law is accepted (``holds``) only if
its Bernstein coefficients are all ``>= -tol * scale`` *and* the grid minimum is
``>= -tol * scale`` for every requested condition.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import ArrayLike

from .bernstein import CONDITIONS, bernstein_map, check_margin
from .domain import Box
from .errors import CertificateError, InputError
from .library import Library, exponents, to_scaled

__all__ = [
    "DEFAULT_GRID",
    "DEFAULT_TOLERANCE",
    "Certificate",
    "certify",
    "force_scale",
    "grid_minimum",
    "require",
]

DEFAULT_GRID = 1001
"""Default grid size per axis: 1001 x 1001 = 1,002,001 points including the box edges."""

DEFAULT_TOLERANCE = 1e-7
"""Default relative tolerance (fraction of ``max |P|``) on Bernstein and grid minima.

Interior-point solvers meet the certificate rows to about 1e-8 relative to the coefficient
magnitudes; 1e-7 of the force scale absorbs that and float round-off, and is physically
negligible (0.1 mN for a 1 kN law).
"""

_QUANTITY = {
    "non_adhesion": "P(zeta, zd)",
    "dissipativity": "P(zeta, zd) - P(zeta, 0) - margin * zd",
    "monotone_elastic": "zeta * dP/dzeta(zeta, 0)",
}


@dataclass(frozen=True)
class Certificate:
    """Outcome of :func:`certify`.

    Attributes
    ----------
    method : str
        E.g. ``"bernstein(elevation=2)+grid(1001x1001)"``.
    holds : bool
        True iff every condition has its Bernstein certificate and its grid minimum within
        ``-tolerance * force_scale``.
    worst_violation : float
        Largest grid violation over the conditions, relative to ``force_scale`` (0 when none).
    domain : dict
        ``{"zeta_max": Z [m], "zd_max": V [m/s]}``.
    conditions : dict
        Condition name -> dict with ``bernstein_min`` and ``grid_min`` [N] (and ``*_rel``
        relative values), ``location`` ``{"zeta": m, "zd": m/s}`` of the grid minimum,
        ``bernstein_location`` (control point of the smallest Bernstein coefficient),
        ``quantity``, ``units``, ``grid_points``, ``degrees``, ``lattice``, ``holds``.
    tolerance : float
        Relative tolerance used.
    force_scale : float
        ``max |P|`` over the grid [N].
    """

    method: str
    holds: bool
    worst_violation: float
    domain: dict[str, float]
    conditions: dict[str, dict[str, Any]]
    tolerance: float = DEFAULT_TOLERANCE
    force_scale: float = 0.0

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready copy (plain dicts, lists, floats, bools, strings)."""
        return {
            "method": self.method,
            "holds": bool(self.holds),
            "worst_violation": float(self.worst_violation),
            "domain": dict(self.domain),
            "conditions": copy.deepcopy(self.conditions),
            "tolerance": float(self.tolerance),
            "force_scale": float(self.force_scale),
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Certificate:
        """The certificate :meth:`as_dict` describes, also after a JSON round trip (a
        number that is not finite written as ``null`` reads as ``nan``); ``tolerance`` and
        ``force_scale``, which a result's document leaves out, default as in the
        constructor."""

        def real(v: Any) -> float:
            return math.nan if v is None else float(v)

        return cls(
            method=d["method"],
            holds=bool(d["holds"]),
            worst_violation=real(d["worst_violation"]),
            domain={k: real(v) for k, v in d["domain"].items()},
            conditions=copy.deepcopy(dict(d["conditions"])),
            tolerance=real(d.get("tolerance", DEFAULT_TOLERANCE)),
            force_scale=real(d.get("force_scale", 0.0)),
        )


def _grid_shape(grid: int | Sequence[int]) -> tuple[int, int]:
    sizes = (grid, grid) if np.ndim(grid) == 0 else tuple(grid)
    if len(sizes) != 2 or any(isinstance(n, bool) or int(n) != n or int(n) < 2 for n in sizes):
        raise InputError(f"grid must be an integer >= 2 or a pair of them, got {grid!r}")
    return int(sizes[0]), int(sizes[1])


def _terms(
    x: np.ndarray, exps: np.ndarray, box: Box, condition: str, margin: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Weights [N] and real exponents of the condition polynomial in (s, u) = (zeta/Z, zd/V)."""
    a, b = exps[:, 0], exps[:, 1]
    if condition == "non_adhesion":
        return x, a, b
    if condition == "dissipativity":
        active = b > 0.0
        weights, alpha, beta = x[active], a[active], b[active]
        if margin > 0.0:
            weights = np.append(weights, -margin * box.zd_max)
            alpha = np.append(alpha, 0.0)
            beta = np.append(beta, 1.0)
        return weights, alpha, beta
    active = b == 0.0
    return a[active] * x[active], a[active], b[active]


def _scan(
    weights: np.ndarray,
    alpha: np.ndarray,
    beta: np.ndarray,
    axes: tuple[np.ndarray, np.ndarray],
    chunk_rows: int,
) -> tuple[float, tuple[int, int], float]:
    """Min, argmin (i, j) and max |.| of sum_k w_k s_i**alpha_k u_j**beta_k over the grid
    ``axes = (s, u)``."""
    if weights.size == 0:
        return 0.0, (0, 0), 0.0
    s, u = axes
    s_pow = s[:, None] ** alpha[None, :] * weights[None, :]
    u_pow_t = (u[:, None] ** beta[None, :]).T
    best, where, peak = math.inf, (0, 0), 0.0
    for start in range(0, s.size, chunk_rows):
        block = s_pow[start : start + chunk_rows] @ u_pow_t
        flat = int(np.argmin(block))
        i, j = divmod(flat, block.shape[1])
        if block[i, j] < best:
            best, where = float(block[i, j]), (start + i, j)
        peak = max(peak, float(np.max(np.abs(block))))
    return best, where, peak


def _scaled(coef: ArrayLike, library: Library, box: Box) -> tuple[np.ndarray, np.ndarray]:
    exps = exponents(library)
    return to_scaled(coef, exps, box), exps


def _axes(shape: tuple[int, int], condition: str) -> tuple[np.ndarray, np.ndarray]:
    s = np.linspace(0.0, 1.0, shape[0])
    u = np.zeros(1) if condition == "monotone_elastic" else np.linspace(0.0, 1.0, shape[1])
    return s, u


def grid_minimum(
    coef: ArrayLike,
    library: Library,
    box: Box,
    condition: str = "non_adhesion",
    *,
    grid: int | Sequence[int] = DEFAULT_GRID,
    margin: float = 0.0,
    chunk_rows: int = 128,
) -> tuple[float, tuple[float, float]]:
    """Minimum of a condition quantity on a dense grid.

    Parameters
    ----------
    coef : array_like, shape (n_terms,)
        Physical coefficients.
    library : sequence of (float, float)
    box : Box
    condition : {"non_adhesion", "dissipativity", "monotone_elastic"}
    grid : int or (int, int), optional
        Points per axis ``(n_zeta, n_zd)``, edges included (``monotone_elastic`` uses
        ``n_zeta`` points on the ``zd = 0`` edge).
    margin : float, optional
        Dissipativity margin [N s/m].
    chunk_rows : int, optional
        Grid rows evaluated at once (memory ``~ 8 * chunk_rows * n_zd`` bytes).

    Returns
    -------
    minimum : float
        Smallest value of the quantity [N].
    location : tuple of float
        ``(zeta [m], zd [m/s])`` where it is reached.
    """
    if condition not in CONDITIONS:
        raise InputError(f"unknown condition {condition!r}; expected one of {CONDITIONS}")
    margin = check_margin(library, margin) if condition == "dissipativity" else 0.0
    shape = _grid_shape(grid)
    x, exps = _scaled(coef, library, box)
    s, u = _axes(shape, condition)
    value, (i, j), _ = _scan(*_terms(x, exps, box, condition, margin), (s, u), chunk_rows)
    return value, (float(s[i] * box.zeta_max), float(u[j] * box.zd_max))


def force_scale(
    coef: ArrayLike,
    library: Library,
    box: Box,
    *,
    grid: int | Sequence[int] = DEFAULT_GRID,
    chunk_rows: int = 128,
) -> float:
    """Force scale ``max |P|`` over the grid [N]."""
    x, exps = _scaled(coef, library, box)
    s, u = _axes(_grid_shape(grid), "non_adhesion")
    return _scan(x, exps[:, 0], exps[:, 1], (s, u), chunk_rows)[2]


def certify(
    coef: ArrayLike,
    library: Library,
    box: Box,
    conditions: str | Sequence[str] = ("non_adhesion", "dissipativity"),
    *,
    elevation: int = 2,
    grid: int | Sequence[int] = DEFAULT_GRID,
    margin: float = 0.0,
    tol: float = DEFAULT_TOLERANCE,
) -> Certificate:
    """Certify a law on the whole box by Bernstein coefficients and a dense grid.

    Parameters
    ----------
    coef : array_like, shape (n_terms,)
        Physical coefficients ``c``.
    library : sequence of (float, float), length n_terms
        Exponent pairs ``(a_i, b_i)``.
    box : Box
        Domain ``[0, Z] x [0, V]``.
    conditions : str or sequence of str, optional
        Subset of ``("non_adhesion", "dissipativity", "monotone_elastic")``.
    elevation : int, optional
        Bernstein degree elevation.
    grid : int or (int, int), optional
        Grid points per axis, box edges included (default 1001 x 1001).
    margin : float, optional
        Dissipativity margin [N s/m].
    tol : float, optional
        Relative tolerance (fraction of ``max |P|``).

    Returns
    -------
    Certificate
    """
    names = (conditions,) if isinstance(conditions, str) else tuple(conditions)
    if not names:
        raise InputError("conditions is empty; name at least one of " + ", ".join(CONDITIONS))
    for name in names:
        if name not in CONDITIONS:
            raise InputError(f"unknown condition {name!r}; expected one of {CONDITIONS}")
    tol = float(tol)
    if not math.isfinite(tol) or tol < 0.0:
        raise InputError(f"tol must be a finite number >= 0, got {tol!r}")
    shape = _grid_shape(grid)
    x, exps = _scaled(coef, library, box)
    scale = force_scale(coef, exps, box, grid=shape)
    reference = scale if scale > 0.0 else 1.0
    results: dict[str, dict[str, Any]] = {}
    worst = 0.0
    for name in names:
        cond_margin = margin if name == "dissipativity" else 0.0
        bmap = bernstein_map(exps, box, name, elevation=elevation, margin=cond_margin)
        bern = np.asarray(bmap.matrix) @ x + np.asarray(bmap.offset)
        row = int(np.argmin(bern))
        bern_min = float(bern[row])
        grid_value, location = grid_minimum(coef, exps, box, name, grid=shape, margin=cond_margin)
        grid_min = min(0.0, grid_value)
        ok = bern_min >= -tol * reference and grid_min >= -tol * reference
        worst = max(worst, -grid_min / reference)
        bz, bv = bmap.control_point(row)
        results[name] = {
            "quantity": _QUANTITY[name],
            "units": "N",
            "holds": bool(ok),
            "bernstein_min": bern_min,
            "bernstein_min_rel": bern_min / reference,
            "bernstein_location": {"zeta": bz, "zd": bv},
            "grid_min": grid_min,
            "grid_min_rel": grid_min / reference,
            "location": {"zeta": location[0], "zd": location[1]},
            "grid_points": int(shape[0] if name == "monotone_elastic" else shape[0] * shape[1]),
            "degrees": list(bmap.degrees),
            "lattice": list(bmap.lattice),
        }
        if name == "dissipativity":
            results[name]["margin"] = float(cond_margin)
    return Certificate(
        method=f"bernstein(elevation={elevation})+grid({shape[0]}x{shape[1]})",
        holds=all(r["holds"] for r in results.values()),
        worst_violation=float(worst),
        domain=box.as_dict(),
        conditions=results,
        tolerance=tol,
        force_scale=float(scale),
    )


def require(certificate: Certificate) -> Certificate:
    """Raise unless the certificate holds.

    Parameters
    ----------
    certificate : Certificate

    Returns
    -------
    Certificate
        The same certificate, when it holds.

    Raises
    ------
    CertificateError
        One-line message naming the condition, where and by how much it fails. A grid
        violation is reported first (the worst one); otherwise the inconclusive Bernstein
        certificate (raise ``elevation``) is reported.
    """
    if certificate.holds:
        return certificate
    failed = {k: v for k, v in certificate.conditions.items() if not v["holds"]}
    limit = -certificate.tolerance
    violated = {k: v for k, v in failed.items() if v["grid_min_rel"] < limit}
    scale = certificate.force_scale
    if violated:
        name, info = min(violated.items(), key=lambda item: item[1]["grid_min_rel"])
        where = (info["location"]["zeta"], info["location"]["zd"])
        message = (
            f"{name} violated: {info['quantity']} = {info['grid_min']:.4g} N "
            f"({-info['grid_min_rel']:.3g} of force scale {scale:.4g} N) "
            f"at zeta={where[0]:.4g} m, zd={where[1]:.4g} m/s [{certificate.method}]"
        )
        violation = -info["grid_min_rel"]
    else:
        name, info = min(failed.items(), key=lambda item: item[1]["bernstein_min_rel"])
        where = (info["bernstein_location"]["zeta"], info["bernstein_location"]["zd"])
        message = (
            f"{name} not certified: Bernstein coefficient {info['bernstein_min']:.4g} N "
            f"({-info['bernstein_min_rel']:.3g} of force scale {scale:.4g} N) near "
            f"zeta={where[0]:.4g} m, zd={where[1]:.4g} m/s although the grid shows no "
            f"violation; raise the elevation [{certificate.method}]"
        )
        violation = 0.0
    raise CertificateError(message, condition=name, location=where, violation=violation)
