"""Effects that a later refit made negligible, taken out of the final model.

An effect named early can stand in for the one named after it (a sensor lag that smears the
onset of a law without its coupling term).  Once the later effect is added, the joint refit
takes the first one's parameter to a negligible value (:func:`.judging.negligible`), or
leaves it explaining less than the noise floor.  It is taken out when the model without it
is as consistent with every record as with it, and the result says so.
"""

import math

from ...errors import InputError, IntegrationError
from .effects import effect
from .judging import negligible
from .problem import _mean, _small_step


def drop_collapsed(run):
    """Take out of ``run.model`` every named effect (a drift's aside) that the model no
    longer needs: without it the model stays consistent with every record it was consistent
    with, and either its parameter is negligible, or the gap criterion rises by less than
    its noise floor (the bar a name had to pass, met by the model without any refit).
    Returns ``[{"effect", "parameter", "value", "reason"}]`` of the effects taken out."""
    dropped = []
    for eid in list(run.model.effects):
        eff = effect(eid)
        if "drift" in eff.phases or eid in run.model.held:
            continue  # a drift's, or held where another channel reads it
        reduced = run.model.without_effect(eff)
        try:
            with_it = run.problem.evaluations(run.model, floor=True)
            without = run.problem.evaluations(reduced, floor=True)
        except (IntegrationError, InputError):
            continue
        if not without or any(
            a.consistent and not b.consistent for a, b in zip(with_it, without, strict=True)
        ):
            continue
        reason = _why_not_needed(run, eff, with_it, without)
        if reason is None:
            continue
        name = eff.parameters[0].name
        dropped.append(
            {
                "effect": eid,
                "parameter": name,
                "value": float(run.model.value(eff)),
                "reason": reason,
            }
        )
        run.model = reduced
        run.uncertainties = {k: v for k, v in run.uncertainties.items() if k != name}
    return dropped


def _why_not_needed(run, eff, with_it, without):
    """Why the model does not need ``eff`` (its evaluations ``with_it`` and ``without``
    it), or None when it does."""
    value = run.model.value(eff)
    small = negligible(_small_step(eff, run.records))
    name, unit = eff.parameters[0].name, eff.parameters[0].unit
    if abs(value) <= small:
        return (
            f"a later refit took {name} to {value:.3g} {unit}, below {small:.3g} "
            f"{unit} (a change of the force under about 0.1 % of its peak): it stood "
            "in for an effect named after it"
        )
    key = run.criterion
    a = _mean(with_it, "criteria").get(key, math.inf)
    b = _mean(without, "criteria").get(key, math.inf)
    floor = _mean(with_it, "noise_floor").get(key, math.inf)
    if not (math.isfinite(a + b + floor) and b <= a + floor):
        return None
    # a survey machine (stiffening supports, a local minimum of k3 at the second
    # iteration) had a contact offset of -0.16 um named beside them; after the joint
    # refit the model without it was as consistent (I2 0.0087 -> 0.0094, floor 0.0075)
    return (
        f"without it ({name} {value:.3g} {unit}) the model is as consistent with the "
        f"records and {key} moves {a:.3g} -> {b:.3g}, within its noise floor {floor:.3g}: "
        "the refits after it left it nothing to explain"
    )
