"""Certified physical constraints for contact-force laws ``F = P(zeta, zd)``.

A law ``P(zeta, zd) = sum_i c_i zeta**a_i zd**b_i`` (``zeta`` interpenetration [m],
``zd = max(dzeta/dt, 0)`` penetration velocity [m/s]) must satisfy on the whole box
``D = [0, Z] x [0, V]``:

* non-adhesion ``P >= 0``;
* dissipativity ``P(zeta, zd) - P(zeta, 0) >= margin * zd`` (``margin = 0`` by default);
* optionally a monotone elastic branch ``dP/dzeta(zeta, 0) >= 0`` and coefficient signs.

Modules
-------
domain
    :class:`Box`, the domain.
library
    Library validation, physical <-> scaled coefficients, features and evaluation.
bernstein
    Bernstein-polynomial certificates (linear maps from coefficients).
builders
    cvxpy constraints on the **scaled** coefficients ``x_i = c_i Z**a_i V**b_i`` [N].
verify
    :func:`certify` (Bernstein + dense grid), :class:`Certificate`, :func:`require`.
solver
    :func:`solve`, a cvxpy wrapper that raises on any non-optimal status.
errors
    :class:`VidiError` (root of the project's one error hierarchy), :class:`InputError`,
    :class:`CertificateError`, :class:`SolverError`.
"""

from .bernstein import (
    CONDITIONS,
    BernsteinMap,
    bernstein_coefficients,
    bernstein_map,
    evaluate_bernstein,
    lattice_factor,
)
from .builders import (
    coefficient_signs,
    constraint_rows,
    dissipativity,
    monotone_elastic,
    non_adhesion,
    normalized_rows,
    physical,
    sign_rows,
)
from .domain import Box
from .errors import CertificateError, InputError, SolverError, VidiError
from .library import evaluate, exponents, features, scale_factors, to_physical, to_scaled
from .solver import solve
from .verify import (
    DEFAULT_GRID,
    DEFAULT_TOLERANCE,
    Certificate,
    certify,
    force_scale,
    grid_minimum,
    require,
)

__all__ = [
    "CONDITIONS",
    "DEFAULT_GRID",
    "DEFAULT_TOLERANCE",
    "BernsteinMap",
    "Box",
    "Certificate",
    "CertificateError",
    "InputError",
    "SolverError",
    "VidiError",
    "bernstein_coefficients",
    "bernstein_map",
    "certify",
    "coefficient_signs",
    "constraint_rows",
    "dissipativity",
    "evaluate",
    "evaluate_bernstein",
    "exponents",
    "features",
    "force_scale",
    "grid_minimum",
    "lattice_factor",
    "monotone_elastic",
    "non_adhesion",
    "normalized_rows",
    "physical",
    "require",
    "scale_factors",
    "sign_rows",
    "solve",
    "to_physical",
    "to_scaled",
]
