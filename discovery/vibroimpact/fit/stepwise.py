"""The output-error stepwise search around the best model."""

from dataclasses import dataclass, field

from ..._api._progress import tick
from .ranking import _best_per_support, _RankingRule
from .shortlist import _Checker

_RESTARTS = 2  # stalled smaller supports restarted from a consistent model, per step


def _settled(model):
    """Whether a model's support needs no other start: it was simulated, and refined (or
    not meant to be) rather than left at a start whose refinement broke a physical
    condition or failed."""
    return bool(model.criteria) and not (
        model.refinement is not None and model.note.startswith("not refined")
    )


@dataclass(eq=False)
class _Stepwise:
    """The output-error stepwise search around the best model: a consistent model loses a
    term (backward), an inconsistent one gains one (forward: the regression may have been
    misled, e.g. by noisy penetration), for up to ``stepwise`` moves.  ``retried``: the
    supports already restarted from a consistent model (each once); ``scanned``: those whose
    springs were scanned (:meth:`rescanned`, each once); ``steps``: the moves made, each
    ``{"kind", "from", "trials"}``."""

    check: _Checker
    rank: _RankingRule
    stepwise: int
    max_terms: int
    retried: set = field(default_factory=set)
    scanned: set = field(default_factory=set)
    steps: list = field(default_factory=list)

    def more(self, steps, ranking):
        """Up to ``stepwise`` moves, and one simplifying move more when the last move made
        the best model consistent (its backward step and restarts would be cut off
        otherwise)."""
        if len(steps) < self.stepwise:
            return True
        return (
            len(steps) == self.stepwise
            and self.stepwise > 0
            and ranking[0].consistent
            and steps[-1]["kind"] != "backward"
        )

    def trials(self, top, models):
        """The models of one move from ``top``, and the move's kind."""
        check, physics = self.check, self.rank.physics
        # supports already refined are not tried again, except that a consistent model's
        # backward step retries a smaller support that was inconsistent from its own
        # (biased regression) start, once, from the consistent coefficients: a refinement
        # that stalled far from the truth must not hide the simplest model.  A support whose
        # refinement from a biased start broke a physical condition is tried again from a
        # move's coefficients (on a random short-contact record the true support's
        # regression had a negative coupling, and its refinement kept it)
        done = frozenset(frozenset(m.law.names) for m in models if _settled(m))
        if not (top.consistent and not (physics and top.defects)):
            # both directions: a wrong term may have to go while a missing one comes in
            trials = check.forward(top, self.max_terms, done) + check.backward(top, done)
            return trials, "forward+backward"
        good = frozenset(frozenset(m.law.names) for m in models if m.criteria and m.consistent)
        trials = check.backward(top, good | self.retried)
        self.retried |= {frozenset(m.law.names) for m in trials} & done
        # smaller supports that stalled and no backward step reaches: the two best,
        # restarted from the consistent model's coefficients
        stalled = sorted(
            (
                m
                for m in models
                if m.criteria
                and not m.consistent
                and len(m.law.names) <= len(top.law.names)
                and frozenset(m.law.names) not in self.retried
                and not (physics and m.defects)
            ),
            key=lambda m: m.criteria[self.rank.criterion],
        )[:_RESTARTS]
        for m in stalled:
            self.retried.add(frozenset(m.law.names))
            trials.append(check.restart(top, set(m.law.names)))
        return trials, "backward"

    def rescanned(self, top, models, ranking):
        """``(models, ranking, top)`` after the best model, when it is not consistent, is
        refined again from its springs scanned wide (:meth:`_Checker.rescanned`; each
        support once, as a move of its own in ``steps``).  Only the best: on a record no
        candidate matches (the bench record, an unloading damper outside ``poly:2``) every
        candidate's scan found no lower basin, 42 simulations for nothing."""
        support = frozenset(top.law.names)
        if top.consistent or support in self.scanned:
            return models, ranking, top
        self.scanned.add(support)
        again = self.check.rescanned(top)
        if again is None:
            return models, ranking, top
        self.steps.append({"kind": "rescan", "from": list(top.law.names), "trials": 1})
        models = _best_per_support(models + [again], self.rank.criterion)
        ranking = self.rank(models)
        return models, ranking, ranking[0]

    def run(self, models, refs, refine, progress):
        """The ranking after the search (its moves in ``steps``)."""
        ranking = self.rank(models)
        steps = self.steps
        if refine and not ranking[0].criteria:
            # no regression law has a periodic orbit with contact: start from the record alone
            start = self.check.physical_start(*refs[0])
            if start is not None:
                steps.append({"kind": "physical start", "from": [], "trials": 1})
                models = models + [start]
                ranking = self.rank(models)
        while refine and ranking[0].criteria and self.more(steps, ranking):
            top = ranking[0]
            models, ranking, top = self.rescanned(top, models, ranking)
            trials, kind = self.trials(top, models)
            if not trials:
                break
            steps.append({"kind": kind, "from": list(top.law.names), "trials": len(trials)})
            tick(
                progress, "fit: stepwise search around the best support", len(steps), self.stepwise
            )
            models = _best_per_support(models + trials, self.rank.criterion)
            ranking = self.rank(models)
            if ranking[0] is top:
                break
        return ranking
