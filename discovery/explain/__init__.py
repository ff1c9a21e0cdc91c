"""The missing-effect workflow: localise the disagreement of a model with a record, name the
missing physical effect from a catalogue, add it, refit, re-verify.

record + model -> :func:`localise` (phases, (zeta, dzeta) plane, grid motion, drift) ->
score tests of the catalogue's effects (:data:`EFFECTS`) -> refit -> :func:`explain`.
"""

from .effects import EFFECTS, Effect, Model, effect, first_order_lag
from .explain import ExplainResult, Iteration, explain, start_law
from .localise import PHASES, localise

__all__ = ["explain", "ExplainResult", "Iteration", "EFFECTS", "Effect", "Model", "effect",
           "first_order_lag", "localise", "PHASES", "start_law"]
