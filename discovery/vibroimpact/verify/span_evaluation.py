"""A law evaluated on a record span block by block: each block's run from its measured
state, its history, folded and compared (:func:`block_outcome`), for every block at once
(:func:`span_run`), on the block farm that holds the span when one is open
(:mod:`~discovery.vibroimpact.verify.block_farm`), else here in block order.
"""

from dataclasses import dataclass

import numpy as np

from ..._api._validate import unchecked
from .block_farm import farm_for
from .criteria import evaluate_criteria
from .motion import MOTION_CRITERION, fold_penetration, penetration_mean
from .trajectory import _block_mean, _history, _memo_run

__all__ = [
    "BlockJob",
    "BlockOutcome",
    "block_outcome",
    "SpanRun",
    "span_run",
    "force_criteria",
    "wants_motion",
]


@dataclass(frozen=True)
class BlockOutcome:
    """One block of an evaluation (:func:`block_outcome`): what was computed, and the first
    exception where a stage failed.

    Attributes
    ----------
    run : tuple or None
        ``(F, onsets, Z)``: the run's force, contact onsets and penetration.
    history : ndarray or None
        The force as compared (:func:`_history`).
    impulse : Impulse or None
        The folded history.
    criteria : dict or None
        The criteria against the measured folded block.
    penetration : float or None
        The block's I5 (:func:`~.motion.fold_penetration`), for a span with positions.
    error : Exception or None
    stage : int
        Where ``error`` came from: 0 none, 1 the run or its history, 2 the fold, 3 the
        criteria, 4 the penetration's.
    """

    run: tuple | None = None
    history: np.ndarray | None = None
    impulse: object = None
    criteria: dict | None = None
    penetration: float | None = None
    error: Exception | None = None
    stage: int = 0


@dataclass(frozen=True)
class BlockJob:
    """What every block of one evaluation is asked (:func:`block_outcome`): the machine,
    the law, the integrator's settings, the observation model, the onset window
    (:func:`simulated_history`), the record's onset time and the criteria computed (None:
    every one)."""

    scenario: object
    law: object
    tolerances: object = None
    observe: object = None
    window: bool = False
    onset: float | None = None
    criteria: tuple | None = None


def force_criteria(names):
    """The criteria of the force histories among ``names`` (None: every one)."""
    return None if names is None else tuple(n for n in names if n != MOTION_CRITERION)


def wants_motion(names):
    """Whether the penetration's criterion is among ``names`` (None: every one)."""
    return names is None or MOTION_CRITERION in names


def block_outcome(reference, k, job):
    """Block ``k`` of ``reference``'s span evaluated for ``job`` (a :class:`BlockJob`): the
    law's run from the block's measured state, its history, folded, its criteria and, for a
    span with positions, its I5 (a function of its arguments: the same here or in a worker
    of a :mod:`~discovery.vibroimpact.verify.block_farm`)."""
    span = reference.span
    blk = span.blocks[k]
    try:
        _, F, onsets, Z = _memo_run(job.scenario, job.law, blk, job.tolerances)
        H = _history(blk, F, onsets, job.observe, job.window)
    except Exception as exc:  # raised by the caller, in block order
        return BlockOutcome(error=exc, stage=1)
    run = (F, onsets, Z)
    try:
        imp = blk.fold.impulse(
            H, threshold=blk.threshold, noise=span.sigma_f, onset_record_time=job.onset
        )
    except Exception as exc:
        return BlockOutcome(run, H, error=exc, stage=2)
    try:
        crit = unchecked(evaluate_criteria)(reference.blocks[k], imp, force_criteria(job.criteria))
    except Exception as exc:
        return BlockOutcome(run, H, imp, error=exc, stage=3)
    if not span.sigma_z > 0 or not wants_motion(job.criteria):
        return BlockOutcome(run, H, imp, crit)
    try:
        pen = fold_penetration(blk.fold, reference.blocks[k], imp, blk.Z, Z)
    except Exception as exc:
        return BlockOutcome(run, H, imp, crit, error=exc, stage=4)
    return BlockOutcome(run, H, imp, crit, pen)


@dataclass(frozen=True)
class SpanRun:
    """Every block of a span evaluated (:func:`span_run`), in block order.  Each stage's
    first failure in block order is raised where the stage's results are asked for, as a
    block-by-block evaluation would raise it."""

    outcomes: tuple

    def _raise(self, stage):
        for o in self.outcomes:
            if o.stage == stage:
                raise o.error

    @property
    def histories(self):
        return [o.history for o in self.outcomes]

    @property
    def penetrations(self):
        return [o.run[2] for o in self.outcomes]

    def impulses(self):
        """Each block's folded history."""
        self._raise(2)
        return [o.impulse for o in self.outcomes]

    def criteria(self, span):
        """``(mean, per_block)`` as :func:`block_criteria`."""
        self._raise(2)
        self._raise(3)
        per = [o.criteria for o in self.outcomes]
        return _block_mean(per, span), per

    def penetration(self, span):
        """``(mean, per_block)`` of I5 as :func:`~.motion.block_penetration`."""
        self._raise(4)
        per = [o.penetration for o in self.outcomes]
        return penetration_mean(span, per), per


def span_run(job, reference):
    """Every block of ``reference``'s span evaluated for ``job`` (a :class:`BlockJob`,
    :func:`block_outcome`): shared out over the block farm that holds the span
    (:func:`~.block_farm.shared_blocks`), else here in block order.  Raises the first
    block's run failure (as :func:`simulated_motion`); the runs a farm made are kept in
    :data:`~.trajectory.MEMO` as if made here."""
    span = reference.span
    scenario, law, tolerances = job.scenario, job.law, job.tolerances
    farm = farm_for(span)
    outcomes = None if farm is None else farm.map(block_outcome, span, (job,))
    if outcomes is not None:
        for blk, o in zip(span.blocks, outcomes, strict=True):
            if o.run is not None:
                for a in o.run:
                    a.setflags(write=False)
                _memo_run(scenario, law, blk, tolerances, made=o.run)
    else:
        outcomes = []
        for k in range(len(span.blocks)):
            outcomes.append(block_outcome(reference, k, job))
            if outcomes[-1].stage == 1:
                break
    out = SpanRun(tuple(outcomes))
    out._raise(1)
    return out
