"""Force-law grammar, canonical names, evaluation with the contact conditions, exports."""

import numpy as np
import pytest
import sympy
from hypothesis import given, settings
from hypothesis import strategies as st

from discovery.errors import InputError, LawSyntaxError
from discovery.vibroimpact.model.law import ZD, ZETA, ForceLaw, Term

# ----------------------------------------------------------------- grammar / round trip

ROUND_TRIP = [
    "2.06e8*z + 1.28e7*zd",
    "2e10*z^1.5 + 5e11*z^1.5*zd",
    "2e8*z - 3e10*z^2 + 1e7*zd",
    "-3.5*z^0.5*zd^1.5 + 0.25*zd^2",
    "1e-05*z^3 - 7*z*zd",
    "4.5*z^0.75",
]


@pytest.mark.parametrize("text", ROUND_TRIP)
def test_parse_to_text_round_trip(text):
    law = ForceLaw.parse(text)
    again = ForceLaw.parse(law.to_text())
    # exact equality: these coefficients have <= 12 significant digits, which to_text keeps
    assert again == law
    assert again.to_text() == law.to_text()


def test_parse_values_and_signs():
    law = ForceLaw.parse("2e8*z - 3e10*z^2 + 1e7*zd")
    assert law.names == ["z", "z^2", "zd"]
    assert law.coefficients == (2e8, -3e10, 1e7)
    first_negative = ForceLaw.parse("-3*z + zd")
    assert first_negative.coefficients == (-3.0, 1.0)
    assert first_negative.to_text().startswith("-3*z")


@pytest.mark.parametrize(
    ("name", "a", "b"),
    [
        ("z", 1, 0),
        ("zd", 0, 1),
        ("z*zd", 1, 1),
        ("z^1.5", 1.5, 0),
        ("z^2*zd", 2, 1),
        ("zd^0.5", 0, 0.5),
        ("z^0.25*zd^3", 0.25, 3),
    ],
)
def test_term_names(name, a, b):
    t = Term(a, b)
    assert t.name == name
    assert Term.parse(name) == t
    assert str(t) == name


@pytest.mark.parametrize(
    ("text", "canonical"),
    [
        ("zd*z", "z*zd"),
        ("z**2*zd", "z^2*zd"),
        ("z*z*zd", "z^2*zd"),
        ("zd^1*z^1.0", "z*zd"),
        ("z^0*zd", "zd"),
    ],
)
def test_equivalent_spellings_give_canonical_name(text, canonical):
    assert Term.parse(text).name == canonical


def test_like_terms_are_summed():
    law = ForceLaw.parse("2*z + 3*zd - 0.5*z + z*2 + zd*z")
    assert law.as_dict() == {"z": 3.5, "zd": 3.0, "z*zd": 1.0}


def test_number_placement_and_products():
    assert ForceLaw.parse("z*2.5").coefficients == (2.5,)
    assert ForceLaw.parse("2*3*z").coefficients == (6.0,)
    assert ForceLaw.parse(".5*z + 1.*zd").coefficients == (0.5, 1.0)
    assert ForceLaw.parse("  +z  ").coefficients == (1.0,)


@pytest.mark.parametrize(
    ("text", "fragment"),
    [
        ("", "empty"),
        ("   ", "empty"),
        ("3", "constant term"),
        ("3 + z", "constant term"),
        ("z^0", "constant term"),
        ("x", "cannot read"),
        ("2*x*z", "cannot read"),
        ("z+", "end of text"),
        ("z^-1", "negative exponent"),
        ("zd**-0.5", "negative exponent"),
        ("2 z", "'*' between factors"),
        ("z zd", "'*' between factors"),
        ("z^", "an exponent"),
        ("--z", "a number, 'z' or 'zd'"),
        ("z^1.5^2", "'+' or '-' between terms"),
        ("1e*z", "cannot read"),
    ],
)
def test_bad_law_text_raises_helpful_error(text, fragment):
    with pytest.raises(LawSyntaxError) as exc:
        ForceLaw.parse(text)
    msg = str(exc.value)
    assert fragment in msg
    # one line, and it shows how a valid law looks
    assert "\n" not in msg
    assert "z" in msg


@pytest.mark.parametrize("value", [3, 2.5, None, ["z"], b"z"])
def test_non_string_law_raises(value):
    with pytest.raises(LawSyntaxError, match="must be text"):
        ForceLaw.parse(value)


def test_law_syntax_error_is_input_error():
    with pytest.raises(InputError):
        ForceLaw.parse("z +* zd")


@pytest.mark.parametrize(("a", "b"), [(0, 0), (-1, 1), (1, -0.5), (np.nan, 1), (np.inf, 0)])
def test_bad_term_exponents(a, b):
    with pytest.raises(InputError, match="exponent"):
        Term(a, b)


@pytest.mark.parametrize("name", ["2*z", "z + zd", "-z"])
def test_term_parse_rejects_non_terms(name):
    with pytest.raises(InputError, match="single term"):
        Term.parse(name)


def test_force_law_constructor_validation():
    z, zd = Term(1, 0), Term(0, 1)
    with pytest.raises(InputError, match="coefficients"):
        ForceLaw((z, zd), (1.0,))
    with pytest.raises(InputError, match="at least one term"):
        ForceLaw((), ())
    with pytest.raises(InputError, match="twice"):
        ForceLaw((z, z), (1.0, 2.0))
    with pytest.raises(InputError, match="finite"):
        ForceLaw((z,), (np.nan,))


def test_from_dict_with_coefficients_and_has_jump():
    law = ForceLaw.from_dict({"z": 2.06e8, "zd": 1.28e7})
    assert law == ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    assert law.has_jump  # a pure zd term (a = 0) makes F jump at onset
    assert not ForceLaw.parse("2e10*z^1.5 + 5e11*z^1.5*zd").has_jump
    law2 = law.with_coefficients([1.0, 2.0])
    assert law2.terms == law.terms and law2.coefficients == (1.0, 2.0)
    coef, a, b, branch = law.kernel_arrays()
    np.testing.assert_array_equal(coef, [2.06e8, 1.28e7])
    np.testing.assert_array_equal(a, [1.0, 0.0])
    np.testing.assert_array_equal(b, [0.0, 1.0])
    np.testing.assert_array_equal(branch, [0.0, 0.0])  # loading terms only


# ----------------------------------------------------------------------- evaluation


def test_call_worked_value():
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    # 2.06e8*1e-3 + 1.28e7*0.5 = 206000 + 6400000; rel 1e-15: two products and a sum
    assert float(law(1e-3, 0.5)) == pytest.approx(6.606e6, rel=1e-15)


def test_no_force_without_contact():
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd + 5*zd^0.5")
    zeta = np.array([-1e-3, -1e-12, 0.0, -0.0])
    out = law(zeta, np.array([1.0, 10.0, 5.0, 2.0]))
    np.testing.assert_array_equal(out, 0.0)  # exact: condition (3) is a hard switch


def test_negative_velocity_acts_as_zero():
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd + 3e9*z*zd^0.5")
    zeta = np.array([1e-4, 2e-3, 5e-5])
    dz = np.array([-0.3, -5.0, -1e-9])
    expected = 2.06e8 * zeta  # only the elastic part survives (condition (5))
    np.testing.assert_allclose(law(zeta, dz), expected, rtol=1e-15, atol=0)
    np.testing.assert_array_equal(law(zeta, dz), law(zeta, 0.0))


def test_force_is_clipped_never_negative():
    law = ForceLaw.parse("2e8*z - 1e12*z^2 + 1e7*zd")
    zeta = np.linspace(-1e-3, 1e-3, 201)
    dz = np.linspace(-1, 1, 101)
    Z, D = np.meshgrid(zeta, dz)
    F = law(Z, D)
    assert np.all(F >= 0)
    P = law.polynomial(np.maximum(Z, 0), np.maximum(D, 0))
    assert np.any((Z > 0) & (P < 0))  # the test really exercises the clipping
    np.testing.assert_array_equal(F, np.where(Z > 0, np.maximum(P, 0), 0.0))
    # a clipped point, by hand: P(1e-3, 0) = 2e5 - 1e6 < 0
    assert float(law(1e-3, 0.0)) == 0.0


def test_vectorised_shapes():
    law = ForceLaw.parse("2e10*z^1.5 + 5e11*z^1.5*zd")
    assert np.shape(law(1e-4, 0.1)) == ()
    assert law(np.full(7, 1e-4), 0.1).shape == (7,)
    zeta = np.linspace(0, 1e-3, 3)[:, None]
    dz = np.linspace(-0.2, 0.4, 4)[None, :]
    F = law(zeta, dz)
    assert F.shape == (3, 4)
    # broadcast result equals elementwise scalar calls (exact: same arithmetic)
    for i in range(3):
        for j in range(4):
            assert F[i, j] == float(law(zeta[i, 0], dz[0, j]))


# -------------------------------------------------------------------------- exports


@pytest.mark.parametrize("text", ROUND_TRIP)
def test_sympy_matches_numeric(text, rng):
    law = ForceLaw.parse(text)
    expr = law.sympy()
    assert expr.free_symbols <= {ZETA, ZD}
    f = sympy.lambdify((ZETA, ZD), expr, "numpy")
    z = rng.uniform(1e-6, 2e-3, 50)
    zd = rng.uniform(0.0, 1.0, 50)
    # rel 1e-12: sympy stores coefficients with 15 digits and rationalises exponents
    np.testing.assert_allclose(f(z, zd), law.polynomial(z, zd), rtol=1e-12, atol=0)
    pos = law.polynomial(z, zd) > 0
    np.testing.assert_allclose(f(z, zd)[pos], law(z, zd)[pos], rtol=1e-12, atol=0)


def test_latex_contains_coefficients_and_symbols():
    tex = ForceLaw.parse("2.06e8*z + 1.28e7*zd").latex()
    assert r"2.060 \cdot 10^{8}" in tex
    assert r"1.280 \cdot 10^{7}" in tex
    assert r"\zeta" in tex and r"\dot{\zeta}_{+}" in tex
    tex2 = ForceLaw.parse("2e8*z - 3e10*z^1.5 + 1.5*zd").latex(digits=3)
    assert r"- 3.00 \cdot 10^{10}" in tex2
    assert r"\frac{3}{2}" in tex2
    assert "1.50" in tex2 and r"1.50 \cdot" not in tex2  # exponent 0 is not written
    # penetration first, a fractional power as a fraction (written without sympy)
    tex3 = ForceLaw.parse("4*z^0.5*zd^2").latex()
    assert tex3 == r"4.000\,\zeta^{\frac{1}{2}} \dot{\zeta}_{+}^{2}"


# --------------------------------------------------------------- property test

EXPONENTS = [0.0, 0.5, 1.0, 1.5, 2.0, 3.0]


@st.composite
def laws(draw):
    pairs = draw(
        st.lists(
            st.tuples(st.sampled_from(EXPONENTS), st.sampled_from(EXPONENTS)).filter(
                lambda p: p != (0.0, 0.0)
            ),
            min_size=1,
            max_size=5,
            unique=True,
        )
    )
    # coefficients with <= 12 significant digits (what to_text promises to keep)
    mant = draw(st.lists(st.integers(1, 10**12 - 1), min_size=len(pairs), max_size=len(pairs)))
    expo = draw(st.lists(st.integers(-12, 12), min_size=len(pairs), max_size=len(pairs)))
    coefs = [float(f"{m}e{e}") for m, e in zip(mant, expo, strict=True)]
    return ForceLaw(tuple(Term(a, b) for a, b in pairs), tuple(coefs))


@settings(max_examples=200, deadline=None)
@given(laws())
def test_property_round_trip_through_text(law):
    assert ForceLaw.parse(law.to_text()) == law
    assert ForceLaw.from_dict(law.as_dict()) == law


@pytest.mark.parametrize("c", [1 / 3, 2.0600000000000005e8])
def test_round_trip_full_precision_coefficient(c):
    law = ForceLaw((Term(1, 0), Term(0, 1)), (c, 1.28e7))
    assert ForceLaw.parse(law.to_text()) == law


def test_check_physical_accepts_real_laws_and_names_what_is_wrong(paper, light):
    from discovery.errors import InputError

    paper.law.check_physical(paper)
    light.law.check_physical(light)
    # a law that turns adhesive at depth is clipped, not refused (conditions (3)-(5) hold
    # by construction)
    ForceLaw.parse("2e8*z - 1e12*z^2 + 1e7*zd").check_physical(paper)
    with pytest.raises(InputError, match="never pushes"):
        ForceLaw.parse("-1e8*z - 1e6*zd").check_physical(paper)
    with pytest.raises(InputError, match="no non-zero coefficient"):
        ForceLaw.parse("0*z").check_physical(paper)
    with pytest.raises(InputError, match=r"condition \(6\)"):
        ForceLaw.parse("2e8*z + 1e7*zd - 1e10*z*zd").check_physical(paper)  # z > 1 mm


def test_springs_scaled_leave_the_damping_and_the_unloading_branch():
    """The elastic terms (no velocity factor) scaled; damping terms, the unloading branch and
    the set as they were (the start laws' softer springs, explain's spring scan)."""
    law = ForceLaw.parse("2e8*z + 1e9*z^1.5 + 1e7*zd + 3e10*z*zd; unloading: 4e6*zd; set: 0.1")
    got = law.with_springs_scaled(0.5)
    assert got.as_dict() == {"z": 1e8, "z^1.5": 5e8, "zd": 1e7, "z*zd": 3e10}
    assert got.unloading == law.unloading
    assert got.unloading_coefficients == law.unloading_coefficients
    assert got.permanent_set == law.permanent_set
