"""Figures drawn by a process forked when a command starts.

Loading matplotlib and a figure module takes a third of a second, and a figure's drawing as
long again: in a command that draws one figure at its end (``vidi verify``), that is a
third of its time, all of it after the work.  A :class:`Drawer` is forked before the command
loads its numerics, loads matplotlib, the figure modules and the modules of the results it
will draw (``preload``) on the second core while the command computes, then draws each
figure it is sent (:meth:`Drawer.draw`: the figure function's name and its arguments,
pickled) in a child forked for it, figures side by side on the cores (one per core at a
time), each one's PDF printed by a child of its own (:mod:`._handoff`) while its PNG is
drawn, and answers when both files are written.  The command's output directory waits for them as
for any handed-off file; a figure the drawer did not write (its drawing raised, the drawer
died, its arguments do not pickle) is drawn by the command itself, so the result does not
depend on the drawer.
Elsewhere (one core, no ``fork``, a figure outside an output directory) a figure is drawn at
once, in this process.
"""

import contextlib
import importlib
import os
import pickle
import queue
import signal
import threading

from . import _handoff

__all__ = ["Drawer", "drawing"]


def _function(name):
    """The figure function ``name`` of :mod:`reports` (its names load their module on first
    use, matplotlib with it), or of a module below it: ``"ueda.figures.chart_figure"``."""
    module, _, function = f"reports.{name}".rpartition(".")
    return getattr(importlib.import_module(module), function)


def _draw_here(name, args, kwargs):
    _function(name)(*args, **kwargs)


class Drawer:
    """The drawing process of one command (see the module docstring); ``None`` of
    :meth:`start` stands for drawing here."""

    def __init__(self, pid, conn):
        self.pid, self.conn = pid, conn
        self.answers, self.sent, self.dead = {}, 0, False
        self.lock = threading.Lock()
        self.queue = None  # the sending thread's jobs (:meth:`_send`)

    @classmethod
    def start(cls, figures=(), preload=()):
        """A drawer that has begun loading the figure functions ``figures`` (names in
        :mod:`reports`) and the modules ``preload`` (the results' it will be sent), or None
        where writes are not handed off (:func:`._handoff.in_parallel`)."""
        if not _handoff.in_parallel():
            return None
        from multiprocessing import Pipe

        mine, its = Pipe()
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child (its work is checked by its files)
            mine.close()
            with contextlib.suppress(OSError):
                os.setpgid(0, 0)  # a group of its own: its figures' children end with it
            _serve(its, figures, preload)
        with contextlib.suppress(OSError):  # (set on both sides: whichever runs first)
            os.setpgid(pid, pid)
        its.close()
        return cls(pid, mine)

    def draw(self, stem, name, *args, **kwargs):
        """``stem.png`` and ``stem.pdf`` written by the figure function ``name`` of
        :mod:`reports` called with ``args`` and ``kwargs`` (among them ``stem``):
        by the drawer when the files lie in an open output directory, else here and now."""
        stage = _handoff.stage_of(f"{stem}.png")
        job = self.sent
        payload = None
        if stage is not None and not self.dead:
            with contextlib.suppress(Exception):  # arguments that do not pickle: drawn here
                payload = pickle.dumps((job, name, args, kwargs, str(stage)), protocol=5)
        if payload is None:
            _draw_here(name, args, kwargs)
            return
        paths = [f"{stem}.png", f"{stem}.pdf"]
        _handoff.finish(paths)  # a second drawing of one file waits for the first
        self._send(payload)
        self.sent += 1
        _handoff.pend(paths, _Job(self, job), lambda: _draw_here(name, args, kwargs))

    def _send(self, payload):
        """Send a job by the sending thread, in order: the command goes on while a job of
        megabytes waits in the pipe for the drawer to take it (it takes the next job when
        it has drawn the last).  A job that cannot be sent (the drawer is gone) is drawn by
        the command where it waits for it."""
        if self.queue is None:
            self.queue = queue.SimpleQueue()
            threading.Thread(target=self._sending, daemon=True).start()
        self.queue.put(payload)

    def _sending(self):
        while (payload := self.queue.get()) is not None:
            try:
                self.conn.send_bytes(payload)
            except OSError:  # the drawer is gone: answered() reads no answer
                self.dead = True
                return

    def answered(self, job):
        """Whether the drawer wrote job ``job``'s files (waits for its answer)."""
        with self.lock:
            while job not in self.answers and not self.dead:
                try:
                    done, ok = self.conn.recv()
                except (EOFError, OSError):
                    self.dead = True
                    break
                self.answers[done] = ok
            return bool(self.answers.get(job, False))

    def kill(self):
        """End the drawer at once, and the children drawing its figures (a failed run: its
        files are not wanted)."""
        self.dead = True
        try:
            os.killpg(self.pid, signal.SIGKILL)
        except OSError:  # not yet its own group's leader
            with contextlib.suppress(OSError):
                os.kill(self.pid, signal.SIGKILL)

    def close(self):
        """End the drawer and reap it: every file it was sent is waited for by now (its
        output directory closed), so it is idle, or still loading when the command stopped
        early (an interrupt: the command does not wait for its imports)."""
        self.dead = True
        if self.queue is not None:
            self.queue.put(None)  # the sending thread ends
        with contextlib.suppress(OSError):
            self.conn.close()
        self.kill()
        with contextlib.suppress(OSError):
            os.waitpid(self.pid, 0)


class _Job:
    """One figure sent to a drawer, as :func:`._handoff.pend` waits for it."""

    def __init__(self, drawer, job):
        self.drawer, self.job = drawer, job

    def wait(self):
        return self.drawer.answered(self.job)

    def kill(self):
        self.drawer.kill()


class _Here:
    """Drawing in this process (one core, no ``fork``): :meth:`Drawer.draw`'s signature."""

    def draw(self, stem, name, *args, **kwargs):
        _draw_here(name, args, kwargs)


@contextlib.contextmanager
def drawing(figures=(), preload=()):
    """``with drawing([...]) as d:`` a :class:`Drawer` started now (:meth:`Drawer.start`; or
    one drawing here), closed when the block ends (its output directories closed within it)."""
    drawer = Drawer.start(figures, preload)
    try:
        yield drawer if drawer is not None else _Here()
    finally:
        if drawer is not None:
            drawer.close()


def _serve(conn, figures, preload):  # pragma: no cover - runs in the forked drawer
    """The drawer's life: load ``figures`` and ``preload``, then draw each job, answering
    ``(job, wrote)`` once its PDF is printed too; it ends when the command closes its end
    (or dies).  Each figure is drawn by a child of this process while the next is taken
    (:class:`_Jobs`)."""
    code = 0
    try:
        signal.signal(signal.SIGINT, signal.SIG_IGN)  # the command decides (it kills this)
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        backends = ("matplotlib.backends.backend_agg", "matplotlib.backends.backend_pdf")
        for name in (*backends, *preload):
            with contextlib.suppress(Exception):
                importlib.import_module(name)
        for name in figures:
            with contextlib.suppress(Exception):
                _function(name)
        jobs = _Jobs(conn)
        while True:
            try:
                job, name, args, kwargs, stage = pickle.loads(conn.recv_bytes())
            except (EOFError, OSError):
                break
            jobs.draw(job, name, args, kwargs, stage)
    except BaseException:  # noqa: BLE001
        code = 1
    finally:
        os._exit(code)


class _Jobs:  # pragma: no cover - runs in the forked drawer
    """The drawer's jobs: each drawn by a child forked from the drawer (matplotlib and the
    figure modules loaded) while the drawer takes the next, at most one job per core at a
    time, and answered by a thread of its own once that child has ended: its files
    written, or not (the command draws it again).  Drawn one after another in the drawer,
    the fit's three figures took 1.0 s of the command's end (CHANGELOG)."""

    def __init__(self, conn):
        self.conn, self.stages, self.lock = conn, set(), threading.Lock()
        self.slots = threading.BoundedSemaphore(_cores())

    def draw(self, job, name, args, kwargs, stage):
        """Draw job ``job`` into the output directory's staging directory ``stage``."""
        if stage not in self.stages:  # open while the drawer lives: its jobs' prints go on
            _handoff.open_stage(stage)
            self.stages.add(stage)
        self.slots.acquire()
        pid = os.fork()
        if pid == 0:
            _drawn(name, args, kwargs)
        threading.Thread(target=self._answered, args=(job, pid), daemon=True).start()

    def _answered(self, job, pid):
        try:
            ok = _handoff.child_wrote(pid)
        finally:
            self.slots.release()
        with self.lock, contextlib.suppress(OSError):
            self.conn.send((job, ok))


def _cores():
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


def _drawn(name, args, kwargs):  # pragma: no cover - runs in a child of the drawer
    """A job's child: draw the figure, wait for its PDF's print, and exit 0 (both files
    written) or 1 (its drawing raised: the prints it began are killed)."""
    code = 1
    try:
        _draw_here(name, args, kwargs)
        _handoff.finish()  # a print that failed is made again here
        code = 0
    except BaseException:  # noqa: BLE001 - the command draws it again
        _handoff.abandon()
    finally:
        os._exit(code)
