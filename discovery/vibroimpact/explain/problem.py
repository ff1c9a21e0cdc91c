"""The residual problem of the missing-effect loop (the fit's
:class:`~discovery.vibroimpact.fit.problem.ModelProblem`: a model's evaluations on every record
with a memo, its residuals, mean criteria and the noise), the drift channel across the impacts
(:mod:`discovery.vibroimpact.explain.drift`), and the mean criteria with the drift's.
"""

import numpy as np

from ..fit.problem import ModelProblem
from ..fit.records import contact_scales
from . import drift as D
from .effects import EFFECTS, drift_fitted, small_step

#: the loop's residual problem: the fit's :class:`~discovery.vibroimpact.fit.problem.ModelProblem`
_Problem = ModelProblem


class _Drift:
    """The drift channel of every record (:mod:`discovery.vibroimpact.explain.drift`)."""

    def __init__(self, pairs, records):
        self.recs = []
        for (sc, m), (_, ref) in zip(pairs, records, strict=True):
            self.recs.append((sc, D.DriftRecord.from_measurement(m, ref.impulse, g=sc.g)))

    def _pairs(self, model):
        return [(model.apply(sc), rec) for sc, rec in self.recs]

    def _loss(self, model):
        """The mass loss the model runs with: its own, else the machine's (a calibrated
        machine may carry one: read as 0, the drift of a loss the machine has explained
        was judged as unexplained)."""
        machine = self.recs[0][0].mass_loss if self.recs else 0.0
        return float(model.scenario.get("mass_loss", machine))

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


class OnRecords:
    """What an explain run and its screening jobs read off their ``records`` (``[(scenario,
    reference)]``, an attribute of the class this is mixed into)."""

    @property
    def scenarios(self):
        """Each record's machine."""
        return [sc for sc, _ in self.records]

    @property
    def spans(self):
        """Whether every record is compared over its span (each block starting with the mass
        left after the record's impacts before it)."""
        return all(getattr(ref, "span", None) is not None for _, ref in self.records)

    def drift_fitted(self, model):
        """``model`` with its drift fitted, with the machine parameters it trades against
        from the records' machines (:func:`~.effects.drift_fitted`)."""
        return drift_fitted(model, self.scenarios)


def _mean(evs, key):
    if not all(getattr(e, key) for e in evs):
        return {}
    return {k: float(np.mean([getattr(e, key)[k] for e in evs])) for k in getattr(evs[0], key)}


def _small_step(eff, records):
    """A small value of the effect's parameter
    (:func:`~discovery.vibroimpact.explain.effects.small_step` at the first record's scales)."""
    tau, v, z0 = contact_scales(*records[0])
    return small_step(eff, records[0][0], records[0][1].impulse.peak, tau=tau, v=v, z0=z0)


def best_of(problem, models, criterion, below=np.inf):
    """``(model, value)`` of the model of ``models`` with the lowest ``criterion`` under
    ``below`` (one evaluation each; a model that cannot be simulated or compared is passed
    over), or ``(None, below)``."""
    from ...errors import InputError, IntegrationError

    best, value = None, below
    for m in models:
        try:
            v = problem.value(m, criterion)
        except (IntegrationError, InputError):
            continue
        if v < value:
            best, value = m, v
    return best, value
