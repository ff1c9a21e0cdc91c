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
_cvxpy
    ``cvxpy``, imported without ``scipy.stats`` (for one name it never uses here).
solver
    :func:`solve`, a cvxpy wrapper that raises on any non-optimal status.
errors
    :class:`VidiError` (root of the project's one error hierarchy), :class:`InputError`,
    :class:`CertificateError`, :class:`SolverError`.
"""

import importlib

# Imported on first use (PEP 562): ``import constraints`` costs nothing until a name is
# needed, so the errors module can be reached without loading cvxpy.
_EXPORTS = {
    "CONDITIONS": "bernstein",
    "BernsteinMap": "bernstein",
    "bernstein_coefficients": "bernstein",
    "bernstein_map": "bernstein",
    "evaluate_bernstein": "bernstein",
    "lattice_factor": "bernstein",
    "coefficient_signs": "builders",
    "constraint_rows": "builders",
    "dissipativity": "builders",
    "monotone_elastic": "builders",
    "non_adhesion": "builders",
    "normalized_rows": "builders",
    "physical": "builders",
    "sign_rows": "builders",
    "cvxpy": "_cvxpy",
    "Box": "domain",
    "CertificateError": "errors",
    "InputError": "errors",
    "SolverError": "errors",
    "VidiError": "errors",
    "evaluate": "library",
    "exponents": "library",
    "features": "library",
    "scale_factors": "library",
    "to_physical": "library",
    "to_scaled": "library",
    "solve": "solver",
    "DEFAULT_GRID": "verify",
    "DEFAULT_TOLERANCE": "verify",
    "Certificate": "verify",
    "certify": "verify",
    "force_scale": "verify",
    "grid_minimum": "verify",
    "require": "verify",
}


def __getattr__(name):
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module 'constraints' has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{module}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))


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
