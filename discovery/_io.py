"""Atomic output directories and provenance records."""

import datetime
import json
import os
import platform
import shutil
import tempfile
from importlib import metadata
from pathlib import Path

import numpy as np

__all__ = ["OutputDir", "provenance", "to_jsonable"]

_PACKAGES = ("vibroimpact-discovery", "numpy", "scipy", "numba", "sympy", "cvxpy", "pysindy",
             "matplotlib")


def provenance(settings=None):
    """Versions, platform and settings: recorded in every ``summary.json``."""
    versions = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    return {"versions": versions, "platform": platform.platform(),
            "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
            "settings": to_jsonable({k: v for k, v in (settings or {}).items()
                                     if not callable(v)})}


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


class OutputDir:
    """Stage outputs in a hidden sibling directory and move them in only on success.

    Earlier results in the target directory are never destroyed or half-written:
    each file is moved with ``os.replace`` (atomic) after the whole job succeeded;
    on an exception the staging directory is removed and the target is untouched.

    Examples
    --------
    >>> with OutputDir("out") as out:              # doctest: +SKIP
    ...     out.write_json("summary.json", {...})
    """

    def __init__(self, target):
        self.target = Path(target)

    def __enter__(self):
        parent = self.target.resolve().parent
        parent.mkdir(parents=True, exist_ok=True)
        self.stage = Path(tempfile.mkdtemp(prefix=f".{self.target.name}.", dir=parent))
        return self

    def path(self, name):
        """Where to write ``name`` now (inside the staging directory)."""
        return self.stage / name

    def write_json(self, name, data):
        with open(self.path(name), "w") as fh:
            json.dump(to_jsonable(data), fh, indent=2)
            fh.write("\n")

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                self.target.mkdir(parents=True, exist_ok=True)
                for f in sorted(self.stage.iterdir()):
                    os.replace(f, self.target / f.name)
        finally:
            shutil.rmtree(self.stage, ignore_errors=True)
        return False


def atomic_write_text(path, text):
    """Write a text file atomically (temporary file + rename)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", dir=path.parent)
    try:
        with os.fdopen(fd, "w") as fh:
            fh.write(text)
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
