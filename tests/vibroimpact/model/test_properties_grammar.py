"""Property-based tests of the force-law grammar (discovery.vibroimpact.model._lawgrammar,
ForceLaw.parse):
every law reads back from its text exactly, user text is never evaluated, and any text
either parses or raises InputError (never another exception)."""

import builtins
import math
from unittest import mock

import sympy
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from discovery.errors import InputError
from discovery.vibroimpact.model._lawgrammar import parse_law_terms
from discovery.vibroimpact.model.law import ForceLaw, Term

SETTINGS = settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])

exponents = st.one_of(
    st.sampled_from([0.0, 0.5, 1.0, 1.5, 2.0, 3.0]),
    st.floats(min_value=0.0, max_value=10.0, allow_nan=False, allow_infinity=False),
)
terms = (
    st.tuples(exponents, exponents).filter(lambda ab: ab != (0.0, 0.0)).map(lambda ab: Term(*ab))
)
coefficients = st.floats(allow_nan=False, allow_infinity=False, allow_subnormal=False)
laws = st.lists(
    st.tuples(terms, coefficients), min_size=1, max_size=6, unique_by=lambda tc: tc[0]
).map(lambda tcs: ForceLaw(tuple(t for t, _ in tcs), tuple(c for _, c in tcs)))

# text near the grammar: its tokens, spaces and a few foreign characters
grammar_text = st.lists(
    st.sampled_from(
        list("zd0123456789.eE+-*^ \t()x_\u0663") + ["**", "zd", "1e308", "2.06e8", "z^1.5"]
    ),
    max_size=30,
).map("".join)


def _forbidden(*args, **kwargs):
    raise AssertionError("user text was evaluated")


@SETTINGS
@given(laws)
def test_round_trip(law):
    text = law.to_text()
    back = ForceLaw.parse(text)
    assert back == law
    assert back.to_text() == text
    for c, d in zip(back.coefficients, law.coefficients, strict=True):
        assert c == d and math.copysign(1, c) == math.copysign(1, d) or c == d == 0


@SETTINGS
@given(st.one_of(st.text(max_size=60), grammar_text))
@example("")
@example("1e999*z")
@example("1e200*1e200*z")
@example("z^1e999")
@example("z^-0")
@example("__import__('os').system('true')*z")
@example("z" * 10000)
@example("+".join(["z"] * 3000))
def test_any_text_parses_or_raises_input_error(text):
    with (
        mock.patch.object(builtins, "eval", _forbidden),
        mock.patch.object(builtins, "exec", _forbidden),
        mock.patch.object(sympy, "sympify", _forbidden),
    ):
        try:
            law = ForceLaw.parse(text)
        except InputError as exc:
            msg = str(exc)
            assert msg and "\n" not in msg
            return
    # what parses is a valid law that reads back
    assert all(math.isfinite(c) for c in law.coefficients)
    assert ForceLaw.parse(law.to_text()) == law


@SETTINGS
@given(
    st.one_of(
        st.none(),
        st.integers(),
        st.floats(),
        st.binary(max_size=10),
        st.lists(st.text(max_size=5), max_size=3),
    )
)
def test_non_text_raises_input_error(value):
    try:
        parse_law_terms(value)
    except InputError:
        return
    raise AssertionError("non-text was accepted")


@SETTINGS
@given(terms)
def test_term_names_read_back(term):
    assert Term.parse(term.name) == term
