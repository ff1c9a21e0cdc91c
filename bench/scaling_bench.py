"""How parallel work scales: a study and ``explain`` on 1, 2 and every core, in one run.

- **study**: 24 runs (the paper's law, two force-noise levels, three selection methods, four
  seeds, 4-period records, refinement on) on the process pool with each worker count; the
  wall time, the speed-up over the smallest count and the parallel efficiency the study
  records (its runs' seconds over the wall time times the workers: 1 means no worker ever
  waited);
- **explain**: the bench's 20-period record with a hidden coupling, the full catalogue, with
  each worker count; the wall time and the speed-up over one worker.

``python run.py scaling [--workers 1,2,16] [--study-workers 2,16] [--paper-study]`` runs
this section alone (the paper study, ``examples/study_paper.toml``, 120 runs, on every
core: meant for a machine with many cores, not for ``make bench`` on two).
"""

import os
import tempfile
import time
from pathlib import Path

import numpy as np

STUDY = {
    "name": "scaling",
    "seeds": 4,
    "factors": {
        "force_noise": [0.01, 0.05],
        "periods": [4],
        "library": ["z, zd, z^2, z*zd, zd^2, z^1.5"],
        "selection": ["best-subset", "stlsq", "sr3"],
        "refine": [True],
    },
}


def worker_counts(text=None):
    """The worker counts to measure: 1, 2 and every core (duplicates dropped), or the
    comma-separated list ``text``."""
    if text:
        return sorted({int(w) for w in text.split(",")})
    return sorted({1, min(2, os.cpu_count() or 1), os.cpu_count() or 1})


def _study(cfg, workers):
    from discovery.vibroimpact.studies import study

    with tempfile.TemporaryDirectory() as d:
        t0 = time.perf_counter()
        res = study(cfg, Path(d) / "s", figures=False, workers=workers)
        wall = time.perf_counter() - t0
        cells = [{k: v for k, v in row.items() if "seconds" not in k} for row in res.cells]
    return {
        "workers": workers,
        "seconds": wall,
        "parallel_efficiency": res.parallel_efficiency,
        "runs": res.executed,
    }, cells


def bench_study_scaling(counts):
    """The 24-run study on each worker count (the tables must agree)."""
    rows, tables = [], []
    for w in counts:
        row, cells = _study(STUDY, w)
        rows.append(row)
        tables.append(cells)
    base = rows[0]
    for row in rows:
        row["speedup"] = base["seconds"] / row["seconds"]
        row["speedup_over_workers"] = base["workers"]
    return {
        "runs": rows[0]["runs"],
        "by_workers": rows,
        "same_table": all(t == tables[0] for t in tables),
    }


def bench_paper_study(workers):
    """The paper study (``examples/study_paper.toml``, 120 runs) on ``workers`` processes."""
    import tomllib

    path = Path(__file__).resolve().parent.parent / "examples" / "study_paper.toml"
    cfg = tomllib.loads(path.read_text())
    row, _ = _study(cfg, workers)
    return row


def bench_explain_scaling(counts):
    """explain on the bench's record with each worker count (the same effect named)."""
    from explain_bench import bench_record

    from discovery.vibroimpact.dynamics.steady_states import steady_state
    from discovery.vibroimpact.explain import explain

    sc, rec = bench_record()
    steady_state(sc, sc.law)  # kernels loaded
    rows, named = [], []
    for w in counts:
        ts = []
        for _ in range(2):
            t0 = time.perf_counter()
            res = explain(sc, rec, "linear", workers=w)
            ts.append(time.perf_counter() - t0)
        rows.append({"workers": w, "seconds": float(np.min(ts))})
        named.append([it.effect for it in res.iterations if it.effect])
    for row in rows:
        row["speedup"] = rows[0]["seconds"] / row["seconds"]
        row["speedup_over_workers"] = rows[0]["workers"]
    return {"by_workers": rows, "named": named[0], "same_named": all(n == named[0] for n in named)}


def bench_scaling(counts=None, paper_study=False, study_counts=None):
    counts = counts or worker_counts()
    out = {
        "cores": os.cpu_count(),
        "study": bench_study_scaling(study_counts or counts),
        "explain": bench_explain_scaling(counts),
    }
    if paper_study:
        out["paper_study"] = bench_paper_study(os.cpu_count() or 1)
    return out


def print_scaling(s):
    st = s["study"]
    print(
        f"study ({st['runs']} runs; same table {st['same_table']}): "
        + "; ".join(
            f"{r['workers']} workers {r['seconds']:.1f} s, {r['speedup']:.2f}x, "
            f"efficiency {r['parallel_efficiency']:.2f}"
            for r in st["by_workers"]
        )
    )
    ex = s["explain"]
    print(
        f"explain (named {ex['named']}, same on every count {ex['same_named']}): "
        + "; ".join(
            f"{r['workers']} workers {r['seconds']:.1f} s, {r['speedup']:.2f}x"
            for r in ex["by_workers"]
        )
    )
    if "paper_study" in s:
        p = s["paper_study"]
        print(
            f"paper study (120 runs) on {p['workers']} workers: {p['seconds']:.0f} s, "
            f"parallel efficiency {p['parallel_efficiency']:.2f}"
        )
