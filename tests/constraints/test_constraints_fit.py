"""Constrained least squares with the builders, verified independently; solve() errors."""

import cvxpy as cp
import numpy as np
import pytest

from constraints import (
    Box,
    SolverError,
    certify,
    coefficient_signs,
    constraint_rows,
    dissipativity,
    evaluate,
    features,
    non_adhesion,
    normalized_rows,
    physical,
    require,
    solve,
    to_physical,
)

# Tolerance of the verification, relative to the force scale max |P| on the box. The
# interior-point solver (CLARABEL) satisfies the row-normalised Bernstein constraints to about
# 1e-8 of the scaled coefficients; 1e-7 (the package default) leaves a margin for that and for
# round-off, and is physically negligible (0.1 mN for a law reaching 1 kN).
TOL = 1e-7

BOX = Box(1e-3, 1.0)
LIBRARY = [(1, 0), (0, 1), (1, 1), (1.5, 0), (1.5, 1)]


def _data(c_true, n=400, noise=1e2, seed=0):
    rng = np.random.default_rng(seed)
    zeta = rng.uniform(0, BOX.zeta_max, n)
    zd = rng.uniform(0, BOX.zd_max, n)
    force = evaluate(c_true, LIBRARY, zeta, zd) + rng.normal(0.0, noise, n)
    return zeta, zd, force


def _fit(zeta, zd, force, constraints_of):
    # scaled features and a force unit keep the problem O(1) whatever Z, V and c are
    theta = features(zeta, zd, LIBRARY, BOX)
    unit = float(np.max(np.abs(force)))
    x = cp.Variable(len(LIBRARY))
    problem = cp.Problem(
        cp.Minimize(cp.sum_squares(theta @ x - force / unit)), constraints_of(x, unit)
    )
    solve(problem)
    return unit * to_physical(x.value, LIBRARY, BOX)


def test_builders_make_an_adhesive_fit_physical():
    # the data come from k zeta - c zd: a pulling viscous term, negative near zeta = 0
    c_true = np.array([1e8, -2e4, 0.0, 0.0, 0.0])
    data = _data(c_true)

    free = _fit(*data, lambda x, unit: [])
    bad = certify(free, LIBRARY, BOX, tol=TOL)
    assert not bad.holds and bad.worst_violation > 0.1
    with pytest.raises(ValueError, match="violated"):
        require(bad)

    fitted = _fit(*data, lambda x, unit: physical(x, LIBRARY, BOX, monotone=True))
    cert = certify(
        fitted, LIBRARY, BOX, ("non_adhesion", "dissipativity", "monotone_elastic"), tol=TOL
    )
    assert cert.holds, cert.conditions
    assert cert.worst_violation <= TOL
    for info in cert.conditions.values():
        assert info["bernstein_min_rel"] >= -TOL and info["grid_min_rel"] >= -TOL
    require(cert)


def test_dissipativity_margin_in_newton_seconds_per_metre():
    library = [(1, 0), (0, 1), (1.5, 1)]
    rng = np.random.default_rng(4)
    zeta = rng.uniform(0, BOX.zeta_max, 300)
    zd = rng.uniform(0, BOX.zd_max, 300)
    force = evaluate([1e8, 5.0, 1e6], library, zeta, zd)  # Q = 5 + 1e6 zeta**1.5 >= 5
    theta = features(zeta, zd, library, BOX)
    unit = float(np.max(np.abs(force)))
    margin = 50.0  # N s/m: more damping than the data have, so the constraint is active
    x = cp.Variable(3)
    cons = non_adhesion(x, library, BOX) + dissipativity(
        x, library, BOX, margin=margin, force_unit=unit
    )
    solve(cp.Problem(cp.Minimize(cp.sum_squares(theta @ x - force / unit)), cons))
    c = unit * to_physical(x.value, library, BOX)
    assert c[1] == pytest.approx(margin, rel=1e-4)  # active at zeta = 0 (solver accuracy)
    cert = certify(c, library, BOX, margin=margin, tol=TOL)
    assert cert.holds, cert.conditions
    assert not certify(c, library, BOX, margin=1.01 * margin, tol=TOL).holds
    with pytest.raises(ValueError, match="impossible"):
        dissipativity(x, [(1.5, 0), (1.5, 1)], BOX, margin=1.0)


def test_coefficient_signs():
    x = cp.Variable(3)
    library = [(1, 0), (0, 1), (2, 0)]
    cons = coefficient_signs(x, library, signs=[1, -1, 0])
    solve(cp.Problem(cp.Minimize(cp.sum_squares(x - np.array([-1.0, 1.0, -3.0]))), cons))
    np.testing.assert_allclose(x.value, [0.0, 0.0, -3.0], atol=1e-7)
    assert coefficient_signs(x, library, signs=0) == []
    with pytest.raises(ValueError, match="signs"):
        coefficient_signs(x, library, signs=[1, 2, 0])
    with pytest.raises(ValueError, match="shape"):
        non_adhesion(cp.Variable(2), library, BOX)


def test_solve_raises_on_infeasible_with_status():
    x = cp.Variable(2)
    problem = cp.Problem(cp.Minimize(cp.sum(x)), [x >= 1, x <= 0])
    with pytest.raises(SolverError, match="infeasible") as info:
        solve(problem)
    assert info.value.status == "infeasible"


def test_solve_raises_on_unbounded():
    x = cp.Variable(2)
    with pytest.raises(SolverError, match="unbounded") as info:
        solve(cp.Problem(cp.Minimize(cp.sum(x))))
    assert info.value.status == "unbounded"


def test_physical_constraints_are_infeasible_for_contradicting_signs():
    # all coefficients forced <= 0 with a strictly positive margin cannot satisfy Q >= margin
    x = cp.Variable(len(LIBRARY))
    cons = physical(x, LIBRARY, BOX, margin=1.0, signs=-1) + [cp.sum(cp.abs(x)) <= 1e3]
    with pytest.raises(SolverError, match="infeasible"):
        solve(cp.Problem(cp.Minimize(0), cons))


# ------------------------------------------------------------- shared rows


def _affine(constraints, x):
    """``(rows, rhs)`` of cvxpy constraints ``g(x) >= 0`` with affine ``g``, by evaluation."""

    def g(v):
        x.value = v
        # cvxpy stores ``a >= b`` as ``b <= a``, whose ``expr`` is ``b - a``
        return np.concatenate([-np.ravel(c.expr.value) for c in constraints])

    n = x.shape[0]
    rhs = g(np.zeros(n))
    rows = np.column_stack([g(np.eye(n)[i]) - rhs for i in range(n)])
    return rows, rhs


@pytest.mark.parametrize(
    "kwargs",
    [
        dict(),
        dict(margin=50.0, force_unit=1e3),
        dict(monotone=True, signs=[1, -1, 0, 1, 0], elevation=3),
    ],
)
def test_constraint_rows_are_the_builders_constraints(kwargs):
    x = cp.Variable(len(LIBRARY))
    rows, rhs = constraint_rows(LIBRARY, BOX, **kwargs)
    ref_rows, ref_rhs = _affine(physical(x, LIBRARY, BOX, **kwargs), x)
    np.testing.assert_allclose(rows, ref_rows, rtol=0, atol=1e-15)
    np.testing.assert_allclose(rhs, ref_rhs, rtol=0, atol=1e-15)
    # normalised: every row has max-norm 1
    np.testing.assert_allclose(np.abs(rows).max(axis=1), 1.0, rtol=1e-15)
    assert np.any(rhs < 0) == ("margin" in kwargs)


def test_normalized_rows_drop_vanishing_rows_and_flag_impossible_ones():
    matrix = np.array([[2.0, -4.0], [0.0, 0.0], [0.0, 0.0], [0.0, 0.5]])
    offset = np.array([1.0, 0.0, -3.0, -1.0])
    rows, rhs, impossible = normalized_rows(matrix, offset)
    np.testing.assert_array_equal(rows, [[0.5, -1.0], [0.0, 1.0]])
    np.testing.assert_array_equal(rhs, [0.25, -2.0])
    np.testing.assert_array_equal(impossible, [2])  # 0 x - 3 >= 0 never holds


def test_constraint_rows_impossible_margin_raises():
    with pytest.raises(ValueError, match="impossible"):
        constraint_rows([(1, 0), (1.5, 1)], BOX, margin=1.0)
