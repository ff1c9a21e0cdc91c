"""vibroimpact-discovery: discover and verify contact-force laws of vibro-impact machines.

Data flow: measurement (CSV) -> :class:`Measurement` -> contact samples and impulse ->
candidate :class:`Library` -> certified sparse fit (:class:`ConstrainedSparseRegressor`)
-> :class:`ForceLaw` -> full simulation to steady state -> criteria I0..I4 -> ranking
(:func:`discover`), identification, landscapes -> figures, LaTeX and ``summary.json``.
"""

from .criteria import CRITERIA, evaluate_criteria
from .discover import DiscoveryResult, RankedModel, discover
from .dynamics import Tolerances, simulate
from .dynamics.steady_state import SteadyState, steady_state
from .errors import InputError, IntegrationError, LawSyntaxError, VidiError
from .explain import ExplainResult, explain
from .identify import IdentificationResult, identify
from .impulse import Impulse, impulse_from_samples, impulse_from_steady_state
from .landscape import Landscape, landscape
from .law import ForceLaw, Term
from .library import Library
from .measurement import Measurement, synthesize
from .regression import Candidate, ConstrainedSparseRegressor
from .response import Response, response
from .samples import ContactSamples, contact_samples
from .scenario import Scenario, builtin_scenarios, load_scenario

__all__ = [
    "CRITERIA", "evaluate_criteria", "simulate", "Tolerances", "SteadyState", "steady_state",
    "InputError", "IntegrationError", "LawSyntaxError", "VidiError", "IdentificationResult",
    "identify", "Impulse", "impulse_from_samples", "impulse_from_steady_state", "Landscape",
    "landscape", "ForceLaw", "Term", "Measurement", "synthesize", "Response", "response",
    "Scenario", "builtin_scenarios", "load_scenario", "discover", "DiscoveryResult",
    "RankedModel", "Library", "ConstrainedSparseRegressor", "Candidate", "ContactSamples",
    "contact_samples", "explain", "ExplainResult",
]
