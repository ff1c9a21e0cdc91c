"""The missing-effect workflow: localise the disagreement of a model with a record, name the
missing physical effect from a catalogue, add it, refit, re-verify.

record + model -> :func:`localise` (phases, (zeta, dzeta) plane, grid motion, drift) ->
score tests of the catalogue's effects (:data:`EFFECTS`) -> refit -> :func:`explain`.
"""

from ..._startup._lazy import lazy_package

_EXPORTS = {
    "EFFECTS": "effects",
    "Effect": "effects",
    "Model": "effects",
    "effect": "effects",
    "first_order_lag": "effects",
    "first_order_lag_at": "effects",
    "ExplainResult": "loop",
    "Iteration": "loop",
    "Score": "score",
    "explain": "loop",
    "ExplainSettings": "loop",
    "start_law": "loop",
    "PHASES": "disagreement",
    "localise": "disagreement",
}

__all__ = [
    "explain",
    "ExplainSettings",
    "ExplainResult",
    "Iteration",
    "Score",
    "EFFECTS",
    "Effect",
    "Model",
    "effect",
    "first_order_lag",
    "first_order_lag_at",
    "localise",
    "PHASES",
    "start_law",
]

lazy_package(__name__, _EXPORTS)
