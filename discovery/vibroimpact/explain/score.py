"""One effect's record in an iteration of the missing-effect loop: its score test and, when
it was refitted, what the refit reached (:attr:`~discovery.vibroimpact.explain.Iteration.scores`).

The screening and the refits fill a working ``dict`` per effect as they go
(:mod:`~discovery.vibroimpact.explain.screening`, :mod:`~discovery.vibroimpact.explain.trials`);
the iteration keeps each as a :class:`Score`.  Its document is that dict: the keys the loop
set, no others (a field it never set is ``None`` here and absent there), so results saved
before the records were typed load as they are.
"""

from dataclasses import dataclass, fields

from ..._api._printing import fmt

__all__ = ["Score"]

#: the fields always in a score's document (``lm`` and ``p`` are None without a score test)
_ALWAYS = ("effect", "lm", "p", "significant")


@dataclass(frozen=True)
class Score:
    """An effect's score test in one iteration, and its refit's outcome when refitted.

    Attributes
    ----------
    effect : str
        The catalogue id.
    lm, p : float or None
        The score (Lagrange-multiplier) statistic and its p-value; None when the effect's
        sensitivity could not be simulated (its ``note`` says so).
    significant : bool
        ``p`` below the family-wise level of the iteration.
    direction : float or None
        The score test's step of the effect's parameter (where a refit starts).
    channel : str or None
        ``"drift"`` (scored on the drift channel) or ``"blocks"`` (a drift scored on the
        records' blocks); None for the averaged cycle.
    signature_agrees : bool or None
        The localisation shows the effect's signature.
    note : str or None
        Why the effect was not refitted or its refit not taken.
    criteria_after : dict or None
        Mean criteria of the refitted model (refitted effects only).
    consistent_after : bool or None
        The refitted model is consistent with every record.
    parameters : dict or None
        ``{name: value}`` of the effect's parameters after the refit.
    repulsive, in_bounds, motion_worse, force_worse : bool or None
        The refit's checks (:mod:`~discovery.vibroimpact.explain.trials`).
    gap : str or None
        The criterion the refit was judged on (``"I2"``, ``"I5"`` or ``"D"``).
    negligible : float or None
        The largest value of the effect's parameter that is negligible.
    beats_law_refit, present : bool or None
        The refit beats the law refitted alone by the noise margin (or by the verdict);
        the effect's parameter is not within two standard errors of 0 (the trials judged).
    law_alone_inconsistent : float or None
        Where the refit beat the law refitted alone by the verdict (within the noise margin,
        lower, at the noise floor and consistent with every record where that law is not):
        that law's gap criterion.
    """

    effect: str
    lm: float | None = None
    p: float | None = None
    significant: bool = False
    direction: float | None = None
    channel: str | None = None
    signature_agrees: bool | None = None
    note: str | None = None
    criteria_after: dict | None = None
    consistent_after: bool | None = None
    parameters: dict | None = None
    repulsive: bool | None = None
    in_bounds: bool | None = None
    gap: str | None = None
    negligible: float | None = None
    motion_worse: bool | None = None
    force_worse: bool | None = None
    beats_law_refit: bool | None = None
    present: bool | None = None
    law_alone_inconsistent: float | None = None

    @classmethod
    def from_dict(cls, d):
        """The score a document (or the loop's working dict) holds; unknown keys are an
        error (a misspelt key would be dropped silently)."""
        names = {f.name for f in fields(cls)}
        unknown = set(d) - names
        if unknown:
            raise KeyError(f"a score has no field(s) {sorted(unknown)}")
        return cls(**d)

    def to_dict(self):
        """The document: the fields the loop set (the ``_ALWAYS`` ones, and the others that
        are not None)."""
        out = {}
        for f in fields(self):
            v = getattr(self, f.name)
            if f.name in _ALWAYS or v is not None:
                out[f.name] = dict(v) if isinstance(v, dict) else v
        return out

    @property
    def refitted(self):
        """Whether the effect was refitted (its refit reached criteria)."""
        return bool(self.criteria_after)

    def __str__(self):
        test = (
            f"LM {fmt(self.lm, 3)}, p {fmt(self.p, 2)}"
            + (" (significant)" if self.significant else "")
            if self.lm is not None
            else "no score test"
        )
        out = f"Score of {self.effect}: {test}"
        if self.refitted and self.gap in self.criteria_after:
            out += f"; refitted: {self.gap} {fmt(self.criteria_after[self.gap], 3)}"
        if self.note:
            out += f"; {self.note}"
        return out
