"""Exactness of the Bernstein maps (the certificate is only as good as this identity)."""

import numpy as np
import pytest

from constraints import Box, bernstein_coefficients, bernstein_map, evaluate, evaluate_bernstein
from constraints.bernstein import check_margin, lattice_factor, monomial_bernstein

BOX = Box(2e-3, 0.8)

LIBRARIES = [
    [(1, 0), (2, 0), (0, 1), (1, 1), (2, 2)],
    [(1.5, 0), (1.5, 1), (1, 0), (0, 1), (0.5, 0.5)],
    [(1 / 3, 0), (4 / 3, 1), (2, 0.25)],
]


def _random_points(rng, n=200):
    s = np.concatenate([rng.uniform(0, 1, n), [0.0, 1.0, 0.0, 1.0]])
    u = np.concatenate([rng.uniform(0, 1, n), [0.0, 0.0, 1.0, 1.0]])
    return s, u


@pytest.mark.parametrize("library", LIBRARIES)
@pytest.mark.parametrize("elevation", [0, 2, 5])
def test_bernstein_form_reproduces_the_law(library, elevation):
    rng = np.random.default_rng(elevation)
    # physical coefficients of realistic magnitude: scaled coefficients ~ N(0, 1e3) N
    x = rng.normal(0.0, 1e3, len(library))
    a, b = np.array(library, dtype=float).T
    c = x / (BOX.zeta_max**a * BOX.zd_max**b)
    bmap = bernstein_map(library, BOX, elevation=elevation)
    q, r = bmap.lattice
    coefs = bernstein_coefficients(c, library, BOX, elevation=elevation)
    assert coefs.shape == tuple(d + 1 for d in bmap.degrees)
    s, u = _random_points(rng)
    direct = evaluate(c, library, BOX.zeta_max * s**q, BOX.zd_max * u**r)
    via_bernstein = evaluate_bernstein(coefs, s, u)
    scale = np.sum(np.abs(x))  # bound on |P| over the box
    assert np.max(np.abs(via_bernstein - direct)) <= 1e-12 * scale


def test_half_integer_lattice_and_degrees():
    bmap = bernstein_map([(1.5, 0), (1.5, 1)], BOX, elevation=2)
    assert bmap.lattice == (2, 1)
    assert bmap.degrees == (3 + 2, 1 + 2)
    assert bmap.matrix.shape == (6 * 4, 2)
    assert bmap.matrix.min() >= 0.0 and bmap.matrix.max() == 1.0


def test_dissipativity_map_is_exact_with_margin():
    rng = np.random.default_rng(7)
    library = [(1.5, 0), (0, 1), (1.5, 1), (1, 0.5)]
    c = np.array([5e10, 300.0, 2e9, 1e5])
    margin = 120.0  # N s/m
    coefs = bernstein_coefficients(c, library, BOX, "dissipativity", margin=margin)
    q, r = bernstein_map(library, BOX, "dissipativity", margin=margin).lattice
    s, u = _random_points(rng)
    zeta, zd = BOX.zeta_max * s**q, BOX.zd_max * u**r
    expected = evaluate(c, library, zeta, zd) - evaluate(c, library, zeta, 0 * zd) - margin * zd
    got = evaluate_bernstein(coefs, s, u)
    assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))


def test_monotone_map_is_exact():
    rng = np.random.default_rng(3)
    library = [(1, 0), (1.5, 0), (2, 0), (1.5, 1)]
    c = np.array([1e7, -2e10, 3e12, 9e9])
    coefs = bernstein_coefficients(c, library, BOX, "monotone_elastic")
    assert coefs.ndim == 1
    q = bernstein_map(library, BOX, "monotone_elastic").lattice[0]
    s = rng.uniform(0, 1, 100)
    zeta = BOX.zeta_max * s**q
    expected = 1e7 * zeta - 1.5 * 2e10 * zeta**1.5 + 2 * 3e12 * zeta**2
    got = evaluate_bernstein(coefs, s)
    assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))


def test_monomial_bernstein_values():
    np.testing.assert_array_equal(monomial_bernstein(0, 4), np.ones(5))
    np.testing.assert_allclose(monomial_bernstein(1, 4), np.arange(5) / 4)
    np.testing.assert_allclose(monomial_bernstein(2, 3), [0, 0, 1 / 3, 1])


def test_lattice_factor():
    assert lattice_factor([1, 2, 0]) == 1
    assert lattice_factor([1.5, 1]) == 2
    assert lattice_factor([0.25, 0.5]) == 4
    assert lattice_factor([1 / 3, 0.5]) == 6
    with pytest.raises(ValueError, match="denominator <= 8"):
        lattice_factor([1 / 9])
    with pytest.raises(ValueError, match="denominator <= 8"):
        bernstein_map([(np.pi, 0)], BOX)


def test_impossible_margin_is_an_error():
    # Hunt-Crossley: Q = chi * zeta**1.5 vanishes at zeta = 0, so no positive margin.
    with pytest.raises(ValueError, match="impossible"):
        check_margin([(1.5, 0), (1.5, 1)], 1.0)
    with pytest.raises(ValueError, match="impossible"):
        bernstein_map([(1.5, 0), (0, 2)], BOX, "dissipativity", margin=1.0)
    assert check_margin([(1.5, 0), (1.5, 1)], 0.0) == 0.0
    with pytest.raises(ValueError, match="margin"):
        check_margin([(0, 1)], -1.0)
