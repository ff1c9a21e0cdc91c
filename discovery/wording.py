"""Wording shared by the printouts and the reports: sentences that follow the number of
records they are about, the article of a name, and the digits that tell an interval's
bounds apart."""

import math

__all__ = ["records", "verb", "a", "interval_digits"]

#: names that start with a vowel letter but not a vowel sound ("a Ueda run")
_CONSONANT_SOUND = ("ueda", "uni", "use", "eu", "one")


def records(n, every=False):
    """The records a sentence is about: ``the record`` for one, ``the 2 records`` (``all 2
    records`` with ``every``) for more, so that a conclusion follows their number."""
    n = int(n)
    if n <= 1:
        return "the record"
    return f"{'all' if every else 'the'} {n} records"


def verb(n, singular, plural):
    """``singular`` for one record, ``plural`` for more (``supports``/``support``)."""
    return singular if int(n) <= 1 else plural


def a(name):
    """``name`` with its indefinite article, by its sound: ``an identify``, ``a fit``,
    ``a Ueda``."""
    name = str(name)
    vowel = name[:1].lower() in tuple("aeiou") and not name.lower().startswith(_CONSONANT_SOUND)
    return f"{'an' if vowel else 'a'} {name}"


def interval_digits(lo, hi, least=4, most=8):
    """Significant digits that print an interval's two bounds apart: ``least``, more while
    they round alike (a narrow interval around a large value), at most ``most``."""
    try:
        lo, hi = float(lo), float(hi)
    except (TypeError, ValueError):
        return least
    if lo == hi or not (math.isfinite(lo) and math.isfinite(hi)):
        return least
    for digits in range(least, most):
        if f"{lo:.{digits - 1}e}" != f"{hi:.{digits - 1}e}":
            return digits
    return most
