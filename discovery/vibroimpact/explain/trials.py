"""Trials: every significant effect refitted with the model (in parallel), the law refitted
alone as the baseline, and the trials judged; the winner polished with the full budget.
"""

import math
from dataclasses import dataclass, replace

import numpy as np

from ...errors import InputError, IntegrationError
from ...numerics.executor import map_on
from ..fit.rescan import lower_basin, springs_scaled
from ..model.law import Term
from ..verify import CONSISTENCY_FACTORS
from ..verify.motion import MOTION_CRITERION
from .effects import effect
from .judging import (
    SUPPORTS_CRITERION,
    _force_worse,
    _keeps_repulsive,
    _keeps_signs,
    _motion_worse,
    _present,
    negligible,
    out_of_bounds,
    physical,
)
from .problem import OnRecords, _mean, _small_step, _with_drift, best_of
from .starts import LawOnly, _output_error, _regressed


def _extend(model, eff, value):
    return model.with_effect(eff, value)


#: the effect's value on the regressed law: its small step times these
_LADDER = tuple(2.0**k for k in range(13))


#: the spring factors scanned around a start whose machine effect is read, not fitted (the
#: supports' ``k3`` from the frame's equation): the regression's spring is biased low by the
#: penetration's noise by a few percent, and a short contact's basin can be narrower
_SPRING_SCAN = tuple(1.0 + 0.01 * k for k in range(-6, 9) if k)


def _same_contacts(ev):
    """Whether an evaluation's contact times agree with its record's (I4 within its
    consistency limit)."""
    i4, lim = (ev.criteria or {}).get("I4"), (ev.limits or {}).get("I4")
    return i4 is not None and lim is not None and i4 <= lim


def _side(guess, lo):
    """-1 where the parameter may be negative (``lo < 0``, an offset) and its LM direction
    ``guess`` points there, else 1."""
    return -1.0 if lo < 0 and guess is not None and guess < 0 else 1.0


def _usable(guess, lo):
    """Whether an LM direction is a start: finite, non-zero and above the lower bound."""
    return guess is not None and np.isfinite(guess) and guess != 0 and guess > lo


def _within(value, share, lo, hi):
    """``value`` clipped to ``share`` of the way to each bound."""
    return min(max(value, share * lo), share * hi)


@dataclass(frozen=True)
class _Refits(OnRecords):
    """How a screening refit runs (the executor's context: the records stay in the forked
    processes): the residual problem, the records, the criterion, the simulations of each
    refit, the integrator's tolerances, the regression of the force on a term list
    (``None`` without positions), the records' drift channel (``None`` without one) and the
    criterion a drift effect's refit must lower (:func:`_law_with_the_drift`)."""

    problem: object
    records: list
    criterion: str
    budget: int
    tolerances: object
    regress: object = None
    drift: object = None
    gap: str | None = None

    def fitted(self, start, budget=None):
        """``start`` refitted by output error on the records (:func:`~.starts._output_error`
        with this screening's criterion, budget and tolerances).  Not gated at the noise
        floor (``floor``): the floor at hand is the model's before the refit, which on a
        record the model misses can be near 1 (draw 39's noisier record in the effects survey
        with a 5 %-off sheet: 0.97 for the start's I2 1.16), and every refit below it would
        lose its restarts (there a sensor lag the record does not hold was named so)."""
        budget = self.budget if budget is None else budget
        return _output_error(self.records, start, self.criterion, budget, self.tolerances)

    def refit(self, model, eff, guess):
        """Add ``eff`` and refit the extended model by output error: the law's coefficients
        and every added effect's parameter jointly (:func:`discovery.identify` on the
        :class:`Model`); returns ``(model, identification)``.

        The start is the best (by the sum of squared residuals of force and penetration,
        what the refit minimises: one simulation each) of the current law with the effect
        at its LM direction ``guess`` (a small value when that is unusable) and the law from
        the certified regression (:func:`_regressed`) with the effect: for a term effect
        the regression on the extended term set; for any other, the regression on the
        current terms (on the loading samples alone for an effect on the unloading branch)
        with the effect's value from a ladder (its small step times 1, 2, ... 4096, within
        its bounds; :meth:`_candidates`).  The best by the criterion is refitted too.  A
        parameter of either sign (an offset) starts on the side of its LM direction (from
        the positive side a refit toward a negative offset stopped short of zero on a noisy
        record, survey draw 26), its ladder climbs both sides, and each ladder's best start
        is refitted as well.  Stiffening supports also start from the ``k3`` the frame's
        equation reads, with the law's spring scanned around the regression's, ranked
        apart, their best refitted too.  The lowest refit is kept."""
        problem = self.problem
        lo, hi = eff.parameters[0].bounds
        h, families, own = self._candidates(model, eff, guess)
        cands = [m for family in families for m in family]
        # the families refitted on their own but not ranked with the rest (a read start)
        pool = cands + [m for f in own for m in f if all(m is not c for c in cands)]
        squares = [problem.squares(m) for m in pool] if len(pool) > 1 else [0.0]
        order = sorted(range(len(pool)), key=lambda i: (squares[i], i))
        ranked = [pool[i] for i in order if i < len(cands)]
        # the best start by the criterion that names the effect too, when it is another:
        # the squares and the criterion can prefer different basins (a set's ladder: the
        # squares' best start stopped at set 0.19, I2 0.127, the criterion's reached the
        # true 0.30, I2 0.0075)
        by_gap = self._by_gap(cands)
        first = [ranked[0]] + ([by_gap] if by_gap is not None and by_gap is not ranked[0] else [])
        for family in own:
            best_of_family = next(pool[i] for i in order if any(pool[i] is x for x in family))
            if all(best_of_family is not m for m in first):
                first.append(best_of_family)
        best = None
        for start in first:
            try:
                res = self.fitted(start)
            except IntegrationError:
                continue
            if best is None or res.value < best.value:
                best = res
        if best is not None:
            best = self.rescanned(best)
            return best.law, best
        starts = ranked[1:2] + [_extend(model, eff, _within(h, 0.5, lo, hi))]
        for i, start in enumerate(starts):
            try:
                res = self.fitted(start)
                return res.law, res
            except IntegrationError:
                if i == len(starts) - 1:
                    raise

    def rescanned(self, res):
        """A refit ``res`` not consistent with every record, its contact times off (I4
        above its limit in a record: another contact sequence's basin), refitted again from
        its law's springs scanned (:data:`_SPRING_SCAN`) where one of them has a sum of
        squares :data:`~discovery.vibroimpact.fit.rescan.RESCAN_DROP` below its end
        (:func:`~discovery.vibroimpact.fit.rescan.lower_basin`); the lower of the two refits by the
        criterion.  Over a record's transient the contact sequence changes with the
        spring, so the sum of squares has basins a few percent wide: on survey draw 27's
        noisier record (a lag) the lag's refit stopped at I2 0.050, its spring 6 % soft,
        where the true model is at 0.025; its spring 7 % stiffer had a sum of squares 32 %
        lower."""
        problem = self.problem
        evs = problem.evaluations(res.law, floor=True)
        if all(e.consistent for e in evs) or all(_same_contacts(e) for e in evs):
            return res
        lower = lower_basin(res.law, _SPRING_SCAN, problem.squares)
        if lower is None:
            return res
        try:
            again = self.fitted(lower[1])
        except IntegrationError:
            return res
        return again if again.value < res.value else res

    def _candidates(self, model, eff, guess):
        """``(h, families, own)``: the effect's small step, signed to its LM direction's
        side, the refit's start candidates by family (see :meth:`refit`): the current law
        with the effect at its LM step first, then the regression's (on the extended terms,
        or with the effect's value on its ladder), for an offset the ladder of laws
        regressed beyond each rung, for stiffening supports the value the frame's own
        equation reads (:meth:`Regressions.supports`), for an offset the one the force's
        onsets read (:meth:`Regressions.offset`, with the law regressed beyond it); and the
        families whose best start is refitted too (``own``).

        A two-sided parameter (an offset) refits each ladder's best start: from the law
        regressed beyond its rung, an offset of -46 um went to a basin at I2 0.32; from the
        plain regression's, to the truth (survey draw 26).  The supports' reading is
        refitted too: on survey draw 33's quieter record (a 0.3 ms contact) the true law's
        basin is a few percent wide in the spring, and no refit from the ladder's rungs
        reached it (I2 1.22-1.41, the truth 0.11), while the frame's equation reads ``k3``
        to 0.1 %.  So is the offset's reading: on draw 26's noisier record every ladder's
        start went to the basin at I2 0.32 again (the offset -66 um), and the onsets read
        -46.4 um."""
        regress = self.regress
        lo, hi = eff.parameters[0].bounds
        # a two-sided parameter (an offset) starts on the side its LM direction points to,
        # and its ladder climbs both sides (far from the truth the direction can point
        # away from it: corpus c11, offset +1.5 mm, direction -0.13 mm)
        step = _small_step(eff, self.records)
        h = step * _side(guess, lo)
        sides = (1.0, -1.0) if lo < 0 else (1.0,)
        families = [[_extend(model, eff, _within(guess if _usable(guess, lo) else h, 0.5, lo, hi))]]
        if eff.target == "term":
            names = list(model.law.names) + [Term.parse(eff.key).name]
            reg = _regressed(model.with_effect(eff, 0.0), names, regress)
            families.append([reg] if reg is not None else [])
            return h, [f for f in families if f], []
        # an effect on the unloading branch leaves the loading samples as they are
        reg = _regressed(
            model, model.law.names, regress, loading=eff.target in ("unloading", "set")
        )
        values = sorted({_within(sd * step * f, 0.9, lo, hi) for sd in sides for f in _LADDER})
        families.append([_extend(reg, eff, v) for v in values] if reg is not None else [])
        if eff.key == "offset":
            # the force starts at the offset: also the law regressed beyond each rung
            # (where no sample's penetration stands above its noise, the only ladder)
            beyond = [(_regressed(model, model.law.names, regress, shift=v), v) for v in values]
            families.append([_extend(b, eff, v) for b, v in beyond if b is not None])
        if eff.key == "sensor_lag":
            # the force is read through the lag: also the law regressed on the force the
            # lag's inverse gives at each rung
            before = [(_regressed(model, model.law.names, regress, lag=v), v) for v in values]
            families.append([_extend(b, eff, v) for b, v in before if b is not None])
        families = [f for f in families if f]
        own = families[1:] if lo < 0 else []
        read = regress.supports() if eff.key == "k3" and regress is not None else None
        if read is not None and lo <= read <= hi:
            family = [_extend(m, eff, read) for m in (model, reg) if m is not None]
            base = family[-1]
            own.append(family + [springs_scaled(base, f) for f in _SPRING_SCAN])
        read = regress.offset() if eff.key == "offset" and regress is not None else None
        if read is not None and lo <= read <= hi:
            beyond = _regressed(model, model.law.names, regress, shift=read)
            own.append([_extend(m, eff, read) for m in (beyond, model) if m is not None])
        return h, families, own

    def _by_gap(self, cands):
        """The candidate start with the lowest gap criterion (one evaluation each, its
        block runs shared with the ranking's), or None."""
        return best_of(self.problem, cands, self.criterion)[0]


def _screen_one(refits, job):
    """One screening refit (:meth:`_Refits.refit`, a task of the executor), or with no
    effect (``eff_id`` None) the law refitted alone from ``model``, or a drift effect's
    parameter fitted to the drift channel and the law refitted with it
    (:func:`_law_with_the_drift`; with the others, it had run in the calling process after
    them, 1.4 s of the bench record's 11 s on two workers): ``(model, identification,
    evaluations, error, simulations)``."""
    problem = refits.problem
    model, eff_id, direction = job
    eff = None if eff_id is None else effect(eff_id)
    n0 = problem.n_sim
    try:
        if eff is None:
            res = refits.rescanned(refits.fitted(model))
            m2 = res.law
        elif "drift" in eff.phases:
            m2 = refits.drift.refit(model, eff, _small_step(eff, refits.records))
            m2, res = _law_with_the_drift(refits, m2, refits.budget, refits.gap)
        else:
            m2, res = refits.refit(model, eff, direction)
        evs = problem.evaluations(m2, floor=True)
    except (IntegrationError, InputError) as exc:
        return None, None, None, str(exc), problem.n_sim - n0
    return m2, res, evs, None, problem.n_sim - n0


def _screen(jobs, refits, workers, executor=None):
    """The screening refits ``[(model, identification, evaluations, error)]`` in the order of
    ``jobs``, on ``executor`` (default: ``workers`` forked processes, so the records are not
    copied; in this process for one worker).  The simulations of every refit are added to the
    problem's count whichever process ran it."""
    problem = refits.problem
    n0 = problem.n_sim
    out = map_on(_screen_one, jobs, refits, workers=workers, executor=executor)
    problem.n_sim = n0 + sum(r[4] for r in out)
    return [r[:4] for r in out]


@dataclass(frozen=True)
class _Trial:
    """A candidate effect refitted: its gap ratio (after / before), its score entry, the
    refitted model, the fit (``None`` for the drift channel), the evaluations of the refitted
    model and the criterion its gap is measured by."""

    ratio: float
    score: dict
    model: object
    result: object
    evaluations: list
    key: str

    def judge(self, eff, null_after, floor, null_consistent=None):
        """Record in the score entry whether the refit beats the law refitted alone
        (``null_after``) by the criterion's margin (its floor times its consistency factor
        less one: the floor for the force, a quarter of it for the penetration,
        :data:`~discovery.vibroimpact.verify.CONSISTENCY_FACTORS`), or, within that margin,
        is lower and consistent with every record where the law refitted alone is not
        (``null_consistent`` False): within the floor the criterion cannot tell the two
        apart, the whole verdict can.  On survey draw 28's noisier record (a slow transient,
        the moulding shedding 0.29 % a contact) the mass loss's refit reached the truth, I2
        0.054 -> 0.026 and consistent, while the law alone stopped at 0.050 with its
        penetration off (I5 0.025 > 0.020): 0.024 short of the floor 0.026, nothing had
        been named.  The refit must reach the noise floor too (within :data:`NEAR_FLOOR` of
        it), as a model that explains the record does: on draw 38's quieter record (a mass
        loss, the machine calibrated from a sheet) a Hertz term of 1.6 % of the force took a
        refit from I2 0.049 to 0.040, just under its limit (0.044) and twice the floor
        (0.017), where the true model reaches 0.016; it stood in for what the calibrated
        machine misses.  Also recorded: whether the effect's parameter ``eff`` is present
        (not within 2 standard errors of 0)."""
        k, s = self.key, self.score
        margin = floor.get(k, 0.0) * (CONSISTENCY_FACTORS.get(k, 2.0) - 1.0)
        after = s["criteria_after"][k]
        # (the drift channel does not depend on the law: a law refit is no baseline)
        s["beats_law_refit"] = bool(
            k == "D" or not null_after or k not in null_after or after <= null_after[k] - margin
        )
        if (
            not s["beats_law_refit"]
            and null_consistent is False
            and s.get("consistent_after")
            and after < null_after[k]
            and (k == SUPPORTS_CRITERION or after <= NEAR_FLOOR * floor.get(k, 0.0))
        ):
            s["beats_law_refit"] = True
            s["law_alone_inconsistent"] = null_after[k]
        # an effect refitted to 0, or to a value within 2 standard errors of 0, only
        # carried a refit of the law
        s["present"] = (
            _present(eff, self.model, self.result, s.get("negligible", 0.0))
            if self.result is not None and k != "D"
            else bool(self.model.value(eff) != 0.0)
        )

    @property
    def names(self):
        """Whether the trial names its effect (once judged): the gap shrinks by 10 %, the
        refit is physical and within bounds, beats the law refitted alone, the parameter is
        present, and the recorded motion is not made worse."""
        s = self.score
        return bool(
            self.ratio <= 0.9
            and (self.key != SUPPORTS_CRITERION or s.get("consistent_after"))
            and s["repulsive"]
            and s["in_bounds"]
            and s["beats_law_refit"]
            and s["present"]
            and not s.get("motion_worse")
            and not s.get("force_worse")
        )


def _law_refit(run, model, budget, *, polish=False):
    """``(result, criteria, evaluations)`` of the model refitted alone (no effect added) on
    ``run``'s records, or None when the refit fails (e.g. a parameter at 0) or is not
    physical (an effect named before pushed past its bound, the contact spring pulling)."""
    try:
        res = _output_error(
            run.records, model, run.criterion, budget, run.tolerances, polish=polish
        )
        if not physical(res.law, model, run.records):
            return None
        evs = run.problem.evaluations(res.law, floor=True)
        after, _ = _with_drift(_mean(evs, "criteria"), {}, run.drift, res.law)
    except (IntegrationError, InputError):
        return None
    return res, after, evs


def _refits_and_baseline(run, chosen, screen_budget, refit_law, gap):
    """The screening refits of the ``chosen`` score entries (:func:`_screen`) and, with
    ``refit_law``, the law refitted alone in the same batch (the last job): ``(refits,
    baseline)``, ``baseline`` as :func:`_refit_trials` returns it."""
    model, records = run.model, run.records
    jobs = [(model, s["effect"], s.get("direction")) for s in chosen]
    law_start = _law_start(run) if refit_law else None
    if law_start is not None:
        jobs.append((law_start, None, None))
    out = _screen(
        jobs,
        _Refits(
            problem=run.problem,
            records=records,
            criterion=run.criterion,
            budget=screen_budget,
            tolerances=run.tolerances,
            regress=run.regress,
            drift=run.drift,
            gap=gap,
        ),
        run.workers,
        run.executor,
    )
    baseline = (None, None, None)
    if law_start is not None:
        law, res, evs, error = out.pop()
        if error is None and physical(law, model, records):
            after, _ = _with_drift(_mean(evs, "criteria"), {}, run.drift, law)
            baseline = (res, after, evs)
    return out, baseline


def _refit_trials(run, step, screen_budget, gap, chosen=None):
    """Every chosen effect (the screening's ranked ones, at most ``run.max_refits``) refitted
    with ``screen_budget`` simulations and checked (physical, within its bounds), and the
    law refitted alone with the same budget (:func:`_law_start`): the refits run in
    parallel, a drift effect's among them (:func:`_screen_one`), the law's last (so one
    process does them in the order written).  Returns ``(trials, baseline)``,
    ``baseline`` is ``(fit, criteria, evaluations)`` of the law refitted alone, or three
    Nones when that refit fails or is not physical (:func:`~.judging.physical`).  Given
    the score entries ``chosen``, those effects are refitted and the law is not."""
    model, records, before = run.model, run.records, step.before
    refit_law = chosen is None
    if refit_law:
        chosen = step.screening.ranked[: run.max_refits]
    eff_by_id = step.screening.by_id
    out, baseline = _refits_and_baseline(run, chosen, screen_budget, refit_law, gap)
    refits = iter(out)
    trials = []
    for s in chosen:
        eff = eff_by_id[s["effect"]]
        # a drift scored on the drift channel is judged there; scored on the blocks of the
        # records' spans (:func:`~.screening._score`), by the gap it leaves on them
        key = "D" if s.get("channel") == "drift" else gap
        try:
            m2, res, evs2, error = next(refits)
            if error is not None:
                raise IntegrationError(error)
        except IntegrationError as exc:
            s["note"] = f"refit failed: {exc}"
            continue
        after, _ = _with_drift(_mean(evs2, "criteria"), {}, run.drift, m2)
        if not after or key not in after or key not in before:
            s["note"] = "the refitted model has no periodic steady state with contact"
            continue
        s["criteria_after"] = after
        s["consistent_after"] = all(e.consistent for e in evs2)
        s["parameters"] = {eff.parameters[0].name: m2.value(eff)}
        # (the drift channel does not depend on the law: no compensation to guard)
        s["repulsive"] = key == "D" or _keeps_repulsive(m2, model, records)
        if not s["repulsive"]:
            s["note"] = (
                "the refit's elastic branch P(zeta, 0) pulls at the record's "
                "penetration: the effect only fits by undoing the contact spring"
            )
        outside = out_of_bounds(m2)  # the effect's, or one named before it
        signs = _keeps_signs(m2, model)
        s["in_bounds"] = not outside and signs
        if outside:
            e = outside[0]
            lo, hi = e.parameters[0].bounds
            s["note"] = (
                f"the refit puts {e.parameters[0].name} = {m2.value(e):.4g} "
                f"outside its physical bounds [{lo:g}, {hi:g}]"
            )
        elif not signs:
            s["note"] = f"the refit turns a coefficient of the law negative ({m2.law})"
        s["gap"] = key
        s["negligible"] = negligible(_small_step(eff, records))
        s["motion_worse"] = _motion_worse(before, after, evs2)
        if s["motion_worse"]:
            s["note"] = (
                f"the refit moves the recorded penetration further away ({MOTION_CRITERION} "
                f"{before[MOTION_CRITERION]:.3g} -> {after[MOTION_CRITERION]:.3g}, beyond its "
                "limit): it fits the force by another motion"
            )
        s["force_worse"] = _force_worse(run.criterion, key, before, after, evs2)
        if s["force_worse"]:
            c = run.criterion
            s["note"] = (
                f"the refit moves the force history further away ({c} {before[c]:.3g} -> "
                f"{after[c]:.3g}, beyond its limit): it fits the penetration by another force"
            )
        trials.append(
            _Trial(
                ratio=after[key] / max(before[key], 1e-300),
                score=s,
                model=m2,
                result=res,
                evaluations=evs2,
                key=key,
            )
        )
    if refit_law:
        baseline = _collapsed_baseline(run, trials, baseline, gap)
    return trials, baseline


def _collapsed_baseline(run, trials, baseline, gap):
    """The law's baseline, or the best trial whose effect's refit collapsed (its parameter
    negligible) with the effect taken out, when that lowers the ``gap`` criterion and stays
    physical: such a trial is a refit of the law from another start (the regression's, a
    ladder's rung).  On survey draw 33's quieter record the law refitted alone stopped at
    I2 0.98 while five trials reached 0.075 with their effect at 0; judged against 0.98, a
    coupling and then a mass loss were named where the record has neither."""
    _, null_after, _ = baseline
    best = null_after.get(gap, np.inf) if null_after else np.inf
    collapsed = [
        x
        for x in trials
        if x.key == gap
        and x.result is not None
        and abs(x.model.value(effect(x.score["effect"]))) <= x.score["negligible"]
        and x.score["criteria_after"][gap] < best
    ]
    if not collapsed:
        return baseline
    x = min(collapsed, key=lambda t: t.score["criteria_after"][gap])
    eff = effect(x.score["effect"])
    reduced = x.model.without_effect(eff)
    if not physical(reduced, run.model, run.records):
        return baseline
    try:
        evs = run.problem.evaluations(reduced, floor=True)
        after, _ = _with_drift(_mean(evs, "criteria"), {}, run.drift, reduced)
    except (IntegrationError, InputError):
        return baseline
    if not after or gap not in after or not after[gap] < best:
        return baseline
    name = eff.parameters[0].name
    errors = {k: v for k, v in x.result.standard_errors.items() if k != name}
    return LawOnly(reduced, errors), after, evs


def _law_start(run):
    """Where the law refitted alone starts: the better (by the criterion, one simulation
    each) of the current model and the regression on its terms; None when neither
    simulates.  An effect is named only when its refit beats this law's refit by the noise
    floor (else the gap was the start's own misfit, and the effect only carried a refit of
    the law)."""
    model, problem = run.model, run.problem
    try:
        starts = [model]
        reg0 = _regressed(model, model.law.names, run.regress)
        if reg0 is not None:
            starts.append(reg0)
        return min(starts, key=lambda m: problem.value(m, run.criterion))
    except (IntegrationError, InputError):
        return None


#: a refit named over the law refitted alone by the verdict reaches this multiple of the
#: noise floor or less (:meth:`_Trial.judge`; the factor of I5's consistency limit)
NEAR_FLOOR = 1.25


def _judged(trials, null_after, floor, eff_by_id, null_evs=None):
    """The trials that name an effect, each judged (:meth:`_Trial.judge`) against the law
    refitted alone (``null_after``, its evaluations ``null_evs``) and the noise ``floor``."""
    null_consistent = all(e.consistent for e in null_evs) if null_evs else None
    for x in trials:
        x.judge(eff_by_id[x.score["effect"]], null_after, floor, null_consistent)
    return [x for x in trials if x.names]


def floor_of(evaluations, criterion):
    """The smallest noise floor of ``criterion`` over a model's ``evaluations`` (one per
    record, made with their floors), or None where one has none: the gate of a refit's
    restarts and polish (:func:`~.starts._output_error`'s ``floor``)."""
    floors = [(e.noise_floor or {}).get(criterion) for e in evaluations or ()]
    if not floors or any(f is None or not np.isfinite(f) for f in floors):
        return None
    return float(min(floors))


def _polish_winner(run, best, eff):
    """The winner refitted with the full budget, kept when it lowers the gap and stays
    within bounds and physical: the trial with that model, fit and evaluations.  A refit
    whose least squares end at or below the winner's noise floor goes no further
    (``floor``: :func:`floor_of` its evaluations)."""
    s, m2, res, evs2, key = best.score, best.model, best.result, best.evaluations, best.key
    try:
        res2 = _output_error(
            run.records,
            m2,
            run.criterion,
            run.budget,
            run.tolerances,
            polish=True,
            floor=floor_of(evs2, run.criterion),
        )
        evs3 = run.problem.evaluations(res2.law, floor=True)
        after3, _ = _with_drift(_mean(evs3, "criteria"), {}, run.drift, res2.law)
        if (
            after3
            and after3[key] <= s["criteria_after"][key]
            and physical(res2.law, run.model, run.records)
        ):
            m2, res, evs2 = res2.law, res2, evs3
            s["criteria_after"] = after3
            s["parameters"] = {p.name: m2.value(eff) for p in eff.parameters}
    except (IntegrationError, InputError):
        pass
    return replace(best, model=m2, result=res, evaluations=evs2)


def _law_with_the_drift(run, model, budget, gap):
    """A drift effect's model (its parameter fitted to the drift channel) with the law
    refitted by output error (:func:`_drift_refit`), from the law as it is and from the
    law the certified regression gives (:func:`~.starts._regressed`), the lower kept: the
    law as it is was fitted without the drift and has made up for it, and where that
    holds the refit in another basin the regression, which reads the force against the
    measured penetration whatever the mass, does not (survey draw 68's noisier record, a
    moulding shedding 0.23 % an impact: the law's spring 23 % stiff, the loss's refit from
    it stopped at I2 0.147, from the regression's law it reaches 0.076 with the law and the
    loss to 0.2 %, the true model's 0.072).  ``run`` is a screening job's :class:`_Refits`.
    ``(model, fit)``: the refit where it lowers the gap criterion, else ``model`` and
    ``None``."""
    try:
        old = _mean(run.problem.evaluations(model, floor=False), "criteria").get(gap, math.inf)
    except (IntegrationError, InputError):
        return model, None
    best, value = (model, None), old
    regressed = _regressed(model, model.law.names, getattr(run, "regress", None))
    met = []  # the held refits' ends
    for start in (model, *([regressed] if regressed is not None else [])):
        fitted, res, new = _drift_refit(run, start, budget, gap, met)
        if res is not None and new < value:
            best, value = (fitted, res), new
    return best


#: two refits whose parameters agree to this (relative) have reached the same point
SAME_POINT = 1e-6


def _met(law, met):
    """Whether ``law``'s parameters agree with one of ``met``'s to :data:`SAME_POINT`."""
    x = np.asarray(law.coefficients, dtype=float)
    return any(
        len(m.coefficients) == x.size and np.allclose(m.coefficients, x, rtol=SAME_POINT, atol=0)
        for m in met
    )


def _drift_refit(run, model, budget, gap, met=None):
    """``(fitted, fit, criterion)``: ``model`` refitted first with the drift parameter held
    (the law was fitted without the drift: this brings it into the record's basin), then,
    on records compared over their span, where each block starts with the mass left,
    jointly with the drift parameter (the blocks fix it far more tightly than the drift
    channel; a record without positions keeps the drift channel's value), and then with the
    machine parameters the drift is refitted with too (:func:`~.effects.drift_fitted`: the
    moulding's mass, which a calibration reads together with the loss; freed only once the
    loss is near its value, the fit reaches it within the same budget); ``(model, None,
    inf)`` where a refit fails, or where its first refit ends where one of ``met`` did (the
    rest would repeat that start's: on the bench record the law as it is and the
    regression's both reached one point to 1e-12, and the loss's last two refits ran twice,
    a quarter of its screening's simulations); ``met`` takes this first refit's end."""
    try:
        res = run.fitted(model, budget)
        if met is not None:
            if _met(res.law, met):
                return model, None, math.inf
            met.append(res.law)
        if run.spans:
            res = run.fitted(replace(res.law, fit_drift=True), budget)
            start = run.drift_fitted(res.law)
            if start.free_machine():
                res = run.fitted(start, budget)
        fitted = replace(res.law, fit_drift=False)
        new = _mean(run.problem.evaluations(fitted, floor=False), "criteria")
    except (IntegrationError, InputError):
        return model, None, math.inf
    return fitted, res, new.get(gap, math.inf)
