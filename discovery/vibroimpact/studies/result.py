"""A study's result: :class:`StudyResult` (its runs, per-cell and pooled aggregates, design
and summary) and the study's description as run (``config.json``'s content)."""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path

from ..._api._printing import readable
from ..._api._result import Result
from ...errors import InputError
from .aggregate import run_rows
from .config import StudyConfig

__all__ = ["StudyResult"]


def _loaded_config(d):
    c = d["config"]
    return StudyConfig(
        name=c["name"],
        cells=tuple(c["cells"]),
        seeds=tuple(c["seeds"]),
        fit=c["fit"],
        record=c["record"],
        varied=tuple(c["varied"]),
        source=c["source"],
    )


@readable
@dataclass(frozen=True, eq=False)
class StudyResult(Result):
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
    n_runs : int
        Runs the design asks for (``runs`` holds the complete ones).
    parallel_efficiency : float or None
    code_version : str
        The code version the run files are keyed by.
    """

    KIND = "study"
    _LOAD = {
        "config": _loaded_config,
        "runs": lambda d: [],  # in the study's runs/ folder, not in its summary
        "inclusion": lambda d: {},  # the runs' inclusion counts: not in the summary either
        "n_runs": lambda d: d["runs"],
        "out": lambda d: Path(d["out"]),
        "figures": lambda d: tuple(Path(d["out"]) / f for f in d.get("figures", ())),
    }

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
    n_runs: int = 0
    parallel_efficiency: float | None = None
    code_version: str = ""

    def as_dict(self):
        """The study's summary (``summary.json``, less the run's provenance)."""
        cfg = self.config
        return {
            "kind": "study",
            "name": cfg.name,
            "runs": self.n_runs,
            "complete": self.complete,
            "executed": self.executed,
            "reused": self.reused,
            "executor": self.executor,
            "seconds": self.seconds,
            "parallel_efficiency": self.parallel_efficiency,
            "code_version": self.code_version,
            "design": self.design(),
            "pooled": self.pooled(),
            "cells": self.cells,
            "config": _config_dict(cfg, self.code_version),
            "out": str(self.out),
            "figures": [Path(f).name for f in self.figures],
        }

    @property
    def complete(self):
        """The number of runs done (on a loaded result, whose runs are in the study's
        ``runs/`` folder and not in its summary, the summary's count)."""
        if self.loaded:
            return self.__dict__["_document"].get("complete", 0)
        return len(self.runs)

    def design(self):
        """The factors with their levels (varied ones first), the fixed options, the fit's
        and the record's options, the seeds and the number of cells."""
        return _design(self.config)

    def pooled(self):
        """``{selection method: recovery, truth among the equivalent models, false
        positives, coverage}`` over the runs (on a loaded result, whose runs are not in its
        summary, the summary's)."""
        if self.loaded:
            return copy.deepcopy(self.__dict__["_document"].get("pooled") or {})
        return _pooled(self.runs, self.config)

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


def _config_dict(cfg, version):
    """The study as run: its cells, seeds and settings, the code version."""
    return {
        "name": cfg.name,
        "source": cfg.source,
        "seeds": cfg.seeds,
        "fit": cfg.fit,
        "record": cfg.record,
        "varied": cfg.varied,
        "cells": cfg.cells,
        "code_version": version,
    }
