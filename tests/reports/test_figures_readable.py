"""Every figure the report commands make, read back as a reader meets it on the page.

A figure is drawn again (the same matplotlib Figure its command saved) and what was drawn
is read: every text's size at the scale the report prints the figure (its PDF's size
against the space the LaTeX gives it), the tick labels of every axis (all different), and
every legend (inside the figure). The figures come from the small runs of ``conftest.py``;
a few cases those runs do not reach (a search that barely moves, a landscape with I5, the
named contact models) are drawn from results made here.
"""

import re
from pathlib import Path

import numpy as np
import pytest

from reports.document import report

#: points: the text width and height of a report page (letter paper, 2.2 cm margins)
LINE_WIDTH_PT, TEXT_HEIGHT_PT = 612 - 2 * 62.362, 792 - 2 * 62.362
MIN_PT = 7.0


def _placements(tex):
    """``{figure file: fraction of the text height}`` of the figures a LaTeX text places."""
    found = re.findall(r"height=([0-9.]+)\\textheight,keepaspectratio\]\{([^}]+)\}", tex)
    return {name: float(frac) for frac, name in found}


def _pdf_size(path):
    """A figure PDF's page size in points (its MediaBox)."""
    box = re.search(rb"/MediaBox \[ *0 0 ([\d.]+) ([\d.]+) *\]", Path(path).read_bytes())
    return float(box[1]), float(box[2])


def _scale(pdf, fraction):
    """How much LaTeX scales a figure placed ``width=\\linewidth,height=fraction
    \\textheight,keepaspectratio``."""
    w, h = _pdf_size(pdf)
    return min(LINE_WIDTH_PT / w, fraction * TEXT_HEIGHT_PT / h)


def _draw(fig):
    """Draw ``fig`` on an Agg canvas: ``(renderer, the texts drawn)``."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.text import Text

    drawn = []
    draw = Text.draw

    def seen(self, renderer):
        if self.get_visible() and self.get_text().strip():
            drawn.append(self)
        return draw(self, renderer)

    canvas = FigureCanvasAgg(fig)
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Text, "draw", seen)
        canvas.draw()
    return canvas.get_renderer(), drawn


def _axis_name(ax, axis):
    return f"{ax.get_title() or ax.get_ylabel() or ax.get_label()!r} {axis.axis_name}-axis"


def defects(fig, scale=1.0):
    """What a reader could not read in ``fig`` printed at ``scale``: a text under 7 pt,
    tick labels that repeat on one axis, a legend past the figure's edge."""
    renderer, texts = _draw(fig)
    shown = {id(t) for t in texts}
    out = [
        f"{t.get_text()[:40]!r} at {t.get_fontsize() * scale:.1f} pt"
        for t in texts
        if t.get_fontsize() * scale < MIN_PT - 1e-6
    ]
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            labels = []
            for tick in axis.get_major_ticks() + axis.get_minor_ticks():
                drawn = [t for t in (tick.label1, tick.label2) if id(t) in shown]
                if drawn:
                    labels.append(drawn[0].get_text())
            if len(set(labels)) < len(labels):
                out.append(f"{_axis_name(ax, axis)} repeats tick labels {labels}")
    box = fig.bbox.padded(1.0)
    legends = [ax.get_legend() for ax in fig.axes] + list(fig.legends)
    for leg in (lg for lg in legends if lg is not None and lg.get_visible()):
        ext = leg.get_window_extent(renderer)
        if not (box.x0 <= ext.x0 and ext.x1 <= box.x1 and box.y0 <= ext.y0 and ext.y1 <= box.y1):
            out.append(f"a legend at {ext.bounds} past the figure's edge {fig.bbox.bounds}")
    return out


def test_the_reading_finds_what_a_reader_cannot_read():
    """The check itself: a 5 pt legend, six equal tick labels and a legend past the edge
    are each found; the same figure drawn right passes."""
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4, 3))
    ax = fig.subplots()
    ax.plot([0, 1, 2], [2.055371e-2, 2.055372e-2, 2.05537e-2], label="a")
    ax.set_yscale("log")  # less than a decade: every minor label 2.05537x10^-2
    ax.legend(fontsize=5, loc="upper left", bbox_to_anchor=(1.1, 1.0))
    found = " | ".join(defects(fig))
    assert "'a' at 5.0 pt" in found and "y-axis repeats tick labels" in found
    assert "past the figure's edge" in found
    ax.set_yscale("linear")  # its labels carry an offset
    ax.legend(fontsize=7, loc="upper left")
    assert defects(fig) == []
    assert defects(fig, scale=0.9)  # the same figure shrunk to 90 %: its 7 pt text is 6.3 pt


# the runs of conftest.py and the figures of each report (model.tex: the fit's own PDF)
KINDS = ["verify", "fit", "fit2", "identify", "landscape", "calibrate", "explain", "advise"]
KINDS += ["study", "ueda", "ueda-attractor"]


@pytest.mark.parametrize("kind", KINDS)
def test_every_figure_of_a_report_reads_on_its_page(runs_and_figures, kind):
    """Every figure a report places (and the model PDF's), at the size it is printed:
    text of 7 pt or more, distinct tick labels, legends inside the figure."""
    runs, figures = runs_and_figures
    d = runs / kind
    placed = [(d / "report.tex", report(d, compile=False).tex.read_text())]
    if (d / "model.tex").exists():
        placed.append((d / "model.tex", (d / "model.tex").read_text()))
    found = []
    for tex, text in placed:
        where = _placements(text)
        assert where, (kind, tex.name)
        for name, fraction in where.items():
            assert (kind, name) in figures, (kind, name, "drawn by no command of the run")
            scale = _scale(d / name, fraction)
            found += [f"{tex.name}: {name}: {x}" for x in defects(figures[kind, name], scale)]
    assert not found, "\n".join(found)


def _ns(**kw):
    from types import SimpleNamespace

    return SimpleNamespace(**kw)


def _identification(values, path):
    t = np.linspace(0, 6e-3, 50)
    imp = _ns(t=t, F=1e6 * np.exp(-t / 1e-3), support=np.array([[0.0, 4e-3]]), duration=6e-3)
    its = [
        {"coefficients": {"z": z, "zd": zd}, "n_simulations": 1 + 2 * k, "value": v}
        for k, ((z, zd), v) in enumerate(zip(path, values, strict=True))
    ]
    final = dict(its[-1]["coefficients"])
    result = _ns(
        law=_ns(names=["z", "zd"], as_dict=lambda: final),
        iterations=its,
        criterion="I2",
        criteria={"I2": values[-1]},
        value=values[-1],
        checks=[],
        n_simulations=45,
        method="least-squares",
    )
    return result, imp


def _drawn(module, draw):
    """The figures ``draw()`` makes through ``module._save`` (not written)."""
    figs = []
    saved = module._save
    module._save = lambda fig, stem: figs.append(fig)
    try:
        draw()
    finally:
        module._save = saved
    return figs


def test_identify_s_history_of_a_search_that_barely_moves_has_distinct_labels():
    """A search whose best I2 moves in its sixth digit (2.05537e-2 throughout) was drawn on
    a log axis with six tick labels alike; its path of the same width on axes whose labels
    must differ too."""
    from reports.vibroimpact import figures

    values = [2.0553712e-2, 2.0553705e-2, 2.0553701e-2, 2.05537e-2]
    path = [(2.0600001e8, 1.2800002e7), (2.0600002e8, 1.2800001e7), (2.06e8, 1.28e7)] * 2
    result, imp = _identification(values, path[:4])
    (fig,) = _drawn(
        figures, lambda: figures.identification_figure(result, imp, [("identified", imp)], "x")
    )
    assert defects(fig) == []
    assert fig.axes[1].get_yscale() == "linear"  # less than a decade: no log axis
    # a search over two decades keeps its log axis
    result, imp = _identification([0.5, 0.05, 0.02, 0.0205], path[:4])
    (fig,) = _drawn(figures, lambda: figures.identification_figure(result, imp, [], "x"))
    assert fig.axes[1].get_yscale() == "log" and defects(fig) == []


def test_identify_s_path_is_the_path_the_search_took():
    """A start the search replaced (its cycle-by-cycle fit began elsewhere) is not drawn
    on the path's axes nor joined to it: the axes hold the path searched, and the title
    says where it began; a start the search began from is marked where it is."""
    from reports.vibroimpact import figures

    path = [(2.1e8, 1.3e7), (2.07e8, 1.29e7), (2.06e8, 1.28e7)]
    result, imp = _identification([0.03, 0.025, 0.0222], path)
    away, at = _drawn(
        figures,
        lambda: [
            figures.identification_figure(result, imp, [], "x", start={"z": 1.5e8, "zd": 9e6}),
            figures.identification_figure(result, imp, [], "x", start={"z": 2.1e8, "zd": 1.3e7}),
        ],
    )
    ax = away.axes[0]
    xs = np.concatenate([ln.get_xdata() for ln in ax.lines])
    assert xs.min() >= 2.06e8 and ax.get_xlim()[0] > 1.9e8, ax.get_xlim()
    assert "cycle-by-cycle fit of the given start" in ax.get_title()
    assert not [ln for ln in ax.lines if ln.get_label().startswith("start")]
    (mark,) = [ln for ln in at.axes[0].lines if ln.get_label().startswith("start")]
    assert (mark.get_xdata()[0], mark.get_ydata()[0]) == (2.1e8, 1.3e7)
    assert defects(away) == [] and defects(at) == []


def test_the_landscape_figure_and_printout_hold_i5_when_computed(runs, capsys):
    """A record with positions gives I5 over the grid: the report's table had it, the
    figure and the command's printout stopped at I4."""
    from matplotlib.figure import Figure

    from discovery._files import _handoff
    from discovery.cli import main

    rec = next(runs.glob("r_*.csv"))
    out = runs / "landscape-record"
    argv = ["landscape", "--data", str(rec), "--grid", "2x2", "--workers", "1", "--out", str(out)]
    drawn = []
    save = Figure.savefig
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", lambda fig, *a, **k: drawn.append(fig) or save(fig, *a, **k))
        mp.setattr(_handoff, "in_parallel", lambda: False)  # the PDF printed here, kept
        assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "  I4: minimum" in printed and "  I5: minimum" in printed, printed
    titles = [ax.get_title().split(" ")[0] for ax in drawn[-1].axes]
    assert {"I0", "I1", "I2", "I3", "I4", "I5"} <= set(titles), titles
    fraction = _placements(report(out, compile=False).tex.read_text())["landscape.pdf"]
    assert defects(drawn[-1], _scale(out / "landscape.pdf", fraction)) == []


def _contact_models_run(d):
    """A contact-models run directory whose fits failed as a fresh clone's did: k driven to
    its floor (1e-300), n and e at the ends of their ranges, an interval over the range."""
    import json

    from discovery import ContactModelsResult
    from discovery.vibroimpact.fit.contact_fit import ContactFit

    def fit(model, params, value, consistent, message="", intervals=None):
        return ContactFit.from_dict(
            {"model": model, "parameters": params, "intervals": intervals or {},
             "criteria": {"I2": value or 0.97, "I4": 0.5}, "value": value,
             "consistent": consistent, "law": "2e8*z", "message": message}
        )  # fmt: skip

    fits = (
        fit("kelvin-voigt", {"k": 1.33e9, "c": 9.3e6}, 0.257, False),
        fit("hertz-damper", {"k": 1e-300, "c": 2.7e11}, None, None,
            "fit degenerate: k = 1e-300 sits at its floor"),
        fit("hunt-crossley", {"k": 1e-300, "n": 0.5, "lambda": 2.7e14}, None, None,
            "fit degenerate: k = 1e-300 sits at its floor; n = 0.5 sits at the end of its "
            "range [0.5, 3]"),
        fit("flores", {"k": 6.8e10, "n": 1.79, "e": 0.46}, None, None,
            "fit degenerate: n's interval spans its whole range",
            {"k": [0.0, 3.6e13], "n": [0.5, 3.0], "e": [0.02, 1.0]}),
    )  # fmt: skip
    r = ContactModelsResult(fits=fits, selected=None, n_records=1)
    d.mkdir()
    (d / "summary.json").write_text(json.dumps({**r.to_dict(), "command": "fit"}))
    manifest = {"command": "fit", "files": ["summary.json"]}
    (d / ".vidi-manifest.json").write_text(json.dumps(manifest))
    return d


def test_the_contact_models_report_draws_its_figure_and_names_why_a_fit_failed(tmp_path):
    """The contact-models report had no figure and printed a degenerate stiffness as
    1.000x10^-300: it draws each model's I2 (failed fits marked) and names a parameter at
    its floor or its range's end as the reason the fit failed, never as a number."""
    from matplotlib.figure import Figure

    d = _contact_models_run(tmp_path / "cm")
    drawn = []
    save = Figure.savefig
    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", lambda fig, *a, **k: drawn.append(fig) or save(fig, *a, **k))
        tex = report(d, compile=False).tex.read_text()
    assert (d / "contact_models.pdf").exists() and (d / "contact_models.png").exists()
    fraction = _placements(tex)["contact_models.pdf"]
    assert drawn and defects(drawn[0], _scale(d / "contact_models.pdf", fraction)) == []
    body = tex.split("section{Scenario}")[0]
    assert "-300" not in body and "1e-300" not in body
    assert r"$k$: at its floor (driven to zero)" in body
    assert r"$n$: at the end of its range [0.5, 3]" in body
    assert r"$n$: its interval spans its whole range" in body
    assert body.count("failed (degenerate)") == 3 and "inconsistent" in body
    labels = [t.get_text() for t in drawn[0].axes[0].texts]
    assert "0.257, inconsistent" in labels and labels.count("0.97, failed (degenerate fit)") == 3
    # the figure is vidi's now (in the manifest): a second report replaces it; a user's own
    # file of its name is never replaced
    import json

    listed = json.loads((d / ".vidi-manifest.json").read_text())["files"]
    assert {"contact_models.pdf", "contact_models.png"} <= set(listed)
    assert report(d, compile=False).tex.exists()
    from discovery.errors import InputError

    mine = _contact_models_run(tmp_path / "mine")
    (mine / "contact_models.pdf").write_text("my own figure\n")
    with pytest.raises(InputError, match="was not written by vidi"):
        report(mine, compile=False)
    assert (mine / "contact_models.pdf").read_text() == "my own figure\n"
