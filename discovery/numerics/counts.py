"""Counts of the work a run does: units that stay put when the machine or the kernel changes.

Seconds depend on the machine and its load; how many laws a command judged against a
record, how many criteria it computed and how many steady states it searched do not.  Each
count is a number in this process's :data:`COUNTS`, raised where the work is done
(:func:`count`); a sweep's worker processes send theirs back with each job's result
(:mod:`~discovery.numerics.executor`), so a run's counts are the same on any executor.

* ``evaluations``: a law judged against a record (one full simulation of the law over the
  record and its criteria, :func:`~discovery.vibroimpact.verify.evaluation.evaluate`),
  counted when asked for (a repeat answered from the cache counts too);
* ``criteria``: criterion sets computed, every criterion of a comparison
  (:func:`~discovery.vibroimpact.verify.criteria.evaluate_criteria`);
* ``objectives``: comparisons of which only some criteria were computed (an optimiser's
  objective, the other criteria of its evaluations only at its end; a transient's I2);
* ``steady_states``: periodic steady states searched
  (:func:`~discovery.vibroimpact.dynamics.steady_states.steady_state`);
* ``period_maps``: drive periods the steady-state searches integrated (Newton's and the
  transient's).

The last two are work done, so a result a worker's cache answered is not counted: they can
differ with the worker count.  A command line run records the counts of its command in
``summary.json`` (``counts``); :func:`counting` gives those of a block of code.
"""

import contextlib
from collections import Counter

__all__ = ["COUNTS", "NAMES", "count", "snapshot", "since", "add", "reset", "counting"]

#: what each count is
NAMES = {
    "evaluations": "laws judged against a record (asked for)",
    "criteria": "criterion sets computed",
    "objectives": "comparisons of an optimiser's criterion alone",
    "steady_states": "steady states searched",
    "period_maps": "drive periods integrated by the steady-state searches",
}

#: this process's counts
COUNTS = Counter()


def count(name, n=1):
    """Add ``n`` to the count ``name`` (one of :data:`NAMES`)."""
    COUNTS[name] += int(n)


def snapshot():
    """The counts now, as a plain dict (every name, zeros included)."""
    return {k: int(COUNTS.get(k, 0)) for k in NAMES}


def since(before):
    """The counts added since ``before`` (a :func:`snapshot`)."""
    return {k: int(COUNTS.get(k, 0)) - int(before.get(k, 0)) for k in NAMES}


def add(delta):
    """Add a worker's counts ``delta`` (a :func:`since`) to this process's."""
    for k, v in (delta or {}).items():
        if k in NAMES and v:
            COUNTS[k] += int(v)


def reset():
    """Set every count to zero (a command line run starts from zero)."""
    COUNTS.clear()


@contextlib.contextmanager
def counting():
    """``with counting() as c:`` -- ``c`` holds the counts of the block once it ends."""
    before = snapshot()
    out = {}
    try:
        yield out
    finally:
        out.update(since(before))
