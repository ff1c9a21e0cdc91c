"""The missing-effect loop: find where the model and the record disagree, name the missing
effect, add it, refit, show the gap shrink.

One iteration (:func:`explain`):

1. **Verify** the current model against every record
(:func:`discovery.vibroimpact.verify.evaluate`):
   if it is consistent (same regime; I2, I4 and I5 within their limits) there is
   nothing to explain, and the loop stops: no false discoveries.
2. **Localise** the disagreement (:func:`~discovery.vibroimpact.explain.localise.localise`).
3. **Score** every applicable catalogue effect by a Lagrange-multiplier (score) test for
   an omitted variable: with the residual ``r = F_N - F_E`` of all records, the output
   Jacobian ``J`` of the model's own coefficients and the output sensitivity ``s`` to the
   effect's parameter (finite differences through full simulations),
   ``LM = (s^T M r)^2 / (sigma^2 s^T M s)``, ``M = I - J (J^T J)^-1 J^T`` (``r`` and ``s``
   are made orthogonal to what a refit of the current coefficients can absorb), ``sigma``
   the noise of the averaged cycles.  Under "the effect is absent" ``LM ~ chi^2(1)``; an
   effect is significant when its p-value is below ``alpha`` divided by the number of
   effects scored (Bonferroni).
4. **Refit** every significant effect (at most ``max_refits``, by LM; a third of the
   simulation budget each, the chosen one polished with the whole, least squares then
   Nelder-Mead): output-error identification of the extended model, the law's
   coefficients and the effect's parameter jointly (:func:`discovery.identify` on the
   :class:`Model`), re-verified.  A term effect's refit starts from the certified
   regression on the extended term set when that simulates closer to the record than the
   current law with the term at its LM step (a start that has compensated for a missing
   Hertz term with a stiffer spring otherwise holds the refit in its basin).  The
   LM statistic is local: an effect whose output is far from linear in its parameter (a
   set, an unloading damper the start law has compensated) can score below one that
   merely correlates with the residual, so the refits, not the scores, decide.  The
   effect is named when its refit lowers the mean I2 by at least 10 % and keeps the
   contact spring repulsive (``P(z0, 0) > 0`` at the record's typical penetration: a
   stiffening support can mimic unloading damping only by turning the spring into a
   pull); two refits within the noise floor of each other are reported as equivalent.
   Its signature (the phases where it acts) is checked against the localisation and
   reported.
5. Repeat until nothing significant remains or ``max_iterations`` is reached.
"""

import itertools
import re
import time
import warnings
from dataclasses import dataclass, field
from typing import NamedTuple

import numpy as np
from scipy.stats import chi2

from ..._printing import fmt, readable
from ..._progress import tick
from ..._result import Result, part
from ..._validate import Choice, Instance, Real, Text, params
from ...catalogue import select
from ...errors import InputError, IntegrationError
from ...numerics.executor import map_on
from ...numerics.memo import Memo, value_key
from ..data.measurement import Measurement
from ..dynamics import Tolerances
from ..fit.identify import (
    INTERVAL_REFITS,
    Intervals,
    as_records,
    bootstrap_intervals,
    contact_scales,
    cycle_pairs,
    identify,
    pair_records,
    record_start,
)
from ..model.law import ForceLaw, Term
from ..model.scenario import Scenario
from ..verify import CONSISTENCY_FACTORS, Reference, evaluate
from ..verify.criteria import criteria_lines
from ..verify.motion import MOTION_CRITERION, penetration_residuals
from . import drift as D
from .effects import EFFECTS, Model, effect, small_step
from .localise import localise

__all__ = ["ExplainResult", "Iteration", "explain", "start_law"]


def _present(eff, model, res):
    """The effect's parameter is away from 0 by more than 2 standard errors."""
    name = eff.parameters[0].name
    v = model.value(eff)
    se = res.standard_errors.get(name)
    return bool(v != 0.0 and (se is None or not np.isfinite(se) or abs(v) > 2.0 * se))


def _law_refit(records, model, criterion, budget, tolerances, problem, drift, polish=False):
    """``(result, criteria, evaluations)`` of the model refitted alone (no effect added),
    or None when the refit fails (e.g. a parameter at 0)."""
    try:
        res = _output_error(records, model, criterion, budget, tolerances, polish=polish)
        evs = problem.evaluations(res.law, floor=True)
        after, _ = _with_drift(_mean(evs, "criteria"), {}, drift, res.law)
    except (IntegrationError, InputError):
        return None
    return res, after, evs


# a number multiplying a factor: the start is a law with coefficients, not a term list
_HAS_COEFFICIENT = re.compile(r"(^|[+\-])\s*[0-9.]+([eE][+\-]?[0-9]+)?\s*\*")


def loaded_model(d):
    """The :class:`Model` of its ``as_dict()`` document."""
    law = ForceLaw.from_dict(d["coefficients"])
    un = d.get("unloading") or {}
    if un or d.get("permanent_set"):
        law = law.with_unloading(
            [Term.parse(k) for k in un], list(un.values()), d.get("permanent_set") or 0.0
        )
    return Model(
        law,
        observation=dict(d.get("observation") or {}),
        effects=tuple(d.get("effects") or ()),
        scenario=dict(d.get("scenario") or {}),
    )


@dataclass(frozen=True, eq=False)
class Iteration(Result):
    """One pass of the loop.

    Attributes
    ----------
    model_before, model_after : Model
    criteria_before, criteria_after : dict
        Mean criteria over records.
    noise_floor : dict
    localisation : dict
        Of the model before (first record).
    scores : list of dict
        Every scored effect: ``effect``, ``lm``, ``p``, ``significant``,
        ``signature_agrees``, and for refitted ones ``criteria_after`` and ``parameters``.
    effect : str or None
        The effect named (None when the iteration stopped the loop).
    evidence : str
    equivalent : list of str
        Effects whose refit explains the record as well (within the noise floor).
    simulated_before, simulated_after : Impulse or None
        The aligned simulated force histories (first record), for figures.
    measured : Impulse or None
        The first record's measured cycle.
    """

    KIND = "explain-iteration"
    _LOAD = {
        "model_before": lambda d: loaded_model(d["model_before"]),
        "model_after": lambda d: loaded_model(d["model_after"]),
    }

    model_before: Model
    model_after: Model
    criteria_before: dict
    criteria_after: dict
    noise_floor: dict
    localisation: dict
    scores: list
    effect: str | None
    evidence: str
    equivalent: list = field(default_factory=list)
    simulated_before: object = None
    simulated_after: object = None
    measured: object = None

    def as_dict(self):
        return {
            "effect": self.effect,
            "evidence": self.evidence,
            "criteria_before": self.criteria_before,
            "criteria_after": self.criteria_after,
            "noise_floor": self.noise_floor,
            "parameters": _parameters(self),
            "model_before": self.model_before.as_dict(),
            "model_after": self.model_after.as_dict(),
            "scores": self.scores,
            "equivalent": self.equivalent,
            "localisation": {
                "phases": self.localisation["phases"],
                "grid": self.localisation.get("grid"),
                "drift": self.localisation.get("drift"),
                "sigma": self.localisation["sigma"],
                "rms": self.localisation["rms"],
            },
        }


def _parameters(it):
    if it.effect is None:
        return {}
    for s in it.scores:
        if s["effect"] == it.effect:
            return s.get("parameters", {})
    return {}


@readable
@dataclass(frozen=True, eq=False)
class ExplainResult(Result):
    """Outcome of :func:`explain`.

    Attributes
    ----------
    iterations : tuple of Iteration
    final_model : Model
    uncertainties : dict
        Standard errors of the final law's coefficients (output error).
    criteria : dict
        Of the final model (mean over records).
    noise_floor : dict
    consistent : bool
        The final model is consistent with every record.
    limits : dict
        The consistency limits of the record (one record only: with several, each
        record has its own).
    stopped_because : str
    seconds : float
    settings : dict
    separability : tuple of dict
        When the start model is consistent with nothing added: each catalogue effect
        refitted with the model (``effect``, ``criterion``, ``before``, ``after``,
        ``floor``, ``parameter``, ``separable``: the refit lowers the criterion by more
        than its noise floor), so a report can say, with numbers, which effects this record
        cannot tell from the model (e.g. a Hertz term on a record a linear law matches).
    intervals : Intervals or None
        Bootstrap intervals of the final model's parameters through the full processing.
    """

    KIND = "explain"
    _LOAD = {
        "iterations": lambda d: tuple(part(Iteration, it) for it in d["iterations"]),
        "final_model": lambda d: loaded_model(d["final_model"]),
        "uncertainties": lambda d: d["final_model"].get("uncertainties", {}),
        "intervals": lambda d: part(Intervals, d["final_model"].get("intervals")),
        "separability": lambda d: tuple(d.get("separability", ())),
    }

    iterations: tuple
    final_model: Model
    uncertainties: dict
    criteria: dict
    noise_floor: dict
    consistent: bool
    stopped_because: str
    seconds: float = 0.0
    settings: dict = field(default_factory=dict)
    separability: tuple = ()
    intervals: object = None
    limits: dict = field(default_factory=dict)

    def as_dict(self):
        return {
            "iterations": [it.as_dict() for it in self.iterations],
            "final_model": {
                **self.final_model.as_dict(),
                "uncertainties": self.uncertainties,
                "intervals": None if self.intervals is None else self.intervals.as_dict(),
            },
            "criteria": self.criteria,
            "noise_floor": self.noise_floor,
            "limits": self.limits,
            "consistent": self.consistent,
            "stopped_because": self.stopped_because,
            "separability": list(self.separability),
            "seconds": self.seconds,
        }

    def _lines(self):
        named = [it.effect for it in self.iterations if it.effect]
        out = [
            f"final model {self.final_model.law}"
            + (f" with {', '.join(named)}" if named else " (nothing named)")
            + ": "
            f"{'consistent' if self.consistent else 'NOT consistent'} with the record(s)"
        ]
        for k, it in enumerate(self.iterations):
            key = next((c for c in ("I2", "D") if c in it.criteria_after), None)
            gap = (
                f"{key} {fmt(it.criteria_before.get(key), 3)} -> "
                f"{fmt(it.criteria_after.get(key), 3)}"
                if key
                else ""
            )
            out.append(f"  iteration {k + 1}: {it.effect or 'nothing named'}  {gap}")
        out += criteria_lines(self.criteria, self.noise_floor, self.limits)
        out.append(f"  stopped because {self.stopped_because}")
        out.append(f"{self.seconds:.1f} s")
        return out


def _polish_start(records, fit, criterion, budget, tol):
    """The cycle-by-cycle start refined on the records' blocks, kept when it keeps the
    measured number of contacts in every record and lowers the criterion, and either stays
    local (every coefficient within 3 standard errors of the cycle-by-cycle fit) or is
    consistent with every record (a far refit that trades the spring for the restitution
    has left the start's basin without explaining the record)."""
    scs, refs = [s for s, _ in records], [r for _, r in records]
    try:
        res = identify(
            scs,
            refs,
            fit.law,
            criterion=criterion,
            method="least-squares",
            max_simulations=budget,
            tolerances=tol,
            short_first=False,
            check=False,
        )
    except (IntegrationError, InputError):
        return fit
    same = all(e.impacts["simulated"] == e.impacts["measured"] for e in res.evaluations)
    base = [evaluate(sc, fit.law, ref, tolerances=tol, floor=False) for sc, ref in records]
    v0 = float(np.mean([e.criteria.get(criterion, np.inf) for e in base]))
    if not (same and res.value <= v0):
        return fit
    se = fit.standard_errors
    near = all(
        abs(b - a) <= 3.0 * se.get(n, 0.0)
        for n, a, b in zip(fit.law.names, fit.law.coefficients, res.law.coefficients, strict=True)
    )
    # a far move is kept only when it reaches a law consistent with every record
    return (
        res
        if near or all(evaluate(sc, res.law, ref, tolerances=tol).consistent for sc, ref in records)
        else fit
    )


def _separability(problem, records, model, catalogue, criterion, before, floor, budget, tol):
    """Whether the record can tell each force-history effect from a consistent model: the
    effect is added (at its small step) and refitted with the model by output error; it is
    ``separable`` when the refit lowers ``criterion`` by more than its noise floor.  (Score
    tests are not used here: at a model already within the noise they find significant
    directions in residuals that are not white, which no refit turns into a better fit.)"""
    out = []
    for e in catalogue:
        if not e.applicable(model) or "drift" in e.phases:
            continue
        row = {
            "effect": e.id,
            "criterion": criterion,
            "before": before.get(criterion),
            "floor": floor.get(criterion),
        }
        try:
            res = _output_error(
                records, _extend(model, e, _small_step(e, records)), criterion, budget, tol
            )
            row["after"] = float(problem.value(res.law, criterion))  # as ``before``
            row["parameter"] = float(res.law.value(e)) if hasattr(res.law, "value") else None
        except IntegrationError as exc:
            row["after"], row["note"] = None, f"refit failed: {exc}"
        gain = (
            None if row["after"] is None or row["before"] is None else row["before"] - row["after"]
        )
        row["separable"] = bool(
            gain is not None and row["floor"] is not None and gain > row["floor"]
        )
        out.append(row)
    return out


def _physical(names, records):
    """Start values from the record alone
    (:func:`discovery.vibroimpact.fit.identify.record_start`)."""
    terms = [ForceLaw.parse(f"1*{n}").terms[0] for n in names]
    return ForceLaw(tuple(terms), tuple(record_start(*records[0], terms)))


def _joined_samples(scenarios, measurements):
    """The contact samples of every record joined (None without positions in every
    record): built once per run, for every regression of the force on a term list."""
    from ..data.samples import contact_samples, join_samples

    try:
        return join_samples(
            [
                contact_samples(m, period=sc.period)
                for sc, m in zip(scenarios, measurements, strict=True)
            ]
        )
    except (InputError, ValueError):
        return None


def _regression(names, samples, loading=False):
    """The certified regression of the force on exactly these terms over ``samples``
    (:func:`_joined_samples`; None without them, or when the regression fails); with
    ``loading``, on the loading samples (``dzeta > 0``) alone, which an unloading branch
    or a set leaves as they are."""
    from ..fit.regression import ConstrainedSparseRegressor

    if samples is None:
        return None
    try:
        keep = samples.dzeta > 0 if loading else np.ones(len(samples), dtype=bool)
        if np.count_nonzero(keep) < 10 * len(names):
            return None
        est = ConstrainedSparseRegressor(library=",".join(names), max_terms=len(names))
        est.fit(
            samples.X[keep],
            samples.F[keep],
            groups=samples.impact[keep],
            sample_weight=samples.weight[keep],
        )
    except (InputError, ValueError):
        return None
    full = [c for c in est.candidates_ if len(c.terms) == len(names)]
    if not full:
        return None
    coef = full[0].coefficients
    terms = [Term.parse(n) for n in names]
    if not all(coef.get(t.name, 0.0) for t in terms):
        return None
    return ForceLaw(tuple(terms), tuple(float(coef[t.name]) for t in terms))


def start_law(text, records, measurements=None):
    """Candidate start laws: ``linear`` (z, zd) or a term list (``z,zd``) gets its
    coefficients from the certified regression on the contact samples (when the records
    have positions: first), then from the record alone (contact time, reduced mass, force
    jump), term-wise mixtures of the two and softer springs; a law with coefficients
    (``2e8*z + 1e7*zd``) is used as given."""
    preferred, others = _start_candidates(text, records, measurements)
    return preferred + others


def _start_candidates(text, records, measurements):
    """``(preferred, others)`` of :func:`start_law`: the given law or the regression (a
    fit to the force itself), and the fallbacks :func:`explain` ranks by one simulation
    each."""
    text = str(text).strip()
    if not text:
        raise InputError(
            "--start is empty; give 'linear', a term list such as 'z,zd' or a "
            "law such as '2e8*z + 1e7*zd'"
        )
    if text != "linear" and "," not in text and _HAS_COEFFICIENT.search(text):
        return [ForceLaw.parse(text)], []
    names = ["z", "zd"] if text == "linear" else [n.strip() for n in text.split(",") if n.strip()]
    for n in names:
        ForceLaw.parse(f"1*{n}")  # a clear error for a bad term name
    E = records[0][1].impulse
    if not len(E.support):
        raise InputError("the record has no contact to start from")
    reg = None
    if measurements is not None:
        reg = _regression(names, _joined_samples([sc for sc, _ in records], measurements))
    phys = _physical(names, records)
    others = [phys]
    if reg is not None and len(names) <= 4 and reg.terms == phys.terms:
        # term-wise mixtures: the regression's damping with the contact time's stiffness
        # (a short contact's few noisy penetration samples can bias one coefficient only)
        for mask in itertools.product((0, 1), repeat=len(names)):
            if 0 < sum(mask) < len(names):
                others.append(
                    reg.with_coefficients(
                        [(phys if m else reg).coefficients[i] for i, m in enumerate(mask)]
                    )
                )
    # softer springs: a contact that damping ends early (the paper's law unloads
    # elastically, so the contact lasts at least a quarter of the spring's period) is far
    # shorter than the half period the contact-time stiffness assumes
    for f in (0.25, 0.25**2, 0.25**3):
        others.append(
            phys.with_coefficients(
                [
                    c * f if t.b == 0 else c
                    for t, c in zip(phys.terms, phys.coefficients, strict=True)
                ]
            )
        )
    return ([reg] if reg is not None else []), others


def _fallbacks(preferred, others, problem, criterion):
    """The start laws in the order they are tried: the preferred ones, then (only when
    those fail) the three closest fallbacks, ranked by one simulation each (a start can
    land in another regime's basin)."""
    yield from preferred
    yield from sorted(others, key=lambda law: problem.value(Model(law), criterion))[:3]


class _Problem:
    """Residuals of a model against all records, and their sensitivities."""

    def __init__(self, records, tolerances):
        self.records, self.tol = records, tolerances
        self.n_sim = 0
        # a model named in one iteration is verified again at the start of the next, and
        # its residual follows its verification: those asks are answered from here (and
        # the block simulations a floor and a residual share, from the verify layer's)
        self._memo = Memo(16)

    def evaluations(self, model, floor=False, smooth_onset=False):
        """The model's evaluation on every record (:func:`~discovery.vibroimpact.verify.evaluate`,
        asked again: answered from the memo)."""
        key = value_key(model.law, model.observation, model.scenario, floor, smooth_onset)
        return self._memo.get(key, lambda: self._evaluate(model, floor, smooth_onset))

    def _evaluate(self, model, floor, smooth_onset):
        evs = []
        for sc, ref in self.records:
            self.n_sim += 1
            evs.append(
                evaluate(
                    model.apply(sc),
                    model.law,
                    ref,
                    tolerances=self.tol,
                    floor=floor,
                    observe=model.observe(),
                    smooth_onset=smooth_onset,
                )
            )
        return evs

    def residual(self, model):
        """The force residual of every compared cycle (the optimisers' continuous form),
        then the recorded penetration's in the force's units
        (:func:`~discovery.vibroimpact.verify.motion.penetration_residuals`)."""
        evs = self.evaluations(model, smooth_onset=True)
        if not all(e.status == "ok" for e in evs):
            return None
        return np.concatenate(
            [
                S.F - E.F
                for e, (_, ref) in zip(evs, self.records, strict=True)
                for E, S in cycle_pairs(e, ref)
            ]
            + [penetration_residuals(ref, e) for e, (_, ref) in zip(evs, self.records, strict=True)]
        )

    def squares(self, model):
        """The sum of squared residuals (force and penetration, :meth:`residual`): what the
        output-error refits minimise (inf when a record has no steady cycle)."""
        r = self.residual(model)
        return np.inf if r is None else float(r @ r)

    def value(self, model, criterion):
        """The mean ``criterion`` over records (inf when a record has no steady cycle)."""
        evs = self.evaluations(model)
        if not all(e.status == "ok" and criterion in (e.criteria or {}) for e in evs):
            return np.inf
        return float(np.mean([e.criteria[criterion] for e in evs]))

    def sigma(self):
        s = [
            ref.noise["F"] / np.sqrt(max(ref.noise["n_cycles"], 1))
            for _, ref in self.records
            if ref.noise
        ]
        return float(np.sqrt(np.mean(np.square(s)))) if s else 0.0


class _Drift:
    """The drift channel of every record (:mod:`discovery.vibroimpact.explain.drift`)."""

    def __init__(self, pairs, records):
        self.recs = []
        for (sc, m), (_, ref) in zip(pairs, records, strict=True):
            self.recs.append((sc, D.DriftRecord.from_measurement(m, ref.impulse)))

    def _pairs(self, model):
        return [(model.apply(sc), rec) for sc, rec in self.recs]

    @staticmethod
    def _loss(model):
        return float(model.scenario.get("mass_loss", 0.0))

    def criterion(self, model):
        """Mean ``D`` over records and its noise floor."""
        out = [
            D.drift_criterion(D.drift_residual(sc, rec, self._loss(model)), rec)
            for sc, rec in self._pairs(model)
        ]
        return float(np.mean([d for d, _ in out])), float(np.mean([f for _, f in out]))

    def score(self, model, eff, h):
        lm, p, direction = D.drift_score(self._pairs(model), self._loss(model), h)
        return {
            "effect": eff.id,
            "lm": lm,
            "p": p,
            "significant": False,
            "direction": direction,
            "channel": "drift",
        }

    def refit(self, model, eff, h):
        """The model with the loss that fits the drift (the law is not refitted: the
        drift channel does not depend on it)."""
        return model.with_effect(
            eff, D.fit_drift(self._pairs(model), h, hi=eff.parameters[0].bounds[1])
        )


def _with_drift(crit, floor, drift, model):
    """Add the drift criterion ``D`` (and its floor) to the cycle's criteria."""
    if drift is None or not crit:
        return crit, floor
    d = drift.criterion(model)
    return {**crit, "D": d[0]}, {**floor, "D": d[1]}


def _drift_free(drift, model, records, alpha):
    """No significant trend across the impacts: the drift channel's score test of a mass
    loss per impact (beyond the model's own) at level ``alpha`` (the family-wise level
    over the catalogue, as for the naming)."""
    if drift is None:
        return True
    eff = next(e for e in EFFECTS if "drift" in e.phases)
    return drift.score(model, eff, _small_step(eff, records))["p"] >= alpha


def _within_noise(evs, criterion):
    """Every record in the measured regime with ``criterion`` within its consistency limit
    (:func:`discovery.vibroimpact.verify.consistency_limits`)."""
    for e in evs:
        if (
            e.status != "ok"
            or e.regime["simulated"] != e.regime["measured"]
            or e.impacts["simulated"] != e.impacts["measured"]
            or not e.noise_floor
        ):
            return False
        lim = e.limits
        if criterion not in lim or not e.criteria[criterion] <= lim[criterion]:
            return False
    return True


def _motion_within(evs):
    """The recorded penetration (I5) within its consistency limit on every record that has
    it: a law that trades spring for damping matches the force, not the motion, and is
    still to be explained."""
    return all(
        MOTION_CRITERION not in e.limits
        or e.criteria.get(MOTION_CRITERION, np.inf) <= e.limits[MOTION_CRITERION]
        for e in evs
    )


def _motion_worse(before, after, evs):
    """Whether a refit takes the recorded penetration (I5) further from the record and
    beyond its limit on a record: a fit of the force by another motion (a sensor lag that
    smears the force of a too-soft spring), which names nothing."""
    k = MOTION_CRITERION
    if k not in before or k not in after or after[k] <= before[k]:
        return False
    return any(k in e.limits and e.criteria.get(k, 0.0) > e.limits[k] for e in evs)


def _failing(evs):
    """The criteria beyond their consistency limit in any record."""
    out = []
    for e in evs:
        lim = e.limits
        out += [k for k in lim if e.criteria.get(k, 0.0) > lim[k] and k not in out]
    return out or ["the comparison"]


def _mean(evs, key):
    if not all(getattr(e, key) for e in evs):
        return {}
    return {k: float(np.mean([getattr(e, key)[k] for e in evs])) for k in getattr(evs[0], key)}


def _small_step(eff, records):
    """A small value of the effect's parameter
    (:func:`~discovery.vibroimpact.explain.effects.small_step` at the first record's scales)."""
    tau, v, z0 = contact_scales(*records[0])
    return small_step(eff, records[0][0], records[0][1].impulse.peak, tau, v, z0)


def _repulsive(law, records):
    """Whether the law's elastic branch pushes the bodies apart at the records' typical
    penetration (a refit that turns the contact spring into a pull has explained the
    residual by undoing the contact, not by the effect; a start that already pulls is
    not held against the effect)."""
    for sc, ref in records:
        _, _, z0 = contact_scales(sc, ref)
        if not float(law.polynomial(z0, 0.0)) > 0:
            return False
    return True


def _keeps_repulsive(refit, model, records):
    """Whether a refit keeps the contact spring pushing (:func:`_repulsive`); a start that
    already pulls is not held against it."""
    return _repulsive(refit.law, records) or not _repulsive(model.law, records)


def _in_bounds(eff, model):
    """Whether the effect's parameter in ``model`` is within its physical bounds."""
    lo, hi = eff.parameters[0].bounds
    return bool(lo <= model.value(eff) <= hi)


def _signature_agrees(eff, loc, top_phases):
    """Whether the localisation shows the effect's signature: its phases among the two
    with the largest shares, the grid's motion off beyond its noise (``"grid"``), or a
    significant trend across the impacts (``"drift"``)."""
    if set(eff.phases) & set(top_phases):
        return True
    if "grid" in eff.phases and (loc.get("grid") or {}).get("exceeds_noise"):
        return True
    return bool("drift" in eff.phases and (loc.get("drift") or {}).get("significant"))


def _extend(model, eff, value):
    return model.with_effect(eff, value)


def _score(problem, model, r0, J, eff, records, sigma):
    # the sensitivity between h and 2h, not from 0: switching an effect on can change the
    # simulated history by a step of its own (an observation model resamples it)
    h = _small_step(eff, records)
    r1 = problem.residual(_extend(model, eff, h))
    r2 = problem.residual(_extend(model, eff, 2 * h)) if r1 is not None else None
    if r2 is None or sigma <= 0:
        return {
            "effect": eff.id,
            "lm": None,
            "p": None,
            "significant": False,
            "note": "its sensitivity could not be simulated",
        }
    s = (r2 - r1) / h
    if J.shape[1]:
        Q, _ = np.linalg.qr(J)
        s_perp = s - Q @ (Q.T @ s)
        r_perp = r0 - Q @ (Q.T @ r0)
    else:
        s_perp, r_perp = s, r0
    den = float(s_perp @ s_perp)
    lm = float((s_perp @ r_perp) ** 2 / (sigma**2 * den)) if den > 0 else 0.0
    return {
        "effect": eff.id,
        "lm": lm,
        "p": float(chi2.sf(lm, 1)),
        "significant": False,
        "direction": float(-(s_perp @ r_perp) / den) if den > 0 else 0.0,
    }


def _jacobian(problem, model, r0):
    law = model.law
    cols = []
    for i, c in enumerate(law.coefficients):
        h = 1e-4 * abs(c)
        coefs = list(law.coefficients)
        coefs[i] = c + h
        r1 = problem.residual(model.with_law(law.with_coefficients(coefs)))
        if r1 is None:
            continue
        cols.append((r1 - r0) / h)
    return np.column_stack(cols) if cols else np.zeros((r0.size, 0))


def _regressed(model, names, regress, loading=False):
    """``model`` with every loading coefficient from the certified regression of the
    measured force on the terms ``names`` (its unloading branch and added effects kept);
    None when the records have no positions or the regression fails.  The regression sees
    the force against the measured penetration alone, so a start law that has compensated
    for a missing effect with its coefficients (a stiffer spring for a Hertz term or for
    stiffening supports) does not hold the refit in its basin."""
    if regress is None:
        return None
    fit = regress(list(names), loading)
    if fit is None:
        return None
    law = model.law
    return model.with_law(
        ForceLaw(
            fit.terms,
            fit.coefficients,
            law.unloading,
            law.unloading_coefficients,
            law.permanent_set,
        )
    )


#: the effect's value on the regressed law: its small step times these
_LADDER = tuple(4.0**k for k in range(7))


def _refit(problem, model, eff, guess, records, criterion, budget, tol, regress=None):
    """Add ``eff`` and refit the extended model by output error: the law's coefficients and
    every added effect's parameter jointly (:func:`discovery.identify` on the
    :class:`Model`); returns ``(model, identification)``.

    The start is the best (by the sum of squared residuals of force and penetration, what
    the refit minimises: one simulation each) of the current law with
    the effect at its LM direction (a small value when that is unusable) and the law from
    the certified regression (:func:`_regressed`) with the effect: for a term effect the
    regression on the extended term set; for any other, the regression on the current
    terms (on the loading samples alone for an effect on the unloading branch) with the
    effect's value from a ladder (its small step times 1, 4, ... 4096, within its
    bounds)."""
    h = _small_step(eff, records)
    hi = eff.parameters[0].bounds[1]
    cands = [_extend(model, eff, min(guess if guess and guess > 0 else h, 0.5 * hi))]
    if eff.target == "term":
        reg = _regressed(
            model.with_effect(eff, 0.0), list(model.law.names) + [Term.parse(eff.key).name], regress
        )
        if reg is not None:
            cands.append(reg)
    else:
        # an effect on the unloading branch leaves the loading samples as they are
        reg = _regressed(
            model, model.law.names, regress, loading=eff.target in ("unloading", "set")
        )
        if reg is not None:
            values = sorted({min(h * f, 0.9 * hi) for f in _LADDER})
            cands += [_extend(reg, eff, v) for v in values]
    ranked = (
        [cands[0]]
        if len(cands) == 1
        else [m for _, _, m in sorted((problem.squares(m), i, m) for i, m in enumerate(cands))]
    )
    starts = ranked[:2] + [_extend(model, eff, min(h, 0.5 * hi))]
    for i, start in enumerate(starts):
        try:
            res = _output_error(records, start, criterion, budget, tol)
            return res.law, res
        except IntegrationError:
            if i == len(starts) - 1:
                raise


def _screen_one(ctx, job):
    """One screening refit (:func:`_refit`, a task of the executor): ``(model,
    identification, evaluations, error, simulations)``; ``ctx`` is ``(problem, records,
    criterion, budget, tol, regress)``."""
    problem, records, criterion, budget, tol, regress = ctx
    model, eff_id, direction = job
    n0 = problem.n_sim
    try:
        m2, res = _refit(
            problem, model, effect(eff_id), direction, records, criterion, budget, tol, regress
        )
        evs = problem.evaluations(m2, floor=True)
    except IntegrationError as exc:
        return None, None, None, str(exc), problem.n_sim - n0
    return m2, res, evs, None, problem.n_sim - n0


def _screen(jobs, context, workers, executor=None):
    """The screening refits ``[(model, identification, evaluations, error)]`` in the order of
    ``jobs``, on ``executor`` (default: ``workers`` forked processes, so the records are not
    copied; in this process for one worker).  The simulations of every refit are added to the
    problem's count whichever process ran it."""
    problem = context[0]
    n0 = problem.n_sim
    out = map_on(_screen_one, jobs, context, workers=workers, executor=executor)
    problem.n_sim = n0 + sum(r[4] for r in out)
    return [r[:4] for r in out]


def _output_error(records, start, criterion, budget, tol, polish=False):
    """Output-error identification of a law or model on every record: least squares, and
    with ``polish`` Nelder-Mead on the budget least squares left.  Least squares can stop
    early, its step rejected, where the residual is not smooth in the coefficients (a force
    jump at the onset moving across the samples); the simplex, which only compares
    criterion values, goes on from there."""
    scs, refs = [s for s, _ in records], [r for _, r in records]
    res = identify(
        scs,
        refs,
        start,
        criterion=criterion,
        method="least-squares",
        max_simulations=budget,
        tolerances=tol,
        check=False,
    )
    left = budget - res.n_simulations
    if not polish or left < 4 * (len(res.law.coefficients) + 1) * len(records):
        return res
    try:
        res2 = identify(
            scs,
            refs,
            res.law,
            criterion=criterion,
            method="nelder-mead",
            max_simulations=left,
            tolerances=tol,
            check=False,
        )
    except IntegrationError:
        return res
    return res2 if res2.value < res.value else res


class _Trial(NamedTuple):
    """A candidate effect refitted: its gap ratio (after / before), its score entry, the
    refitted model, the fit (``None`` for the drift channel), the evaluations of the refitted
    model and the criterion its gap is measured by."""

    ratio: float
    score: dict
    model: object
    result: object
    evaluations: list
    key: str


class _Screening(NamedTuple):
    """The score tests of one iteration: the candidate effects, their scores, the
    family-wise level, the localisation's two largest phases, the significant effects ranked
    (and those without a local score) and whether the cycle is within its noise."""

    cands: list
    scores: list
    level: float
    top_phases: list
    ranked: list
    quiet: bool


@dataclass
class _Run:
    """One :func:`explain` call: its fixed inputs and the state of its loop."""

    problem: object
    records: list
    catalogue: list
    criterion: str
    alpha: float
    budget: int
    tolerances: object
    drift: object
    regress: object
    workers: object
    executor: object
    max_refits: int
    meas_first: object
    model: object = None
    uncertainties: dict = field(default_factory=dict)
    iterations: list = field(default_factory=list)
    separability: tuple = ()
    stopped: str = ""

    def drift_free(self, model):
        return _drift_free(
            self.drift, model, self.records, self.alpha / max(len(self.catalogue), 1)
        )


def _records_of(scenario, measurement, n_boot, seed):
    """``(pairs, records)``: the records paired with their scenarios, and as references
    (each with its noise floor from ``n_boot`` replicates)."""
    pairs = pair_records(scenario, measurement)
    records = as_records(
        [sc for sc, _ in pairs],
        [
            m
            if isinstance(m, Reference)
            else Reference.from_measurement(m, sc, n_boot=n_boot, seed=seed)
            for sc, m in pairs
        ],
    )
    return pairs, records


def _fit_start(start, records, plain, problem, criterion, budget, tolerances, progress):
    """The start law fitted to the records: the first of the start candidates (and their
    fallbacks) that simulates."""
    preferred, others = (
        ([start], []) if isinstance(start, ForceLaw) else _start_candidates(start, records, plain)
    )
    fit, why = None, ""
    for law in _fallbacks(preferred, others, problem, criterion):
        try:
            # the start is fitted cycle by cycle (each cycle from the machine's state before
            # it): over several cycles a law can trade its spring against the missing
            # effect through the restitution (a soft spring mimics damping while
            # unloading), and the effect would then look absent
            short = [(sc, ref.shortened() or ref) for sc, ref in records]
            tick(progress, "explain: fitting the start cycle by cycle", 0, None)
            fit = _output_error(short, law, criterion, budget, tolerances, polish=True)
            fit = _polish_start(records, fit, criterion, max(budget // 3, 8), tolerances)
            break
        except IntegrationError as exc:
            why = str(exc)
    if fit is None:
        raise IntegrationError(
            f"no start law for {start!r} has a periodic steady state with "
            f"contact for the record ({why}); give --start as a law with "
            "coefficients closer to the record"
        )
    return fit


def _stop_consistent(run, before, floor):
    """The model is consistent: the loop stops (and, when nothing was named, says which
    effects this record cannot tell from the model)."""
    run.stopped = (
        "the model is consistent with the record(s): I2, I4 (and I5 with positions) "
        "within their consistency limits, no drift across the impacts, nothing left to "
        "explain"
    )
    if any(it.effect for it in run.iterations):
        return
    run.separability = _separability(
        run.problem,
        run.records,
        run.model,
        run.catalogue,
        run.criterion,
        before,
        floor,
        max(run.budget // 3, 12),
        run.tolerances,
    )
    hidden = [s["effect"] for s in run.separability if not s["separable"]]
    if hidden:
        run.stopped += (
            "; this record cannot tell " + ", ".join(hidden) + " from the "
            f"model (each refitted with the model lowers {run.criterion} by "
            "less than its noise floor: see separability)"
        )


def _screen_effects(run, evs, loc, cycle_ok):
    """Score tests of the applicable effects at the current model; the significant ones
    ranked by their statistic."""
    model, records, problem = run.model, run.records, run.problem
    r0 = problem.residual(model)
    J = _jacobian(problem, model, r0)
    sigma = problem.sigma()
    # a cycle within its noise leaves only the drift to explain: consistent, or failing
    # I4 alone (the supports of a noisy record) while the criterion the refits lower is
    # within its limit (lowering it further would fit the noise)
    quiet = cycle_ok or (_within_noise(evs, run.criterion) and _motion_within(evs))
    cands = [
        e
        for e in run.catalogue
        if e.applicable(model)
        and (run.drift is not None or "drift" not in e.phases)
        and (not quiet or "drift" in e.phases)
    ]
    scores = [
        run.drift.score(model, e, _small_step(e, records))
        if "drift" in e.phases
        else _score(problem, model, r0, J, e, records, sigma)
        for e in cands
    ]
    level = run.alpha / max(len(scores), 1)
    top_phases = sorted(loc["phases"], key=lambda p: -loc["phases"][p]["share"])[:2]
    for s, e in zip(scores, cands, strict=True):
        s["significant"] = bool(s["p"] is not None and s["p"] < level)
        s["signature_agrees"] = _signature_agrees(e, loc, top_phases)
    ranked = sorted((s for s in scores if s["significant"]), key=lambda s: -s["lm"])
    if any(s.get("channel") == "drift" for s in ranked):
        # a record that drifts has no steady cycle to compare: the drift comes first
        ranked = [s for s in ranked if s.get("channel") == "drift"]
    else:
        # an effect whose small step already changes the regime has no local score;
        # its refit (from the regression, over a ladder of values) still decides
        ranked += [s for s in scores if s["lm"] is None]
    return _Screening(cands, scores, level, top_phases, ranked, quiet)


def _stop_nothing_significant(run, evs, before, floor, loc, screening, cycle_ok):
    """No effect is significant: the iteration is recorded and the loop stops."""
    criterion = run.criterion
    why = f"no catalogue effect is significant (score tests at family-wise level {run.alpha:g})"
    run.stopped = "no catalogue effect explains the remaining disagreement significantly"
    if screening.quiet and not cycle_ok:
        why = (
            f"{criterion} is within its noise limit and the model fails "
            f"{', '.join(_failing(evs))} alone, which no effect is fitted to (the "
            "contact supports of a noisy record); " + why
        )
        run.stopped = (
            f"{criterion} is within its noise limit; the model fails "
            f"{', '.join(_failing(evs))} alone, which is not explained by an "
            "effect"
        )
    run.iterations.append(
        Iteration(
            run.model,
            run.model,
            before,
            before,
            floor,
            loc,
            screening.scores,
            None,
            why,
            [],
            evs[0].simulated,
            evs[0].simulated,
            run.records[0][1].impulse,
        )
    )


def _refit_trials(run, chosen, eff_by_id, before, screen_budget, gap):
    """Every chosen effect refitted with ``screen_budget`` simulations (the refits of the
    force history in parallel, the drift channel here) and checked: physical, within its
    bounds; the trials."""
    model, criterion, records = run.model, run.criterion, run.records
    # the screening refits of the force history are independent: one process each
    refits = iter(
        _screen(
            [
                (model, s["effect"], s.get("direction"))
                for s in chosen
                if "drift" not in eff_by_id[s["effect"]].phases
            ],
            (run.problem, records, criterion, screen_budget, run.tolerances, run.regress),
            run.workers,
            run.executor,
        )
    )
    trials = []
    for s in chosen:
        eff = eff_by_id[s["effect"]]
        key = "D" if "drift" in eff.phases else gap
        try:
            if key == "D":
                m2, res = run.drift.refit(model, eff, _small_step(eff, records)), None
                evs2 = run.problem.evaluations(m2, floor=True)
            else:
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
        s["in_bounds"] = _in_bounds(eff, m2)
        if not s["in_bounds"]:
            lo, hi = eff.parameters[0].bounds
            s["note"] = (
                f"the refit puts {eff.parameters[0].name} = {m2.value(eff):.4g} "
                f"outside its physical bounds [{lo:g}, {hi:g}]"
            )
        s["gap"] = key
        s["motion_worse"] = _motion_worse(before, after, evs2)
        if s["motion_worse"]:
            s["note"] = (
                f"the refit moves the recorded penetration further away ({MOTION_CRITERION} "
                f"{before[MOTION_CRITERION]:.3g} -> {after[MOTION_CRITERION]:.3g}, beyond its "
                "limit): it fits the force by another motion"
            )
        trials.append(_Trial(after[key] / max(before[key], 1e-300), s, m2, res, evs2, key))
    return trials


def _law_baseline(run, screen_budget):
    """The law refitted alone with the same budget (from the better of the current model and
    the regression on its terms): ``(fit, criteria, evaluations)``, or ``(None, None,
    None)``.  An effect is named only when its refit beats this by the noise floor (else the
    gap was the start's own misfit, and the effect only carried a refit of the law)."""
    model, problem = run.model, run.problem
    try:
        null_starts = [model]
        reg0 = _regressed(model, model.law.names, run.regress)
        if reg0 is not None:
            null_starts.append(reg0)
        null_start = min(null_starts, key=lambda m: problem.value(m, run.criterion))
    except (IntegrationError, InputError):
        null_start = None
    refit0 = (
        None
        if null_start is None
        else _law_refit(
            run.records,
            null_start,
            run.criterion,
            screen_budget,
            run.tolerances,
            problem,
            run.drift,
        )
    )
    return (None, None, None) if refit0 is None else refit0


def _judged(trials, null_after, floor, eff_by_id):
    """The trials that name an effect: the gap shrinks by 10 %, the refit is physical and
    within bounds, beats the law refitted alone by the criterion's margin (its floor times
    its consistency factor less one: the floor for the force, a quarter of it for the
    penetration, :data:`~discovery.vibroimpact.verify.CONSISTENCY_FACTORS`), and the
    effect's parameter is not within 2 standard errors of 0."""
    for x in trials:
        k = x.key
        margin = floor.get(k, 0.0) * (CONSISTENCY_FACTORS.get(k, 2.0) - 1.0)
        # (the drift channel does not depend on the law: a law refit is no baseline)
        x.score["beats_law_refit"] = bool(
            k == "D"
            or not null_after
            or k not in null_after
            or x.score["criteria_after"][k] <= null_after[k] - margin
        )
    for x in trials:
        # an effect refitted to 0, or to a value within 2 standard errors of 0, only
        # carried a refit of the law
        e_ = eff_by_id[x.score["effect"]]
        x.score["present"] = (
            _present(e_, x.model, x.result)
            if x.result is not None
            else bool(x.model.value(e_) != 0.0)
        )
    return [
        x
        for x in trials
        if x.ratio <= 0.9
        and x.score["repulsive"]
        and x.score["in_bounds"]
        and x.score["beats_law_refit"]
        and x.score["present"]
        and not x.score.get("motion_worse")
    ]


def _polish_winner(run, best, eff):
    """The winner refitted with the full budget, kept when it lowers the gap and stays
    within bounds and physical: ``(model, fit, evaluations)``."""
    s, m2, res, evs2, key = best.score, best.model, best.result, best.evaluations, best.key
    try:
        res2 = _output_error(
            run.records, m2, run.criterion, run.budget, run.tolerances, polish=True
        )
        evs3 = run.problem.evaluations(res2.law, floor=True)
        after3, _ = _with_drift(_mean(evs3, "criteria"), {}, run.drift, res2.law)
        if (
            after3
            and after3[key] <= s["criteria_after"][key]
            and _in_bounds(eff, res2.law)
            and _keeps_repulsive(res2.law, run.model, run.records)
        ):
            m2, res, evs2 = res2.law, res2, evs3
            s["criteria_after"] = after3
            s["parameters"] = {p.name: m2.value(eff) for p in eff.parameters}
    except (IntegrationError, InputError):
        pass
    return m2, res, evs2


def _only_the_law_refit(run, s, key, evs, before, floor, loc, screening):
    """Polished with the full budget, the winner's parameter is within 2 standard errors
    of 0: the gain was the law's own refit.  Nothing is named; when the polished law refit
    lowers the gap it becomes the model (the loop then screens again).  Returns whether it
    did."""
    refit = _law_refit(
        run.records,
        run.model,
        run.criterion,
        run.budget,
        run.tolerances,
        run.problem,
        run.drift,
        polish=True,
    )
    if refit is None or not refit[1] or not refit[1][key] < before[key]:
        return False
    law_refit, after_law, evs_law = refit[0].law, refit[1], refit[2]
    run.iterations.append(
        Iteration(
            run.model,
            law_refit,
            before,
            after_law,
            floor,
            loc,
            screening.scores,
            None,
            f"{s['effect']} refitted with the full budget has its parameter within 2 "
            "standard errors of 0: the gain was the law's own refit "
            f"({key} {before[key]:.3g} -> {after_law[key]:.3g}); nothing is named",
            [],
            evs[0].simulated,
            evs_law[0].simulated,
            run.records[0][1].impulse,
        )
    )
    run.model = law_refit
    return True


def _name_effect(run, good, evs, before, floor, loc, screening, m2, res, evs2):
    """The winner is named: the iteration records its evidence and the effects as good."""
    s, key = good[0].score, good[0].key
    value = s["criteria_after"][key]
    tol_eq = floor.get(key, 0.0)
    equivalent = [
        x.score["effect"]
        for x in good[1:]
        if x.key == key and x.score["criteria_after"][key] <= value + tol_eq
    ]
    score = (
        f"score test LM = {s['lm']:.3g} (p = {s['p']:.2g} < {screening.level:.2g})"
        if s["lm"] is not None
        else "no score test (a small step of it changes the regime)"
    )
    evidence = (
        f"{score}; refitted, "
        f"{key} {before[key]:.3g} -> {value:.3g} (noise floor "
        f"{floor.get(key, float('nan')):.3g}); signature "
        f"{'agrees' if s['signature_agrees'] else 'does not agree'} with the "
        f"localisation (largest shares: {', '.join(screening.top_phases)})"
        + (
            ""
            if s["signature_agrees"]
            else "; named on the score test and the refit, which decide: the phases "
            "where the residual is largest are a hint, and an effect that changes the "
            "impact as a whole moves the residual everywhere"
        )
    )
    run.iterations.append(
        Iteration(
            run.model,
            m2,
            before,
            s["criteria_after"],
            floor,
            loc,
            screening.scores,
            s["effect"],
            evidence,
            equivalent,
            evs[0].simulated,
            evs2[0].simulated,
            run.records[0][1].impulse,
        )
    )
    run.model = m2
    if res is not None:
        run.uncertainties = dict(res.standard_errors)


def _gap(run, evs):
    """The criterion the gap is measured on: the refits' criterion, or the penetration's
    (I5) when the model is within its limit on the force and fails by the motion alone (a
    spring too soft behind a missing effect matches the force)."""
    if _within_noise(evs, run.criterion) and not _motion_within(evs):
        return MOTION_CRITERION
    return run.criterion


def _refit_and_name(run, evs, before, floor, loc, screening):
    """Refit the ranked effects, compare with the law refitted alone, and name the best
    (or refit the law, or stop).  Returns whether the loop goes on."""
    # every candidate is refitted with a third of the budget; the winner gets the rest
    screen_budget = max(run.budget // 3, 4 * len(run.records))
    eff_by_id = {e.id: e for e in screening.cands}
    gap = _gap(run, evs)
    trials = _refit_trials(
        run, screening.ranked[: run.max_refits], eff_by_id, before, screen_budget, gap
    )
    null, null_after, null_evs = _law_baseline(run, screen_budget)
    good = _judged(trials, null_after, floor, eff_by_id)
    if not good and null_after and gap in null_after and null_after[gap] <= 0.9 * before[gap]:
        run.iterations.append(
            Iteration(
                run.model,
                null.law,
                before,
                null_after,
                floor,
                loc,
                screening.scores,
                None,
                f"no effect beats the law refitted alone ("
                f"{gap} {before[gap]:.3g} -> "
                f"{null_after[gap]:.3g}) by its noise floor: the "
                "law is refitted, nothing is named",
                [],
                evs[0].simulated,
                null_evs[0].simulated,
                run.records[0][1].impulse,
            )
        )
        run.model = null.law
        run.uncertainties = dict(null.standard_errors)
        return True
    if not good:
        run.iterations.append(
            Iteration(
                run.model,
                run.model,
                before,
                before,
                floor,
                loc,
                screening.scores,
                None,
                "no refit of a significant effect (or of one without a "
                f"score) lowers {gap} by 10 %",
                [],
                evs[0].simulated,
                evs[0].simulated,
                run.records[0][1].impulse,
            )
        )
        run.stopped = "the candidate effects do not shrink the gap when refitted"
        return False
    good.sort(key=lambda x: x.ratio)
    best = good[0]
    eff = eff_by_id[best.score["effect"]]
    m2, res, evs2 = best.model, best.result, best.evaluations
    if res is not None and run.budget > screen_budget:
        m2, res, evs2 = _polish_winner(run, best, eff)
    if res is not None and not _present(eff, m2, res):
        if _only_the_law_refit(run, best.score, best.key, evs, before, floor, loc, screening):
            return True
    _name_effect(run, good, evs, before, floor, loc, screening, m2, res, evs2)
    return True


def _iteration(run, max_iterations):
    """One iteration of the loop (verify, localise, score, refit, name); returns whether the
    loop goes on."""
    evs = run.problem.evaluations(run.model, floor=True)
    before, floor = _with_drift(
        _mean(evs, "criteria"), _mean(evs, "noise_floor"), run.drift, run.model
    )
    cycle_ok = all(e.consistent for e in evs)
    if cycle_ok and run.drift_free(run.model):
        _stop_consistent(run, before, floor)
        return False
    if len(run.iterations) >= max_iterations:
        return False
    loc = localise(
        run.model.apply(run.records[0][0]),
        run.model,
        run.records[0][1],
        evs[0],
        run.meas_first,
        tolerances=run.tolerances,
    )
    screening = _screen_effects(run, evs, loc, cycle_ok)
    if not screening.ranked:
        _stop_nothing_significant(run, evs, before, floor, loc, screening, cycle_ok)
        return False
    return _refit_and_name(run, evs, before, floor, loc, screening)


def _check_settings(max_simulations, budget, alpha, workers, max_iterations):
    """The settings :func:`explain` checks beyond their types; returns the simulation
    budget of each refit (``budget=`` is the deprecated name of ``max_simulations=``)."""
    if budget is not None:
        warnings.warn(
            "explain(budget=...) is renamed max_simulations=... (the CLI's --max-simulations)",
            DeprecationWarning,
            stacklevel=4,
        )
        max_simulations = budget
    if not (0 < alpha < 1):
        raise InputError(f"alpha must be in (0, 1); got {alpha!r}")
    if workers is not None and not (isinstance(workers, int) and workers >= 1):
        raise InputError(f"workers must be an integer >= 1; got {workers!r}")
    if not (isinstance(max_iterations, int) and max_iterations >= 0):
        raise InputError(f"max_iterations must be an integer >= 0; got {max_iterations!r}")
    return max_simulations


# the progress stage of explain's iterations
_ITERATIONS = "explain: iterations (localise, score, refit)"


def _intervals(run, n_boot_intervals, seed, progress, refit="two-step"):
    """Bootstrap intervals of the final model's parameters (``None`` when not asked for or
    when a replicate cannot be simulated)."""
    if not n_boot_intervals:
        return None
    try:
        tick(progress, "explain: bootstrap intervals", 0, n_boot_intervals)
        return bootstrap_intervals(
            [sc for sc, _ in run.records],
            [r for _, r in run.records],
            run.model,
            n_boot=int(n_boot_intervals),
            seed=seed,
            criterion=run.criterion,
            tolerances=run.tolerances,
            workers=run.workers,
            executor=run.executor,
            refit=refit,
        )
    except IntegrationError:
        return None


@params(
    scenario=(Scenario, list, tuple),
    measurement=(Measurement, Reference, list, tuple),
    start=(Text(), ForceLaw),
    criterion=Text(),
    alpha=Real(0, 1, open_low=True),
    max_iterations=Real(1, integer=True),
    max_simulations=Real(1, integer=True),
    budget=(None, Real(1, integer=True)),
    n_boot=Real(0, integer=True),
    seed=Real(0, integer=True),
    tolerances=(Tolerances, None),
    effects=(None, list, tuple),
    max_refits=Real(1, integer=True),
    workers=(None, Real(1, integer=True)),
    n_boot_intervals=Real(0, integer=True),
    interval_refit=Choice(*INTERVAL_REFITS),
    executor=(None, Instance("discovery.numerics.executor", "Executor")),
)
def explain(
    scenario,
    measurement,
    start="linear",
    *,
    criterion="I2",
    alpha=0.01,
    max_iterations=3,
    max_simulations=150,
    n_boot=16,
    seed=0,
    tolerances=None,
    effects=None,
    max_refits=8,
    workers=None,
    n_boot_intervals=30,
    interval_refit="two-step",
    progress=None,
    executor=None,
    budget=None,
):
    """Explain the disagreement of a start model with one or several records by named
    physical effects (see the module docstring).

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
        One per record (or one for all).
    measurement : Measurement, Reference, or a sequence of them
    start : str or ForceLaw
        ``"linear"`` (z, zd), a term list (``"z,zd"``) or a law with coefficients; the
        start is first refined by simulation.
    criterion : str
        Criterion of the refits (the mean over records).
    alpha : float
        Family-wise significance level of the score tests.
    max_iterations : int
        Effects added at most.
    max_simulations : int
        Simulations of each refit (the CLI's ``--max-simulations``).
    n_boot, seed : int
        Noise-floor bootstrap.
    tolerances : Tolerances, optional
    effects : sequence of str, optional
        Catalogue ids to consider (default all).
    max_refits : int
        Significant effects refitted per iteration (the largest scores first; default 8,
        the whole catalogue: a score test is local, and an effect that ranked low at a
        far start was the one that explained the record).
    workers : int, optional
        Processes for the screening refits (default: all cores; the result does not
        depend on it).
    executor : Executor, optional
        Where the screening refits run (:mod:`discovery.numerics.executor`); overrides ``workers``
        and is not closed here.
    n_boot_intervals, interval_refit : int, str
        Bootstrap replicates of the final model's 95 % parameter intervals (0 = none) and how
        each is refitted (:func:`discovery.vibroimpact.fit.intervals.bootstrap_intervals`).
    progress : callable, optional
        ``progress(stage, done, total)`` at each stage and iteration (:mod:`discovery._progress`).
    budget : int, optional
        Deprecated name of ``max_simulations``.

    Returns
    -------
    ExplainResult
    """
    t0 = time.perf_counter()
    budget = _check_settings(max_simulations, budget, alpha, workers, max_iterations)
    pairs, records = _records_of(scenario, measurement, n_boot, seed)
    ms = [m for _, m in pairs]
    catalogue = select(EFFECTS, effects)
    problem = _Problem(records, tolerances)
    plain = [m for m in ms if not isinstance(m, Reference)]
    all_plain = len(plain) == len(ms)
    samples = _joined_samples([sc for sc, _ in records], plain) if all_plain else None
    fit = _fit_start(
        start,
        records,
        plain if all_plain else None,
        problem,
        criterion,
        budget,
        tolerances,
        progress,
    )
    run = _Run(
        problem,
        records,
        catalogue,
        criterion,
        alpha,
        budget,
        tolerances,
        drift=_Drift(pairs, records) if not any(isinstance(m, Reference) for m in ms) else None,
        regress=(
            (lambda names, loading=False: _regression(names, samples, loading))
            if samples is not None
            else None
        ),
        workers=workers,
        executor=executor,
        max_refits=max_refits,
        meas_first=ms[0] if not isinstance(ms[0], Reference) else None,
        model=Model(fit.law),
        uncertainties=dict(fit.standard_errors),
        stopped=f"the budget of {max_iterations} added effect(s) is used",
    )
    for _ in range(max_iterations + 1):
        tick(progress, _ITERATIONS, len(run.iterations), max_iterations)
        if not _iteration(run, max_iterations):
            break
    evs = problem.evaluations(run.model, floor=True)
    crit, floor = _with_drift(
        _mean(evs, "criteria"), _mean(evs, "noise_floor"), run.drift, run.model
    )
    return ExplainResult(
        intervals=_intervals(run, n_boot_intervals, seed, progress, interval_refit),
        iterations=tuple(run.iterations),
        final_model=run.model,
        uncertainties=run.uncertainties,
        criteria=crit,
        noise_floor=floor,
        limits=dict(evs[0].limits) if len(evs) == 1 else {},
        consistent=all(e.consistent for e in evs) and run.drift_free(run.model),
        stopped_because=run.stopped,
        separability=tuple(run.separability),
        seconds=time.perf_counter() - t0,
        settings={
            "start": str(start),
            "criterion": criterion,
            "alpha": alpha,
            "max_iterations": max_iterations,
            "max_simulations": budget,
            "n_boot": n_boot,
            "seed": seed,
            "effects": [e.id for e in catalogue],
            "max_refits": max_refits,
            "workers": workers,
            "intervals": {"replicates": n_boot_intervals, "refit": interval_refit},
            "records": len(records),
            "simulations": problem.n_sim,
        },
    )
