"""The names a run owns while it writes (staging and aside directories, temporary files,
writability probes: ``.NAME.KIND.PID-START.TOKEN``), removing those of killed runs, file
modes, atomic file writes and the atomic swap of two directories."""

import contextlib
import ctypes
import ctypes.util
import errno
import os
import re
import secrets
import shutil
import sys
from pathlib import Path

_STAGING, _ASIDE, _TMP = "vidi-staging", "vidi-old", "vidi-tmp"
_OWNED = re.compile(
    r"^\.(?P<name>.+)\.(?P<kind>vidi-staging|vidi-old|vidi-tmp)\.(?P<pid>\d+)-"
    r"(?P<start>\d+)\.[0-9a-f]+$"
)
_PROBE = re.compile(r"^\.vidi-probe\.(?P<pid>\d+)-(?P<start>\d+)\.[0-9a-f]+$")


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
