"""A study's run files ``runs/<key>.json``: the code version every run's key includes
(:func:`code_version`), and the check a file read back passes to count as a run of the
study (anything else is named and run again)."""

from __future__ import annotations

from pathlib import Path

from ..._files._io import load_json

__all__ = ["code_version"]


def code_version():
    """The package version and a hash of its source (every ``.py`` file of ``discovery`` and
    ``constraints``): part of every run's key, so a change of the code that computes a run
    gives new runs, and a change of anything else (documentation, tests) keeps them."""
    from importlib import metadata

    try:
        version = metadata.version("vibroimpact-discovery")
    except metadata.PackageNotFoundError:
        version = "unknown"
    return f"{version}+src.{_source_hash()}"


def _source_hash():
    import hashlib

    root = Path(__file__).resolve().parents[3]
    h = hashlib.sha256()
    for pkg in ("discovery", "constraints"):
        for path in sorted((root / pkg).rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:12]


# a run file's fields and their types (the driver's own records; anything else is redone)
_RUN_FIELDS = {
    "key": str,
    "cell": int,
    "status": str,
    "exact": bool,
    "truth_equivalent": bool,
    "seconds": (int, float),
}
_OK_FIELDS = {"selected": list, "fp": int, "tp": int, "fn": int, "coverage": dict}


def _run_problem(data, key, n_cells):
    """Why ``data`` (a parsed run file named ``key``) is not a run of this study, else None."""
    if not isinstance(data, dict):
        return "not a JSON object"
    for name, kind in _RUN_FIELDS.items():
        v = data.get(name)
        if not isinstance(v, kind) or (kind is int and isinstance(v, bool)):
            return f"field {name!r} missing or of the wrong type"
    if data["key"] != key:
        return "the key it holds is not its file name (a copied file?)"
    if not 0 <= data["cell"] < n_cells:
        return "its cell is not one of the study's"
    if data["status"] not in ("ok", "failed"):
        return "its status is neither ok nor failed"
    if data["status"] == "ok":
        for name, kind in _OK_FIELDS.items():
            v = data.get(name)
            if not isinstance(v, kind) or (kind is int and isinstance(v, bool)):
                return f"field {name!r} missing or of the wrong type"
    return None


def _read_run(path, run=None, n_cells=None, bad=None):
    """The record in run file ``path``, or None when there is none or it is not a run of
    this study (checked against ``run``, the run it should hold: its key and cell; the
    reason goes to ``bad``)."""
    data, why = load_json(path)
    if data is None:
        if why is not None and bad is not None:
            bad.append((path, why))
        return None
    key = Path(path).stem
    why = _run_problem(data, key, n_cells if n_cells is not None else 1 << 62)
    if why is None and run is not None and data["cell"] != run["cell"]:
        why = "its cell is not the one its key names"
    if why is not None:
        if bad is not None:
            bad.append((path, why))
        return None
    return data
