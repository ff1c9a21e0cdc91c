"""Reports: figures and LaTeX documents as pure functions of results."""

from .figures import (
    explain_figure,
    fit_impulse_figure,
    fit_loop_figure,
    fit_surface_figure,
    identification_figure,
    landscape_figure,
    verify_figure,
)

__all__ = ["landscape_figure", "identification_figure", "fit_impulse_figure",
           "fit_surface_figure", "fit_loop_figure", "verify_figure", "explain_figure"]
