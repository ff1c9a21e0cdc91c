"""What a report says, computed from a run's document (its ``summary.json``, the result's
``to_dict()``) alone.

One function per run kind turns the document into the template's context: tables (rows of
cells), the model as LaTeX, the figures the run wrote, and conclusions written from the
numbers (which terms the data support, what is inconsistent and where, what would separate
models the record cannot tell apart). The kinds live by system: the vibro-impact commands in
:mod:`reports.vibroimpact.context`, a study in :mod:`reports.vibroimpact.study_context`,
Ueda's commands in :mod:`reports.ueda.context`; the cells they share in :mod:`reports.cells`.
``discovery.report`` checks a document's schema version and kind (``discovery.load``) before
it gets here; a summary from before the schema version is read by its keys as it always was.
"""

from __future__ import annotations

from .cells import (  # noqa: F401  (the shared cells, read by the tests from here)
    FIGURE_CAPTIONS,
    _criteria_table,
    _figures,
    _machine_rows,
    _provenance,
    _scenario_rows,
    criterion_definition,
    criterion_names,
    criterion_tex,
)
from .lawtex import prose
from .run import run_document
from .ueda.context import _ueda_attractor, _ueda_chart, _ueda_discover, _ueda_explain
from .vibroimpact.context import (  # noqa: F401
    _effect_parameter_rows,
    _explain,
    _fit,
    _identify,
    _landscape,
    _verify,
)
from .vibroimpact.study_context import _study

__all__ = ["context", "KINDS", "criterion_names"]


def _advise(doc, run_dir):
    from .vibroimpact.advise_report import advise_context

    return advise_context(doc, run_dir, _figures)


def _calibrate(doc, run_dir):
    """A calibration's report: the machine section of the frame holds its table."""
    s = doc.summary
    lines = list(s.get("disagreements") or [])
    res = s.get("residual") or {}
    if s.get("calibrated"):
        if not lines:
            lines.append(
                "The record agrees with the scenario's machine: every value the record "
                "determines holds the scenario's within its 95 % interval."
            )
        fr, mo = res.get("frame") or {}, res.get("moulding") or {}
        if fr and mo:
            lines.append(
                "The equations' weak-form residual, as a share of the force: frame "
                f"{100 * fr.get('record', float('nan')):.2g} % with the calibrated machine "
                f"({100 * fr.get('sheet', float('nan')):.2g} % with the scenario's), moulding "
                f"{100 * mo.get('record', float('nan')):.2g} % "
                f"({100 * mo.get('sheet', float('nan')):.2g} %)."
            )
    lines += list(s.get("notes") or [])
    return {
        "title": "The machine as the record shows it",
        "conclusions": [prose(x) for x in lines],
        "figures": _figures(run_dir, ["calibrate"]),
    }


KINDS = {
    "calibrate": _calibrate,
    "verify": _verify,
    "advise": _advise,
    "fit": _fit,
    "identify": _identify,
    "landscape": _landscape,
    "explain": _explain,
    "ueda attractor": _ueda_attractor,
    "ueda chart": _ueda_chart,
    "ueda discover": _ueda_discover,
    "ueda explain": _ueda_explain,
    "study": _study,
}


TEMPLATES = {
    "calibrate": "calibrate",
    "verify": "verify",
    "advise": "advise",
    "fit": "fit",
    "identify": "identify",
    "landscape": "landscape",
    "explain": "explain",
    "study": "study",
}


def context(doc, run_dir):
    """The template context of a run (a :class:`~reports.run.RunDocument`, or its summary
    dict): the kind's own part plus provenance and scenario."""
    doc = run_document(doc)
    summary = doc.summary
    kind = doc.command
    build = KINDS.get(kind)
    named = kind == "fit" and summary.get("library") == "contact-models"
    loop = summary.get("result") == "campaign"  # advise --until-settled, or the API's
    kind = "advise" if loop else kind
    if named:
        from .contact_models import contact_models_context  # the named models' fit

        build = contact_models_context
    if loop:  # advise --until-settled: the experiment loop
        from .vibroimpact.campaign_report import campaign_context

        build = campaign_context
    if build is None:
        from discovery.errors import InputError

        raise InputError(f"no report for a {kind!r} run; reports cover {', '.join(KINDS)} runs")
    c = build(doc, run_dir)  # every kind's context reads the run's typed result
    c["kind"] = kind
    template = "campaign" if loop else TEMPLATES.get(kind, "ueda")
    c["template"] = ("contact_models" if named else template) + ".tex.j2"
    c["provenance"] = _provenance(summary, run_dir)
    c["scenario"] = _scenario_rows(summary.get("scenario"))
    machine = summary if kind == "calibrate" else summary.get("machine")
    c["machine"] = _machine_rows(machine)
    c["machine_used"] = (machine or {}).get("used", "record")
    c["machine_lines"] = [prose(x) for x in (machine or {}).get("disagreements") or []]
    c["data"] = summary.get("data") or (summary.get("settings") or {}).get("data")
    c["seconds"] = summary.get("seconds")
    return c
