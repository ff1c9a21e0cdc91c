"""Wording shared by the printouts and the reports: sentences that follow the number of
records they are about, and the article of a name."""

__all__ = ["records", "verb", "a"]

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
