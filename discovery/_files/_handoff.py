"""Files of a staged result written by a forked process while the command goes on.

A figure is saved twice, as a PNG and as a PDF; the PDF's print (a layout pass of its own
and the fonts' subsetting, about half of a figure's time) needs nothing the command does
after it.  :func:`write` hands such a write to a forked child when the file lies in the
staging directory of an open :class:`~discovery._files._io.OutputDir` of this process, on
Linux with a second core, and returns at once; the output directory waits for its
children before it puts the result in place (:func:`finish`) and kills them when the run
fails (:func:`abandon`).  A reader of such a file within the run (LaTeX reading a figure)
waits for it first (:func:`finish` with its paths).

A child that fails or is killed leaves its file to the parent, which writes it itself:
the result does not depend on the hand-off.  Files another process writes (a command's
figure drawer, :mod:`._drawer`) are waited for the same way (:func:`pend`).  Elsewhere (a
figure an API user saves, one core, no ``fork``) the write is done at once, in this
process.
"""

import contextlib
import os
import signal
import sys
import threading
from pathlib import Path

__all__ = [
    "write",
    "pend",
    "finish",
    "pending",
    "writers",
    "abandon",
    "open_stage",
    "close_stage",
    "in_parallel",
    "child_wrote",
]

_STAGES = []  # the staging directories of this process's open output directories
_PENDING = {}  # path -> (what writes it: a _Child or a drawer's job, the write itself)
# held while the registry changes and while its children are waited for: a reader in another
# thread (LaTeX's, in ``vidi fit``) returns once the file it waits for is there
_LOCK = threading.RLock()


def in_parallel():
    """Whether a write may be handed to a forked child here: Linux (``fork`` is safe with
    the libraries loaded; elsewhere it is not promised) and a second core to run it on."""
    if not (sys.platform.startswith("linux") and hasattr(os, "fork")):
        return False
    try:
        return len(os.sched_getaffinity(0)) > 1
    except (AttributeError, OSError):  # pragma: no cover - Linux has it
        return (os.cpu_count() or 1) > 1


def open_stage(stage):
    """``stage`` (an output directory's staging directory) takes handed-off writes."""
    _STAGES.append(Path(os.path.abspath(stage)))


def close_stage(stage):
    """``stage`` takes no more; its pending children are killed (:func:`abandon`)."""
    stage = Path(os.path.abspath(stage))
    abandon(stage)
    with contextlib.suppress(ValueError):
        _STAGES.remove(stage)


def _stage_of(path):
    return next((s for s in _STAGES if s == path.parent or s in path.parents), None)


def stage_of(path):
    """The open stage that holds ``path`` (None outside every one)."""
    return _stage_of(Path(os.path.abspath(path)))


class _Child:
    """A forked child writing a file: ``wait()`` is whether it wrote it (its outcome kept:
    asked again, it answers again), ``kill()`` ends it."""

    def __init__(self, pid):
        self.pid, self.status = pid, None

    def wait(self):
        if self.status is None:
            try:
                _, self.status = os.waitpid(self.pid, 0)
            except ChildProcessError:  # reaped elsewhere: its outcome is unknown
                self.status = -1
        return os.WIFEXITED(self.status) and os.WEXITSTATUS(self.status) == 0

    def kill(self):
        with contextlib.suppress(OSError):
            os.kill(self.pid, signal.SIGKILL)
        with contextlib.suppress(OSError):
            os.waitpid(self.pid, 0)


def child_wrote(pid):
    """Whether the forked child ``pid`` exited 0 (waits for it)."""
    return _Child(pid).wait()


class _Once:
    """A write shared by several paths (a figure's PNG and PDF): done at most once here."""

    def __init__(self, fn):
        self.fn, self.done = fn, False

    def __call__(self):
        if not self.done:
            self.done = True
            self.fn()


def pend(paths, writer, fn):
    """The files ``paths`` are being written by ``writer`` (an object with ``wait()``, whether
    it wrote them, and ``kill()``); where it did not, :func:`finish` writes them by calling
    ``fn()`` once."""
    once = _Once(fn)
    with _LOCK:
        for path in paths:
            _PENDING[Path(os.path.abspath(path))] = (writer, once)


def write(path, fn):
    """Write the file ``path`` by calling ``fn()`` (which writes it and may be called again):
    in a forked child when ``path`` lies in an open stage and :func:`in_parallel`, else at
    once.  A second write of one path waits for the first."""
    path = Path(os.path.abspath(path))
    if _stage_of(path) is None or not in_parallel():
        fn()
        return
    with _LOCK:
        finish([path])
        _PENDING[path] = (_Child(_forked(fn)), fn)


def _forked(fn):
    """The pid of a forked child that calls ``fn()`` and exits: 0 when it wrote, else 1."""
    pid = os.fork()
    if pid == 0:  # the child: write, then leave without the parent's exit handlers
        code = 1
        try:
            # Ctrl-C reaches the whole process group: the parent alone decides (it kills
            # this child); and not the parent's SIGTERM handler (it raises its exception)
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            signal.signal(signal.SIGTERM, signal.SIG_DFL)
            fn()
            code = 0
        except BaseException:  # noqa: BLE001 - the parent writes the file again
            code = 1
        finally:
            os._exit(code)
    return pid


def finish(paths=None, under=None):
    """Wait for the children writing ``paths`` (default: every pending one, or those in
    the directory ``under``); a file whose child failed is written here."""
    with _LOCK:
        for path in _selected(paths, under):
            writer, fn = _PENDING.pop(path)
            if not writer.wait():
                fn()


def pending(under):
    """The files being written into the directory ``under`` now."""
    with _LOCK:
        return _selected(None, under)


def writers(paths):
    """What writes each of ``paths`` that is pending (each with ``wait()``): a thread may wait
    for them without holding the registry, then :func:`finish` them at once."""
    with _LOCK:
        return [_PENDING[p][0] for p in _selected(paths, None)]


def abandon(under=None, paths=None):
    """Kill and reap the children writing into ``under`` (default: all) or writing
    ``paths``, their files left unwritten (a failed run's staging directory is removed)."""
    with _LOCK:
        for path in _selected(paths, under):
            writer, _ = _PENDING.pop(path)
            writer.kill()


def _selected(paths, under):
    if paths is not None:
        wanted = {Path(os.path.abspath(p)) for p in paths}
        return [p for p in list(_PENDING) if p in wanted]
    if under is None:
        return list(_PENDING)
    under = Path(os.path.abspath(under))
    return [p for p in list(_PENDING) if under in p.parents]
