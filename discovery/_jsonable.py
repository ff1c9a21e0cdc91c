"""JSON in and out: values made JSON-ready, JSON files read without raising."""

import json
from pathlib import Path

import numpy as np


def load_json(path):
    """``(data, None)`` of a JSON file, ``(None, None)`` when there is none, ``(None, why)``
    when it cannot be read as JSON (why in a few words)."""
    try:
        with open(path, encoding="utf-8") as fh:
            return json.load(fh), None
    except FileNotFoundError:
        return None, None
    except (OSError, ValueError, RecursionError) as exc:
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
