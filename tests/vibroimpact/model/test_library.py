"""Candidate term libraries (discovery.vibroimpact.model.library) and the estimator's scikit-learn
contract."""

import inspect
import re

import numpy as np
import pytest
from sklearn.base import clone

from discovery.errors import InputError
from discovery.vibroimpact.fit.regression import ConstrainedSparseRegressor
from discovery.vibroimpact.model.library import Library

# ------------------------------------------------------------------ parsing


def test_poly2_names_in_degree_order():
    assert Library.parse("poly:2").names == ["z", "zd", "z^2", "z*zd", "zd^2"]


def test_poly3_has_every_monomial_of_degree_1_to_3():
    lib = Library.parse("poly:3")
    assert len(lib) == 9
    # every (a, b) with 1 <= a + b <= 3, each once
    expected = {(a, d - a) for d in (1, 2, 3) for a in range(d + 1)}
    assert {(int(a), int(b)) for a, b in lib.exponents} == expected


def test_hunt_crossley_terms():
    lib = Library.parse("hc")
    assert lib.names == ["z^1.5", "z^1.5*zd"]
    np.testing.assert_array_equal(lib.exponents, [[1.5, 0.0], [1.5, 1.0]])


def test_explicit_list_keeps_order():
    lib = Library.parse("z^1.5, zd, z*zd,z")
    assert lib.names == ["z^1.5", "zd", "z*zd", "z"]


@pytest.mark.parametrize(
    "spec, names",
    [
        ("poly:1+hc", ["z", "zd", "z^1.5", "z^1.5*zd"]),
        ("poly:2+z,zd", ["z", "zd", "z^2", "z*zd", "zd^2"]),  # z, zd already in poly:2
        ("hc+hc", ["z^1.5", "z^1.5*zd"]),
        ("poly:1 + poly:2", ["z", "zd", "z^2", "z*zd", "zd^2"]),
    ],
)
def test_sums_deduplicate_and_keep_first_order(spec, names):
    assert Library.parse(spec).names == names


def test_add_operator_accepts_text():
    assert (Library.parse("z") + "zd,z").names == ["z", "zd"]


def test_parse_returns_library_unchanged():
    lib = Library.parse("poly:2")
    assert Library.parse(lib) is lib


@pytest.mark.parametrize(
    "spec",
    [
        "",
        "   ",
        "poly:0",
        "poly:x",
        "poly:",
        "poly:2.5",
        "poly:9",
        "q",
        "z,q",
        "z,z",
        "2*z",
        None,
        3,
    ],
)
def test_bad_specs_raise_input_error(spec):
    with pytest.raises(InputError):
        Library.parse(spec)


@pytest.mark.parametrize(
    "spec, hint",
    [
        ("contact-model", "did you mean 'contact-models'?"),
        ("poly2", "did you mean 'poly:2'?"),
        ("Poly 3", "did you mean 'poly:3'?"),
        ("q", "fit also takes 'contact-models'"),
    ],
)
def test_a_near_miss_is_named(spec, hint):
    with pytest.raises(InputError, match=re.escape(hint)):
        Library.parse(spec)


@pytest.mark.parametrize("spec", ["+", " + "])
def test_only_plus_signs_raise_input_error(spec):
    with pytest.raises(InputError):
        Library.parse(spec)


# ---------------------------------------------------------------- transform


def test_transform_shape_and_values():
    lib = Library.parse("poly:2+hc")
    X = np.array(
        [
            [2e-4, 0.3],  # loading
            [2e-4, -0.3],  # unloading: zd = 0
            [-1e-4, 0.5],  # no contact: zeta clipped to 0
            [0.0, 0.0],
        ]
    )
    T = lib.transform(X)
    assert T.shape == (4, len(lib))
    z = np.array([2e-4, 2e-4, 0.0, 0.0])
    zd = np.array([0.3, 0.0, 0.5, 0.0])
    expected = np.column_stack([z, zd, z**2, z * zd, zd**2, z**1.5, z**1.5 * zd])
    # same arithmetic in another order: equal to a few ulps
    np.testing.assert_allclose(T, expected, rtol=1e-14, atol=0)
    # every column with a zeta factor vanishes where zeta < 0
    has_z = lib.exponents[:, 0] > 0
    assert np.all(T[2, has_z] == 0.0)
    # every column with a zd factor vanishes where dzeta < 0
    has_zd = lib.exponents[:, 1] > 0
    assert np.all(T[1, has_zd] == 0.0)
    np.testing.assert_array_equal(lib.fit_transform(X), T)
    assert list(lib.get_feature_names_out()) == lib.names


@pytest.mark.parametrize("X", [np.zeros((3, 3)), np.zeros(4), np.zeros((2, 1))])
def test_transform_rejects_wrong_shapes(X):
    with pytest.raises(InputError):
        Library.parse("poly:1").transform(X)


def test_subset_and_law():
    lib = Library.parse("poly:2")
    sub = lib.subset(np.array([True, False, False, True, False]))
    assert sub.names == ["z", "z*zd"]
    law = lib.law([2.0, 0.0, 0.0, 3.0, 0.0])
    assert law.as_dict() == {"z": 2.0, "z*zd": 3.0}
    with pytest.raises(InputError):
        lib.law(np.zeros(5))


# ------------------------------------------------------------------ pysindy


def test_from_pysindy_polynomial_library_matches_poly2():
    ps = pytest.importorskip("pysindy")
    pl = ps.PolynomialLibrary(degree=2, include_bias=False)
    pl.fit(np.random.default_rng(0).uniform(size=(30, 2)))
    lib = Library.from_pysindy(pl)
    assert set(lib.names) == set(Library.parse("poly:2").names)
    assert len(lib) == 5


def test_from_pysindy_drops_the_bias():
    ps = pytest.importorskip("pysindy")
    pl = ps.PolynomialLibrary(degree=3, include_bias=True)
    pl.fit(np.ones((10, 2)))
    assert set(Library.from_pysindy(pl).names) == set(Library.parse("poly:3").names)


def test_from_pysindy_rejects_three_inputs():
    ps = pytest.importorskip("pysindy")
    pl = ps.PolynomialLibrary(degree=2, include_bias=False)
    pl.fit(np.ones((10, 3)))
    with pytest.raises(InputError):
        Library.from_pysindy(pl)


# ----------------------------------------------------- scikit-learn contract


def _toy(n=300, seed=0):
    rng = np.random.default_rng(seed)
    z = rng.uniform(0, 1e-3, n)
    v = rng.uniform(-0.5, 0.5, n)
    y = 2e8 * z + 1e7 * np.maximum(v, 0) + rng.normal(0, 1e3, n)
    return np.column_stack([z, v]), y


def test_get_params_are_the_constructor_arguments():
    sig = inspect.signature(ConstrainedSparseRegressor.__init__)
    names = [p for p in sig.parameters if p != "self"]
    args = dict(
        library="z,zd,z*zd",
        selection="l1-path",
        scoring="aic",
        max_terms=2,
        cv=3,
        margin=1.5,
        monotone=True,
        signs=[1, 1, 0],
        box_margin=0.2,
        elevation=3,
        threshold=0.1,
        n_lambdas=7,
        solver="CLARABEL",
        grid=51,
        cv_report=True,
    )
    assert set(args) == set(names)  # the test covers every parameter
    est = ConstrainedSparseRegressor(**args)
    params = est.get_params()
    assert set(params) == set(names)
    for k in names:
        assert params[k] is args[k]  # stored unchanged, not copied or converted
    # no learned attribute before fit (sklearn: __init__ only stores its arguments)
    assert not [a for a in vars(est) if a.endswith("_")]


def test_defaults_match_signature():
    sig = inspect.signature(ConstrainedSparseRegressor.__init__)
    params = ConstrainedSparseRegressor().get_params()
    for k, p in sig.parameters.items():
        if k != "self":
            assert params[k] == p.default


def test_clone_and_set_params():
    est = ConstrainedSparseRegressor(library="poly:3", signs=[1, 1, 0, 0, 0, 0, 0, 0, 0])
    c = clone(est)
    assert c is not est and c.get_params() == est.get_params()
    c.set_params(max_terms=2, scoring="cv")
    assert c.max_terms == 2 and c.scoring == "cv" and est.max_terms == 4


def test_fit_returns_self_learns_underscored_attributes_and_keeps_params():
    X, y = _toy()
    est = ConstrainedSparseRegressor(library="poly:2", max_terms=3, grid=101)
    before = dict(vars(est))
    params = est.get_params()
    assert est.fit(X, y) is est
    assert est.get_params() == params  # fit never overwrites a parameter
    learned = [a for a in vars(est) if a not in before]
    assert learned and all(a.endswith("_") for a in learned), learned
    for a in (
        "library_",
        "box_",
        "coef_",
        "support_",
        "law_",
        "candidates_",
        "certificate_",
        "n_features_in_",
    ):
        assert hasattr(est, a)
    assert est.coef_.shape == (5,) and est.support_.dtype == bool
    # clone of a fitted estimator is unfitted
    assert not hasattr(clone(est), "coef_")
