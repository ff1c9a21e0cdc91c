"""Reports: figures and LaTeX documents as pure functions of results.

Names are imported on first use (matplotlib only when a figure is drawn).
"""

from discovery._lazy import lazy_package

_EXPORTS = {
    name: "vibroimpact.figures"
    for name in (
        "explain_figure",
        "fit_impulse_figure",
        "fit_loop_figure",
        "fit_surface_figure",
        "identification_figure",
        "landscape_figure",
        "verify_figure",
        "loops_figure",
    )
}
_EXPORTS["advise_figure"] = "vibroimpact.advise_figures"

__all__ = [
    "advise_figure",
    "landscape_figure",
    "identification_figure",
    "fit_impulse_figure",
    "fit_surface_figure",
    "fit_loop_figure",
    "verify_figure",
    "explain_figure",
    "loops_figure",
]

lazy_package(__name__, _EXPORTS)
