"""Worker processes that die with their parent and leave interruptions to it.

For a ``ProcessPoolExecutor`` (fork or spawn)::

    from discovery.numerics._workers import worker_initializer, terminate_pool

    pool = ProcessPoolExecutor(n, mp_context=get_context("fork"),
                               **worker_initializer(_init, init_args))
    try:
        ...
    except BaseException:
        terminate_pool(pool)      # Ctrl-C / errors: no queued work is waited for
        raise
    else:
        pool.shutdown()

Each worker, before the pool's own initializer runs:

* asks the kernel to send it SIGKILL when its parent dies (``prctl(PR_SET_PDEATHSIG)``
  on Linux via ctypes; elsewhere it falls back to a watchdog thread that polls the
  parent's pid once a second), and exits at once if the parent is already gone (the
  race between fork and prctl);
* ignores SIGINT: Ctrl-C in a terminal reaches the whole process group, and the parent
  alone decides (it stops the pool) - no traceback from every worker;
* restores the default SIGTERM action (the parent's handler, inherited through fork,
  would raise the parent's exception in the worker).

Note: PR_SET_PDEATHSIG fires when the *thread* that forked the worker ends.  The pool
forks its workers from the thread that submits work (the main thread of ``vidi``); a
pool driven from a short-lived thread would lose its workers when that thread ends.
"""

import contextlib
import ctypes
import ctypes.util
import os
import signal
import sys
import threading
import time

__all__ = ["die_with_parent", "worker_initializer", "terminate_pool"]

_PR_SET_PDEATHSIG = 1


def _watch_parent(parent_pid, interval=1.0):
    def watch():
        while True:
            time.sleep(interval)
            if os.getppid() != parent_pid:
                os._exit(1)

    threading.Thread(target=watch, name="vidi-parent-watch", daemon=True).start()


def die_with_parent(parent_pid=None):
    """Make the calling (worker) process end when ``parent_pid`` (default: its current
    parent) ends; ignore SIGINT and restore the default SIGTERM.

    Returns
    -------
    str
        How: ``"prctl"`` (Linux), ``"watchdog"`` (elsewhere) or ``"none"`` (the parent
        pid is unknown).
    """
    parent_pid = os.getppid() if parent_pid is None else int(parent_pid)
    with contextlib.suppress(ValueError, OSError):
        signal.signal(signal.SIGINT, signal.SIG_IGN)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
    how = "none"
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
            if libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0) == 0:
                how = "prctl"
        except (OSError, AttributeError):
            pass
    if how != "prctl" and parent_pid > 1:
        _watch_parent(parent_pid)
        how = "watchdog"
    if os.getppid() != parent_pid:  # the parent died before the death signal was armed
        os._exit(1)
    return how


def _initializer(parent_pid, init, initargs):
    die_with_parent(parent_pid)
    if init is not None:
        init(*initargs)


def worker_initializer(init=None, initargs=()):
    """Keyword arguments ``initializer=, initargs=`` for ``ProcessPoolExecutor`` (or
    ``multiprocessing.Pool``): :func:`die_with_parent` in every worker, then
    ``init(*initargs)``."""
    return {"initializer": _initializer, "initargs": (os.getpid(), init, tuple(initargs))}


def terminate_pool(pool):
    """Stop a ``ProcessPoolExecutor`` now: cancel queued work, kill the workers (they
    hold nothing that needs cleaning up) and do not wait for running tasks."""
    procs = list((getattr(pool, "_processes", None) or {}).values())
    with contextlib.suppress(Exception):
        pool.shutdown(wait=False, cancel_futures=True)
    for p in procs:
        with contextlib.suppress(Exception):
            p.kill()
    for p in procs:
        with contextlib.suppress(Exception):
            p.join(timeout=5)
