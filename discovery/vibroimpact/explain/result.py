"""The results of the missing-effect loop: one :class:`Iteration` per pass and the
:class:`ExplainResult` of :func:`~discovery.vibroimpact.explain.explain`, with the
:class:`~discovery.vibroimpact.explain.effects.Model` read back from its document.
"""

from dataclasses import dataclass, field

from ..._api._printing import fmt, readable
from ..._api._result import Result, part
from ..fit.intervals import Intervals
from ..model.law import ForceLaw, Term
from ..verify.criteria import criteria_lines
from .effects import Model
from .score import Score

__all__ = ["ExplainResult", "Iteration", "loaded_model"]


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
        held=tuple(d.get("held") or ()),
    )


def read_text(eid, read):
    """What the loop read before it began (``read``: ``{"k3", "low", "high"}`` of the
    supports the frame's own equation reads), as one phrase."""
    return (
        f"{eid} k3 = {read['k3']:.5g} [{read['low']:.5g}, {read['high']:.5g}] N/m^3 (the "
        "machine's own equations, the machine given with linear supports; held there in "
        "every refit)"
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
    scores : tuple of Score
        Every scored effect: its score test, and for refitted ones the refit's criteria
        and parameters.
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
        "scores": lambda d: tuple(Score.from_dict(s) for s in d["scores"]),
    }

    model_before: Model
    model_after: Model
    criteria_before: dict
    criteria_after: dict
    noise_floor: dict
    localisation: dict
    scores: tuple
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
            "scores": [s.to_dict() for s in self.scores],
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
        if s.effect == it.effect:
            return s.parameters or {}
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
    dropped : tuple of dict
        Effects named in an iteration and taken out of the final model because a later
        refit made them negligible (``effect``, ``parameter``, ``value``, ``reason``;
        :mod:`~discovery.vibroimpact.explain.pruning`).
    """

    KIND = "explain"
    _LOAD = {
        "iterations": lambda d: tuple(part(Iteration, it) for it in d["iterations"]),
        "final_model": lambda d: loaded_model(d["final_model"]),
        "uncertainties": lambda d: d["final_model"].get("uncertainties", {}),
        "intervals": lambda d: part(Intervals, d["final_model"].get("intervals")),
        "separability": lambda d: tuple(d.get("separability", ())),
        "dropped": lambda d: tuple(d.get("dropped", ())),
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
    dropped: tuple = ()

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
            "dropped": list(self.dropped),
            "seconds": self.seconds,
        }

    def _lines(self):
        named = list(self.final_model.effects)
        out = [
            f"final model {self.final_model}"
            + (f" with {', '.join(named)}" if named else " (nothing named)")
            + ": "
            f"{'consistent' if self.consistent else 'NOT consistent'} with the record(s)"
        ]
        if (self.settings or {}).get("start_note"):
            out.append(f"  start: {self.settings['start_note']}")
        for eid, value in (self.settings or {}).get("known", {}).items():
            kept = eid in named
            out.append(
                f"  known before the loop: {eid} {value:.4g} (given: a calibration's), "
                + (
                    "in the start, refitted with the law"
                    if kept
                    else "left out: the start with it fitted the record no better"
                )
            )
        for eid, r in (self.settings or {}).get("read", {}).items():
            out.append(f"  read before the loop: {read_text(eid, r)}")
        for k, it in enumerate(self.iterations):
            key = next((c for c in ("I2", "D") if c in it.criteria_after), None)
            gap = (
                f"{key} {fmt(it.criteria_before.get(key), 3)} -> "
                f"{fmt(it.criteria_after.get(key), 3)}"
                if key
                else ""
            )
            out.append(f"  iteration {k + 1}: {it.effect or 'nothing named'}  {gap}")
        for d in self.dropped:
            out.append(f"  taken out: {d['effect']} ({d['reason']})")
        out += criteria_lines(self.criteria, self.noise_floor, self.limits)
        out.append(f"  stopped because {self.stopped_because}")
        out.append(f"{self.seconds:.1f} s")
        return out
