"""Separability: at a model consistent with the record, whether the record can tell each
catalogue effect from it (each effect refitted with the model).
"""

from ...errors import IntegrationError
from .problem import _small_step
from .starts import _output_error
from .trials import _extend


def _separability(run, step, budget):
    """Whether the record can tell each force-history effect of ``run``'s catalogue from its
    consistent model (``step``: its criteria and noise floor): the effect is added (at its
    small step) and refitted with the model by output error with ``budget`` simulations; it
    is ``separable`` when the refit lowers the criterion by more than its noise floor.
    (Score tests are not used here: at a model already within the noise they find
    significant directions in residuals that are not white, which no refit turns into a
    better fit.)"""
    problem, records, model, criterion = run.problem, run.records, run.model, run.criterion
    before, floor, tol = step.before, step.floor, run.tolerances
    out = []
    for e in run.catalogue:
        if not e.applicable(model) or "drift" in e.phases:
            continue
        row = {
            "effect": e.id,
            "criterion": criterion,
            "before": before.get(criterion),
            "floor": floor.get(criterion),
        }
        try:
            res = _output_error(
                records, _extend(model, e, _small_step(e, records)), criterion, budget, tol
            )
            row["after"] = float(problem.value(res.law, criterion))  # as ``before``
            row["parameter"] = float(res.law.value(e)) if hasattr(res.law, "value") else None
        except IntegrationError as exc:
            row["after"], row["note"] = None, f"refit failed: {exc}"
        gain = (
            None if row["after"] is None or row["before"] is None else row["before"] - row["after"]
        )
        row["separable"] = bool(
            gain is not None and row["floor"] is not None and gain > row["floor"]
        )
        out.append(row)
    return out
