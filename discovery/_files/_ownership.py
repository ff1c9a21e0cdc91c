"""Which command a result belongs to: the command this process runs, the manifest every
result directory holds, the sidecar of a single-file output, and the refusal to replace
another command's results."""

import contextlib
import json
import re
from pathlib import Path

from ..errors import InputError
from ._jsonable import load_json
from ._text import short

MANIFEST = ".vidi-manifest.json"
"""The file in every result directory that lists what the run wrote (and which command):
a later run may replace those files only; anything else in the directory is the user's."""

_RUN = {"command": None, "overwrite": False}


def set_run(command, overwrite=False):
    """The command this process runs (``"verify"``, ``"ueda simulate"``, ...) and whether
    the user allowed replacing another command's results (``--overwrite``)."""
    _RUN.update(command=command, overwrite=bool(overwrite))


@contextlib.contextmanager
def running(command):
    """Within the block this process runs ``command`` (an API call such as ``study`` that
    owns its output directory like the CLI command of that name); ``--overwrite`` carries
    over only from the same command."""
    prev = dict(_RUN)
    set_run(command, prev["overwrite"] and prev["command"] == command)
    try:
        yield
    finally:
        _RUN.update(prev)


# the names a vidi command can write into a result directory (its kinds of file at the top,
# a study's runs/ folder): a manifest entry outside them (a user's notes.txt, a data folder)
# is never taken as vidi's, whatever the manifest says
_VIDI_WRITES = re.compile(
    r"^[^/]+\.(?:json|csv|png|pdf|tex|log|svg)$"  # the kinds of file a result holds
    r"|^runs$|^runs/[^/]+\.json$"  # a study's run files (an older manifest lists the folder)
)


_RUN_FILE = re.compile(r"^[0-9a-f]+\.json$")  # a study's run file, in its runs/ folder


def vidi_writes(name):
    """True when ``name`` (relative to a result directory, ``/`` between folders) is a name
    some vidi command writes there."""
    return bool(_VIDI_WRITES.match(name))


def read_manifest(path, strict=False):
    """``(command, files)`` of a manifest file, ``None`` when there is none.  A malformed one
    (not an object, ``files`` not a list of names) raises :class:`InputError` when
    ``strict``, else reads as ``(None, [])``: nothing in it is claimed as vidi's."""
    data, why = load_json(path)
    if data is None and why is None:
        return None
    if why is None:
        if not isinstance(data, dict):
            why = f"holds a JSON {type(data).__name__}, not an object"
        elif not isinstance(data.get("files", []), list) or not all(
            isinstance(f, str) for f in data.get("files", [])
        ):
            why = "its 'files' is not a list of file names"
        elif data.get("command") is not None and not isinstance(data["command"], str):
            why = "its 'command' is not a text"
    if why is not None:
        if strict:
            raise InputError(
                f"{short(path)!r} is not a vidi manifest ({why}); remove it if the "
                "directory is yours, or give another output directory"
            )
        return None, []
    return data.get("command"), [f for f in data.get("files", []) if vidi_writes(f)]


def _owner(directory, strict=False):
    """``(command, files)`` of an earlier result directory: from its manifest (only the
    names a vidi command can write count), else from a legacy ``summary.json`` that names
    its command (files unknown), else ``(None, None)``: a ``summary.json`` without a
    ``command`` is the user's own file, not a vidi result."""
    d = Path(directory)
    got = read_manifest(d / MANIFEST, strict)
    if got is not None:
        return got
    try:
        with open(d / "summary.json", encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError, RecursionError):
        return None, None
    cmd = data.get("command") if isinstance(data, dict) else None
    return (cmd, None) if isinstance(cmd, str) and cmd else (None, None)


def _refuse_other_command(owner, text, option):
    here = _RUN["command"]
    if owner and here and owner != here and not _RUN["overwrite"]:
        raise InputError(
            f"{option} {text!r} holds the results of `vidi {owner}`; give this "
            f"`vidi {here}` run its own output, or add --overwrite to replace "
            "them (files you added there are kept)"
        )


def _owner_file(sidecar):
    """``(command, None)`` from a single-file output's ``X.summary.json`` sidecar."""
    try:
        with open(sidecar, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return None, None
    cmd = data.get("command") if isinstance(data, dict) else None
    return (cmd if isinstance(cmd, str) else None), None
