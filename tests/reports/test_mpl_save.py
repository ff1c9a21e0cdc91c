"""``reports._mpl.save``: a figure laid out once and drawn once for its PNG writes what
``savefig(..., bbox_inches="tight")`` writes."""

import re
from pathlib import Path

import numpy as np
import pytest


def _figure(past_the_edge=False):
    """A constrained figure with mathtext in its legend; with a text past its right edge."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4.0, 3.0), layout="constrained")
    ax = fig.subplots()
    ax.plot(np.linspace(0.0, 1.0, 50), np.linspace(0.0, 1.0, 50) ** 2, label=r"$\dot{\zeta}_{+}$")
    ax.set_xlabel(r"penetration $\zeta$ [mm]")
    ax.legend(loc="best")
    if past_the_edge:
        fig.text(0.75, 0.5, "a note that runs past the right edge")
    return fig


def _media_box(path):
    box = re.search(rb"/MediaBox \[ *0 0 ([\d.]+) ([\d.]+) *\]", Path(path).read_bytes())
    return float(box[1]), float(box[2])


@pytest.mark.parametrize(
    "bounds", [(-0.25, -0.5, 4.5, 3.75), (0.5, 0.25, 2.5, 2.0), (-0.25, 0.25, 3.0, 3.5)]
)
def test_the_png_cut_from_the_canvas_is_what_savefig_writes(tmp_path, bounds):
    """A box (inches) on whole pixels, past the figure's edges or inside them: the pixels cut
    from the drawn canvas, the rest painted in the figure's background, are savefig's."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.image import imread
    from matplotlib.transforms import Bbox

    from reports._mpl import _write_png

    bbox, dpi = Bbox.from_bounds(*bounds), 100
    fig = _figure()
    agg = FigureCanvasAgg(fig)
    fig.set_dpi(dpi)
    agg.draw()
    _write_png(tmp_path / "cut.png", agg, bbox, dpi)
    ref = _figure()
    ref.set_dpi(dpi)
    FigureCanvasAgg(ref).draw()  # laid out as the canvas was, then kept so
    ref.set_layout_engine("none")
    ref.savefig(tmp_path / "ref.png", dpi=dpi, bbox_inches=bbox)
    got, want = imread(tmp_path / "cut.png"), imread(tmp_path / "ref.png")
    assert got.shape == want.shape == (int(bbox.height * dpi), int(bbox.width * dpi), 4)
    assert np.abs(got - want).max() <= 1.5 / 255


@pytest.mark.parametrize("past_the_edge", [False, True])
def test_save_writes_what_a_tight_savefig_writes(tmp_path, past_the_edge):
    """The PNG (cut from the one drawing, or drawn by savefig when a text runs past the edge) is
    savefig's tight PNG to within a pixel's shift, the PDF's page is savefig's, and the
    figure is left as it was given (canvas, dpi, layout engine)."""
    from matplotlib.image import imread

    from reports._mpl import save

    fig = _figure(past_the_edge)
    canvas, dpi, engine = fig.canvas, fig.dpi, fig.get_layout_engine()
    png, pdf = save(fig, str(tmp_path / "saved"))
    assert fig.canvas is canvas and fig.dpi == dpi and fig.get_layout_engine() is engine
    ref = _figure(past_the_edge)
    ref.savefig(tmp_path / "ref.png", dpi=130, bbox_inches="tight")
    ref.savefig(tmp_path / "ref.pdf", bbox_inches="tight")
    got, want = imread(png), imread(tmp_path / "ref.png")
    assert got.shape == want.shape
    # antialiasing moves with the sub-pixel shift; a wrong cut or a blank part moves more
    assert np.mean(np.abs(got - want).max(axis=-1) > 0.5) < 0.03
    assert np.all(np.abs(np.subtract(_media_box(pdf), _media_box(tmp_path / "ref.pdf"))) < 1.5)
    if past_the_edge:  # the note's end is drawn: ink right of the figure's edge (the cut
        # begins at most savefig.pad_inches left of the figure's)
        edge = int((fig.get_figwidth() + 0.1) * 130) + 1
        assert np.any(got[:, edge:, :3] < 0.5)


@pytest.mark.parametrize("past_the_edge", [False, True])
def test_the_png_is_drawn_once(tmp_path, monkeypatch, past_the_edge):
    """One drawing on an Agg renderer per PNG, whether cut from the canvas or written by
    savefig past the figure's edge: its extent is read from the layout's text metrics
    before anything is drawn (it was drawn twice past the edge, 0.1 s of explain's figure)."""
    from matplotlib.backends.backend_agg import RendererAgg
    from matplotlib.figure import Figure

    from reports._mpl import save

    draws = []
    draw = Figure.draw

    def counted(fig, renderer):
        draws.append(isinstance(renderer, RendererAgg))
        return draw(fig, renderer)

    monkeypatch.setattr(Figure, "draw", counted)
    save(_figure(past_the_edge), str(tmp_path / "saved"))
    assert sum(draws) == 1
