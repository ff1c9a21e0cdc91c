"""Provenance of a run: versions, platform, git commit, input checksums and settings."""

import datetime
import hashlib
import os
import platform
import subprocess
from importlib import metadata, resources
from pathlib import Path

from ._jsonable import to_jsonable

# the solvers cvxpy uses here: CLARABEL (default), OSQP (fallback in the regression)
_PACKAGES = (
    "vibroimpact-discovery",
    "numpy",
    "scipy",
    "numba",
    "sympy",
    "cvxpy",
    "clarabel",
    "osqp",
    "scikit-learn",
    "pysindy",
    "matplotlib",
    "jinja2",
    "tqdm",
    "pandas",
    "distributed",
)


def _project_root():
    return Path(__file__).resolve().parents[2]


def git_state(root=None, timeout=2.0):
    """``(commit, dirty)`` of the git checkout the package runs from, else ``(None, None)``.

    Only a checkout whose top level holds the package counts (``root/.git`` exists): an
    installed copy inside some other repository is not attributed to that repository.
    ``dirty`` is True when tracked files differ from the commit (None if unknown).
    """
    root = Path(root) if root is not None else _project_root()
    if not (root / ".git").exists():
        return None, None
    env = {**os.environ, "GIT_OPTIONAL_LOCKS": "0", "LC_ALL": "C"}

    def git(*args):
        return subprocess.run(
            ["git", "-C", str(root), *args],
            capture_output=True,
            text=True,
            timeout=timeout,
            env=env,
            stdin=subprocess.DEVNULL,
        )

    try:
        head = git("rev-parse", "HEAD")
        if head.returncode != 0:
            return None, None
        commit = head.stdout.strip() or None
    except (OSError, subprocess.SubprocessError):
        return None, None
    try:
        st = git("status", "--porcelain", "--untracked-files=no")
        dirty = bool(st.stdout.strip()) if st.returncode == 0 else None
    except (OSError, subprocess.SubprocessError):
        dirty = None
    return commit, dirty


def file_sha256(path):
    """Hex sha256 of a file's bytes (read in chunks), or None if it cannot be read."""
    h = hashlib.sha256()
    try:
        if not isinstance(path, str | os.PathLike):  # an importlib resource
            h.update(path.read_bytes())
            return h.hexdigest()
        with open(path, "rb") as fh:
            for chunk in iter(lambda: fh.read(1 << 20), b""):
                h.update(chunk)
    except (OSError, AttributeError):
        return None
    return h.hexdigest()


def _input_record(value):
    if value is None:
        return None
    text = str(value)
    path = value
    if isinstance(value, str) and not os.path.exists(value):
        # a built-in scenario name: checksum of the packaged file
        res = resources.files("discovery.vibroimpact.model") / "scenarios" / f"{value}.toml"
        if res.is_file():
            return {"path": f"builtin:{value}", "sha256": file_sha256(res)}
    if not isinstance(path, str | os.PathLike) or not os.path.isfile(path):
        return {"path": text, "sha256": None}
    return {
        "path": str(Path(path).resolve()),
        "sha256": file_sha256(path),
        "bytes": os.path.getsize(path),
    }


def provenance(settings=None, inputs=None):
    """Versions, platform, git commit, input checksums and settings: recorded in every
    ``summary.json``.

    Parameters
    ----------
    settings : dict, optional
        The run's options (callables are left out).
    inputs : dict, optional
        ``{"data": path, "scenario": path or built-in name, ...}``; each becomes
        ``{"path", "sha256", "bytes"}`` (``sha256`` None when it is not a readable file).

    Returns
    -------
    dict
        ``versions`` (python and the packages, None when not installed), ``git``
        (``commit``, ``dirty``: None outside a git checkout), ``platform``, ``created``
        (UTC), ``inputs``, ``settings``.
    """
    versions = {"python": platform.python_version()}
    for name in _PACKAGES:
        try:
            versions[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            versions[name] = None
    commit, dirty = git_state()
    out = {
        "versions": versions,
        "git": {"commit": commit, "dirty": dirty},
        "platform": platform.platform(),
        "created": datetime.datetime.now(datetime.UTC).isoformat(timespec="seconds"),
        "settings": to_jsonable({k: v for k, v in (settings or {}).items() if not callable(v)}),
    }
    if inputs is not None:
        out["inputs"] = {k: _input_record(v) for k, v in inputs.items()}
    return out
