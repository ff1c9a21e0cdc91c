"""Progress of long runs: one callback protocol for the API, one reporter for the CLI.

A long API function takes ``progress``: a callable ``progress(stage, done, total)``
(``total`` may be None) it calls as the work advances, :func:`tick` doing the calling;
``None`` (the default) for automatic progress, a :class:`Reporter` when the session is
interactive (stderr is a terminal, or the call runs in a Jupyter kernel) and nothing
otherwise (scripts, logs, pipes, worker processes, a long function called by another);
``True`` for a :class:`Reporter` whatever the session; ``False`` for none.
:func:`reports_progress` resolves the argument once for every long entry point. The CLI
passes a :class:`Reporter`: a tqdm bar with an ETA on stderr when stderr is a terminal,
one plain line per stage otherwise, nothing with ``--quiet``.
"""

from __future__ import annotations

import contextvars
import functools
import inspect
import multiprocessing
import sys
import threading
import time

__all__ = ["tick", "Reporter", "interactive", "resolve", "reports_progress"]

# True while a long API function runs: the long functions it calls (identify inside discover)
# stay silent under progress=None, the caller's stages being the ones reported
_RUNNING = contextvars.ContextVar("discovery_progress_running", default=False)


def tick(progress, stage, done, total=None):
    """Report ``done`` of ``total`` in ``stage`` to ``progress`` (when there is one)."""
    if progress is not None:
        progress(stage, int(done), None if total is None else int(total))


def _in_kernel():
    """Whether this runs in a Jupyter (IPython) kernel; IPython is not imported here."""
    ipython = sys.modules.get("IPython")
    get_ipython = getattr(ipython, "get_ipython", None)
    if get_ipython is None:
        return False
    try:
        shell = get_ipython()
    except Exception:  # noqa: BLE001 - an odd IPython is not interactive
        return False
    return getattr(shell, "kernel", None) is not None


def _shown(stream):
    """Whether ``stream`` is a terminal or a notebook's output (a bar reads well there)."""
    isatty = getattr(stream, "isatty", None)
    try:
        tty = bool(isatty()) if callable(isatty) else False
    except (OSError, ValueError):  # a closed or detached stream
        tty = False
    return tty or _in_kernel()


def interactive(stream=None):
    """Whether a person watches ``stream`` (default stderr): a terminal, or a notebook's
    output (a Jupyter kernel), from the main thread of the main process."""
    if threading.current_thread() is not threading.main_thread():
        return False
    if multiprocessing.parent_process() is not None:
        return False
    return _shown(sys.stderr if stream is None else stream)


def resolve(progress, where="progress"):
    """``(callable or None, owned)`` for a ``progress`` argument (see the module docstring);
    ``owned`` is true for a :class:`Reporter` made here, which the caller closes."""
    if progress is None:
        if _RUNNING.get() or not interactive():
            return None, False
        return Reporter(bar=True), True
    if progress is True:
        return Reporter(bar=_shown(sys.stderr)), True
    if progress is False:
        return None, False
    if callable(progress):
        return progress, False
    from ..errors import VidiTypeError
    from ._validate import _received

    raise VidiTypeError(
        f"{where}: progress must be None (automatic), True, False or a callable "
        f"progress(stage, done, total); got {_received(progress)}"
    )


def reports_progress(func):
    """Decorator of a long API function with a ``progress`` parameter: the function sees
    the resolved callable (or None), and a :class:`Reporter` made for it is closed when
    it returns or raises (an interrupt leaves no half-drawn bar)."""
    signature = inspect.signature(func)
    if "progress" not in signature.parameters:  # a programming error, caught at import
        raise AssertionError(f"{func.__qualname__}: no parameter 'progress'")

    @functools.wraps(func)
    def reporting(*args, **kwargs):
        bound = signature.bind(*args, **kwargs)
        rep, owned = resolve(bound.arguments.get("progress"), func.__qualname__)
        bound.arguments["progress"] = rep
        token = _RUNNING.set(True)
        try:
            return func(*bound.args, **bound.kwargs)
        finally:
            _RUNNING.reset(token)
            if owned:
                rep.close()

    reporting.__vidi_progress__ = True  # for the test that every long function resolves it
    return reporting


class Reporter:
    """The CLI's progress: a bar per stage on a terminal; elsewhere a line per stage, and a
    line with the count every :attr:`every` seconds while a stage goes on (a log or a pipe
    never stays silent for minutes)."""

    #: seconds between two lines of one stage outside a terminal
    every = 10.0

    def __init__(self, quiet=False, stream=None, bar=None):
        self.stream = sys.stderr if stream is None else stream
        self.quiet = bool(quiet)
        isatty = getattr(self.stream, "isatty", lambda: False)
        self.bar = bool(isatty()) if bar is None else bool(bar)
        self.stage = None
        self._bar = None
        self._last = 0.0

    def __call__(self, stage, done, total=None):
        if self.quiet:
            return
        if stage != self.stage:
            self.close()
            self.stage = stage
            if self.bar:
                from tqdm import tqdm

                self._bar = tqdm(
                    total=total,
                    desc=stage,
                    file=self.stream,
                    leave=False,
                    dynamic_ncols=True,
                    mininterval=0.2,
                )
            else:
                print(f"{stage} ...", file=self.stream, flush=True)
                self._last = time.monotonic()
        elif not self.bar and time.monotonic() - self._last >= self.every:
            count = f"{done}/{total}" if total else f"{done}"
            print(f"{stage}: {count} ...", file=self.stream, flush=True)
            self._last = time.monotonic()
        if self._bar is not None:
            if total is not None and self._bar.total != total:
                self._bar.total = total
            self._bar.n = min(done, total) if total else done
            self._bar.refresh()

    def close(self):
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
