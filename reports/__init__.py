"""Reports: figures (and, later, LaTeX documents) as pure functions of results."""

from .figures import identification_figure, landscape_figure

__all__ = ["landscape_figure", "identification_figure"]
