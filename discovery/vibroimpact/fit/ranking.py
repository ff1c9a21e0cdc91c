"""The ranking rule of discovery: which checked model comes first."""

from dataclasses import dataclass

import numpy as np

__all__ = ["rank"]


def rank(models, criterion="I2", sim_rtol=0.1, sim_atol=0.005, physics=True):
    """Order checked models: the models consistent with the records first, the fewest terms
    first, then by the criterion (the records cannot tell them apart); then the others
    whose criterion is within ``sim_rtol`` (relative) or ``sim_atol`` of the best, by BIC;
    then the rest by the criterion; models without a periodic steady state with contact last.

    With ``physics`` (default) laws that are no contact laws
    (:meth:`ForceLaw.contact_defects`: no spring, a negative damper) come after every
    contact law, ranked among themselves by the same rule."""
    if physics:
        sound = [m for m in models if not m.defects]
        if len(sound) < len(models):
            unsound = [m for m in models if m.defects]
            head = rank(sound, criterion, sim_rtol, sim_atol, physics=False)
            tail = rank(unsound, criterion, sim_rtol, sim_atol, physics=False)
            # models without a periodic steady state stay last of all
            return (
                [m for m in head if m.criteria]
                + [m for m in tail if m.criteria]
                + [m for m in head if not m.criteria]
                + [m for m in tail if not m.criteria]
            )
    ok = [m for m in models if m.criteria]
    bad = sorted((m for m in models if not m.criteria), key=lambda m: m.candidate.bic)
    if not ok:
        return bad
    good = sorted(
        (m for m in ok if m.consistent), key=lambda m: (len(m.law.names), m.criteria[criterion])
    )
    rest = [m for m in ok if not m.consistent]
    if not rest:
        return good + bad
    best = min(m.criteria[criterion] for m in rest)
    limit = max(best * (1 + sim_rtol), best + sim_atol)
    tier = sorted(
        (m for m in rest if m.criteria[criterion] <= limit), key=lambda m: m.candidate.bic
    )
    tail = sorted(
        (m for m in rest if m.criteria[criterion] > limit), key=lambda m: m.criteria[criterion]
    )
    return good + tier + tail + bad


def _best_per_support(models, criterion):
    """One model per support: the consistent one, else the lowest criterion (a support
    refined again from another start keeps its better refinement)."""
    best = {}
    for m in models:
        key = frozenset(m.law.names)
        score = (not m.consistent, m.criteria.get(criterion, np.inf) if m.criteria else np.inf)
        if key not in best or score < best[key][0]:
            best[key] = (score, m)
    keep = {id(m) for _, m in best.values()}
    return [m for m in models if id(m) in keep]


@dataclass(frozen=True)
class _RankingRule:
    """The settings of :func:`rank`, applied by calling the rule on models."""

    criterion: str = "I2"
    sim_rtol: float = 0.1
    sim_atol: float = 0.005
    physics: bool = True

    def __call__(self, models):
        return rank(models, self.criterion, self.sim_rtol, self.sim_atol, physics=self.physics)
