"""The outcome of the missing-effect workflow for Ueda's oscillators: one
:class:`Iteration` per pass of the loop, and the :class:`Explanation`
(:func:`discovery.ueda.explain`)."""

from dataclasses import dataclass, field

from .._api._printing import generic_lines, readable
from .._api._result import Result, part
from .effects import EFFECTS, effect_dict
from .polynomial import ForcedPolynomial

__all__ = ["Iteration", "Explanation", "model_dict"]


@dataclass(frozen=True, eq=False)
class Iteration(Result):
    """One pass of the loop.

    Attributes
    ----------
    effect : str or None
        The effect named (None when this pass stopped the loop).
    evidence : dict
        For the named effect: ``lm`` (score statistic), ``p``, ``gate`` (the Bonferroni
        level), ``share`` (fraction of the weak-form residual's sum of squares its column
        explains), ``text``; otherwise ``text`` only.
    scores : list of dict
        Every scored effect: ``effect``, ``terms``, ``lm``, ``p``, ``share``,
        ``direction`` (the coefficient it would take), ``significant``, ``in_bounds``.
    criteria_before, criteria_after : dict
        ``residual_rms`` (weak form, relative to ``b``), ``energy_distance``,
        ``floor_q95``, ``energy_consistent``, ``regime_record``, ``regime_model``,
        ``regime_agrees``, ``lyapunov``, ``consistent``, ``diverged`` (the simulation
        entries only when simulating).
    parameters : dict
        ``{term: {"value", "stderr"}}`` of the added terms after the refit.
    model_before, model_after : ForcedPolynomial
    verification_before, verification_after : Verification or None
        The simulations behind the criteria (for figures).
    equivalent : list of str
        Significant effects the record cannot tell from the named one: added instead,
        each leaves the named one insignificant, and beside it each is insignificant.
    """

    KIND = "ueda-explain-iteration"
    _LOAD = {
        "model_before": lambda d: ForcedPolynomial.from_dict(d.get("model_before")),
        "model_after": lambda d: ForcedPolynomial.from_dict(d.get("model_after")),
    }

    effect: str | None
    evidence: dict
    scores: list
    criteria_before: dict
    criteria_after: dict
    parameters: dict
    model_before: ForcedPolynomial
    model_after: ForcedPolynomial
    verification_before: object = field(default=None, repr=False)
    verification_after: object = field(default=None, repr=False)
    equivalent: list = field(default_factory=list)

    def as_dict(self):
        return {
            "effect": self.effect,
            "evidence": self.evidence,
            "scores": self.scores,
            "equivalent": self.equivalent,
            "criteria_before": self.criteria_before,
            "criteria_after": self.criteria_after,
            "parameters": self.parameters,
            "model_before": model_dict(self.model_before),
            "model_after": model_dict(self.model_after),
        }


@readable
@dataclass(frozen=True, eq=False)
class Explanation(Result):
    """Outcome of :func:`explain`.

    Attributes
    ----------
    iterations : tuple of Iteration
    start_model, final_model : ForcedPolynomial
    start_terms, final_terms : tuple of str
    coefficients, standard_errors : dict
        Of the final model's terms and the forcing (weak-form least squares; standard
        errors from the autocorrelation-consistent sandwich).
    criteria_start, criteria : dict
        Of the start and the final model (see :class:`Iteration`).
    noise_floor : dict
        ``residual_rms`` (the relative weak-form residual that white measurement noise of
        the estimated sd alone gives), ``energy_distance_q95`` and ``_median`` (the record's
        random halves), ``noise_sd``, ``noise_fraction_of_range``.
    consistent : bool
        The final model's attractor is consistent with the record's (None without
        simulation).
    stopped_because : str
    """

    KIND = "ueda-explain"
    _LOAD = {
        "iterations": lambda d: tuple(part(Iteration, it) for it in d["iterations"]),
        "start_model": lambda d: ForcedPolynomial.from_dict(d.get("start_model")),
        "final_model": lambda d: ForcedPolynomial.from_dict(d.get("final_model")),
        "start_terms": lambda d: tuple(d["start_terms"]),
        "final_terms": lambda d: tuple(d["final_terms"]),
        # the final model's coefficients are saved with the final model
        "coefficients": lambda d: d["final_model"].get("coefficients"),
        "standard_errors": lambda d: d["final_model"].get("standard_errors"),
        "settings": lambda d: (
            d["method"] if isinstance(d.get("method"), dict) else d.get("settings")
        ),
    }

    iterations: tuple
    start_model: ForcedPolynomial
    final_model: ForcedPolynomial
    start_terms: tuple
    final_terms: tuple
    coefficients: dict
    standard_errors: dict
    criteria_start: dict
    criteria: dict
    noise_floor: dict
    consistent: object
    stopped_because: str
    seconds: float = 0.0
    settings: dict = field(default_factory=dict)
    start_verification: object = field(default=None, repr=False)
    final_verification: object = field(default=None, repr=False)

    @property
    def effects_added(self):
        """Ids of the effects named, in order."""
        return tuple(it.effect for it in self.iterations if it.effect)

    @property
    def gap(self):
        """The start model's gap against the final model's: ``{criterion: {"before",
        "after", "ratio"}}`` for the weak-form residual and the energy distance."""
        out = {}
        for k in ("residual_rms", "energy_distance"):
            if k in self.criteria_start:
                a, b = self.criteria_start[k], self.criteria[k]
                out[k] = {"before": a, "after": b, "ratio": (a / b) if b > 0 else float("inf")}
        return out

    def as_dict(self, settings_key="settings"):
        """The document's keys; ``settings_key`` names the method's settings (the command
        line keeps ``settings`` for its options)."""
        return {
            "start_terms": list(self.start_terms),
            "final_terms": list(self.final_terms),
            "effects_added": list(self.effects_added),
            "iterations": [it.as_dict() for it in self.iterations],
            "start_model": model_dict(self.start_model),
            "final_model": {
                **model_dict(self.final_model),
                "coefficients": self.coefficients,
                "standard_errors": self.standard_errors,
            },
            "criteria_start": self.criteria_start,
            "criteria": self.criteria,
            "gap": self.gap,
            "noise_floor": self.noise_floor,
            "consistent": self.consistent,
            "stopped_because": self.stopped_because,
            "catalogue": [
                effect_dict(e) for e in EFFECTS if e.id in self.settings.get("effects", ())
            ],
            settings_key: self.settings,
            "seconds": self.seconds,
        }

    def _lines(self):
        return generic_lines(self)


def model_dict(m):
    """An equation as a dict: its terms, forcing and text."""
    return {**m.as_dict(), "equation": m.text()}
