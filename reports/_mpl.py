"""Figures drawn on ``matplotlib.figure.Figure`` objects: no pyplot, so drawing a report
never switches the backend of a notebook or a GUI session that imported ``discovery``."""

import contextlib
import functools

import matplotlib as mpl
import numpy as np
from matplotlib import colormaps
from matplotlib.figure import Figure

from discovery.outputs import hand_off

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
    """The figure as ``stem.png`` and ``stem.pdf``, each cropped to its artists with
    :rc:`savefig.pad_inches` round them (``bbox_inches="tight"``); returns both paths.

    Laid out once: ``savefig(..., bbox_inches="tight")`` lays a figure out and draws it
    twice per file (once to find its extent, once to print it), each time with a new
    renderer, so its layout engine runs twice and every text is measured and every
    mathtext label parsed again (matplotlib caches both per renderer). Here the figure is
    laid out once by its layout engine on an Agg canvas at the PNG's ``dpi``, its extent
    read from that layout's text metrics, and drawn once: on that canvas, the PNG cut
    from it, or, when an artist runs past the figure's edge, by savefig within the extent
    (the explain figure's legend; it was drawn twice so). The PDF is printed in the same
    layout: within a command's output directory by a forked child while the command goes
    on (the directory waits for it: :mod:`discovery._files._handoff`), else before this
    returns. The figure is left as it was given (its canvas, dpi and layout engine).
    """
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    paths = [f"{stem}.png", f"{stem}.pdf"]
    own_dpi, engine, canvas = fig.dpi, fig.get_layout_engine(), fig.canvas
    try:
        agg = FigureCanvasAgg(fig)  # the figure's canvas until the end of the save
        fig.set_dpi(dpi)
        _lay_out(fig)  # as the canvas's draw would, with its renderer's text metrics
        _set_layout_engine(fig, None)  # laid out: the PNG and the PDF are drawn in this layout
        # the PDF printed by a forked child while the PNG is drawn here, where it may
        # (discovery._files._handoff), else here and now: the same file either way. The
        # PDF backend is loaded here first (0.1-0.5 s, its fonts' subsetting), once for
        # every child, not by each
        import matplotlib.backends.backend_pdf  # noqa: F401

        hand_off(paths[1], functools.partial(_print_pdf, fig, paths[1], own_dpi))
        # the extent before any draw: the layout measured every text on this renderer
        tight = fig.get_tightbbox(agg.get_renderer())
        bbox = tight.padded(mpl.rcParams["savefig.pad_inches"])
        if _drawn_whole(fig, tight):
            agg.draw()
            _write_png(paths[0], agg, bbox, dpi)
        else:  # savefig draws it once, past the figure's edge or on the user's background
            fig.savefig(paths[0], dpi=dpi, bbox_inches=bbox)
    finally:
        fig.set_dpi(own_dpi)
        _set_layout_engine(fig, engine)
        fig.set_canvas(canvas)
    return paths


def _lay_out(fig):
    """Run ``fig``'s layout engine on its canvas's renderer: the first step of
    ``Figure.draw`` (which, as there, lets a ValueError of a layout that cannot be met
    pass), taken apart so that the PNG and the PDF are drawn in the one layout."""
    engine = fig.get_layout_engine()
    if fig.axes and engine is not None:
        with contextlib.suppress(ValueError):
            engine.execute(fig)


def _print_pdf(fig, path, dpi):
    """``fig`` as the PDF ``path`` in the layout it has (no layout engine run), at ``dpi``
    (its rasterized parts, if any), cut to its own extent: a PDF's text is measured
    unhinted, up to a few per cent wider than the PNG's, and a long line at the edge would
    lose its end.  The figure is left as it was given."""
    own_dpi, engine = fig.dpi, fig.get_layout_engine()
    try:
        fig.set_dpi(dpi)
        _set_layout_engine(fig, None)
        fig.savefig(path, bbox_inches="tight")
    finally:
        fig.set_dpi(own_dpi)
        _set_layout_engine(fig, engine)


def _set_layout_engine(fig, engine):
    """``fig``'s layout engine set to ``engine``, None included (which
    ``Figure.set_layout_engine`` reads as "the rcParams' default")."""
    with mpl.rc_context({"figure.autolayout": False, "figure.constrained_layout.use": False}):
        fig.set_layout_engine(engine)


def _drawn_whole(fig, tight):
    """Whether the figure's canvas holds every pixel savefig would write: its artists
    (within ``tight``, inches) inside its edges, and the figure's own background (the
    default rcParams) round them."""
    rc = mpl.rcParams
    w, h = fig.get_size_inches()
    return (
        tight.x0 >= 0.0
        and tight.y0 >= 0.0
        and tight.x1 <= w
        and tight.y1 <= h
        and not rc["savefig.transparent"]
        and str(rc["savefig.facecolor"]) == "auto"
        and str(rc["savefig.edgecolor"]) == "auto"
    )


def _write_png(path, agg, bbox, dpi):
    """The pixels of ``agg`` (drawn at ``dpi``) within ``bbox`` (inches) as a PNG: what
    ``savefig(path, dpi=dpi, bbox_inches=bbox)`` writes, to within a pixel's shift; the part
    of ``bbox`` past the figure's edge painted in its background."""
    from matplotlib.colors import to_rgba
    from matplotlib.image import imsave

    full = np.asarray(agg.buffer_rgba())
    rows, cols = full.shape[:2]
    w, h = int(bbox.width * dpi), int(bbox.height * dpi)
    # the figure's pixel under the output's top left corner (rows count from the top)
    i0, j0 = round(rows - bbox.y0 * dpi) - h, round(bbox.x0 * dpi)
    out = np.empty((h, w, 4), dtype=np.uint8)
    out[...] = np.round(np.asarray(to_rgba(agg.figure.get_facecolor())) * 255)
    top, left = max(0, -i0), max(0, -j0)
    bottom, right = min(h, rows - i0), min(w, cols - j0)
    if bottom > top and right > left:
        out[top:bottom, left:right] = full[top + i0 : bottom + i0, left + j0 : right + j0]
    imsave(path, out, format="png", dpi=dpi)


def colormap(name):
    """A registered colormap by name."""
    return colormaps[name]
