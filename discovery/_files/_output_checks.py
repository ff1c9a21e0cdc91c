"""Refusing an output path before any work starts (:func:`check_output`).

Refused: a symbolic link (results never replace through a link), a file where a directory is
expected or anything but a regular file where a file is, not writable, the current
directory, an input file or a directory holding one, a directory holding another command's
results (unless ``--overwrite``: :func:`~discovery._files._ownership.set_run`), a file that vidi
did not write (no ``X.summary.json`` sidecar naming the command) or another command's file,
and a non-empty directory that is no vidi result at all."""

import contextlib
import os
import re
import secrets
from pathlib import Path

from ..errors import InputError
from ._ownership import _RUN, _owner, _owner_file, _refuse_other_command
from ._staging import _OWNED, _proc_start
from ._text import short

# names of the files a result directory may hold (an earlier result that may be replaced)
_RESULT_FILE = re.compile(r"^[^/]+\.(json|csv|png|pdf|tex|txt|svg)$", re.IGNORECASE)


def _same_file(a, b):
    try:
        return os.path.samefile(a, b)
    except OSError:
        return os.path.abspath(a) == os.path.abspath(b)


def _inside(child, parent):
    """True when ``child`` is ``parent`` or lies below it (both resolved)."""
    try:
        Path(child).resolve().relative_to(Path(parent).resolve())
        return True
    except ValueError:
        return False


def _nearest_existing(path):
    p = Path(os.path.abspath(path))
    while not p.exists() and p != p.parent:
        p = p.parent
    return p


def _writable_dir(d):
    """Can entries be created in directory ``d``?  ``os.access`` for ordinary users; for
    root (whom it always answers yes, e.g. in /proc) by creating and removing a probe."""
    if not os.access(d, os.W_OK | os.X_OK):
        return False
    if not hasattr(os, "geteuid") or os.geteuid() != 0:
        return True
    probe = os.path.join(
        d, f".vidi-probe.{os.getpid()}-{_proc_start(os.getpid())}.{secrets.token_hex(4)}"
    )  # owned: clean_stale removes it
    try:
        os.mkdir(probe)
    except OSError:
        return False
    with contextlib.suppress(OSError):
        os.rmdir(probe)
    return True


def _check_output_file(p, text, option):
    """:func:`check_output` for an output file: a regular file vidi wrote, or a new one."""
    if p.is_dir():
        raise InputError(
            f"{option} {text!r} is a directory; give a file name inside it, "
            f"e.g. {str(p / 'D.csv')!r}"
        )
    if p.exists() and not p.is_file():
        raise InputError(
            f"{option} {text!r} exists and is not a regular file (a pipe, a "
            "device or a socket); it is never replaced: give a new file name"
        )
    if p.is_file():
        sidecar = p if p.name.endswith(".summary.json") else p.with_suffix(".summary.json")
        owner, _ = _owner_file(sidecar)
        if owner is None and not _RUN["overwrite"] and _RUN["command"]:
            raise InputError(
                f"{option} {text!r} exists and was not written by vidi (no "
                f"{sidecar.name} beside it); give a new file name, or add "
                "--overwrite to replace it"
            )
        _refuse_other_command(owner, text, option)


def _check_output_dir(p, text, option, inputs):
    """:func:`check_output` for an output directory: new, or an earlier result that holds
    no input and is not the current directory."""
    if p.exists() and not p.is_dir():
        raise InputError(
            f"{option} {text!r} is an existing file; give a directory (it is "
            "created) or remove the file"
        )
    if not p.is_dir():
        return
    if _inside(Path.cwd(), p):
        raise InputError(
            f"{option} {text!r} is the current directory or above it; the "
            "result directory is replaced as a whole, so give a new "
            "subdirectory such as results/run1"
        )
    for inp in inputs:
        if inp is not None and os.path.isfile(inp) and _inside(inp, p):
            raise InputError(
                f"{option} {text!r} holds the input file {str(inp)!r}; "
                "the result directory is replaced as a whole, so give "
                "another directory"
            )
    _check_replaceable(p, text, option)


def check_output(path, inputs=(), *, kind="dir", option="--out"):
    """Refuse an output path before any work starts; returns it as a :class:`Path`.

    Parameters
    ----------
    path : str or Path
        The output directory (``kind="dir"``) or file (``kind="file"``).
    inputs : iterable of paths
        Input files (data, scenario): the output may neither be one nor, for a
        directory, contain one (the directory is replaced as a whole).
    kind : {"dir", "file"}
    option : str
        Option name used in the messages.

    Raises
    ------
    InputError
        ``path`` is empty, an existing file where a directory is expected (or a
        directory where a file is), an input file, not writable, the current directory
        (or above it), a directory holding an input, or a non-empty directory that is
        not an earlier result.
    """
    text = "" if path is None else str(path)
    if not text.strip():
        what = "a directory such as results/run1" if kind == "dir" else "a file such as D.csv"
        raise InputError(f"{option} is empty; give {what}")
    p = Path(text)
    text = short(text)  # the messages below show a very long path shortened
    for inp in inputs:
        if inp is not None and os.path.isfile(inp) and _same_file(p, inp):
            raise InputError(
                f"{option} {text!r} is the input file {str(inp)!r}; write the results elsewhere"
            )
    if p.is_symlink():
        raise InputError(
            f"{option} {text!r} is a symbolic link; results never replace "
            "through a link: give the real path or a new name"
        )
    if kind == "file":
        _check_output_file(p, text, option)
    else:
        _check_output_dir(p, text, option, inputs)
    parent = _nearest_existing(Path(os.path.abspath(p)).parent)
    if not parent.is_dir():
        raise InputError(
            f"{option} {text!r}: {str(parent)!r} is a file, not a directory; "
            "choose another location"
        )
    if not _writable_dir(parent):
        raise InputError(
            f"{option} {text!r}: cannot write in {str(parent)!r} (permission "
            "denied or read-only); choose a writable location"
        )
    return p


def _check_replaceable(p, text, option):
    """An existing directory may receive a new result only when it is empty or holds an
    earlier result (a manifest, or a legacy summary.json beside output files) of the same
    command (or with ``--overwrite``); the files a user added are kept by the commit."""
    entries = [e for e in os.scandir(p) if not _OWNED.match(e.name)]
    if not entries:
        return
    owner, files = _owner(p, strict=True)
    if owner is not None or files is not None:
        _refuse_other_command(owner, text, option)
        return
    # no manifest, no summary.json naming its command: not a vidi result
    subdirs = sorted(e.name for e in entries if e.is_dir(follow_symlinks=False))
    odd = sorted(
        e.name
        for e in entries
        if not e.is_dir(follow_symlinks=False)
        and not (e.is_file(follow_symlinks=False) and _RESULT_FILE.match(e.name))
    )
    rest = sorted(e.name for e in entries if e.name not in subdirs and e.name not in odd)
    shown = ", ".join(short(n, 60) for n in ((subdirs + odd)[:3] or rest[:3]))
    raise InputError(
        f"{option} {text!r} is a non-empty directory that is not an earlier "
        f"vidi result (it holds {shown}); results replace the directory as a "
        "whole, so give a new or empty directory such as "
        f"{short(p / 'run1')!r}"
    )
