"""The LaTeX template environment: one escape for every string, numbers as math.

Templates live in ``reports/templates`` and use LaTeX-safe delimiters (as nbconvert's LaTeX
templates do): ``((* block *))`` for statements, ``((( value )))`` for values and
``((= comment =))`` for comments, so that TeX's own braces and percent signs need no
escaping. Undefined names are errors (:class:`jinja2.StrictUndefined`).

Every value printed by a template goes through :func:`escape` (the environment's
``finalize``), unless it is a :class:`Tex`: text this package made as LaTeX (a law from
sympy, a number from :func:`num`). A record name, a path, a column or scenario name, a law's
text or a verdict therefore can never inject TeX (``\\input{/etc/passwd}``, ``\\write18``).
"""

from __future__ import annotations

import math
import re
from pathlib import Path

from discovery.wording import interval_digits

__all__ = ["Tex", "escape", "num", "nums", "scientific", "interval", "environment"]

_SPECIAL = {
    "\\": r"\textbackslash{}",
    "_": r"\_",
    "%": r"\%",
    "&": r"\&",
    "#": r"\#",
    "$": r"\$",
    "{": r"\{",
    "}": r"\}",
    "^": r"\textasciicircum{}",
    "~": r"\textasciitilde{}",
    "`": r"\textasciigrave{}",
    "<": r"\textless{}",
    ">": r"\textgreater{}",
    "\n": " ",
    "\r": " ",
    "\t": " ",
    "\x0c": " ",
}


class Tex(str):
    """A string that is already LaTeX (made by this package, never from user input)."""

    __slots__ = ()


def escape(value):
    """Any value as LaTeX-safe text; a :class:`Tex` passes unchanged."""
    if isinstance(value, Tex):
        return value
    if value is None:
        return "--"
    text = str(value)
    # control characters other than the whitespace above could confuse TeX's reader
    # control characters, and characters beyond Latin-1 that pdflatex's T1 fonts lack,
    # become '?'
    return "".join(
        _SPECIAL.get(ch, ch) if (ch.isprintable() and ord(ch) < 0x100) or ch in _SPECIAL else "?"
        for ch in text
    )


def _exponent(value):
    """The decimal exponent of a finite non-zero number (``None`` for anything else)."""
    try:
        v = float(value)
    except (TypeError, ValueError):
        return None
    if isinstance(value, bool) or not math.isfinite(v) or v == 0:
        return None
    return int(math.floor(math.log10(abs(v))))


def scientific(*values):
    """Whether numbers printed side by side (a table row: a value, its error and interval;
    a criterion, its noise floor and limit) take the scientific form: all of them when any
    one needs it (its exponent below -3, or 5 and above), so that ``46836`` is never
    printed beside ``1.0\\cdot 10^{8}`` nor ``5.14\\cdot 10^{-4}`` beside ``0.00564``."""
    exps = [e for e in map(_exponent, values) if e is not None]
    return any(not -3 <= e < 5 for e in exps)


def num(value, digits=3, unit=None, sci=None):
    """A number as LaTeX math (``$2.06\\cdot 10^{8}$``); ``--`` when missing or not finite.

    ``sci``: None chooses by the number alone (plain from 0.001 to 99999), True prints it
    in the scientific form (a number between 1 and 10 without its ``10^0``), False plain;
    :func:`scientific` decides it for numbers printed side by side."""
    if value is None or isinstance(value, bool):
        return Tex("--") if value is None else Tex(str(value).lower())
    try:
        v = float(value)
    except (TypeError, ValueError):
        return Tex(escape(value))
    if not math.isfinite(v):
        return Tex("--")
    if v == 0:
        body = "0"
    else:
        exp = int(math.floor(math.log10(abs(v))))
        plain = -3 <= exp < 5 if sci is None else not sci or exp == 0
        if plain:
            body = f"{v:.{max(digits - 1 - exp, 0)}f}" if exp < digits else f"{v:.0f}"
        else:
            mant = f"{v / 10**exp:.{digits - 1}f}"
            if mant.startswith(("10.", "-10.")):  # rounding carried into the next decade
                exp += 1
                mant = f"{v / 10**exp:.{digits - 1}f}"
            body = rf"{mant}\cdot 10^{{{exp}}}" if exp else mant
    return Tex(f"${body}$" + (rf"\,\mathrm{{{unit}}}" if unit else ""))


def nums(*values, digits=3):
    """``values`` as :func:`num` prints them, in one form (:func:`scientific`)."""
    sci = scientific(*values)
    return [num(v, digits, sci=sci) for v in values]


def interval(lo, hi, digits=4, sci=None):
    """``[lo, hi]`` as LaTeX numbers (:func:`num`, both in one form), with more than
    ``digits`` significant digits where the bounds would otherwise print alike."""
    d = interval_digits(lo, hi, digits)
    sci = scientific(lo, hi) if sci is None else sci
    return Tex(f"[{num(lo, d, sci=sci)}, {num(hi, d, sci=sci)}]")


def _final(value):
    """Every printed value, as markup that autoescaping leaves alone: a :class:`Tex` as it
    is, anything else through :func:`escape` (macro output is markup already)."""
    from markupsafe import Markup

    if isinstance(value, Markup):
        return value
    return Markup(str(value) if isinstance(value, Tex) else escape(value))


_SPEC = re.compile(r"^[lrcp{}0-9.\\a-z@>|]+$")


def _spec(text):
    """A tabular column spec written in a template (checked, never user text)."""
    if not _SPEC.match(str(text)):
        raise ValueError(f"not a column spec: {text!r}")
    return Tex(text)


def environment():
    """The jinja2 environment of the report templates."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(Path(__file__).with_name("templates"))),
        block_start_string="((*",
        block_end_string="*))",
        variable_start_string="(((",
        variable_end_string=")))",
        comment_start_string="((=",
        comment_end_string="=))",
        undefined=jinja2.StrictUndefined,
        finalize=_final,
        autoescape=True,
        trim_blocks=True,
        lstrip_blocks=True,
        keep_trailing_newline=True,
    )
    env.filters["num"] = num
    env.filters["spec"] = _spec
    env.filters["tex"] = lambda v: v if isinstance(v, Tex) else Tex(escape(v))
    env.filters["tt"] = lambda v: Tex(r"\texttt{" + escape(v) + "}")
    from .rules import rule_tex

    env.globals["consistency_rule"] = Tex(rule_tex())  # the rule as the verdict applies it
    return env
