"""vibroimpact-discovery: discover and verify contact-force laws of vibro-impact machines.

Data flow: measurement (CSV) -> :class:`Measurement` -> contact samples and impulse ->
candidate :class:`Library` -> certified sparse fit (:class:`ConstrainedSparseRegressor`)
-> :class:`ForceLaw` -> full simulation to steady state -> criteria I0..I4 -> ranking
(:func:`discover`), identification, landscapes -> figures, LaTeX and ``summary.json``.
"""

from ._lazy import lazy_package

# Names are imported on first use (:mod:`discovery._lazy`): ``import discovery`` and
# ``vidi --help`` do not load numba, cvxpy, sympy and matplotlib.
_EXPORTS = {
    'CRITERIA': 'criteria',
    'evaluate_criteria': 'criteria',
    'DiscoveryResult': 'discover',
    'RankedModel': 'discover',
    'discover': 'discover',
    'Tolerances': 'dynamics',
    'simulate': 'dynamics',
    'SteadyState': 'dynamics.steady_state',
    'steady_state': 'dynamics.steady_state',
    'InputError': 'errors',
    'IntegrationError': 'errors',
    'LawSyntaxError': 'errors',
    'VidiError': 'errors',
    'VidiTypeError': 'errors',
    'ExplainResult': 'explain',
    'explain': 'explain',
    'IdentificationResult': 'identify',
    'identify': 'identify',
    'Impulse': 'impulse',
    'impulse_from_samples': 'impulse',
    'impulse_from_steady_state': 'impulse',
    'Landscape': 'landscape',
    'landscape': 'landscape',
    'ForceLaw': 'law',
    'Term': 'law',
    'Library': 'library',
    'Measurement': 'measurement',
    'synthesize': 'measurement',
    'Candidate': 'regression',
    'ConstrainedSparseRegressor': 'regression',
    'Response': 'response',
    'response': 'response',
    'ContactSamples': 'samples',
    'contact_samples': 'samples',
    'Scenario': 'scenario',
    'builtin_scenarios': 'scenario',
    'load_scenario': 'scenario',
    'Report': 'report',
    'StudyResult': 'studies.driver',
    'study': 'studies.driver',
    'load_study': 'studies.config',
    'field_record': 'studies.records',
    'Executor': 'executor',
    'make_executor': 'executor',
    'report': 'report',
}



__all__ = [
    "CRITERIA", "evaluate_criteria", "simulate", "Tolerances", "SteadyState", "steady_state",
    "InputError", "IntegrationError", "LawSyntaxError", "VidiError", "VidiTypeError",
    "IdentificationResult",
    "identify", "Impulse", "impulse_from_samples", "impulse_from_steady_state", "Landscape",
    "landscape", "ForceLaw", "Term", "Measurement", "synthesize", "Response", "response",
    "Scenario", "builtin_scenarios", "load_scenario", "discover", "DiscoveryResult",
    "RankedModel", "Library", "ConstrainedSparseRegressor", "Candidate", "ContactSamples",
    "contact_samples", "explain", "ExplainResult", "report", "Report", "study", "StudyResult",
    "load_study", "field_record", "Executor", "make_executor",
]

lazy_package(__name__, _EXPORTS)
