"""LaTeX of laws, terms and prose, made by this package from text it parses.

A report never prints LaTeX it read: a contact law is rebuilt from its own text (or its
``{term: coefficient}`` mapping) by the law grammar (:mod:`discovery.vibroimpact.model`), a
Ueda equation from its coefficients over the library's term names, and prose is escaped
with its code (between backticks) set in typewriter and its exponents (``z^2``, ``m/s^2``)
set as exponents. Anything that does not parse is an :class:`~discovery.errors.InputError`
naming the field.
"""

from __future__ import annotations

import math
import re

from .texenv import Tex, escape

__all__ = [
    "sci",
    "law_of",
    "law_equation",
    "law_inline",
    "term_tex",
    "ueda_equation",
    "ueda_term_tex",
    "prose",
    "value_tex",
    "unit_tex",
]

_ZETA, _ZD, _ZDABS = r"\zeta", r"\dot\zeta_{+}", r"|\dot\zeta|"


def sci(value, digits=4):
    """A number in scientific notation as math-mode LaTeX (no ``$``): ``2.06\\cdot 10^{8}``
    (plain between 0.01 and 1000)."""
    v = float(value)
    if v == 0 or not math.isfinite(v):
        return "0" if v == 0 else r"\text{--}"
    exp = int(math.floor(math.log10(abs(v))))
    if -2 <= exp < 3:
        text = f"{v:.{digits}g}"
        return text
    mant = f"{v / 10**exp:.{digits - 1}f}".rstrip("0").rstrip(".")
    if mant in ("10", "-10"):
        exp += 1
        mant = mant[:-1]
    return mant + rf"\cdot 10^{{{exp}}}"


def _exp(p):
    p = float(p)
    return str(int(p)) if p.is_integer() else f"{p:g}"


def _power(sym, p):
    return sym if p == 1 else f"{sym}^{{{_exp(p)}}}"


def _monomial(term, names=(_ZETA, _ZD)):
    parts = []
    if term.a:
        parts.append(_power(names[0], term.a))
    if term.b:
        parts.append(_power(names[1], term.b))
    return r"\,".join(parts)


def term_tex(name, unloading=False):
    """A term's name (``z^2*zd``) as math (``$\\zeta^{2}\\,\\dot\\zeta_{+}$``; an unloading
    term's velocity as ``|\\dot\\zeta|``); a name that is not a term is escaped text."""
    from discovery.errors import VidiError
    from discovery.vibroimpact.model.law import Term

    try:
        names = (_ZETA, _ZDABS) if unloading else (_ZETA, _ZD)
        return Tex(f"${_monomial(Term.parse(str(name)), names)}$")
    except (VidiError, TypeError, ValueError):
        return Tex(r"\texttt{" + escape(name) + "}")


def law_of(value, where):
    """A :class:`ForceLaw` from a summary's law text or ``{term: coefficient}`` mapping (a
    ``ForceLaw`` itself as it is);
    :class:`InputError` naming ``where`` when it is neither."""
    from discovery.errors import InputError, VidiError
    from discovery.vibroimpact.model.law import ForceLaw

    if isinstance(value, ForceLaw):  # a typed result's law
        return value
    try:
        if isinstance(value, str):
            return ForceLaw.parse(value)
        if isinstance(value, dict) and value:
            if any(isinstance(v, bool) or not isinstance(v, int | float) for v in value.values()):
                raise TypeError("coefficients must be numbers")
            return ForceLaw.from_dict(value)
    except (VidiError, TypeError, ValueError):
        pass
    shown = " ".join(str(value).split())[:60]
    raise InputError(
        f"summary.json: {where} is not a force law ({shown!r}); run the command again to "
        "rewrite the summary"
    )


def _sum(coefs, terms, names):
    out = []
    for c, t in zip(coefs, terms, strict=True):
        body = sci(abs(c))
        out.append(("-" if c < 0 else "+") + rf" {body}\,{_monomial(t, names)}")
    text = " ".join(out)
    return text[2:] if text.startswith("+ ") else text


def law_equation(law):
    """The body of an ``equation`` environment for a :class:`ForceLaw`: ``F`` for
    ``zeta > 0`` with the loading polynomial ``P`` on its own line and, for a law with an
    unloading branch, that branch as its own case."""
    p = _sum(law.coefficients, law.terms, (_ZETA, _ZD))
    if not law.has_unloading_branch:
        return Tex(
            r"\begin{aligned}F(\zeta,\dot\zeta) &= \max\bigl(0,\; P(\zeta,\dot\zeta_{+})\bigr)"
            r"\quad(\zeta>0),\qquad F = 0\quad(\zeta\le 0),\\"
            rf"P(\zeta,\dot\zeta_{{+}}) &= {p}\end{{aligned}}"
        )
    s = law.permanent_set
    at = r"P(u,0)" if s else r"P(\zeta,0)"
    q = ""
    if law.unloading:
        q = " - Q(\\zeta,|\\dot\\zeta|)"
    lines = [
        r"F(\zeta,\dot\zeta) &= \begin{cases}"
        r"\max\bigl(0,\; P(\zeta,\dot\zeta)\bigr) & \text{loading, } \dot\zeta>0,\\"
        rf"\max\bigl(0,\; {at}{q}\bigr) & \text{{unloading, }} \dot\zeta\le 0,"
        r"\end{cases}\quad(\zeta>0)",
        rf"P(\zeta,\dot\zeta_{{+}}) &= {p}",
    ]
    if law.unloading:
        u = _sum(law.unloading_coefficients, law.unloading, (_ZETA, _ZDABS))
        lines.append(rf"Q(\zeta,|\dot\zeta|) &= {u}")
    if s:
        lines.append(
            rf"u &= \frac{{\zeta - s\,\zeta_{{\max}}}}{{1-s}},\quad s = {sci(s)}"
            r"\ \text{(permanent set)}"
        )
    return Tex(r"\begin{aligned}" + r"\\".join(lines) + r"\end{aligned}")


def law_inline(law):
    """A law as inline math ``$P = ...$`` (its unloading branch after a semicolon)."""
    text = "$" + _sum(law.coefficients, law.terms, (_ZETA, _ZD)) + "$"
    if law.unloading:
        text += (
            "; unloading $Q = "
            + _sum(law.unloading_coefficients, law.unloading, (_ZETA, _ZDABS))
            + "$"
        )
    if law.permanent_set:
        text += f"; permanent set ${sci(law.permanent_set)}$"
    return Tex(text)


def ueda_equation(coefficients, where="coefficients"):
    """``\\ddot x = ...`` from a Ueda discovery's ``{term: coefficient}`` (the library's
    names ``x``, ``x'``, ``x^2 x'``, ..., and ``B cos(nu t)``)."""
    from discovery.errors import InputError
    from discovery.ueda.polynomial import MONOMIALS, TERMS

    if not isinstance(coefficients, dict) or not coefficients:
        raise InputError(f"summary.json: {where} is not a mapping of terms to numbers")
    out = []
    for name, c in coefficients.items():
        if isinstance(c, bool) or not isinstance(c, int | float):
            raise InputError(f"summary.json: {where}[{str(name)[:40]!r}] is not a number")
        if c == 0:
            continue
        if name == "B cos(nu t)":
            sym = r"B\cos\nu t"
        elif name in TERMS:
            i, j = MONOMIALS[TERMS.index(name)]
            parts = ([_power("x", i)] if i else []) + ([_power(r"\dot x", j)] if j else [])
            sym = r"\,".join(parts)
        else:
            raise InputError(
                f"summary.json: {where} names {str(name)[:40]!r}, not a term of the library"
            )
        body = sci(abs(c))
        out.append(("-" if c < 0 else "+") + (rf" {body}\,{sym}" if sym else f" {body}"))
    text = " ".join(out) or "0"
    text = text[2:] if text.startswith("+ ") else text
    return Tex(rf"\ddot x = {text}")


def ueda_term_tex(name):
    """A Ueda library term (``x^2 x'``, ``B cos(nu t)``) as math; anything else escaped."""
    from discovery.ueda.polynomial import MONOMIALS, TERMS

    if name == "B cos(nu t)":
        return Tex(r"$B\cos\nu t$")
    if name in TERMS:
        i, j = MONOMIALS[TERMS.index(name)]
        parts = ([_power("x", i)] if i else []) + ([_power(r"\dot x", j)] if j else [])
        return Tex("$" + (r"\,".join(parts) or "1") + "$")
    return Tex(r"\texttt{" + escape(name) + "}")


# a term's name (``z``, ``zd``, ``z^2*zd``) or the penetration's (``zeta``) standing alone:
# not part of a word, a path or a file name (``z.csv``, ``data/z``)
_TERMISH = re.compile(
    r"(?<![\w^./\\-])(?:zeta|(?:zd|z)(?:\^\d+(?:\.\d+)?)?(?:\*(?:zd|z)(?:\^\d+(?:\.\d+)?)?)*)"
    r"(?![\w^/\\-]|\.\w)"
)
_CARET = re.compile(r"\^(-?\d+(?:\.\d+)?)")
_CODE = re.compile(r"`([^`\n]{1,200})`")


def _plain(text):
    """Escaped text with ``^n`` set as an exponent and every term name (``zd`` as well as
    ``z^2``) and ``zeta`` as math, as the tables set them."""
    out, pos = [], 0
    for m in _TERMISH.finditer(text):
        tok = m.group(0)
        out.append(_carets(text[pos : m.start()]))
        out.append(Tex(f"${_ZETA}$") if tok == "zeta" else term_tex(tok))
        pos = m.end()
    out.append(_carets(text[pos:]))
    return "".join(out)


_ENUM = re.compile(r"(?<![\w.])([-+]?\d+(?:\.\d+)?)[eE]([-+]?\d+)(?![\w.])")


def _symbols(text):
    """Escaped text with ``->``, ``<=`` and ``>=`` as their symbols."""
    return (
        escape(text)
        .replace(r"-\textgreater{}", r"$\to$")
        .replace(r"\textless{}=", r"$\le$")
        .replace(r"\textgreater{}=", r"$\ge$")
    )


def _numbers(text):
    r"""Escaped text with numbers like ``3.93e+06`` set as ``$3.93\cdot 10^{6}$``."""
    out, pos = [], 0
    for m in _ENUM.finditer(text):
        out.append(_symbols(text[pos : m.start()]))
        exp = int(m.group(2))
        out.append(f"${m.group(1)}" + (rf"\cdot 10^{{{exp}}}$" if exp else "$"))
        pos = m.end()
    out.append(_symbols(text[pos:]))
    return "".join(out)


def _carets(text):
    out, pos = [], 0
    for m in _CARET.finditer(text):
        out.append(_numbers(text[pos : m.start()]))
        out.append(f"$^{{{m.group(1)}}}$")
        pos = m.end()
    out.append(_numbers(text[pos:]))
    return "".join(out)


def prose(text):
    """A sentence (a verdict, a warning, a conclusion) as LaTeX: escaped, ```code``` in
    typewriter, exponents and term names typeset."""
    if isinstance(text, Tex):
        return text
    text = "" if text is None else str(text)
    out, pos = [], 0
    for m in _CODE.finditer(text):
        out.append(_plain(text[pos : m.start()]))
        out.append(r"\texttt{" + escape(m.group(1)) + "}")
        pos = m.end()
    out.append(_plain(text[pos:]))
    return Tex("".join(out))


_RULE = re.compile(r" \(max\(f x noise floor, floor \+ [^)]*\) \+ [^,]*, f = [^)]*\)")


def verdict_tex(text):
    """A verdict as LaTeX (:func:`prose`) without the consistency rule's parenthesis, which
    the report typesets once beside its criteria table (``limit_rule``)."""
    if isinstance(text, Tex) or text is None:
        return prose(text)
    return prose(_RULE.sub("", str(text)))


def _as_law(text):
    """The :class:`ForceLaw` a setting's text writes with its coefficients
    (``2.06e8*z + 4e6*zd``), or None (a term list, a name, a number)."""
    from discovery.errors import VidiError
    from discovery.vibroimpact.model.law import ForceLaw

    if not isinstance(text, str) or "z" not in text or not re.search(r"\d", _CARET.sub("", text)):
        return None  # a term, a name: no coefficient outside the exponents
    try:
        return ForceLaw.parse(text)
    except (VidiError, TypeError, ValueError):
        return None


def value_tex(value):
    """A setting's value (a study's design, a run's settings) as LaTeX: a law typeset whole
    as the report's equations set it (:func:`law_inline`), a list item by item, anything
    else as :func:`prose`."""
    if isinstance(value, list | tuple):
        span = _numeric_span(value)
        if span is not None:
            return prose(span)
        return Tex(", ".join(value_tex(v) for v in value))
    law = _as_law(value)
    if law is not None:
        return law_inline(law)
    return prose("" if value is None else str(value))


def _numeric_span(values, most=6):
    """A long list of numbers (a sweep's axis: 200 values of ``nu`` ran off the page) as its
    range: ``"0.8 to 1.2, 200 evenly spaced values"`` (or ``"... 200 values"`` when they are
    not evenly spaced); None for a short list or one that is not all numbers."""
    if len(values) <= most or not all(
        isinstance(v, int | float) and not isinstance(v, bool) for v in values
    ):
        return None
    steps = [b - a for a, b in zip(values, values[1:], strict=False)]
    even = max(steps) - min(steps) <= 1e-9 * max(abs(v) for v in values) + 1e-300
    spaced = "evenly spaced " if even else ""
    return f"{values[0]:.6g} to {values[-1]:.6g}, {len(values)} {spaced}values"


def unit_tex(unit):
    """A unit (``m/s^2``, ``N s/m``) as text with exponents raised."""
    return Tex(_carets(unit).replace(" ", r"\,"))
