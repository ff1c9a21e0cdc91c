"""Atomic output directories (:class:`OutputDir`).

Atomicity scheme (:class:`OutputDir`): a command writes its whole result set into a
hidden *staging* directory beside the target, ``.NAME.vidi-staging.PID-START.TOKEN``
(``PID`` and ``START``, the process start time, identify the run that owns it).  Only
after the command succeeded is the staging directory put in place of the target as a
whole:

* no target yet: one ``rename(staging, target)``;
* a target holding an earlier result: on Linux ``renameat2(RENAME_EXCHANGE)`` swaps
  the two directories in one atomic step; the earlier set is then at the staging name
  and is removed.  Elsewhere (or on a file system without the exchange), the target
  is first renamed aside to ``.NAME.vidi-old.PID-START.TOKEN``, the staging directory
  is renamed to the target, and the aside copy is removed.

A reader therefore sees the complete earlier set or the complete new set, never a
mix (in the fallback there is a window of two renames in which the target is
absent).  On an exception (including Ctrl-C) the staging directory is removed and
the target is untouched.  A run killed by SIGKILL leaves its staging (or aside)
directory behind: the next run for the same target removes it once the process
that made it is gone, and puts an aside copy back when the target is missing (a
kill between the two renames of the fallback).

Results are atomic *as a directory* and never take what is not theirs.  Every result
directory holds ``.vidi-manifest.json``: the command that wrote it and the files it wrote.
After the swap, every entry of the earlier directory that is not in its manifest (a user's
notes, another record, a file dropped in while the run went on) is moved back into the new
one (as ``NAME.kept`` when the new result uses its name), and only then is the earlier set
removed.  :func:`check_output` (called by the commands before any work) refuses a target
that is not safe to replace (:mod:`discovery._files._output_checks`).

The other jobs live in small modules, their names re-exported here: provenance records
(:mod:`discovery._files._provenance`), JSON values and files
(:mod:`discovery._files._jsonable`), the command a result belongs to and its manifest
(:mod:`discovery._files._ownership`), the names a run owns while it writes and atomic file
writes (:mod:`discovery._files._staging`).
"""

import contextlib
import json
import os
import re
import shutil
from importlib import metadata
from pathlib import Path

from ..errors import InputError
from . import _handoff
from ._jsonable import load_json as load_json
from ._jsonable import to_jsonable
from ._output_checks import check_output
from ._ownership import _RUN, MANIFEST, _owner, read_manifest, running, set_run, vidi_writes
from ._provenance import file_sha256, git_state, provenance
from ._staging import (
    _ASIDE,
    _OWNED,
    _STAGING,
    _chmod_default,
    _exchange,
    _fsync_dir,
    _owned_name,
    atomic_write_text,
    clean_stale,
)
from ._staging import _proc_start as _proc_start
from ._text import short

__all__ = [
    "OutputDir",
    "provenance",
    "to_jsonable",
    "check_output",
    "atomic_write_text",
    "file_sha256",
    "git_state",
    "clean_stale",
    "set_run",
    "running",
    "MANIFEST",
    "vidi_writes",
    "read_manifest",
    "short",
]

_RUN_FILE = re.compile(r"^[0-9a-f]+\.json$")  # a study's run file, in its runs/ folder


class OutputDir:
    """Build a result set in a staging directory and put it in place as a whole.

    See the module docstring for the scheme.  ``with OutputDir(p) as out:`` gives
    ``out.path(name)`` (where to write ``name`` now) and ``out.write_json(name, data)``;
    on leaving the block without an exception the staging directory replaces ``p``
    atomically, otherwise it is removed and ``p`` is untouched.

    Examples
    --------
    >>> with OutputDir("out") as out:              # doctest: +SKIP
    ...     out.write_json("summary.json", {...})
    """

    def __init__(self, target, inputs=()):
        self._raw = "" if target is None else str(target)  # Path("") would read as "."
        self.target = Path(self._raw)
        self.inputs = tuple(inputs)
        self.stage = None

    def __enter__(self):
        check_output(self._raw, self.inputs)
        target = Path(os.path.abspath(self.target))
        clean_stale(target)
        self._made = []
        p = target.parent
        while not p.exists():
            self._made.append(p)
            p = p.parent
        try:
            target.parent.mkdir(parents=True, exist_ok=True)
            self.stage = target.parent / _owned_name(target, _STAGING)
            os.mkdir(self.stage)
        except OSError as exc:
            for d in self._made:
                with contextlib.suppress(OSError):
                    d.rmdir()
            raise InputError(
                f"--out {short(self.target)!r}: cannot create {short(exc.filename)!r} "
                f"({exc.strerror}); choose a writable location"
            ) from None
        _chmod_default(self.stage, directory=True)
        self._abs = target
        _handoff.open_stage(self.stage)
        return self

    def path(self, name):
        """Where to write ``name`` now (inside the staging directory)."""
        return self.stage / name

    def write_json(self, name, data):
        with open(self.path(name), "w", encoding="utf-8") as fh:
            json.dump(to_jsonable(data), fh, indent=2)
            fh.write("\n")

    def _write_manifest(self):
        files = sorted(
            str(f.relative_to(self.stage).as_posix())
            for f in self.stage.rglob("*")
            if f.name != MANIFEST and not f.is_dir()
        )
        try:
            version = metadata.version("vibroimpact-discovery")
        except metadata.PackageNotFoundError:
            version = None
        with open(self.stage / MANIFEST, "w", encoding="utf-8") as fh:
            json.dump({"command": _RUN["command"], "files": files, "vidi": version}, fh, indent=2)
            fh.write("\n")

    def _keep_user_files(self, old, target):
        """Move every entry of the earlier directory ``old`` that the earlier run did not
        write back into ``target``: a user's notes, a file dropped in during the run, a file
        added inside one of vidi's folders.  vidi's are the names its manifest lists that a
        command can write (:func:`vidi_writes`; a folder listed whole, as older manifests
        did, is vidi's with what it holds); a legacy result without a manifest: the names
        the new result uses.  A name the new result also uses is kept as ``NAME.kept``."""
        _, files = _owner(old)
        if files is None:
            ours = {f.name for f in target.iterdir()} | {"summary.json"}
        else:
            ours = set(files) | {MANIFEST}
        self._keep_from(Path(old), Path(target), ours, "")

    def _keep_from(self, old, target, ours, prefix, whole=False):
        """Move the user's entries of folder ``old`` into ``target`` (see
        :meth:`_keep_user_files`); ``whole``: an older manifest listed this folder whole, so
        its run files (``HEX.json``) are vidi's and anything else in it the user's."""
        for e in list(os.scandir(old)):
            rel = prefix + e.name
            if _OWNED.match(e.name):  # a temporary file or staging folder of a killed run
                continue
            is_dir = e.is_dir(follow_symlinks=False)
            if not is_dir and (rel in ours or (whole and _RUN_FILE.match(e.name))):
                continue
            if is_dir and (rel in ours or any(f.startswith(rel + "/") for f in ours)):
                sub = target / e.name
                if not os.path.lexists(sub):
                    os.mkdir(sub)
                if sub.is_dir() and not sub.is_symlink():
                    self._keep_from(Path(e.path), sub, ours, rel + "/", rel in ours)
                    continue
            dest = target / e.name
            k = 0
            while os.path.lexists(dest):
                k += 1
                dest = target / (f"{e.name}.kept" if k == 1 else f"{e.name}.kept{k}")
            os.rename(e.path, dest)

    def _commit(self):
        self._write_manifest()
        for f in self.stage.iterdir():
            if f.is_file():
                with contextlib.suppress(OSError), open(f, "rb") as fh:
                    os.fsync(fh.fileno())
        _fsync_dir(self.stage)
        target = self._abs
        if not os.path.lexists(target):
            os.rename(self.stage, target)
            _fsync_dir(target.parent)
            return
        if target.is_symlink() or not target.is_dir():
            raise InputError(
                f"--out {short(self.target)!r} became a file or a link during the "
                "run; the results were not written"
            )
        if _exchange(self.stage, target):
            old = self.stage  # now holds the earlier result
        else:
            old = target.parent / _owned_name(target, _ASIDE)
            os.rename(target, old)
            try:
                os.rename(self.stage, target)
            except BaseException:
                os.rename(old, target)
                raise
        self._keep_user_files(old, target)
        _fsync_dir(target.parent)
        shutil.rmtree(old, ignore_errors=True)

    def __exit__(self, exc_type, exc, tb):
        try:
            if exc_type is None:
                _handoff.finish(under=self.stage)  # the figures printed by children
                self._commit()
        finally:
            if self.stage is not None:
                _handoff.close_stage(self.stage)  # a failed run's children killed
            if self.stage is not None and self.stage.exists():
                shutil.rmtree(self.stage, ignore_errors=True)
            if exc_type is not None or not self._abs.exists():
                for d in self._made:  # parents created for a run that failed
                    with contextlib.suppress(OSError):
                        d.rmdir()
        return False
