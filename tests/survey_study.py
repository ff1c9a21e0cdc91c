"""The shipped example study (``examples/study_paper.toml``), run and saved for its table.

Not a test module.  Runs the study (:func:`discovery.study`, the same as ``vidi study
--config examples/study_paper.toml``) into a scratch directory and writes a run file
(:mod:`tests.measured`): its header, one row per cell (the factors, runs, exact-support
recoveries, false positives per run, intervals covered) and one ``pooled`` row per selection
method (the study's :meth:`~discovery.StudyResult.pooled`).  docs/validation.md's table of the
study is rendered from it (:mod:`tests.tables`).

Run from the repository root (10-20 minutes on two shared cores)::

    python -m tests.survey_study --workers 2 --out docs/_measured/study-paper.jsonl
"""

import argparse
import sys
import tempfile
import time
from pathlib import Path

from tests import measured

CONFIG = measured.ROOT / "examples" / "study_paper.toml"

#: the docs' copies of the study's figures (docs/validation.md and the gallery show them)
FIGURES = measured.ROOT / "reports" / "assets"
_FIGURES = {"recovery_map.png": "study_recovery_map.png", "coverage.png": "study_coverage.png"}


def keep_figures(study_dir, figures):
    """Copy the study's recovery map and coverage figures (PNG) from its directory into
    ``figures`` under the names the docs show, so they are the table's run."""
    import shutil

    for name, kept in _FIGURES.items():
        found = sorted(study_dir.rglob(name))
        if found:
            shutil.copyfile(found[0], figures / kept)


#: the cell's keys kept in the run file (the factors that vary, then the counts)
_CELL_KEYS = (
    "selection",
    "force_noise",
    "periods",
    "runs",
    "failed",
    "recovered",
    "fp_per_run",
    "covered",
    "intervals",
    "consistent",
    "seconds_median",
    "simulations_median",
)


def rows_of(result):
    """The run file's rows of a finished study: one per cell, one ``pooled`` per method."""
    cells = [{"kind": "cell", **{k: c.get(k) for k in _CELL_KEYS}} for c in result.cells]
    pooled = [{"kind": "pooled", "selection": m, **p} for m, p in result.pooled().items()]
    return cells + pooled


def _noise_levels(rows):
    """The force-noise levels and record lengths of the cells, in the order they came."""
    noises, periods = [], []
    for r in rows:
        if r["kind"] != "cell":
            continue
        if r["force_noise"] not in noises:
            noises.append(r["force_noise"])
        if r["periods"] not in periods:
            periods.append(r["periods"])
    return noises, periods


def header(rows):
    """The table's two header lines: one column per force-noise level."""
    noises, _ = _noise_levels(rows)
    cols = [
        "method",
        *(f"{100 * n:g} %" for n in noises),
        "all (95 % CI)",
        "false terms / run",
        "95 % intervals covered",
    ]
    return ("| " + " | ".join(cols) + " |", "|" + "---|" * len(cols))


def markdown_row(rows, label):
    """One selection method's row: exact-support recoveries per cell (one ``k/n`` per record
    length, at each force noise), then pooled over the cells with its Wilson interval, the
    false terms per run and the intervals' coverage."""
    noises, periods = _noise_levels(rows)
    cell = {
        (r["force_noise"], r["periods"]): r
        for r in rows
        if r["kind"] == "cell" and r["selection"] == label
    }
    pooled = next(r for r in rows if r["kind"] == "pooled" and r["selection"] == label)
    per_noise = [
        " ".join(f"{cell[(n, p)]['recovered']}/{cell[(n, p)]['runs']}" for p in periods)
        for n in noises
    ]
    lo, hi = pooled["recovery_ci"]
    clo, chi = pooled["coverage_ci"]
    fp = pooled["fp_per_run"]
    cells = [
        label,
        *per_noise,
        f"{pooled['recovered']}/{pooled['runs']} ({lo:.2f}-{hi:.2f})",
        "--" if fp is None else f"{fp:.2f}",
        f"{pooled['covered']}/{pooled['intervals']} ({clo:.2f}-{chi:.2f})"
        if pooled["intervals"]
        else "--",
    ]
    return "| " + " | ".join(str(c) for c in cells) + " |"


def stamp(files, rows):
    """The line under the table: the run file, its commit and date, and the study's cost."""
    head, _ = measured.read(files[-1])
    note = f" ({head['note']})" if head.get("note") else ""
    cells = [r for r in rows if r["kind"] == "cell"]
    _, periods = _noise_levels(rows)
    seconds = [r["seconds"] for r in rows if r["kind"] == "timing"]
    minutes = seconds[-1] / 60 if seconds else float("nan")
    return (
        f"*Per method, each force-noise column gives the exact-support recoveries at "
        f"{' / '.join(str(p) for p in periods)} recorded periods. Rendered by `make tables` "
        f"from `{files[-1].name}` (commit {head.get('commit') or 'not recorded'}, "
        f"{str(head.get('started', '?'))[:10]}): {len(cells)} cells, "
        f"{sum(r['runs'] for r in cells)} runs, {minutes:.1f} min on "
        f"{head.get('workers', '?')} worker process(es){note}.*"
    )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--workers", type=int, default=2, help="worker processes (2)")
    ap.add_argument("--out", required=True, help="the run file to write")
    ap.add_argument("--config", default=str(CONFIG), help="the study (the shipped example)")
    ap.add_argument(
        "--figures",
        default=str(FIGURES),
        help="where the study's recovery map and coverage figures are copied (the docs')",
    )
    args = ap.parse_args(argv)
    from discovery import study
    from reports.vibroimpact.study_figures import study_figures

    run = measured.RunFile(args.out, "survey_study", argv, workers=args.workers)
    t0 = time.perf_counter()
    with tempfile.TemporaryDirectory() as tmp:
        result = study(
            args.config, Path(tmp) / "study", workers=args.workers, figures=study_figures
        )
        rows = rows_of(result)
        keep_figures(Path(tmp) / "study", Path(args.figures))
    for r in rows:
        run.write(r)
    run.write({"kind": "timing", "seconds": time.perf_counter() - t0})
    print(result)
    return 0


if __name__ == "__main__":
    sys.exit(main())
