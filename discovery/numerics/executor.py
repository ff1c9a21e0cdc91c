"""One executor for every sweep: serial, a local process pool, or a Dask cluster.

A sweep (landscape rows, chart rows, explain's screening refits, study runs) is a list of
*jobs* and one read-only *context* shared by all of them, and a module-level function
``fn(context, job)`` that does one job.  :meth:`Executor.run` yields ``(index, result)`` as
jobs finish, in any order; the caller puts each result in its place, so the outcome does
not depend on the executor, the worker count or the order of completion::

    with make_executor(workers=2) as ex:           # or scheduler="local" / "tcp://..."
        for i, out in ex.run(fn, jobs, context):
            results[i] = out

* :class:`Serial`: in this process (``workers=1``).
* :class:`Pool`: forked local processes (the default).  The context reaches the workers
  through the fork, not by pickling; workers die with their parent and leave Ctrl-C to it
  (:mod:`discovery.numerics._workers`).
* :class:`Dask`: a ``distributed.Client`` (``scheduler="local"`` starts a ``LocalCluster``
  of single-threaded worker processes).  The context is scattered once to every worker;
  tasks are pure functions of their arguments (the seeds are in the jobs), so a task that
  runs twice (a worker lost mid-task) gives the same result; the scheduler reschedules the
  tasks of a lost worker.  A ``warm`` callable (the caller's: it compiles the kernels its
  jobs use) runs here and on one worker before the others, so that numba's cache is built
  once before any worker compiles (concurrent cache builds crash workers).

Jobs should each last well over 100 ms on a cluster (per-task overhead is ~1 ms locally and
more across machines): callers batch short work (a landscape row, not a point).
"""

from __future__ import annotations

import contextlib
import os
import sys
from concurrent.futures import FIRST_COMPLETED, ProcessPoolExecutor, wait
from multiprocessing import get_context

from .._api._validate import Real, Text, params
from ..errors import InputError
from . import counts
from ._workers import terminate_pool, worker_initializer

__all__ = ["Executor", "Serial", "Pool", "Dask", "make_executor", "map_on", "one_blas_thread"]

# A worker's job returns its result with the work it counted (:mod:`.counts`), so a run's
# counts do not depend on the executor.

_CONTEXT = {}  # the context of the sweep running in this (worker) process
_THREAD_VARS = ("OMP_NUM_THREADS", "MKL_NUM_THREADS", "OPENBLAS_NUM_THREADS")


def _set_context(context):
    _CONTEXT.clear()
    _CONTEXT["value"] = context


def one_blas_thread():
    """A job runs with one BLAS thread wherever it runs.  A BLAS with its default threads
    gains nothing on these small jobs: its idle threads spin, using a second core's CPU
    time for one core's wall time, and in parallel workers they take the other workers'
    cores.  One thread count everywhere also makes a job's arithmetic the same on every
    executor.

    The BLAS libraries loaded are found once per process and looked for again only after
    a module was imported (finding them took 1.6 ms, a tenth of a short refit)."""
    try:
        from threadpoolctl import ThreadpoolController
    except ImportError:  # pragma: no cover - a dependency
        return contextlib.nullcontext()
    loaded = (os.getpid(), len(sys.modules))
    if _BLAS.get("loaded") != loaded:
        _BLAS["controller"] = ThreadpoolController()
        _BLAS["loaded"] = loaded
    return _BLAS["controller"].limit(limits=1, user_api="blas")


_BLAS = {}  # this process's threadpool controller and the modules loaded when it was made


def _job(fn, context, job):
    with one_blas_thread():
        return fn(context, job)


def _counted(fn, context, job):
    """A worker's job: its result and the work it counted (:mod:`.counts`), which the
    parent adds to its own."""
    before = counts.snapshot()
    out = _job(fn, context, job)
    return out, counts.since(before)


def _call(fn, job):
    return _counted(fn, _CONTEXT.get("value"), job)


def _call_with(fn, context, job):
    return _counted(fn, context, job)


def _received(result):
    out, delta = result
    counts.add(delta)
    return out


class Executor:
    """Runs ``fn(context, job)`` for every job; see the module docstring."""

    name = "executor"
    workers = 1

    def run(self, fn, jobs, context=None):
        """Yield ``(index, fn(context, jobs[index]))`` as the jobs finish."""
        raise NotImplementedError

    def map(self, fn, jobs, context=None, done=None):
        """The results in the order of ``jobs`` (a list); ``done(k, n)`` after each of the
        ``n`` jobs finishes (progress)."""
        out = [None] * len(jobs)
        for k, (i, r) in enumerate(self.run(fn, jobs, context), start=1):
            out[i] = r
            if done is not None:
                done(k, len(jobs))
        return out

    def close(self):
        """Release the workers (a no-op for executors that own none)."""

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def __repr__(self):
        return f"{type(self).__name__}(workers={self.workers})"


class Serial(Executor):
    """Every job in this process, in order."""

    name = "serial"

    def run(self, fn, jobs, context=None):
        for i, job in enumerate(jobs):
            yield i, _job(fn, context, job)


class Pool(Executor):
    """Forked local worker processes (a new pool per sweep: the context is forked in)."""

    name = "process pool"

    def __init__(self, workers=None):
        self.workers = max(1, int(workers or os.cpu_count() or 1))

    def run(self, fn, jobs, context=None):
        jobs = list(jobs)
        n = min(self.workers, len(jobs))
        if n <= 1:
            yield from Serial().run(fn, jobs, context)
            return
        pool = ProcessPoolExecutor(
            n, mp_context=get_context("fork"), **worker_initializer(_set_context, (context,))
        )
        try:
            pending = {pool.submit(_call, fn, job): i for i, job in enumerate(jobs)}
            while pending:
                done, _ = wait(pending, return_when=FIRST_COMPLETED)
                for fut in done:
                    i = pending.pop(fut)
                    yield i, _received(fut.result())
        except BaseException:
            terminate_pool(pool)  # interrupted, failed or abandoned: no waiting for the queue
            raise
        pool.shutdown()


def _warm_worker(warm):
    """Run the warm-up callable ``warm`` (if any) in this process; returns its PID."""
    if warm is not None:
        warm()
    return os.getpid()


class Dask(Executor):
    """A ``distributed.Client``: ``address`` is a scheduler (``tcp://host:port``) or
    ``"local"`` for a ``LocalCluster`` of ``workers`` single-threaded processes; ``warm``
    (a callable without arguments, or None) compiles the kernels before any job: here and
    on one worker first, then on the rest, which only read numba's cache."""

    name = "dask"

    def __init__(self, address="local", workers=None, warm=None):
        try:
            from distributed import Client, LocalCluster
        except ImportError:
            raise InputError(
                "--scheduler needs Dask's distributed scheduler; install it with "
                "pip install 'vibroimpact-discovery[dask]'"
            ) from None
        self.address = str(address)
        self._cluster = None
        if self.address == "local":
            # compile (or load) the kernels here first: the workers then only read the cache
            _warm_worker(warm)
            n = max(1, int(workers or os.cpu_count() or 1))
            import dask

            # the workers get this process's BLAS/OpenMP thread settings, like the pool's
            # forked workers (Dask sets them to 1 by default; a BLAS initialised with
            # another thread count can sum in another order and move an optimiser's path)
            environ = {
                k: v
                for k, v in dask.config.get("distributed.nanny.pre-spawn-environ", {}).items()
                if k not in _THREAD_VARS
            }
            environ.update({k: os.environ[k] for k in _THREAD_VARS if k in os.environ})
            with (
                dask.config.set({"distributed.nanny.pre-spawn-environ": environ}),
                _sigint_blocked(),
            ):
                self._cluster = LocalCluster(
                    n_workers=n,
                    threads_per_worker=1,
                    processes=True,
                    dashboard_address=":0",  # no warning when another cluster holds 8787
                    silence_logs=50,
                )
            self.client = Client(self._cluster)
        else:
            try:
                self.client = Client(self.address, timeout="5s")
            except (OSError, TimeoutError, ValueError) as exc:
                raise InputError(
                    f"cannot reach the Dask scheduler at {self.address} ({exc}); "
                    "start one (dask scheduler) or use --scheduler local"
                ) from None
            workers = sorted(self.client.scheduler_info()["workers"])
            if workers:  # one worker builds the cache, then the others load it
                self.client.run(_warm_worker, warm, workers=workers[:1])
                self.client.run(_warm_worker, warm)
        self.workers = max(1, len(self.client.scheduler_info()["workers"]))

    def run(self, fn, jobs, context=None):
        from distributed import as_completed

        jobs = list(jobs)
        if not jobs:
            return
        ctx = self.client.scatter(context, broadcast=True, hash=False)
        futures = self.client.map(_call_with, [fn] * len(jobs), [ctx] * len(jobs), jobs, pure=False)
        index = {f.key: i for i, f in enumerate(futures)}
        try:
            for fut in as_completed(futures):
                yield index[fut.key], _received(fut.result())
        finally:
            self.client.cancel(futures)
            with contextlib.suppress(Exception):
                self.client.cancel([ctx])

    def close(self):
        with contextlib.suppress(Exception):
            self.client.close()
        if self._cluster is not None:
            with contextlib.suppress(Exception):
                self._cluster.close()

    def __repr__(self):
        return f"Dask({self.address!r}, workers={self.workers})"


def map_on(fn, jobs, context=None, *, workers=None, executor=None, done=None):
    """``executor.map(fn, jobs, context, done)``, or without an executor on one of
    ``workers`` local processes (``None``: one per CPU; never more than the jobs) made for
    this call and closed after it."""
    jobs = list(jobs)
    if executor is not None:
        return executor.map(fn, jobs, context, done)
    with make_executor(min(int(workers or os.cpu_count() or 1), max(len(jobs), 1))) as ex:
        return ex.map(fn, jobs, context, done)


@contextlib.contextmanager
def _sigint_blocked():
    """SIGINT ignored while a LocalCluster spawns its workers: they start with it ignored
    (a disposition that survives ``exec``), so a Ctrl-C at the terminal (sent to the whole
    process group) reaches this process only, which stops the study and closes the
    cluster, instead of printing every worker's traceback.  This process's own handler is
    back once the cluster has started."""
    import signal
    import threading

    if threading.current_thread() is not threading.main_thread():
        yield
        return
    try:
        old = signal.signal(signal.SIGINT, signal.SIG_IGN)
    except (ValueError, OSError):
        yield
        return
    try:
        yield
    finally:
        signal.signal(signal.SIGINT, old)


@params(workers=(None, Real(1, 4096, integer=True)), scheduler=(None, Text()))
def make_executor(workers=None, scheduler=None, *, warm=None):
    """The executor for ``workers`` local processes (``None``: one per CPU; 1: serial), or
    a Dask cluster when ``scheduler`` is given (``"local"`` or a scheduler address), whose
    workers first run ``warm`` (see :class:`Dask`; :func:`discovery.make_executor` passes
    the package's :func:`discovery.warm.warm`)."""
    if scheduler:
        return Dask(scheduler, workers, warm)
    n = max(1, int(workers or os.cpu_count() or 1))
    return Serial() if n == 1 else Pool(n)
