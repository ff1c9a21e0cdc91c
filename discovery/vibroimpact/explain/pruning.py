"""Effects that a later refit made negligible, taken out of the final model.

An effect named early can stand in for the one named after it (a sensor lag that smears the
onset of a law without its coupling term).  Once the later effect is added, the joint refit
takes the first one's parameter to a negligible value (:func:`.judging.negligible`).  It is
taken out when the model without it is as consistent with every record as with it, and the
result says so.
"""

from ...errors import InputError, IntegrationError
from .effects import effect
from .judging import negligible
from .problem import _small_step


def drop_collapsed(run):
    """Take out of ``run.model`` every named effect whose parameter is negligible, when the
    model without it stays consistent with every record it was consistent with.  Returns
    ``[{"effect", "parameter", "value", "reason"}]`` of the effects taken out."""
    dropped = []
    for eid in list(run.model.effects):
        eff = effect(eid)
        if "drift" in eff.phases:
            continue
        value = run.model.value(eff)
        small = negligible(_small_step(eff, run.records))
        if abs(value) > small:
            continue
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
        name, unit = eff.parameters[0].name, eff.parameters[0].unit
        dropped.append(
            {
                "effect": eid,
                "parameter": name,
                "value": float(value),
                "reason": (
                    f"a later refit took {name} to {value:.3g} {unit}, below {small:.3g} "
                    f"{unit} (a change of the force under about 0.1 % of its peak): it stood "
                    "in for an effect named after it"
                ),
            }
        )
        run.model = reduced
        run.uncertainties = {k: v for k, v in run.uncertainties.items() if k != name}
    return dropped
