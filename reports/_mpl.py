"""Figures drawn on ``matplotlib.figure.Figure`` objects: no pyplot, so drawing a report
never switches the backend of a notebook or a GUI session that imported ``discovery``."""

from matplotlib import colormaps
from matplotlib.figure import Figure

__all__ = ["subplots", "save", "colormap", "PRINT_WIDTH", "MIN_TEXT_PT", "print_sizes"]

_FIGURE_KEYS = ("figsize", "dpi", "layout")

#: inches: the width a report figure is drawn at. The text width of a report page (letter
#: paper, 2.2 cm margins) is 6.77 in; a figure is saved with 0.1 in of white round its
#: artists, so one drawn this wide (nothing past its edges) is printed at its own size or
#: larger, its text at least as large as drawn
PRINT_WIDTH = 6.5

#: points: the smallest text a figure may print (at the size the report places it)
MIN_TEXT_PT = 7.0


def print_sizes():
    """An rc context for a figure drawn at :data:`PRINT_WIDTH`: text of 7 to 8 pt."""
    import matplotlib

    return matplotlib.rc_context(
        {
            "font.size": 8,
            "axes.titlesize": 8,
            "axes.labelsize": 8,
            "xtick.labelsize": 7,
            "ytick.labelsize": 7,
            "legend.fontsize": 7,
        }
    )


def figure(**kwargs):
    """A standalone Figure (``figsize``, ``dpi``, ``layout``), for a grid of its own."""
    return Figure(**kwargs)


def subplots(nrows=1, ncols=1, **kwargs):
    """``(figure, axes)`` like ``pyplot.subplots``, on a standalone Figure."""
    fig = Figure(**{k: kwargs.pop(k) for k in _FIGURE_KEYS if k in kwargs})
    return fig, fig.subplots(nrows, ncols, **kwargs)


def save(fig, stem, dpi=130):
    """The figure as ``stem.png`` and ``stem.pdf``; returns both paths."""
    paths = [f"{stem}.png", f"{stem}.pdf"]
    fig.savefig(paths[0], dpi=dpi, bbox_inches="tight")
    fig.savefig(paths[1], bbox_inches="tight")
    return paths


def colormap(name):
    """A registered colormap by name."""
    return colormaps[name]
