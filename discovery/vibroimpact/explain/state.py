"""The state of one :func:`~discovery.vibroimpact.explain.explain` call: its fixed inputs and
its loop (:class:`_Run`), and one iteration's view of the current model (:class:`_Step`).
"""

from dataclasses import dataclass, field

from .effects import Model
from .problem import OnRecords, _Drift, _drift_free, _mean, _Problem, _with_drift
from .result import Iteration
from .score import Score


@dataclass
class _Run(OnRecords):
    """One :func:`explain` call: its fixed inputs and the state of its loop."""

    problem: _Problem
    records: list
    catalogue: list
    criterion: str
    alpha: float
    budget: int
    tolerances: object
    drift: _Drift | None
    regress: object
    workers: int | None
    executor: object
    max_refits: int
    meas_first: object
    model: Model | None = None
    uncertainties: dict = field(default_factory=dict)
    iterations: list = field(default_factory=list)
    separability: tuple = ()
    stopped: str = ""

    def drift_free(self, model):
        return _drift_free(
            self.drift, model, self.records, self.alpha / max(len(self.catalogue), 1)
        )

    def step(self):
        """The current model verified against every record (:class:`_Step`)."""
        evs = self.problem.evaluations(self.model, floor=True)
        before, floor = _with_drift(
            _mean(evs, "criteria"), _mean(evs, "noise_floor"), self.drift, self.model
        )
        return _Step(
            model=self.model,
            evaluations=evs,
            before=before,
            floor=floor,
            cycle_ok=all(e.consistent for e in evs),
            measured=self.records[0][1].impulse,
        )


@dataclass
class _Step:
    """One iteration's view of the current model: its evaluations on every record, their
    mean criteria and noise floor (the drift's ``D`` added), whether every record's cycle is
    consistent, the first record's measured cycle, and, once made, the localisation and the
    screening."""

    model: Model
    evaluations: list
    before: dict
    floor: dict
    cycle_ok: bool
    measured: object
    loc: dict | None = None
    screening: object = None

    def iteration(
        self,
        *,
        model_after,
        criteria_after,
        evidence,
        simulated_after,
        effect=None,
        equivalent=(),
    ):
        """The :class:`Iteration` from this step to ``model_after`` (``effect`` and the
        ``equivalent`` ones when an effect is named)."""
        return Iteration(
            model_before=self.model,
            model_after=model_after,
            criteria_before=self.before,
            criteria_after=criteria_after,
            noise_floor=self.floor,
            localisation=self.loc,
            scores=tuple(Score.from_dict(s) for s in self.screening.scores),
            effect=effect,
            evidence=evidence,
            equivalent=list(equivalent),
            simulated_before=self.evaluations[0].simulated,
            simulated_after=simulated_after,
            measured=self.measured,
        )
