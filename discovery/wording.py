"""Wording shared by the printouts and the reports: sentences that follow the number of
records they are about."""

__all__ = ["records", "verb"]


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
