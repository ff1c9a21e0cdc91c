"""One error hierarchy: the constraints package's errors are discovery's VidiErrors."""

import cvxpy as cp
import pytest

import constraints
import discovery.errors
from constraints import Box, bernstein_map, certify, require, solve
from constraints.errors import CertificateError, InputError, SolverError, VidiError


def test_discovery_reexports_the_one_root():
    assert discovery.errors.VidiError is VidiError is constraints.VidiError
    assert discovery.errors.InputError is InputError
    assert issubclass(discovery.errors.LawSyntaxError, VidiError)
    assert issubclass(discovery.errors.IntegrationError, VidiError)


@pytest.mark.parametrize(
    "cls, builtin",
    [(InputError, ValueError), (CertificateError, ValueError), (SolverError, RuntimeError)],
)
def test_every_constraints_error_is_a_vidi_error_and_its_builtin(cls, builtin):
    assert issubclass(cls, VidiError) and issubclass(cls, builtin)


def test_raised_errors_are_catchable_as_vidi_error():
    with pytest.raises(VidiError, match="zeta_max"):
        Box(-1.0, 1.0)
    with pytest.raises(VidiError, match="unknown condition"):
        bernstein_map([(1, 0)], Box(1e-3, 1.0), "sticky")
    x = cp.Variable(1)
    with pytest.raises(VidiError, match="infeasible"):
        solve(cp.Problem(cp.Minimize(x), [x >= 1, x <= 0]))
    cert = certify([-1.0], [(1, 0)], Box(1e-3, 1.0), ["non_adhesion"])
    with pytest.raises(VidiError, match="non_adhesion"):
        require(cert)
