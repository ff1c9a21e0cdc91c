"""The measured tables of the documentation, rendered from the surveys' saved runs.

Not a test module.  A table lives in its page between ``<!-- table:NAME -->`` and
``<!-- /table:NAME -->``; :data:`TABLES` says which run files of ``docs/_measured/``
(:mod:`tests.measured`) make each row and how.  Below every table a line names the runs it
was made from, with the commit and the date of each, so a table says which code made it.

    python -m tests.tables          # rewrite the tables in docs/ and the README (make tables)
    python -m tests.tables --check  # exit 1, naming them, when a page's table is stale
    python -m tests.tables --show NAME [--runs FILE ...]  # print one table (from FILEs)

A *draft* table (``draft=True``) is defined before its runs are saved: its page keeps a
hand-written table, without the markers, until then (``--show NAME --runs FILE`` renders it
from any run files).  Once its runs are in ``docs/_measured/``, put its markers in the page
in place of the hand-written table, run ``make tables`` and drop ``draft=True``.

The renderer reads the saved runs only (seconds); ``make surveys`` runs the surveys again
first (hours).  ``tests/test_tables.py`` holds the pages to what this renders.
"""

import argparse
import re
import sys
from dataclasses import dataclass
from pathlib import Path

from . import (
    bench_history,
    bench_scaling,
    measured,
    readme_text,
    realistic_survey,
    survey_advise,
    survey_calibration,
    survey_campaign,
    survey_contact_models,
    survey_corpus,
    survey_effects,
    survey_explain,
    survey_explain_cases,
    survey_fit_sheet,
    survey_intervals,
    survey_memory_orbits,
    survey_study,
)

ROOT = measured.ROOT


@dataclass(frozen=True)
class Table:
    """A measured table: its page, header lines, and its rows, each a label and the glob
    patterns of its run files in ``docs/_measured/`` (read in the order the runs started,
    a later run's row of a record replacing an earlier one) that ``read`` gathers and
    ``row(rows, label)`` turns into a markdown row (or a list of them).  A table whose
    columns come from its runs has ``header(rows)`` instead of fixed lines (``rows``: every
    row of its run files, as ``read`` gives them), and ``stamp(files, rows)`` its own line
    under it (naming what the columns are made from).  A ``draft`` table's page may lack
    its markers (its runs are not saved yet: see the module's docstring)."""

    page: str
    header: object
    rows: tuple
    row: object
    read: object
    stamp: object = None
    draft: bool = False


_rows = measured.rows


_INTERVAL_RUNS = {
    "held out": ("intervals-272*.jsonl",),
    "mended": ("intervals-208*.jsonl",),  # with the P4 records run again, if any
    "corpus": ("intervals-corpus*.jsonl",),
}

#: the corpus's two tables, one row per record (a later run of a record replaces its row)
_CORPUS_RUNS = ("corpus*.jsonl",)

#: explain's random survey (a later run of a draw replaces its row)
_EXPLAIN_RUNS = ("explain-random*.jsonl",)

#: the scaling bench on each machine (a later run on as many cores replaces its rows)
_SCALING_RUNS = ("scaling*.jsonl",)


#: the effects survey's columns (with the true machine, and calibrated from a sheet off)
_EFFECTS_HEADER = (
    "| hidden | records | explain raised an error | true model not consistent | "
    "effect does not show (start consistent) | right effect(s) kept, where it shows | "
    "where the record tells it (the law alone, refitted, not consistent; of two effects, "
    "neither alone) | "
    "clean: an effect kept | final model consistent | 95 % interval holds the "
    "truth | lower noise wrong where higher right |",
    "|---|---|---|---|---|---|---|---|---|---|---|",
)


def _by_label(page, header, survey, pattern, labels):
    """A survey's table of one row per label (a class or a category, and "all"), each
    rendered by the survey's ``markdown_row`` from its runs ``pattern``."""
    return Table(
        page=page,
        header=header,
        rows=tuple((label, (pattern,)) for label in labels),
        row=survey.markdown_row,
        read=survey.read_rows,
    )


#: the effects survey's rows: each class hidden, then all
_EFFECT_ROWS = (*survey_effects.CLASSES, "all")


def _two_points(pattern):
    """docs/contact-models.md's table of a second operating point (the run files of
    ``pattern``): a row per truth and arm (:func:`survey_contact_models.markdown_row`)."""
    return Table(
        page="docs/contact-models.md",
        header=(
            "| truth | arm | records | right name | right or equivalent | settled | settled "
            "where the first record left the other family open |",
            "|---|---|---|---|---|---|---|",
        ),
        rows=tuple(
            (f"{truth}/{arm}", (pattern,))
            for truth in ("hunt-crossley", "lankarani-nikravesh")
            for arm in ("none", "advised", "random")
        ),
        row=survey_contact_models.markdown_row,
        read=survey_contact_models.read_rows,
        stamp=survey_contact_models.stamp,
    )


def _paragraph(page, lines, runs, read, stamp=None):
    """Text of ``page`` rendered by ``lines(rows)`` from the run files ``runs`` (read with
    ``read``): a table without rows (``stamp``: its line under it, default the run files')."""
    return Table(
        page=page,
        header=lines,
        rows=(("run", runs),),
        row=lambda rows, label: [],
        read=read,
        stamp=stamp,
    )


def _readme(page, lines):
    """A paragraph of ``page`` from the README's run (:mod:`tests.survey_readme`,
    :mod:`tests.readme_text`)."""
    return _paragraph(page, lines, ("readme*.jsonl",), readme_text.read_rows)


#: the README's measured paragraphs, in the README and again in the getting-started page
_README_TEXT = {
    f"{part}-{suffix}": _readme(page, lines)
    for part, lines in (
        ("setup", readme_text.setup_lines),
        ("demo", readme_text.demo_lines),
        ("times", readme_text.times_lines),
    )
    for suffix, page in (("readme", "README.md"), ("start", "docs/getting-started.md"))
}


TABLES = {
    **_README_TEXT,
    "bench-readme": _paragraph(
        "README.md",
        bench_history.readme_lines,
        ("bench-history.jsonl",),
        bench_history.read_rows,
        bench_history.readme_stamp,
    ),
    "effects": _by_label(
        "docs/validation.md", _EFFECTS_HEADER, survey_effects, "effects*.jsonl", _EFFECT_ROWS
    ),
    "effects-sheet": _by_label(
        "docs/validation.md", _EFFECTS_HEADER, survey_effects, "sheet-effects*.jsonl", _EFFECT_ROWS
    ),
    "effects-readme": Table(
        page="README.md",
        header=(
            "| records | machine given | right effect(s) kept, where it shows | where the record "
            "tells it | clean: an effect kept | final model consistent | 95 % interval holds "
            "the truth | lower noise wrong where higher right |",
            "|---|---|---|---|---|---|---|---|",
        ),
        rows=(("all", ("effects*.jsonl",)), ("all sheet", ("sheet-effects*.jsonl",))),
        row=survey_effects.readme_row,
        read=survey_effects.read_rows,
    ),
    "fit-sheet": _by_label(
        "docs/validation.md",
        survey_fit_sheet.HEADER,
        survey_fit_sheet,
        "fit-sheet*.jsonl",
        (*survey_fit_sheet.CATEGORIES, "all"),
    ),
    "fit-sheet-readme": Table(
        page="README.md",
        header=survey_fit_sheet.HEADER,
        rows=(("all", ("fit-sheet*.jsonl",)),),
        row=survey_fit_sheet.markdown_row,
        read=survey_fit_sheet.read_rows,
    ),
    "memory-orbits": Table(
        page="docs/contact-models.md",
        header=(
            "| draws | n | periodic | strobe point in a contact | nonperiodic | failed | "
            "agree with the long run | or with its twin at rtol 1e-11 | periodic, agree |",
            "|---|---|---|---|---|---|---|---|---|",
        ),
        rows=tuple(
            (label, ("memory-orbits*.jsonl",))
            for label in ("flores", "lankarani-nikravesh", *survey_memory_orbits.CATEGORIES, "all")
        ),
        row=survey_memory_orbits.markdown_row,
        read=survey_memory_orbits.read_rows,
    ),
    "calibration": Table(
        page="docs/calibration.md",
        header=(
            "| records | n | masses within 2 % | true law consistent: true machine | sheet | "
            "calibrated | wrong laws rejected: true machine | sheet | calibrated |",
            "|---|---|---|---|---|---|---|---|---|",
        ),
        rows=tuple(
            (label, ("calibration*.jsonl",))
            for label in ("force noise 1 %", "force noise 3 %", "all")
        ),
        row=survey_calibration.markdown_row,
        read=survey_calibration.read_rows,
    ),
    "calibration-classes": Table(
        page="docs/calibration.md",
        header=(
            "| class | n | masses within 2 % | true law consistent: true machine | sheet | "
            "calibrated | wrong laws rejected: true machine | sheet | calibrated |",
            "|---|---|---|---|---|---|---|---|---|",
        ),
        rows=tuple(
            (label, ("calibration*.jsonl",))
            for label in ("p1", "p1-slow", "subharmonic", "short-contact")
        ),
        row=survey_calibration.markdown_row,
        read=survey_calibration.read_rows,
    ),
    "intervals": Table(
        page="docs/validation.md",
        header=(
            "| records | category: P1 / slow P1 / short / subharmonic | kind: linear / coupling "
            "strong / weak / Hunt-Crossley | noise: low / high | all | code |",
            "|---|---|---|---|---|---|",
        ),
        rows=(
            ("seeds 272-335, held out", _INTERVAL_RUNS["held out"]),
            ("seeds 208-271", _INTERVAL_RUNS["mended"]),
            ("corpus c01-c13", _INTERVAL_RUNS["corpus"]),
        ),
        row=survey_intervals.markdown_row,
        read=survey_intervals.read_rows,
    ),
    "intervals-readme": Table(
        page="README.md",
        header=(
            "| records | P1 / slow P1 / short / subharmonic | linear / coupling strong / weak / "
            "Hertz | noise low / high | all |",
            "|---|---|---|---|---|",
        ),
        rows=(
            ("64 random, held out", _INTERVAL_RUNS["held out"]),
            ("64 random", _INTERVAL_RUNS["mended"]),
            ("corpus c01-c13", _INTERVAL_RUNS["corpus"]),
        ),
        row=survey_intervals.readme_row,
        read=survey_intervals.read_rows,
    ),
    "advise": Table(
        page="docs/validation.md",
        header=(
            "| force noise | cases run | counted | first record alone selects | + advised point: "
            "selected | + random point: selected | advised: no rival left | random: no rival "
            "left |",
            "|---|---|---|---|---|---|---|---|",
        ),
        rows=(("1 %", ("advise-1*.jsonl",)), ("3 %", ("advise-3*.jsonl",))),
        row=survey_advise.markdown_row,
        read=_rows,
    ),
    "campaign": Table(
        page="docs/advise.md",
        header=(
            "| noise | runs | raised an error | stopped | ends with the true law | of which on "
            "the first record | records (median / most) | quieter wrong where noisier right |",
            "|---|---|---|---|---|---|---|---|",
        ),
        rows=tuple((label, ("campaign-random*.jsonl",)) for label in survey_campaign.LABELS),
        row=survey_campaign.markdown_row,
        read=_rows,
    ),
    "campaign-calibration": Table(
        page="docs/advise.md",
        header=(
            "| predicted at the advised point | pairs | rival rejected by the joint fit "
            "| pair told apart (one of the two rejected) |",
            "|---|---|---|---|",
        ),
        rows=tuple((label, ("campaign*.jsonl",)) for label in survey_campaign.PREDICTED),
        row=survey_campaign.calibration_row,
        read=_rows,
    ),
    "corpus": Table(
        page="docs/validation.md",
        header=(
            "| record | true law verified | regime read (simulated) | every coefficient x0.7 "
            "and x1.3 | `explain` from `z + zd` |",
            "|---|---|---|---|---|",
        ),
        rows=tuple(
            (label, _CORPUS_RUNS)
            for label in (
                "c01 slow transient (multiplier ~0.99)",
                "c02 steep onset (`z*zd`, 2 % noise)",
                "c03 Hertz",
                "c04 period two",
                "c05 5 kHz",
                "c06 unloading damping",
                "c07 3 % noise",
            )
        ),
        row=survey_corpus.markdown_row,
        read=survey_corpus.read_rows,
    ),
    "corpus-effects": Table(
        page="docs/validation.md",
        header=(
            "| record | true law verified (I2, I5 against their limits) | `explain` from "
            "`z + zd` |",
            "|---|---|---|",
        ),
        rows=tuple(
            (label, _CORPUS_RUNS)
            for label in (
                "c08 strong coupling",
                "c09 soft Hertz (P2)",
                "c10 unloading damping behind a stiff spring",
                "c11 contact offset 1.5 mm",
                "c12 coupling and unloading damping",
                "c13 steep onset at 0.5 % noise",
                "c14 a moulding 5 % heavier than its sheet (machine calibrated)",
                "c15 coupling; the supports 8 % stiffer, 25 % more damped than the sheet",
                "c16 unloading damping; every machine parameter off its sheet",
            )
        ),
        row=survey_corpus.effects_row,
        read=survey_corpus.read_rows,
    ),
    "study-paper": Table(
        page="docs/validation.md",
        header=survey_study.header,
        rows=tuple(
            (method, ("study-paper*.jsonl",))
            for method in ("best-subset", "l1-path", "constrained-sr3", "stlsq", "sr3")
        ),
        row=survey_study.markdown_row,
        read=_rows,
        stamp=survey_study.stamp,
    ),
    "realistic-properties": Table(
        page="docs/validation.md",
        header=(
            "| category | true law consistent | wrong law inconsistent (detectable) | not "
            "detectable |",
            "|---|---|---|---|",
        ),
        rows=tuple(
            (label, ("realistic-properties*.jsonl",))
            for label in ("`p1`", "`p1-slow`", "`subharmonic`", "`short-contact`", "all")
        ),
        row=realistic_survey.category_row,
        read=_rows,
    ),
    "realistic-span": Table(
        page="docs/validation.md",
        header=(
            "| setting | true law consistent | wrong law inconsistent (detectable) | not "
            "detectable |",
            "|---|---|---|---|",
        ),
        rows=(
            ("default (as above)", ("realistic-default*.jsonl",)),
            ("field-like (`--field`)", ("realistic-field*.jsonl",)),
        ),
        row=realistic_survey.markdown_row,
        read=_rows,
    ),
    "explain-random": Table(
        page="docs/validation.md",
        header=(
            "| draws | run | Hertz-type (skipped) | tests nothing | clean: an effect named | "
            "hidden effect too weak | `explain` raised an error | start's I2 beyond its limit "
            "| right effect first, gap to the bar | right first, short of the bar | wrong "
            "effect first | nothing named | more than one kept |",
            "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
        ),
        rows=tuple((label, _EXPLAIN_RUNS) for label in survey_explain.LABELS),
        row=survey_explain.markdown_row,
        read=survey_explain.read_rows,
    ),
    "explain-random-readme": Table(
        page="README.md",
        header=(
            "| draws | start's I2 beyond its limit: right effect first, gap to the bar | "
            "wrong effect first | clean records: an effect named | `explain` raised an error |",
            "|---|---|---|---|---|",
        ),
        rows=(("random", _EXPLAIN_RUNS),),
        row=survey_explain.readme_row,
        read=survey_explain.read_rows,
    ),
    "explain-random-misses": Table(
        page="docs/validation.md",
        header=(
            "| draw | category | regime | hidden | named | I2 start -> final (floor) | outcome |",
            "|---|---|---|---|---|---|---|",
        ),
        rows=(("misses", _EXPLAIN_RUNS),),
        row=survey_explain.misses_rows,
        read=survey_explain.read_rows,
    ),
    "explain-cases": Table(
        page="docs/validation.md",
        header=survey_explain_cases.HEADER,
        rows=tuple((name, ("explain-cases*.jsonl",)) for name in survey_explain_cases.CASES),
        row=survey_explain_cases.markdown_row,
        read=survey_explain_cases.read_rows,
    ),
    # several seeds' runs combined (make surveys)
    "contact-models": Table(
        page="docs/validation.md",
        header=survey_contact_models.MODELS_HEADER,
        rows=tuple(
            (label, ("contact-models-*.jsonl",)) for label in survey_contact_models.MODELS_LABELS
        ),
        row=survey_contact_models.models_row,
        read=survey_contact_models.read_rows,
        stamp=survey_contact_models.models_stamp,
    ),
    "contact-two-points": _two_points("contact-two-points*.jsonl"),
    # the same, with the drive's knobs limited to +-10 % amplitude and +-5 % frequency
    "contact-narrow-points": _two_points("contact-narrow-points*.jsonl"),
    # make bench's runs as columns, the last few (tests/bench_history.py)
    "bench-history": Table(
        page="docs/validation.md",
        header=bench_history.header,
        rows=tuple((label, ("bench-history*.jsonl",)) for label in bench_history.ROWS),
        row=bench_history.markdown_row,
        read=bench_history.read_rows,
        stamp=bench_history.stamp,
    ),
    "scaling": Table(
        page="docs/validation.md",
        header=bench_scaling.header,
        rows=((bench_scaling.STUDY, _SCALING_RUNS), (bench_scaling.EXPLAIN, _SCALING_RUNS)),
        row=bench_scaling.markdown_row,
        read=bench_scaling.read_rows,
        stamp=bench_scaling.stamp,
    ),
}


def run_files(patterns):
    """The run files matching ``patterns``, in the order the runs started."""
    found = {p for pattern in patterns for p in measured.MEASURED.glob(pattern)}
    if not found:
        raise SystemExit(f"no saved survey run matches {', '.join(patterns)} in docs/_measured")
    return sorted(found, key=lambda p: (str(measured.read(p)[0].get("started", "")), p.name))


def _stamp(files):
    """The line under a table: each run file it was made from, its commit and date."""
    runs = []
    for path in files:
        header, _ = measured.read(path)
        name = path.name
        commit = f"commit {header['commit']}" if header.get("commit") else "commit not recorded"
        runs.append(f"`{name}` ({commit}, {str(header.get('started', '?'))[:10]})")
    return (
        "*Rendered by `make tables` from the survey runs in `docs/_measured/`: "
        + ", ".join(runs)
        + ".*"
    )


def render(name, runs=None):
    """The lines of table ``name`` between its markers (without indentation); ``runs``:
    run files every row is made from, in place of its saved runs."""
    table = TABLES[name]
    files = list(runs or ())
    if runs is None:
        for _, patterns in table.rows:
            files += [p for p in run_files(patterns) if p not in files]
    everything = table.read(files) if callable(table.header) or table.stamp else None
    lines = list(table.header(everything) if callable(table.header) else table.header)
    for label, patterns in table.rows:
        row = table.row(table.read(run_files(patterns) if runs is None else files), label)
        lines += [row] if isinstance(row, str) else list(row)
    stamp = table.stamp(files, everything) if table.stamp else _stamp(files)
    return [*lines, "", stamp]


def _block(name):
    return re.compile(
        rf"^(?P<indent>[ \t]*)<!-- table:{re.escape(name)} -->\n.*?^[ \t]*<!-- /table:"
        rf"{re.escape(name)} -->$",
        re.M | re.S,
    )


def rendered_page(page):
    """The text of ``page`` (relative to the repository root) with its tables rendered."""
    text = (ROOT / page).read_text()
    for name, table in TABLES.items():
        if table.page != page:
            continue
        found = _block(name).search(text)
        if found is None and table.draft:
            continue  # not in its page yet
        if found is None:
            raise SystemExit(f"{page}: no <!-- table:{name} --> ... <!-- /table:{name} -->")
        pad = found.group("indent")
        body = [f"{pad}{line}" if line else "" for line in render(name)]
        new = "\n".join([f"{pad}<!-- table:{name} -->", *body, f"{pad}<!-- /table:{name} -->"])
        text = text[: found.start()] + new + text[found.end() :]
    return text


def markers(page):
    """The table names marked in ``page``."""
    return re.findall(r"<!-- table:([\w-]+) -->", (ROOT / page).read_text())


def pages():
    return sorted({t.page for t in TABLES.values()})


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="exit 1 when a table is stale")
    ap.add_argument("--show", metavar="NAME", choices=list(TABLES), help="print one table")
    ap.add_argument(
        "--runs", nargs="+", type=Path, help="with --show: the run files to render it from"
    )
    args = ap.parse_args(argv)
    if args.show:
        print("\n".join(render(args.show, args.runs)))
        return 0
    stale = []
    for page in pages():
        unknown = set(markers(page)) - set(TABLES)
        if unknown:
            raise SystemExit(f"{page}: tables with no definition in tests/tables.py: {unknown}")
        text = rendered_page(page)
        if text != (ROOT / page).read_text():
            stale.append(page)
            if not args.check:
                Path(ROOT / page).write_text(text)
    if args.check and stale:
        print(f"stale measured tables in {', '.join(stale)}: run make tables", file=sys.stderr)
        return 1
    print(("rewrote " + ", ".join(stale)) if stale else "the measured tables are up to date")
    return 0


if __name__ == "__main__":
    sys.exit(main())
