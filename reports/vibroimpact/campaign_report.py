"""The report of an experiment loop (``vidi advise --until-settled``, ``discovery.campaign``):
how it stopped, each step's joint fit and the record it asked for next, the records, and
the candidates left."""

from __future__ import annotations

from ..lawtex import law_inline, law_of
from ..texenv import Tex, escape, num

__all__ = ["campaign_context"]

#: what each way of stopping means for the reader
_STOPPED = {
    "settled": "One law remains.",
    "twins": "The candidates left are twins within the bounds: no drive setting there tells "
    "them apart (wider bounds, another knob or another sensor might).",
    "no usable point": "No drive setting of the bounds is safe with an orbit of every "
    "candidate: widen the bounds or the safe region.",
    "budget": "The loop reached its budget of records with candidates left (--max-records; "
    "--resume goes on from its records).",
    "none consistent": "No law the fit can form is consistent with every record: explain "
    "names what is missing.",
}


def _law(text):
    """A law as inline math, a text the grammar does not read (a named model) as code."""
    from discovery.errors import InputError

    try:
        return law_inline(law_of(text, "law"))
    except InputError:
        return Tex(r"\texttt{" + str(escape(text)) + "}")


def _t(*parts):
    return Tex("".join(p if isinstance(p, Tex) else str(escape(str(p))) for p in parts))


def _separation(p):
    """The advised point's predicted separation and the one with each rival refitted."""
    if p.get("separation") is None:
        sep = "a regime change"
    else:
        sep = num(p["separation"])
    refit = p.get("refitted")
    return _t(sep, " / ", num(refit) if refit is not None else "--")


def _step_rows(steps):
    rows = []
    for k, s in enumerate(steps, start=1):
        p = s.point
        rows.append(
            [
                k,
                s.records,
                "yes" if s.consistent else "no",
                len(s.candidates) - 1,
                "--" if p is None else _t(num(p["amplitude"]), r" N, ", num(p["frequency"]), " Hz"),
                "--" if p is None else _separation(p),
            ]
        )
    return rows


def _selected(steps):
    return [_t(f"Step {k}: ", _law(s.selected)) for k, s in enumerate(steps, start=1) if s.selected]


def _record_rows(records):
    rows = []
    for k, r in enumerate(records, start=1):
        source = str(r.get("source") or "--").rsplit("/", 1)[-1]
        rows.append(
            [
                k,
                _t(num(r["amplitude"]), " N"),
                _t(num(r["frequency"]), " Hz"),
                _t(num(r["m2"]), " kg"),
                Tex(r"\texttt{" + str(escape(source)) + "}"),
            ]
        )
    return rows


def campaign_context(doc, run_dir):
    """The template context of a loop's run (a :class:`~reports.run.RunDocument` of a
    :class:`~discovery.CampaignResult`)."""
    r = doc.result
    head = _t(
        f"The loop stopped ({r.stopped}) after {len(r.records)} record"
        + ("" if len(r.records) == 1 else "s")
        + ": ",
        _STOPPED.get(r.stopped, r.reason),
    )
    out = [head, _t("The last joint fit selects ", _law(r.law), ".")] if r.law else [head]
    if r.stopped != "settled":  # the reason names the laws concerned
        out.append(_t("In the loop's words: ", r.reason, "."))
    return {
        "title": "The experiment loop",
        "conclusions": out,
        "steps": _step_rows(r.steps),
        "selected": _selected(r.steps),
        "records": _record_rows(r.records),
        "remaining": [_law(t) for t in r.remaining] if len(r.remaining) > 1 else [],
        "machine_note": "calibrated from the records (with its scale range)"
        if r.machine_from == "record"
        else "the sheets as given",
        "figures": [],
    }
