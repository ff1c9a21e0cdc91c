"""The residual problem of the missing-effect loop: a model's evaluations on every record (with
a memo), its force and penetration residuals, mean criteria and the noise; and the drift
channel across the impacts (:mod:`discovery.vibroimpact.explain.drift`).
"""

import numpy as np

from ...numerics.memo import Memo, value_key
from ..fit.records import contact_scales, cycle_pairs
from ..verify import evaluate
from ..verify.motion import penetration_residuals
from . import drift as D
from .effects import EFFECTS, small_step


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


def _mean(evs, key):
    if not all(getattr(e, key) for e in evs):
        return {}
    return {k: float(np.mean([getattr(e, key)[k] for e in evs])) for k in getattr(evs[0], key)}


def _small_step(eff, records):
    """A small value of the effect's parameter
    (:func:`~discovery.vibroimpact.explain.effects.small_step` at the first record's scales)."""
    tau, v, z0 = contact_scales(*records[0])
    return small_step(eff, records[0][0], records[0][1].impulse.peak, tau=tau, v=v, z0=z0)
