"""JSON in and out: values made JSON-ready, JSON files read without raising."""

import json
from pathlib import Path

import numpy as np

#: the largest JSON document read (a summary of a long study is a few MB)
MAX_DOCUMENT_BYTES = 64 * 2**20


def load_json(path):
    """``(data, None)`` of a JSON file, ``(None, None)`` when there is none, ``(None, why)``
    when it cannot be read as JSON (why in a few words): not a regular file (a device such
    as ``/dev/zero`` would be read until memory runs out), over
    :data:`MAX_DOCUMENT_BYTES`, not JSON, or nested too deeply."""
    p = Path(path)
    try:
        if not p.exists():
            return None, None
        if not p.is_file():
            return None, "is not a regular file"
        if p.stat().st_size > MAX_DOCUMENT_BYTES:
            return None, f"is over {MAX_DOCUMENT_BYTES // 2**20} MB, no summary is that large"
        with open(p, encoding="utf-8") as fh:
            return json.load(fh), None
    except FileNotFoundError:
        return None, None
    except (OSError, ValueError, RecursionError, MemoryError) as exc:
        return None, f"cannot be read as JSON ({type(exc).__name__})"


def to_jsonable(obj):
    """Convert numpy scalars/arrays and nested containers to JSON-ready values."""
    if isinstance(obj, dict):
        return {str(k): to_jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [to_jsonable(v) for v in obj]
    if isinstance(obj, np.ndarray):
        return to_jsonable(obj.tolist())
    if isinstance(obj, np.integer | np.bool_):
        return obj.item()
    if isinstance(obj, float | np.floating):
        v = float(obj)
        return v if np.isfinite(v) else None
    if isinstance(obj, Path):
        return str(obj)
    return obj


def reads_document(from_dict):
    """A ``from_dict`` classmethod's function that turns a document it cannot read (a
    missing or mistyped field, deep nesting) into one
    :class:`~discovery.errors.InputError` naming the class, not Python's own exception.
    Apply under ``@classmethod``."""
    import functools

    from ..errors import InputError, VidiError

    @functools.wraps(from_dict)
    def read(cls, doc, *args, **kwargs):
        try:
            return from_dict(cls, doc, *args, **kwargs)
        except VidiError:
            raise
        except (
            KeyError,
            TypeError,
            ValueError,
            AttributeError,
            ArithmeticError,
            RecursionError,
        ) as exc:
            text = str(exc)
            text = text if len(text) <= 80 else text[:77] + "..."
            raise InputError(
                f"{cls.__name__}.from_dict: the document cannot be read ({type(exc).__name__}: "
                f"{text}); give what {cls.__name__}.to_dict() wrote"
            ) from None

    return read
