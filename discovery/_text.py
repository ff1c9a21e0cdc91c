"""Text for one-line messages."""


def short(text, limit=160):
    """``text`` for a one-line message: a very long path shows its start and end only."""
    text = str(text)
    if len(text) <= limit:
        return text
    half = (limit - 5) // 2
    return f"{text[:half]} ... {text[-half:]}"


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
