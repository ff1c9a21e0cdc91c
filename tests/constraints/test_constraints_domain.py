"""Box validation and library helpers."""

import math

import numpy as np
import pytest

from constraints import Box, evaluate, exponents, features, to_physical, to_scaled


@pytest.mark.parametrize("field", ["zeta_max", "zd_max"])
@pytest.mark.parametrize("bad", [0.0, -1.0, math.inf, math.nan, "abc"])
def test_box_rejects_bad_bounds(field, bad):
    kwargs = {"zeta_max": 1e-3, "zd_max": 1.0, field: bad}
    with pytest.raises(ValueError, match=field) as info:
        Box(**kwargs)
    assert repr(bad) in str(info.value)


def test_box_serialises():
    box = Box(1e-3, 2)
    assert box.as_dict() == {"zeta_max": 1e-3, "zd_max": 2.0}


def test_box_from_data_uses_positive_parts_and_margin():
    box = Box.from_data([-1.0, 2e-3, 1e-3], [0.5, -3.0, 1.0], margin=0.1)
    assert box.zeta_max == pytest.approx(2.2e-3)
    assert box.zd_max == pytest.approx(1.1)


@pytest.mark.parametrize(
    ("zeta", "zd", "match"),
    [([-1.0, 0.0], [1.0], "zeta"), ([1.0], [0.0, -2.0], "zd"), ([np.nan], [1.0], "zeta")],
)
def test_box_from_data_errors(zeta, zd, match):
    with pytest.raises(ValueError, match=match):
        Box.from_data(zeta, zd)


@pytest.mark.parametrize(
    ("library", "match"),
    [
        ([], "empty"),
        ([(1, 0), (0, 0)], r"entry 1 = \(0, 0\)"),
        ([(1, -1)], ">= 0"),
        ([(1, 0), (1.0, 0.0)], "repeats"),
        ([(1,)], "pair"),
    ],
)
def test_library_validation(library, match):
    with pytest.raises(ValueError, match=match):
        exponents(library)


def test_scaling_round_trip_and_features():
    rng = np.random.default_rng(1)
    box = Box(1e-3, 0.5)
    library = [(1, 0), (1.5, 0), (1.5, 1), (0, 1)]
    c = np.array([1e8, 3e10, 4e10, 2e3])
    x = to_scaled(c, library, box)
    np.testing.assert_allclose(to_physical(x, library, box), c, rtol=1e-14)
    z = rng.uniform(0, box.zeta_max, 50)
    v = rng.uniform(0, box.zd_max, 50)
    np.testing.assert_allclose(features(z, v, library, box) @ x, evaluate(c, library, z, v))
    np.testing.assert_allclose(features(z, v, library) @ c, evaluate(c, library, z, v))
    with pytest.raises(ValueError, match="negative"):
        features([-1e-4], [0.1], library)
