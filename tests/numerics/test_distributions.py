"""Student's t quantile without scipy, against scipy's and the closed forms."""

import math

import numpy as np
import pytest
from scipy.special import stdtr, stdtrit

from discovery.numerics.distributions import t_cdf, t_quantile

DOFS = [1, 2, 3, 4, 5, 7, 10, 17, 30, 63, 100, 250, 499, 500, 501, 1000, 1e4, 1e5, 1e6]
PS = [0.6, 0.9, 0.95, 0.975, 0.99, 0.995, 0.9995, 0.025, 0.1, 1e-6]


@pytest.mark.parametrize("dof", DOFS + [0.5, 1.5, 2.5, 3.7])
def test_the_quantile_is_scipys(dof):
    for p in PS:
        want = float(stdtrit(dof, p))
        assert t_quantile(dof, p) == pytest.approx(want, rel=1e-10, abs=0.0)


@pytest.mark.parametrize("dof", DOFS)
def test_the_distribution_function_is_scipys(dof):
    for t in (0.0, 0.3, 1.0, 1.96, 2.5, 6.0, -1.5):
        want = float(stdtr(dof, t))
        tail = min(want, 1.0 - want)
        assert abs(t_cdf(t, dof) - want) <= 1e-10 * tail + 1e-300


def test_closed_forms():
    """One degree of freedom: Cauchy, ``tan(pi (p - 1/2))``; two: ``(2p - 1) / sqrt(2 p (1 - p))``;
    infinitely many: the normal quantile (the Cornish-Fisher series' first term)."""
    for p in np.linspace(0.01, 0.99, 41):
        assert t_quantile(1, p) == pytest.approx(
            math.tan(math.pi * (p - 0.5)), rel=1e-11, abs=1e-12
        )
        two = (2 * p - 1) / math.sqrt(2 * p * (1 - p))
        assert t_quantile(2, p) == pytest.approx(two, rel=1e-11, abs=1e-12)
    assert t_quantile(1e6, 0.975) == pytest.approx(1.959963984540054, rel=2e-6)
    assert t_quantile(30, 0.5) == 0.0
    assert t_quantile(30, 0.025) == -t_quantile(30, 0.975)


@pytest.mark.parametrize("dof, p", [(0, 0.5), (-1, 0.9), (5, 0.0), (5, 1.0), (5, float("nan"))])
def test_bad_arguments_are_refused(dof, p):
    with pytest.raises(ValueError, match="t_quantile needs"):
        t_quantile(dof, p)


def test_the_normal_quantile_is_scipys():
    from scipy.special import ndtri

    from discovery.numerics.distributions import normal_quantile

    for p in [1e-12, 1e-6, 0.025, 0.16, 0.5, 0.84, 0.975, 0.995, 1 - 1e-9]:
        assert normal_quantile(p) == pytest.approx(float(ndtri(p)), rel=1e-14, abs=1e-15)


def test_chi2_of_one_degree_is_scipys_and_the_squared_normal():
    from scipy.special import chdtrc

    from discovery.numerics.distributions import chi2_sf_one

    for x in [1e-10, 0.01, 0.5, 1.0, 3.841458820694124, 10.0, 50.0, 300.0]:
        assert chi2_sf_one(x) == pytest.approx(float(chdtrc(1, x)), rel=1e-12)
    # P(Z^2 > 1.96^2) = 2 P(Z > 1.96) = 0.05 at the normal's 97.5 % quantile
    assert chi2_sf_one(1.959963984540054**2) == pytest.approx(0.05, rel=1e-12)
    assert chi2_sf_one(0.0) == 1.0 and chi2_sf_one(-1.0) == 1.0
    assert math.isnan(chi2_sf_one(float("nan")))
