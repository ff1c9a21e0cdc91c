"""Text for one-line messages."""


def short(text, limit=160):
    """``text`` for a one-line message: a very long path shows its start and end only."""
    text = str(text)
    if len(text) <= limit:
        return text
    half = (limit - 5) // 2
    return f"{text[:half]} ... {text[-half:]}"
