"""The study driver: plan the runs, do the missing ones on an executor, aggregate from files.

Output directory::

    DIR/runs/<key>.json     one file per run, named by the hash of its full description and
                            the code version, written to a temporary name and renamed: a
                            study killed at any moment (even ``kill -9``) resumes where it
                            stopped, with nothing lost or done twice
    DIR/config.json         the parsed study (cells, seeds, fixed options)
    DIR/cells.csv           one row per cell: recovery with its Wilson interval, false
                            positives, coverage of the intervals, coefficient error, ...
    DIR/runs.csv            one row per run
    DIR/inclusion.csv       how often each term was selected, per cell
    DIR/*.png, *.pdf        recovery against noise per method, recovery over noise x record
                            length, interval coverage against nominal, term inclusion
    DIR/summary.json        provenance (versions, commit, settings, seeds, executor)

The aggregates are always computed from the run files of the study's runs, never from
memory, so a resumed study and one run in one go give the same tables.
"""

from __future__ import annotations

import json
import math
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

from ..._io import MANIFEST, atomic_write_text, check_output, provenance, running, to_jsonable
from ..._printing import readable
from ..._progress import tick
from ..._validate import Instance, Real, Text, params
from ...errors import InputError
from ...numerics.executor import make_executor
from .aggregate import aggregate, run_rows, to_csv
from .config import StudyConfig, load_study
from .run import run_one

__all__ = ["study", "StudyResult", "code_version"]

_FIT_DEFAULTS = {"n_boot_intervals": 0}


def code_version():
    """The package version and a hash of its source (every ``.py`` file of ``discovery`` and
    ``constraints``): part of every run's key, so a change of the code that computes a run
    gives new runs, and a change of anything else (documentation, tests) keeps them."""
    from importlib import metadata

    try:
        version = metadata.version("vibroimpact-discovery")
    except metadata.PackageNotFoundError:
        version = "unknown"
    return f"{version}+src.{_source_hash()}"


def _source_hash():
    import hashlib

    root = Path(__file__).resolve().parents[3]
    h = hashlib.sha256()
    for pkg in ("discovery", "constraints"):
        for path in sorted((root / pkg).rglob("*.py")):
            h.update(str(path.relative_to(root)).encode())
            h.update(path.read_bytes())
    return h.hexdigest()[:12]


def _read_run(path):
    try:
        with open(path, encoding="utf-8") as fh:
            data = json.load(fh)
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) and "key" in data else None


@readable
@dataclass(frozen=True)
class StudyResult:
    """Outcome of :func:`study`.

    Attributes
    ----------
    config : StudyConfig
    runs : list of dict
        Every run's record (as in its file), in run order.
    cells : list of dict
        One aggregate row per cell (``cells.csv``).
    inclusion : dict
        ``{cell index: {term: selection frequency}}``.
    out : Path
        The study directory.
    executed, reused : int
        Runs done by this call, and runs found in files from an earlier call.
    seconds : float
    executor : str
    """

    config: StudyConfig
    runs: list
    cells: list
    inclusion: dict
    out: Path
    executed: int = 0
    reused: int = 0
    seconds: float = 0.0
    executor: str = ""
    figures: tuple = field(default_factory=tuple)

    def table(self, runs=False):
        """The cells (or with ``runs=True`` every run) as a pandas DataFrame."""
        try:
            import pandas as pd
        except ImportError:
            raise InputError(
                "StudyResult.table() needs pandas; install it with pip install "
                "pandas (or read cells.csv)"
            ) from None
        return pd.DataFrame(run_rows(self.config, self.runs) if runs else self.cells)

    def _lines(self):
        cfg = self.config
        out = [
            f"study {cfg.name!r}: {len(cfg.cells)} cells x {len(cfg.seeds)} seeds = "
            f"{cfg.n_runs} runs ({self.executed} run now, {self.reused} from earlier files; "
            f"{self.seconds:.1f} s on {self.executor})"
        ]
        shown = list(cfg.varied) or ["selection"]
        head = "  ".join(f"{f[:14]:<14}" for f in shown)
        out.append(f"  {head}  recovery (95 % CI)    FP/run  coverage  coef.err")
        for row in self.cells:
            vals = "  ".join(f"{str(row[f])[:14]:<14}" for f in shown)
            rec = (
                f"{row['recovered']:>3}/{row['runs']:<3} "
                f"({row['recovery_low']:.2f}-{row['recovery_high']:.2f})"
            )
            cov = "-" if not row["intervals"] else f"{row['covered']}/{row['intervals']}"
            err = "-" if math.isnan(row["coef_error_median"]) else f"{row['coef_error_median']:.2g}"
            fp = "-" if math.isnan(row["fp_per_run"]) else f"{row['fp_per_run']:.2f}"
            out.append(f"  {vals}  {rec:<21} {fp:>6}  {cov:>8}  {err:>8}")
        failed = sum(r["status"] != "ok" for r in self.runs)
        if failed:
            out.append(f"  {failed} run(s) failed (counted as not recovered; see runs.csv)")
        out.append(f"results in {self.out}")
        return out


def _write_manifest(out, names):
    data = {"command": "study", "files": sorted(set(names))}
    atomic_write_text(out / MANIFEST, json.dumps(data, indent=1))


def _design(cfg):
    """The factors with their levels (varied ones first), the fixed options and seeds."""
    from .aggregate import _factor_text

    levels = {}
    for f in cfg.cells[0]:
        vals = []
        for c in cfg.cells:
            v = _factor_text(f, c[f])
            if v not in vals:
                vals.append(v)
        levels[f] = vals
    return {
        "varied": {f: levels[f] for f in cfg.varied},
        "fixed": {f: levels[f][0] for f in levels if f not in cfg.varied},
        "fit": cfg.fit,
        "record": cfg.record,
        "seeds": list(cfg.seeds),
        "cells": len(cfg.cells),
    }


def _pooled(records, cfg):
    """Per selection method over every other factor: recovery, truth among the equivalent
    models, false positives, coverage (with Wilson intervals)."""
    from .aggregate import wilson

    out = {}
    for m in sorted({cfg.cells[r["cell"]]["selection"] for r in records}):
        rs = [r for r in records if cfg.cells[r["cell"]]["selection"] == m]
        ok = [r for r in rs if r["status"] == "ok"]
        k = sum(bool(r["exact"]) for r in rs)
        cov = [c for r in ok for c in (r.get("coverage") or {}).values()]
        out[m] = {
            "runs": len(rs),
            "recovered": k,
            "recovery_ci": wilson(k, len(rs)),
            "equivalent": sum(bool(r["truth_equivalent"]) for r in rs),
            "fp_per_run": (sum(r["fp"] for r in ok) / len(ok)) if ok else None,
            "covered": int(sum(cov)),
            "intervals": len(cov),
            "coverage_ci": wilson(sum(cov), len(cov)),
            "failed": len(rs) - len(ok),
        }
    return out


def _write_config(out, cfg, version):
    """``config.json``: the study as run (its cells, seeds and settings, the code version)."""
    atomic_write_text(
        out / "config.json",
        json.dumps(
            to_jsonable(
                {
                    "name": cfg.name,
                    "source": cfg.source,
                    "seeds": cfg.seeds,
                    "fit": cfg.fit,
                    "record": cfg.record,
                    "varied": cfg.varied,
                    "cells": cfg.cells,
                    "code_version": version,
                }
            ),
            indent=1,
            allow_nan=True,
        ),
    )


def _run_missing(todo, have, runs, rundir, version, workers, scheduler, executor, progress):
    """Run ``todo`` on the executor, one file per finished run; returns the executor's name
    and the number of runs done."""
    own = executor is None
    ex = make_executor(workers, scheduler) if own else executor
    name = repr(ex)
    try:
        done = 0
        tick(progress, "study: runs", len(have), len(runs))
        for _, res in ex.run(run_one, todo):
            res["code_version"] = version
            atomic_write_text(
                rundir / f"{res['key']}.json",
                json.dumps(to_jsonable(res), indent=1, allow_nan=True),
            )
            done += 1
            tick(progress, "study: runs", len(have) + done, len(runs))
    finally:
        if own:
            ex.close()
    return name, done


def _write_tables(out, cfg, records):
    """``cells.csv``, ``runs.csv`` and ``inclusion.csv`` from the run files; returns the
    cells and the term inclusion per cell."""
    cells, inclusion = aggregate(cfg, records)
    rows = run_rows(cfg, records)
    atomic_write_text(out / "cells.csv", to_csv(cells))
    atomic_write_text(out / "runs.csv", to_csv(rows))
    terms = sorted({t for inc in inclusion.values() for t in inc})
    inc_rows = [
        {**{f: c[f] for f in cfg.varied}, **{t: inclusion[i].get(t, 0.0) for t in terms}}
        for i, c in enumerate(cells)
    ]
    atomic_write_text(out / "inclusion.csv", to_csv(inc_rows))
    return cells, inclusion


def _summary(cfg, runs, records, result, version, cells, workers, scheduler, max_runs):
    """``summary.json`` of the study."""
    return {
        "command": "study",
        "kind": "study",
        "name": cfg.name,
        "runs": len(runs),
        "complete": len(records),
        "executed": result.executed,
        "reused": result.reused,
        "executor": result.executor,
        "code_version": version,
        "design": _design(cfg),
        "pooled": _pooled(records, cfg),
        "cells": cells,
        "seconds": result.seconds,
        **provenance(
            settings={
                "config": cfg.source,
                "fit": cfg.fit,
                "record": cfg.record,
                "seeds": list(cfg.seeds),
                "workers": workers,
                "scheduler": scheduler,
                "max_runs": max_runs,
            },
            inputs={"config": cfg.source} if os.path.isfile(cfg.source) else None,
        ),
    }


@params(
    config=(Text(), os.PathLike, dict, StudyConfig),
    out=(Text(), os.PathLike),
    workers=(None, Real(1, 4096, integer=True)),
    scheduler=(None, Text()),
    executor=(None, Instance("discovery.numerics.executor", "Executor")),
    max_runs=(None, Real(0, integer=True)),
)
def study(
    config,
    out,
    *,
    workers=None,
    scheduler=None,
    executor=None,
    progress=None,
    max_runs=None,
    figures=True,
):
    """Run a model-term selection study (see :mod:`discovery.vibroimpact.studies`).

    Parameters
    ----------
    config : str, Path, dict or StudyConfig
        A study file (TOML), its parsed mapping, or a :class:`StudyConfig`.
    out : str or Path
        The study directory.  Runs already there (from an interrupted or earlier call with
        the same code version) are reused, not run again.
    workers : int, optional
        Local worker processes (default one per CPU; 1 runs in this process).
    scheduler : str, optional
        A Dask scheduler address (``tcp://host:port``) or ``"local"`` for a LocalCluster.
    executor : Executor, optional
        Use this executor (overrides ``workers`` and ``scheduler``; not closed here).
    progress : callable, optional
        ``progress(stage, done, total)`` as runs finish.
    max_runs : int, optional
        Do at most this many missing runs, then aggregate what the files hold (a study in
        slices; the rest runs on the next call).
    figures : bool
        Draw the figures.

    Returns
    -------
    StudyResult
    """
    t0 = time.perf_counter()
    cfg = load_study(config)
    cfg = StudyConfig(**{**cfg.__dict__, "fit": {**_FIT_DEFAULTS, **cfg.fit}})
    with running("study"):  # the directory is a study's, whatever ran before in this process
        out = check_output(out, [cfg.source] if cfg.source else [])
    version = code_version()
    runs = cfg.runs(version)
    rundir = out / "runs"
    rundir.mkdir(parents=True, exist_ok=True)
    _write_manifest(out, ["runs", "config.json"])
    _write_config(out, cfg, version)
    have = {r["key"] for r in runs if _read_run(rundir / f"{r['key']}.json") is not None}
    todo = [r for r in runs if r["key"] not in have]
    if max_runs is not None:
        todo = todo[: int(max_runs)]
    name, done = _run_missing(
        todo, have, runs, rundir, version, workers, scheduler, executor, progress
    )
    records = [rec for r in runs if (rec := _read_run(rundir / f"{r['key']}.json")) is not None]
    cells, inclusion = _write_tables(out, cfg, records)
    paths = ()
    if figures and records:
        from reports.vibroimpact.study_figures import study_figures

        paths = tuple(study_figures(cfg, records, out))
    written = ["runs", "config.json", "cells.csv", "runs.csv", "inclusion.csv", "summary.json"]
    written += [Path(p).name for p in paths]
    result = StudyResult(
        config=cfg,
        runs=records,
        cells=cells,
        inclusion=inclusion,
        out=out,
        executed=done,
        reused=len(have),
        seconds=time.perf_counter() - t0,
        executor=name,
        figures=paths,
    )
    summary = _summary(cfg, runs, records, result, version, cells, workers, scheduler, max_runs)
    atomic_write_text(
        out / "summary.json", json.dumps(to_jsonable(summary), indent=1, allow_nan=True)
    )
    _write_manifest(out, written)
    return result
