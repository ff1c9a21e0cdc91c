"""The noise floor of a record span: what the law would score against its own record if it
were the truth, every replicate through the span's own processing (drawn block states, the
record's force noise at its sample times, the same folds and criteria).

A replicate's block whose folded force shows no contact (a short contact averaged over the
few cycles of a transient block, or hidden by the noise) has no criteria, since they are
relative to the replicate's own force.  The floor is the mean over the replicates whose
every block shows a contact; where no replicate does (survey draw 35: the 2-cycle first
block of every replicate), over the blocks that show one in each replicate.  The record's
own blocks all show a contact, so a block that none of the law's replicates shows is the
law's misfit, and the law's criteria carry it (its simulated block against the recorded
one).  Replicates that lost a block are not mixed with complete ones: they are the draws
whose trajectory left the record's (survey draw 9, stiffening supports: counted in, they
raised the true law's I2 floor from a few hundredths to 0.85).
"""

from dataclasses import dataclass

import numpy as np

from ..._api._validate import unchecked
from ...errors import InputError, IntegrationError, NoContactError
from .block_farm import farm_for
from .criteria import CRITERIA, evaluate_criteria
from .motion import MOTION_CRITERION, fold_penetration
from .trajectory import simulated_motion

__all__ = ["span_floor"]


@dataclass(frozen=True)
class _FloorJob:
    """What every replicate of one noise floor is asked (:func:`_floor_replicate`): the
    machine and law, the noise-free folded blocks, the runs from the measured states
    (``(histories, penetrations)``, or ``None`` when they failed), the integrator's
    settings, the observation model and the criteria's names."""

    scenario: object
    law: object
    simulated: list
    measured: tuple | None
    tolerances: object
    observe: object
    names: list


def _with_contact(span, reps, simulated):
    """``(blocks, criteria)`` of the blocks whose replicate ``reps`` shows a contact:
    their indices and each one's force criteria against ``simulated``."""
    criteria = unchecked(evaluate_criteria)
    kept, per = [], []
    for i, (m, s) in enumerate(zip(reps, simulated, strict=True)):
        try:
            per.append(criteria(m, s, None))
        except NoContactError:
            continue
        kept.append(i)
    return kept, per


def _weighted(span, kept, values):
    """The mean of ``values`` (one per kept block) weighted by those blocks' cycles."""
    w = np.array([span.blocks[i].fold.n_cycles for i in kept], dtype=float)
    return float(np.dot(w / w.sum(), values))


def _floor_replicate(span, draw, job):
    """One replicate of :func:`span_floor` from its ``draw`` (start states, force and
    penetration noise): ``(criteria, contacts in its last block, complete)`` over the
    blocks that show a contact (``complete``: every block does), or ``None`` when its
    record cannot be folded or no block shows one."""
    starts, noise, noise_z = draw
    measured = job.measured
    sc, law, tol, observe = job.scenario, job.law, job.tolerances, job.observe
    try:
        # the truth as a record holds it: point samples
        hist, zs = simulated_motion(sc, law, span, tolerances=tol, starts=starts, observe=observe)
    except IntegrationError:  # a failed draw: the measured states' histories instead
        if measured is None:
            measured = simulated_motion(sc, law, span, tolerances=tol, observe=observe)
        hist, zs = measured
    try:
        reps = span.impulses([h + e for h, e in zip(hist, noise, strict=True)])
    except InputError:
        return None
    kept, per = _with_contact(span, reps, job.simulated)
    if not kept:
        return None
    crit = {k: _weighted(span, kept, [p[k] for p in per]) for k in per[0]}
    if MOTION_CRITERION in job.names:
        # the noise-free penetrations from the measured states
        z_sim = (
            measured[1]
            if measured is not None
            else simulated_motion(sc, law, span, tolerances=tol)[1]
        )
        i5 = [
            fold_penetration(
                span.blocks[i].fold, reps[i], job.simulated[i], zs[i] + noise_z[i], z_sim[i]
            )
            for i in kept
        ]
        crit[MOTION_CRITERION] = _weighted(span, kept, i5)
    return crit, int(len(reps[-1].support)), len(kept) == len(reps)


def _floor_job(reference, draw, job):
    """:func:`_floor_replicate` on a block farm (the exception it raised, returned)."""
    try:
        return _floor_replicate(reference.span, draw, job)
    except Exception as exc:
        return exc


def span_floor(scenario, law, span, simulated, *, n_boot=16, seed=0, tolerances=None, observe=None):
    """Noise floor of every criterion if ``law`` were the truth, through the span's own
    processing.

    Each replicate starts every block from a state drawn from that block's state-fit
    covariance, adds the record's force noise at the record's sample times, folds, and is
    compared block by block with ``simulated`` (the folded noise-free histories from the
    measured states).

    Returns
    -------
    dict
        ``{"mean": {I0..I5}, "q95": {I0..I5}, "sd": {I0..I5}, "n_boot": n, "seed": seed,
        "impacts": [contacts per cycle of each replicate's last block]}``.
    """
    rng = np.random.default_rng(seed)
    # the penetration noise from its own stream: the force criteria's floor is unchanged
    rng_z = np.random.default_rng((seed, 5))
    names = list(CRITERIA) + ([MOTION_CRITERION] if span.sigma_z > 0 else [])
    draws = []  # every replicate's draws first: the same streams, whoever runs them
    # each block's state as a run on this machine starts from it (re-estimated from the
    # flight when the machine differs from the record's: stiffening supports, a scale);
    # drawn from the record's own, a block on stiff supports started from another state
    # (survey draw 9: the true law's I2 floor 0.85, its replicates' contacts elsewhere)
    states = [b.state_for(scenario) for b in span.blocks]
    for _ in range(n_boot):
        starts = [st.draw(rng) for st in states]
        noise = [rng.normal(0.0, span.sigma_f, b.F.size) for b in span.blocks]
        noise_z = [rng_z.normal(0.0, span.sigma_z, b.F.size) for b in span.blocks]
        draws.append((starts, noise, noise_z))
    try:
        # the noise-free runs from the measured states (memoised): a failed draw's stand-in
        # and the penetrations the replicates' are compared with
        measured = simulated_motion(scenario, law, span, tolerances=tolerances, observe=observe)
    except IntegrationError:
        measured = None  # a replicate that needs them runs them, and raises
    job = _FloorJob(scenario, law, simulated, measured, tolerances, observe, names)
    farm = farm_for(span)
    replicates = None if farm is None else farm.map(_floor_job, span, (job,), items=draws)
    if replicates is None:
        replicates = [_floor_replicate(span, d, job) for d in draws]
    for r in replicates:
        if isinstance(r, Exception):
            raise r
    usable = [r for r in replicates if r is not None]  # None: the replicate could not be folded
    samples = {n: [] for n in names}
    impacts = []  # contacts per cycle each replicate shows (noise can split a contact)
    for crit, contacts, _ in [r for r in usable if r[2]] or usable:
        for n, v in crit.items():
            samples[n].append(v)
        impacts.append(contacts)
    if not samples["I2"]:
        inf = {n: float("inf") for n in names}
        return {
            "mean": inf,
            "q95": dict(inf),
            "sd": dict(inf),
            "n_boot": 0,
            "seed": seed,
            "impacts": [],
        }
    return {
        "impacts": impacts,
        "mean": {n: float(np.mean(v)) for n, v in samples.items()},
        "q95": {n: float(np.quantile(v, 0.95)) for n, v in samples.items()},
        "sd": {n: float(np.std(v, ddof=1)) if len(v) > 1 else 0.0 for n, v in samples.items()},
        "n_boot": len(samples["I2"]),
        "seed": seed,
    }
