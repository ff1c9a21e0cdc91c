"""Results that read well: ``print(result)``, a short ``repr`` and a notebook view.

One mechanism for every result class (:func:`readable`): the class gives ``_lines()``, a
short report in the manner of lmfit's ``fit_report`` (the verdict first, then the
coefficients with their errors and intervals, the criteria against their noise floors,
warnings); ``str`` joins the lines, ``repr`` is the first line, and ``_repr_html_`` shows
the same text in a notebook. The lines are a pure function of the result.
"""

from __future__ import annotations

import html

from ..wording import interval_digits

__all__ = [
    "readable",
    "coefficient_lines",
    "fmt",
    "generic_lines",
    "interval_text",
]


def fmt(v, digits=4):
    """A number in a few significant digits (``--`` when missing)."""
    if v is None:
        return "--"
    try:
        return f"{float(v):.{digits}g}"
    except (TypeError, ValueError):
        return str(v)


def interval_text(lo, hi, least=4):
    """``[lo, hi]`` with enough significant digits that the bounds differ
    (:func:`interval_digits`; the extra digits printed on both bounds alike)."""
    digits = interval_digits(lo, hi, least)
    if digits == least:
        return f"[{fmt(lo, digits)}, {fmt(hi, digits)}]"
    return f"[{float(lo):#.{digits}g}, {float(hi):#.{digits}g}]"


def coefficient_lines(coefficients, errors=None, intervals=None, indent="  "):
    """One line per coefficient: value, standard error, 95 % interval."""
    if not coefficients:
        return []
    bounds = getattr(intervals, "bounds", None) or (intervals or {})
    out = [f"{indent}{'term':<12}{'value':>13}{'std error':>12}   95 % interval"]
    for k, v in coefficients.items():
        b = bounds.get(k) if isinstance(bounds, dict) else None
        iv = interval_text(b[0], b[1]) if b is not None else "--"
        out.append(f"{indent}{k:<12}{fmt(v, 6):>13}{fmt((errors or {}).get(k), 2):>12}   {iv}")
    return out


def readable(cls):
    """Class decorator (outermost, after ``@dataclass``): ``str``, ``repr`` and
    ``_repr_html_`` from ``cls._lines()``."""

    def __str__(self):
        return "\n".join(self._lines())

    def __repr__(self):
        lines = self._lines()
        return f"<{cls.__name__}: {lines[0] if lines else ''}>"

    def _repr_html_(self):
        return "<pre style='white-space: pre-wrap'>" + html.escape(str(self)) + "</pre>"

    cls.__str__, cls.__repr__, cls._repr_html_ = __str__, __repr__, _repr_html_
    return cls


def generic_lines(result, limit=12):
    """Lines from ``result.as_dict()``: its scalar entries and short mappings."""
    d = result.to_dict() if getattr(result, "loaded", False) else result.as_dict()
    d = {k: v for k, v in d.items() if k not in ("schema_version", "result")}
    out = [type(result).__name__]
    for k, v in d.items():
        if isinstance(v, bool | int | float | str) and len(str(v)) < 120:
            out.append(f"  {k}: {fmt(v) if isinstance(v, float) else v}")
        elif (
            isinstance(v, dict)
            and 0 < len(v) <= 6
            and all(isinstance(x, bool | int | float | str) for x in v.values())
        ):
            out.append(
                f"  {k}: "
                + ", ".join(f"{a} {fmt(b) if isinstance(b, float) else b}" for a, b in v.items())
            )
        if len(out) > limit:
            break
    return out
