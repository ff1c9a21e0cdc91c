"""vibroimpact-discovery: discover and verify contact-force laws of vibro-impact machines.

Data flow: measurement (CSV) -> :class:`Measurement` -> contact samples and impulse ->
candidate :class:`Library` -> certified sparse fit (:class:`ConstrainedSparseRegressor`)
-> :class:`ForceLaw` -> full simulation to steady state -> criteria I0..I4 -> ranking
(:func:`discover`), identification, landscapes -> figures, LaTeX and ``summary.json``.
"""

import importlib
import sys
import types

# Names are imported on first use (PEP 562), so ``import discovery`` and ``vidi --help`` do not
# load numba, cvxpy, sympy and matplotlib.  Five functions share their name with the
# submodule that defines them (``discovery.explain`` ...): importing that submodule binds
# the package attribute to the module, so those five are properties of the package's
# class and always give the function.
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
    'report': 'report',
}
_SHADOWED = ("discover", "explain", "identify", "landscape", "report", "response")


def _export(name):
    return getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)


def __getattr__(name):
    if name not in _EXPORTS:
        raise AttributeError(f"module 'discovery' has no attribute {name!r}")
    value = _export(name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))


class _Package(types.ModuleType):
    pass


def _function_property(name):
    def get(module):
        return _export(name)

    def set_(module, value):  # the import system binds the submodule here: keep the function
        pass

    return property(get, set_)


for _name in _SHADOWED:
    setattr(_Package, _name, _function_property(_name))
sys.modules[__name__].__class__ = _Package

__all__ = [
    "CRITERIA", "evaluate_criteria", "simulate", "Tolerances", "SteadyState", "steady_state",
    "InputError", "IntegrationError", "LawSyntaxError", "VidiError", "VidiTypeError",
    "IdentificationResult",
    "identify", "Impulse", "impulse_from_samples", "impulse_from_steady_state", "Landscape",
    "landscape", "ForceLaw", "Term", "Measurement", "synthesize", "Response", "response",
    "Scenario", "builtin_scenarios", "load_scenario", "discover", "DiscoveryResult",
    "RankedModel", "Library", "ConstrainedSparseRegressor", "Candidate", "ContactSamples",
    "contact_samples", "explain", "ExplainResult", "report", "Report",
]
