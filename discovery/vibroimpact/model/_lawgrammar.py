"""A small recursive-descent parser for force-law text.

Grammar (whitespace is ignored)::

    law     := signed ( ('+' | '-') term )*
    signed  := ['+' | '-'] term
    term    := number '*' monomial | monomial | monomial '*' number
    monomial:= factor ( '*' factor )*
    factor  := ('z' | 'zd') [ ('^' | '**') number ]
    number  := decimal literal, e.g. 2.06e8, 1.5, 0.25

The parser never evaluates user text (no ``eval``, no ``sympify``).  It returns
a list of ``(coefficient, a, b)`` where the term is ``c * z^a * zd^b``.
"""

import re

from ...errors import LawSyntaxError

_TOKEN = re.compile(  # ASCII digits only: "\d" would also take full-width and other digits
    r"\s*(?:(?P<num>(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?)|(?P<sym>zd|z)|(?P<op>\*\*|[-+*^]))",
    re.ASCII,
)

MAX_LAW_CHARS = 10_000
MAX_EXPONENT = 10.0  # largest exponent of a term: z^10 already spans 40 decades of force
MAX_LAW_TERMS = 100


def _tokenize(text):
    tokens, pos = [], 0
    text = text.rstrip()
    while pos < len(text):
        m = _TOKEN.match(text, pos)
        if m is None or m.end() == pos:
            raise LawSyntaxError(
                f"cannot read force law {text!r} at position {pos} ({text[pos : pos + 8]!r}); "
                "write terms like '2.06e8*z + 1.28e7*zd' using z, zd, numbers, * and ^"
            )
        kind = m.lastgroup
        tokens.append((kind, m.group(kind), pos))
        pos = m.end()
    return tokens


class _Parser:
    def __init__(self, text):
        self.text = text
        self.tokens = _tokenize(text)
        self.i = 0

    def _peek(self):
        return self.tokens[self.i] if self.i < len(self.tokens) else (None, None, len(self.text))

    def _fail(self, what):
        kind, value, pos = self._peek()
        found = "end of text" if kind is None else repr(value)
        raise LawSyntaxError(
            f"force law {self.text!r}: expected {what} at position {pos}, found {found}; "
            "write terms like '2.06e8*z + 1.28e7*zd'"
        )

    def _take(self, kind, value=None):
        k, v, _ = self._peek()
        if k == kind and (value is None or v == value):
            self.i += 1
            return v
        return None

    def parse(self):
        if not self.tokens:
            raise LawSyntaxError("force law is empty; write terms like '2.06e8*z + 1.28e7*zd'")
        terms = []
        sign = -1.0 if self._take("op", "-") else 1.0
        if sign > 0:
            self._take("op", "+")
        terms.append(self._term(sign))
        while self._peek()[0] is not None:
            op = self._take("op", "+") or self._take("op", "-")
            if op is None:
                self._fail("'+' or '-' between terms")
            terms.append(self._term(1.0 if op == "+" else -1.0))
        return terms

    def _number(self):
        v = self._take("num")
        return None if v is None else float(v)

    def _term(self, sign):
        coef = 1.0
        a = b = 0.0
        have_symbol = False
        first = True
        while True:
            if not first and not self._take("op", "*"):
                break
            first = False
            num = self._number()
            if num is not None:
                coef *= num
                continue
            sym = self._take("sym")
            if sym is None:
                self._fail("a number, 'z' or 'zd'")
            have_symbol = True
            power = 1.0
            if self._take("op", "^") or self._take("op", "**"):
                neg = self._take("op", "-")
                power = self._number()
                if power is None:
                    self._fail("an exponent")
                if neg:
                    raise LawSyntaxError(
                        f"force law {self.text!r}: negative exponent on {sym}; "
                        "exponents must be >= 0 (the force must stay finite at contact onset)"
                    )
                if power > MAX_EXPONENT:
                    raise LawSyntaxError(
                        f"force law {self.text!r}: exponent {power:.6g} on {sym} is above "
                        f"{MAX_EXPONENT:g}; a contact law's powers are small (1, 1.5, 2, ...)"
                    )
            if sym == "z":
                a += power
            else:
                b += power
        if self._peek()[0] in ("num", "sym"):
            self._fail("'*' between factors")
        if not have_symbol or (a == 0.0 and b == 0.0):
            raise LawSyntaxError(
                f"force law {self.text!r}: a constant term is not allowed (F must vanish "
                "without contact); multiply it by z or zd"
            )
        return sign * coef, a, b


def parse_law_terms(text):
    """Parse force-law text into ``[(coefficient, a, b), ...]`` (``c * z^a * zd^b``)."""
    if not isinstance(text, str):
        raise LawSyntaxError(f"force law must be text, got {type(text).__name__}")
    if len(text) > MAX_LAW_CHARS:
        raise LawSyntaxError(
            f"force law text of {len(text)} characters; a contact law has a "
            f"few terms (at most {MAX_LAW_TERMS}, {MAX_LAW_CHARS} characters)"
        )
    terms = _Parser(text).parse()
    if len(terms) > MAX_LAW_TERMS:
        raise LawSyntaxError(
            f"force law of {len(terms)} terms; a contact law has a few (at "
            f"most {MAX_LAW_TERMS}): simplify it"
        )
    return terms
