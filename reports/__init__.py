"""Reports: figures and LaTeX documents as pure functions of results.

Names are imported on first use (PEP 562; matplotlib only when a figure is drawn).
"""

import importlib

_EXPORTS = {
    "explain_figure": "vibroimpact.explain_figures",
    "fit_impulse_figure": "vibroimpact.fit_figures",
    "fit_loop_figure": "vibroimpact.fit_figures",
    "fit_surface_figure": "vibroimpact.fit_figures",
    "identification_figure": "vibroimpact.figures",
    "landscape_figure": "vibroimpact.figures",
    "verify_figure": "vibroimpact.verify_figures",
    "loops_figure": "vibroimpact.verify_figures",
}
_EXPORTS["advise_figure"] = "vibroimpact.advise_figures"
_EXPORTS["calibration_figure"] = "vibroimpact.calibration_figures"

__all__ = [
    "advise_figure",
    "calibration_figure",
    "landscape_figure",
    "identification_figure",
    "fit_impulse_figure",
    "fit_surface_figure",
    "fit_loop_figure",
    "verify_figure",
    "explain_figure",
    "loops_figure",
]


def __getattr__(name):
    if name not in _EXPORTS:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{_EXPORTS[name]}", __name__), name)
    globals()[name] = value
    return value


def __dir__():
    return sorted(set(globals()) | set(_EXPORTS))
