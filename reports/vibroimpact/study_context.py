"""What a study's report says: recovery, coverage and inclusion from its document."""

from __future__ import annotations

from ..cells import (
    _figures,
)
from ..lawtex import value_tex
from ..texenv import Tex, escape, num


def _frac(k, n, ci=None):
    """``k/n (lo--hi)``, or -- without cases."""
    if not n:
        return Tex("--")
    out = escape(f"{k}/{n}")
    if ci and ci[0] == ci[0]:
        out += f" ({ci[0]:.2f}--{ci[1]:.2f})"
    return Tex(out)


def _study(doc, run_dir):
    r = doc.result
    d = r.design()
    varied = list(d.get("varied") or {})
    pooled = r.pooled()
    cells = r.cells or []
    name = r.config.name
    c = {
        "title": "Model-term selection study" + (f": {name}" if name else ""),
        "design": [
            [Tex(r"\texttt{" + escape(k) + "}"), value_tex(v)]
            for k, v in (d.get("varied") or {}).items()
        ]
        + [
            [Tex(r"\texttt{" + escape(k) + "}"), Tex(value_tex(v) + " (fixed)")]
            for k, v in (d.get("fixed") or {}).items()
        ]
        + [
            ["fit options", "; ".join(f"{k}={v}" for k, v in (d.get("fit") or {}).items()) or "--"],
            [
                "record options",
                "; ".join(f"{k}={v}" for k, v in (d.get("record") or {}).items()) or "--",
            ],
            ["seeds", ", ".join(map(str, d.get("seeds") or []))],
            [
                "runs",
                f"{r.complete or 0} of {r.n_runs or 0} done ({d.get('cells', '?')} cells)",
            ],
        ],
        "varied": varied,
        "pooled": [
            [
                m,
                _frac(p["recovered"], p["runs"], p.get("recovery_ci")),
                f"{p['equivalent']}/{p['runs']}",
                num(p.get("fp_per_run"), 2),
                _frac(p["covered"], p["intervals"], p.get("coverage_ci")),
                p.get("failed", 0),
            ]
            for m, p in pooled.items()
        ],
        "cells": [
            [
                *(value_tex(row.get(f, "")) for f in varied),
                _frac(
                    row["recovered"],
                    row["runs"],
                    (row.get("recovery_low"), row.get("recovery_high")),
                ),
                num(row.get("fp_per_run"), 2),
                _frac(row.get("covered", 0), row.get("intervals", 0)),
                num(row.get("coef_error_median"), 2),
            ]
            for row in cells
        ],
    }
    concl = []
    if pooled:
        rate = {m: p["recovered"] / max(p["runs"], 1) for m, p in pooled.items()}
        top = [m for m in pooled if rate[m] == max(rate.values())]
        p = pooled[top[0]]
        concl.append(
            f"Across the study, {' and '.join(top)} recovered the exact true support "
            f"most often: {p['recovered']} of {p['runs']} runs"
            + (" each." if len(top) > 1 else ".")
        )
        for m, p in pooled.items():
            if p["intervals"]:
                share = p["covered"] / p["intervals"]
                lo, hi = p["coverage_ci"]
                verdict = (
                    "consistent with the nominal 95 %"
                    if lo <= 0.95 <= hi
                    else "below the nominal 95 %: the intervals are too narrow"
                    if hi < 0.95
                    else "above the nominal 95 %"
                )
                concl.append(
                    f"{m}: the 95 % intervals held the truth in {share:.0%} of "
                    f"{p['intervals']} cases ({lo:.2f}--{hi:.2f}), {verdict}."
                )
    if pooled and not any(p.get("intervals") for p in pooled.values()):
        concl.append(
            "No run has coefficient intervals (they come from the refinement by "
            "simulation: set refine = [true]), so there is no coverage chart."
        )
    concl.append(
        "Records were made by the independent scipy path from rest; no selection "
        "used the truth (no oracle settings)."
    )
    c["conclusions"] = concl
    c["figures"] = _figures(run_dir, ["recovery_noise", "recovery_map", "coverage", "inclusion"])
    return c
