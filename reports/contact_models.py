"""The report of a ``vidi fit --library contact-models`` run, from its typed result
(:class:`~discovery.ContactModelsResult`): every named model fitted, its parameters with
their 95 % intervals, its verdict, and which model the record supports and which it cannot
tell from it."""

from __future__ import annotations

from discovery.vibroimpact.model.contact_registry import CONTACT_MODELS
from discovery.wording import records as the_records
from discovery.wording import verb

from .cells import _figures, _scenarios_table
from .lawtex import prose
from .texenv import Tex, escape, interval, num
from .vibroimpact.contact_figures import at_floor, failed, failure_reasons

__all__ = ["contact_models_context", "drawn_by_report"]

_PARAM_TEX = {"k": "k", "n": "n", "c": "c", "lambda": r"\lambda", "e": "e"}


def _form(model):
    """A model's force in LaTeX, as its registry entry writes it ("" for no model)."""
    spec = CONTACT_MODELS.get(model)
    return spec.latex if spec is not None else ""


def _parameter_cells(f):
    """A fit's parameters with their intervals; a parameter its failed fit drove to its
    floor or its range's end is named with that reason, never printed as a number."""
    why, other = failure_reasons(f)
    cells = [prose(x) for x in other]
    for k, v in f.parameters.items():
        name = f"${_PARAM_TEX.get(k, escape(k))}$"
        if k in why or at_floor(v):
            cells.append(f"{name}: " + escape(why.get(k, "at its floor (driven to zero)")))
            continue
        text = f"{name} = {num(v, 4)}"
        iv = f.intervals.get(k)
        if iv:
            text += f" {interval(*iv)}"
        cells.append(text)
    return cells


def _rows(fits, selected):
    rows = []
    for f in fits:
        name = Tex(escape(f.model) + (r" $\star$" if f.model == selected else ""))
        ok = {True: "consistent", False: "inconsistent"}.get(f.consistent, "failed")
        if failed(f) and failure_reasons(f)[0]:
            ok = "failed (degenerate)"
        rows.append(
            [
                name,
                Tex(f"${_form(f.model)}$"),
                num(f.value, 3),
                escape(ok),
                Tex("; ".join(_parameter_cells(f))),
            ]
        )
    return rows


def contact_models_context(doc, run_dir):
    """The template context (``contact_models.tex.j2``) of a
    :class:`~reports.run.RunDocument`."""
    r = doc.result
    s = doc.summary  # the records and scenarios as the command was given them
    n = r.n_records or len(_listed(s.get("data"))) or 1
    return {
        "title": "The named contact models against a record",
        "supports": f"{the_records(n)} {verb(n, 'supports', 'support')}",
        "rows": _rows(r.fits or (), r.selected),
        # the run's conclusion as it wrote it (one written before the summary kept the
        # number of records named a single record and had no final period)
        "conclusions": [prose(s.get("conclusion") or r.conclusion or "--")],
        "interval_method": escape((r.settings or {}).get("interval_method", "--")),
        # drawn by the report (the command draws none): :func:`drawn_by_report`
        "figures": _figures(run_dir, ["contact_models"]),
        "records": [escape(str(d)) for d in _listed(s.get("data"))],
        "scenarios": _scenarios_table(s.get("scenarios") or [s.get("scenario")]),
    }


def _listed(value):
    """A field that is one name or a list of them, as a list."""
    if value is None:
        return []
    return list(value) if isinstance(value, list) else [value]


def drawn_by_report(doc):
    """``[(stem, draw)]``: the figures of a run its command did not draw, which its report
    draws from the run's document (``draw(path_stem)`` writes the PNG and the PDF): the
    named contact models' I2 for a ``--library contact-models`` fit; none for another run."""
    if doc.command != "fit" or doc.summary.get("library") != "contact-models":
        return []
    from .vibroimpact.contact_figures import contact_models_figure

    return [("contact_models", lambda stem: contact_models_figure(doc.result, stem))]
