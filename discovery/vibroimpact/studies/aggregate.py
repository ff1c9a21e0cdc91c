"""A study's aggregates, always computed from the run files (never from memory).

Per cell (one combination of the factors, over its seeds): recovery rate of the exact
support with a Wilson 95 % interval, how often the truth is among the equivalent models,
false-positive terms per run and the share of runs with any, missed terms per run, the
coverage of the 95 % coefficient intervals on exact supports (with its Wilson interval:
honest intervals cover about 95 %), the median normalised coefficient error, the share of
selected models consistent with their records, failures, median simulations and seconds;
and how often each library term was selected.

No measure here uses the truth to tune a selection: every method selects from the record
alone, and the truth only scores what it selected.  (A study that tuned a threshold on the
truth would have to label it oracle and keep it out of these tables.)
"""

from __future__ import annotations

import csv
import io
import json
import math

import numpy as np

__all__ = ["wilson", "aggregate", "run_rows", "to_csv", "CELL_COLUMNS"]

Z95 = 1.959963984540054


def wilson(k, n, z=Z95):
    """Wilson score interval ``(low, high)`` of a binomial proportion ``k / n``
    (``(nan, nan)`` for ``n = 0``)."""
    if n <= 0:
        return (math.nan, math.nan)
    p = k / n
    den = 1 + z * z / n
    mid = (p + z * z / (2 * n)) / den
    half = z * math.sqrt(p * (1 - p) / n + z * z / (4 * n * n)) / den
    lo, hi = max(0.0, mid - half), min(1.0, mid + half)
    # exact at the ends (rounding would put the bound a hair inside)
    return (0.0 if k == 0 else min(lo, p), 1.0 if k == n else max(hi, p))


def _factor_text(name, value):
    if name == "scenario":
        items = value if isinstance(value, list) else [value]
        return " + ".join(
            it if isinstance(it, str) else ",".join(f"{k}={v}" for k, v in it.items())
            for it in items
        )
    if name == "law" and value is None:
        return "(scenario's)"
    return value if isinstance(value, str | int | float | bool) else json.dumps(value)


def _median(values):
    v = [x for x in values if x is not None and np.isfinite(x)]
    return float(np.median(v)) if v else math.nan


CELL_COLUMNS = (
    "runs",
    "failed",
    "recovered",
    "recovery",
    "recovery_low",
    "recovery_high",
    "equivalent",
    "fp_per_run",
    "any_fp",
    "fn_per_run",
    "covered",
    "intervals",
    "coverage",
    "coverage_low",
    "coverage_high",
    "coef_error_median",
    "consistent",
    "simulations_median",
    "seconds_median",
)


def aggregate(config, runs):
    """One row per cell of ``config`` (factor values, then :data:`CELL_COLUMNS`) and
    ``{cell: {term: selection frequency}}``, from the run records ``runs``."""
    by_cell = {}
    for r in runs:
        by_cell.setdefault(r["cell"], []).append(r)
    rows, inclusion = [], {}
    for ci, cell in enumerate(config.cells):
        rs = by_cell.get(ci, [])
        ok = [r for r in rs if r["status"] == "ok"]
        n, k = len(rs), sum(bool(r["exact"]) for r in rs)
        cov = [c for r in ok for c in r.get("coverage", {}).values()]
        lo, hi = wilson(k, n)
        clo, chi = wilson(sum(cov), len(cov))
        row = {f: _factor_text(f, cell[f]) for f in cell}
        row.update(
            runs=n,
            failed=n - len(ok),
            recovered=k,
            recovery=k / n if n else math.nan,
            recovery_low=lo,
            recovery_high=hi,
            equivalent=(sum(bool(r["truth_equivalent"]) for r in rs) / n) if n else math.nan,
            fp_per_run=float(np.mean([r["fp"] for r in ok])) if ok else math.nan,
            any_fp=float(np.mean([r["fp"] > 0 for r in ok])) if ok else math.nan,
            fn_per_run=float(np.mean([r["fn"] for r in ok])) if ok else math.nan,
            covered=int(sum(cov)),
            intervals=len(cov),
            coverage=(sum(cov) / len(cov)) if cov else math.nan,
            coverage_low=clo,
            coverage_high=chi,
            coef_error_median=_median([r.get("coef_error") for r in ok]),
            consistent=float(np.mean([r["consistent"] for r in ok])) if ok else math.nan,
            simulations_median=_median([r.get("simulations") for r in ok]),
            seconds_median=_median([r.get("seconds") for r in rs]),
        )
        rows.append(row)
        terms = {}
        for r in ok:
            for t in r["selected"]:
                terms[t] = terms.get(t, 0) + 1
        inclusion[ci] = {t: c / len(ok) for t, c in sorted(terms.items())} if ok else {}
    return rows, inclusion


RUN_COLUMNS = (
    "key",
    "cell",
    "seed",
    "status",
    "exact",
    "selected",
    "tp",
    "fp",
    "fn",
    "truth_equivalent",
    "coef_error",
    "covered",
    "intervals",
    "interval_method",
    "consistent",
    "I2",
    "I2_floor",
    "verdict",
    "simulations",
    "seconds",
    "error",
)


def run_rows(config, runs):
    """One flat row per run (factor values, then :data:`RUN_COLUMNS`), in run order."""
    out = []
    for r in sorted(runs, key=lambda r: (r["cell"], r["seed"])):
        cell = config.cells[r["cell"]]
        row = {f: _factor_text(f, cell[f]) for f in cell}
        cov = r.get("coverage", {}) or {}
        row.update(
            key=r["key"],
            cell=r["cell"],
            seed=r["seed"],
            status=r["status"],
            exact=bool(r.get("exact")),
            selected=" + ".join(r.get("selected", [])),
            tp=r.get("tp"),
            fp=r.get("fp"),
            fn=r.get("fn"),
            truth_equivalent=bool(r.get("truth_equivalent")),
            coef_error=r.get("coef_error"),
            covered=sum(cov.values()),
            intervals=len(cov),
            interval_method=r.get("interval_method"),
            consistent=r.get("consistent"),
            I2=(r.get("criteria") or {}).get("I2"),
            I2_floor=(r.get("noise_floor") or {}).get("I2"),
            verdict=r.get("verdict", ""),
            simulations=r.get("simulations"),
            seconds=r.get("seconds"),
            error=r.get("error", ""),
        )
        out.append(row)
    return out


def _cell_text(v):
    if isinstance(v, float):
        return "" if math.isnan(v) else f"{v:.6g}"
    if v is None:
        return ""
    return str(v)


def to_csv(rows):
    """CSV text of a list of dict rows (the keys of the first row are the columns)."""
    if not rows:
        return ""
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    cols = list(rows[0])
    w.writerow(cols)
    for r in rows:
        w.writerow([_cell_text(r.get(c)) for c in cols])
    return buf.getvalue()
