"""The table of how parallel work scales (docs/validation.md), from the scaling runs saved in
``docs/_measured/scaling*.jsonl``.

Not a test module.  Each row of those run files is one run of ``bench/scaling_bench.py`` on
one machine: what :func:`bench_scaling` returns (the 24-run study and ``explain`` on each
worker count) with the machine's cores, its processor and the run's provenance.
``cd bench && python run.py scaling --out ../docs/_measured/scaling-NAME.jsonl`` writes such
a file (:func:`write_run`; ``--append`` adds the row to one) and ``make bench`` writes its
own section to ``scaling-bench.jsonl``.  The table has two rows per machine, the latest run
on as many cores replacing an earlier one, the largest machine first; a column per worker
count measured.
"""

import os

from . import measured

STUDY = "24-run study: wall time (efficiency)"
EXPLAIN = "`explain`, bench record"


def cpu_model():
    """The processor's name (``/proc/cpuinfo``), or None."""
    try:
        with open("/proc/cpuinfo") as fh:
            for line in fh:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return None


def write_run(path, result, command, append=False):
    """Write ``result`` (``bench_scaling``'s dict with the run's provenance) as a row of
    the run file ``path``, headed by ``command``, the commit, the code version and the
    machine."""
    machine = {"cores": result.get("cores") or os.cpu_count(), "machine": cpu_model()}
    out = measured.RunFile(path, "scaling_bench", append=append, command=command, **machine)
    out.write({**machine, **result})


def read_rows(paths):
    """The runs of ``paths`` (each row with its file's header as ``run``), one per number of
    cores (the latest), most cores first."""
    by_cores = {}
    for path in paths:
        header, rows = measured.read(path)
        for r in rows:
            by_cores[r["cores"]] = {**r, "run": header, "file": path.name}
    return [by_cores[c] for c in sorted(by_cores, reverse=True)]


def worker_counts(runs):
    return sorted(
        {w["workers"] for r in runs for part in ("study", "explain") for w in _by(r, part)}
    )


def _by(run, part):
    return (run.get(part) or {}).get("by_workers") or []


def header(runs):
    counts = worker_counts(runs)
    cells = [str(w) for w in counts]
    if cells:
        cells[0] += " worker" if counts[0] == 1 else " workers"
    return (
        "| work | machine | " + " | ".join(cells) + " |",
        "|---" * (len(counts) + 2) + "|",
    )


def _seconds(x):
    return f"{x:.0f} s" if x >= 100 else f"{x:.1f} s"


def machine(run):
    """``16 cores, Intel Xeon`` (the machine as its run recorded it)."""
    name = run.get("machine") or run["run"].get("machine")
    return f"{run['cores']} cores" + (f", {name}" if name else "")


def _study_cell(w):
    eff = w.get("parallel_efficiency")
    return _seconds(w["seconds"]) + (f" ({eff:.2f})" if eff is not None else "")


def _explain_cells(rows):
    base = rows[0]["seconds"] if rows else None
    return {
        w["workers"]: _seconds(w["seconds"])
        + (f" ({base / w['seconds']:.2f}x)" if w is not rows[0] else "")
        for w in rows
    }


def markdown_row(runs, label):
    """The rows ``label`` (:data:`STUDY` or :data:`EXPLAIN`) of the table: one per machine."""
    counts = worker_counts(runs)
    lines = []
    for r in runs:
        if label == STUDY:
            cells = {w["workers"]: _study_cell(w) for w in _by(r, "study")}
        else:
            cells = _explain_cells(sorted(_by(r, "explain"), key=lambda w: w["workers"]))
        row = [label, machine(r), *(cells.get(w, "") for w in counts)]
        lines.append("| " + " | ".join(row) + " |")
    return lines


def stamp(files, runs):
    """The line under the table: the run files of the rows shown, with the commit and the
    date of each (a file whose runs later ones replaced is not named)."""
    shown = [p for p in files if p.name in {r["file"] for r in runs}]
    items = []
    for path in shown:
        header, _ = measured.read(path)
        commit = f"commit {header['commit']}" if header.get("commit") else "commit not recorded"
        items.append(f"`{path.name}` ({commit}, {str(header.get('started', '?'))[:10]})")
    return (
        "*Rendered by `make tables` from the scaling runs in `docs/_measured/`: "
        + ", ".join(items)
        + ".*"
    )
