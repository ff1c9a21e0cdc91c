"""A record's blocks shared out over forked processes, for the fitting loops that cannot
be split any other way.

An optimiser's evaluations follow one another: each point depends on the last.  But one
evaluation of a record compared over its span (:mod:`~discovery.vibroimpact.verify.trajectory`)
is a set of independent blocks, each simulated from the machine's measured state before
it, folded and compared on its own; only their mean joins them.  A :class:`BlockFarm`
forks ``workers - 1`` processes that hold the records (through the fork: nothing is
pickled but the law and the answers) and, for each evaluation, does block ``k`` in
participant ``k mod n`` (this process is participant 0), so a worker sees the same blocks
at every evaluation and its memo of runs answers the repeats.

The answers are the same bits as block by block in one process: each block is the same
function of the same values wherever it runs, and the mean is taken here, in block order.
::

    with shared_blocks(references, workers=4):
        identify(...)        # every evaluation and exact Jacobian on these records' spans

A farm answers only in the process that made it (a pool forked while it is open does
its jobs block by block), and only for the spans of the references it was made with
(and their cycle-by-cycle versions, :meth:`Reference.shortened`).  Items a worker cannot
answer (an answer that cannot be sent, a worker lost) are done here; a lost worker closes
the farm, and this process does every block from then on.
"""

import contextlib
import multiprocessing
import os
import pickle
from multiprocessing import get_context

from ...numerics import counts
from ...numerics._workers import die_with_parent

__all__ = ["BlockFarm", "shared_blocks", "farm_for", "block_workers"]

_OPEN = []  # the farms open in this process, innermost last


def farm_for(span):
    """The open farm that holds ``span`` in this process, or ``None``."""
    for farm in reversed(_OPEN):
        if farm.holds(span):
            return farm
    return None


def _serve(conn, references, parent):
    """A worker's loop: ``(fn, span index, items, args)`` -> ``[fn(reference, item, *args)
    for item in items]``; ``None`` ends it."""
    die_with_parent(parent)
    while True:
        try:
            msg = conn.recv()
        except EOFError:
            return
        if msg is None:
            return
        fn, i, items, shared = msg
        before = counts.snapshot()
        try:
            out = [fn(references[i], item, *pickle.loads(shared)) for item in items]
            conn.send((out, counts.since(before)))  # the work it counted goes with it
        except Exception:  # an answer that cannot be sent: the parent does these items
            conn.send(None)


class BlockFarm:
    """``workers`` participants (this process and ``workers - 1`` forked ones) sharing out
    the blocks of ``references``' spans; see the module docstring.

    Attributes
    ----------
    size : int
        Participants (at most the largest span's blocks).
    """

    def __init__(self, references, workers):
        refs, seen = [], set()
        for r in references:
            for x in (r, r.shortened() if getattr(r, "span", None) is not None else None):
                if x is not None and getattr(x, "span", None) is not None and id(x) not in seen:
                    seen.add(id(x))
                    refs.append(x)
        self._refs = refs
        self._index = {id(r.span): i for i, r in enumerate(refs)}
        most = max((len(r.span.blocks) for r in refs), default=1)
        self.size = max(1, min(int(workers), most))
        self._owner = os.getpid()
        self._conns, self._procs = [], []
        ctx = get_context("fork")
        try:
            for _ in range(self.size - 1):
                here, there = ctx.Pipe()
                p = ctx.Process(target=_serve, args=(there, refs, self._owner), daemon=True)
                p.start()
                there.close()
                self._conns.append(here)
                self._procs.append(p)
        except BaseException:
            self.close()
            raise

    def holds(self, span):
        """Whether this farm answers for ``span`` here (made in this process, with it)."""
        i = self._index.get(id(span))
        return (
            bool(self._procs)
            and os.getpid() == self._owner
            and i is not None
            and self._refs[i].span is span
        )

    def map(self, fn, span, args, items=None):
        """``[fn(reference, item, *args) for item in items]``, shared out: ``items`` are the
        span's block indices by default (a replicate's draws, say, otherwise); ``fn`` a
        module-level function that returns its exceptions rather than raising them.
        ``None`` when ``args`` cannot be sent (the caller does the work itself)."""
        i = self._index[id(span)]
        items = list(range(len(span.blocks)) if items is None else items)
        n = len(items)
        size = min(self.size, n)
        try:
            shared = pickle.dumps(args)
        except (pickle.PicklingError, AttributeError, TypeError):
            return None  # a model's closure (an observation model, say): done here
        out = [None] * n
        sent = set()
        try:
            for w in range(1, size):
                with contextlib.suppress(OSError):  # a worker gone: its items are done here
                    self._conns[w - 1].send((fn, i, items[w::size], shared))
                    sent.add(w)
            for k in range(0, n, size):
                out[k] = fn(self._refs[i], items[k], *args)
            lost = len(sent) < size - 1
            for w in range(1, size):
                got = None
                if w in sent:
                    try:
                        got = self._conns[w - 1].recv()
                    except (EOFError, OSError):  # the worker is gone
                        lost = True
                    if got is not None:
                        got, delta = got
                        counts.add(delta)
                if got is None:  # its items done here, as they would be without a farm
                    got = [fn(self._refs[i], items[k], *args) for k in range(w, n, size)]
                for k, o in zip(range(w, n, size), got, strict=True):
                    out[k] = o
        except BaseException:
            # interrupted: the workers' answers would be read as the next ones
            self.close()
            raise
        if lost:
            self.close()  # this process does every block from now on
        return out

    def close(self):
        """End the workers (they hold nothing to save)."""
        for c in self._conns:
            with contextlib.suppress(Exception):
                c.send(None)
                c.close()
        for p in self._procs:
            p.join(timeout=1.0)
            if p.is_alive():
                p.kill()
                p.join(timeout=5.0)
        self._conns, self._procs = [], []
        if self in _OPEN:
            _OPEN.remove(self)


def block_workers(workers, executor=None):
    """The processes of a block farm: an executor's local workers (one with a serial
    executor or a Dask cluster, whose workers are elsewhere), else ``workers`` (``None``:
    every core)."""
    if executor is not None:
        from ...numerics.executor import Pool

        return executor.workers if isinstance(executor, Pool) else 1
    return int(workers or os.cpu_count() or 1)


@contextlib.contextmanager
def shared_blocks(references, workers):
    """A :class:`BlockFarm` over ``references`` while the block runs (``None`` with one
    worker, or with no record compared over a span of several blocks).

    Inside, this process and the farm's workers use one BLAS thread, whatever the farm
    (:func:`~discovery.numerics.executor.one_blas_thread`): an idle BLAS thread spins on
    the core a worker needs, and one thread count gives the same arithmetic on any number
    of workers."""
    from ...numerics.executor import one_blas_thread

    with one_blas_thread():
        refs = [r for r in references if getattr(r, "span", None) is not None]
        # a daemonic process (a worker of another pool) may not have children
        alone = multiprocessing.current_process().daemon
        if alone or not refs or not workers or int(workers) <= 1:
            yield None
            return
        farm = BlockFarm(refs, workers)
        if farm.size <= 1:
            farm.close()
            yield None
            return
        _OPEN.append(farm)
        try:
            yield farm
        finally:
            farm.close()
