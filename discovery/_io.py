"""Atomic output directories, output checks and provenance records.

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
that is a symbolic link (results never replace through a link), a file where a directory
is expected or anything but a regular file where a file is, not writable, the current
directory, an input file or a directory holding one, a directory holding another command's
results (unless ``--overwrite``: :func:`set_run`), a file that vidi did not write (no
``X.summary.json`` sidecar naming the command) or another command's file, and a non-empty
directory that is no vidi result at all.
"""

import contextlib
import ctypes
import ctypes.util
import datetime
import errno
import hashlib
import json
import os
import platform
import re
import secrets
import shutil
import subprocess
import sys
from importlib import metadata, resources
from pathlib import Path

import numpy as np

from .errors import InputError

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

# names of the files a result directory may hold (an earlier result that may be replaced)
_RESULT_FILE = re.compile(r"^[^/]+\.(json|csv|png|pdf|tex|txt|svg)$", re.IGNORECASE)
_STAGING, _ASIDE, _TMP = "vidi-staging", "vidi-old", "vidi-tmp"
_OWNED = re.compile(
    r"^\.(?P<name>.+)\.(?P<kind>vidi-staging|vidi-old|vidi-tmp)\.(?P<pid>\d+)-"
    r"(?P<start>\d+)\.[0-9a-f]+$"
)
_PROBE = re.compile(r"^\.vidi-probe\.(?P<pid>\d+)-(?P<start>\d+)\.[0-9a-f]+$")

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


def short(text, limit=160):
    """``text`` for a one-line message: a very long path shows its start and end only."""
    text = str(text)
    if len(text) <= limit:
        return text
    half = (limit - 5) // 2
    return f"{text[:half]} ... {text[-half:]}"


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


# ---------------------------------------------------------------------------- provenance
def _project_root():
    return Path(__file__).resolve().parent.parent


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


# ------------------------------------------------------------------------ file modes
def _umask():
    """The process umask, read without changing it where /proc allows."""
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith("Umask:"):
                    return int(line.split()[1], 8)
    except (OSError, ValueError, IndexError):
        pass
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def _chmod_default(path, directory=False):
    """Give ``path`` the mode ``open``/``mkdir`` would (0666/0777 minus the umask);
    mkstemp and mkdtemp create 0600/0700."""
    with contextlib.suppress(OSError):
        os.chmod(path, (0o777 if directory else 0o666) & ~_umask())


def _fsync_dir(path):
    with contextlib.suppress(OSError):
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


def atomic_write_text(path, text):
    """Write a text file atomically (temporary file + rename), mode 0666 minus umask.

    The temporary file ``.NAME.vidi-tmp.PID-START.TOKEN`` is removed on any exception;
    one left by a killed run is removed by the next write of the same file."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    clean_stale(path)
    tmp = path.parent / _owned_name(path, _TMP)
    fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # the umask applies
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as fh:
            fh.write(text)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


# --------------------------------------------------------------------- output checks
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


def _owner_file(sidecar):
    """``(command, None)`` from a single-file output's ``X.summary.json`` sidecar."""
    try:
        with open(sidecar, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return None, None
    cmd = data.get("command") if isinstance(data, dict) else None
    return (cmd if isinstance(cmd, str) else None), None


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


# ---------------------------------------------------------------- staging directories
def _proc_start(pid):
    """Start time of process ``pid`` (clock ticks since boot) on Linux, else 0."""
    try:
        with open(f"/proc/{pid}/stat", "rb") as fh:
            stat = fh.read().decode("ascii", "replace")
        return int(stat.rsplit(")", 1)[1].split()[19])
    except (OSError, ValueError, IndexError):
        return 0


def _alive(pid, start):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except PermissionError:
        return True  # another user's live process
    except OSError:
        return True
    if start and os.path.exists("/proc/self/stat"):
        now = _proc_start(pid)
        return now == 0 or now == start  # the pid was reused by another process otherwise
    return True


def _owned_name(target, kind):
    return f".{target.name}.{kind}.{os.getpid()}-{_proc_start(os.getpid())}.{secrets.token_hex(4)}"


def clean_stale(target):
    """Remove the staging/aside directories (and temporary files) of ``target`` left by
    runs that were killed (their process is gone).  When the target itself is missing,
    the newest aside copy (the earlier result, renamed aside just before a kill) is put
    back first.

    Returns
    -------
    list of Path
        What was removed or restored.
    """
    target = Path(os.path.abspath(target))
    parent = target.parent
    if not parent.is_dir():
        return []
    stale = []
    try:
        for e in os.scandir(parent):
            m = _OWNED.match(e.name)
            if (
                m
                and m["name"] == target.name
                and not _alive(int(m["pid"]), int(m["start"]))
                and e.is_dir(follow_symlinks=False) == (m["kind"] != _TMP)
            ):
                stale.append((m["kind"], Path(e.path)))
            m = _PROBE.match(e.name)  # a writability probe of a killed run
            if m and not _alive(int(m["pid"]), int(m["start"])) and e.is_dir(follow_symlinks=False):
                stale.append(("probe", Path(e.path)))
    except OSError:
        return []
    done = []
    asides = sorted((p for k, p in stale if k == _ASIDE), key=lambda p: p.stat().st_mtime)
    if asides and not os.path.lexists(target):
        with contextlib.suppress(OSError):
            os.rename(asides[-1], target)
            done.append(target)
    for kind, p in stale:
        if kind == _TMP:
            with contextlib.suppress(OSError):
                p.unlink()
                done.append(p)
        elif p.exists():
            shutil.rmtree(p, ignore_errors=True)
            done.append(p)
    return done


_libc = None


def _exchange(a, b):
    """Atomically swap directories ``a`` and ``b`` (Linux renameat2 RENAME_EXCHANGE);
    False when the platform or file system does not support it."""
    global _libc
    if not sys.platform.startswith("linux"):
        return False
    try:
        if _libc is None:
            _libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        fn = _libc.renameat2
    except (OSError, AttributeError):
        return False
    fn.argtypes = [ctypes.c_int, ctypes.c_char_p, ctypes.c_int, ctypes.c_char_p, ctypes.c_uint]
    fn.restype = ctypes.c_int
    at_fdcwd, rename_exchange = -100, 2
    if fn(at_fdcwd, os.fsencode(a), at_fdcwd, os.fsencode(b), rename_exchange) == 0:
        return True
    err = ctypes.get_errno()
    if err in (errno.ENOSYS, errno.EINVAL, errno.ENOTSUP, errno.EOPNOTSUPP, errno.EPERM):
        return False
    raise OSError(err, os.strerror(err), str(b))


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
                self._commit()
        finally:
            if self.stage is not None and self.stage.exists():
                shutil.rmtree(self.stage, ignore_errors=True)
            if exc_type is not None or not self._abs.exists():
                for d in self._made:  # parents created for a run that failed
                    with contextlib.suppress(OSError):
                        d.rmdir()
        return False
