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

A study is staged like every other result: its runs land in a work directory beside the
target, ``.DIR.vidi-study/runs`` (kept when the study is interrupted or killed, so the same
command continues where it stopped; removed when no run landed), and the whole directory
(runs, config, tables, figures, manifest) replaces ``DIR`` in one step only at the end.  An
interrupted or failing study therefore leaves an earlier ``DIR`` exactly as it was.  A study
whose cells, seeds or options differ from the finished one in ``DIR`` is refused unless
``--overwrite`` (then it replaces it whole; the files a user added are kept).  Every run file
is checked against its name and its schema; a bad one is named and run again.
"""

from __future__ import annotations

import json
import os
import sys
import time
from pathlib import Path

from ..._api._progress import reports_progress
from ..._api._validate import Instance, Real, Text, params
from ..._files._io import _RUN, MANIFEST, check_output, provenance, running, short, to_jsonable
from ...errors import InputError, VidiTypeError
from .config import StudyConfig, load_study
from .result import StudyResult
from .run_files import _read_run, code_version
from .workdir import _Work

__all__ = ["study", "StudyResult", "code_version"]

_FIT_DEFAULTS = {"n_boot_intervals": 0}


def _note(text):
    print(f"vidi: note: {text}", file=sys.stderr)


def _provenance(cfg, settings):
    """The study's provenance (its ``summary.json`` after the result's keys)."""
    return provenance(
        settings={
            "config": cfg.source,
            "fit": cfg.fit,
            "record": cfg.record,
            "seeds": list(cfg.seeds),
            **settings,
        },
        inputs={"config": cfg.source} if os.path.isfile(cfg.source) else None,
    )


@params(
    config=(Text(), os.PathLike, dict, StudyConfig),
    out=(Text(), os.PathLike),
    workers=(None, Real(1, 4096, integer=True)),
    scheduler=(None, Text()),
    executor=(None, Instance("discovery.numerics.executor", "Executor")),
    max_runs=(None, Real(0, integer=True)),
)
@reports_progress
def study(
    config,
    out,
    *,
    workers=None,
    scheduler=None,
    executor=None,
    progress=None,
    max_runs=None,
    figures=None,
):
    """Run a model-term selection study (see :mod:`discovery.vibroimpact.studies`).

    Parameters
    ----------
    config : str, Path, dict or StudyConfig
        A study file (TOML), its parsed mapping, or a :class:`StudyConfig`.
    out : str or Path
        The study directory, written as a whole at the end (the runs land in
        ``.OUT.vidi-study`` beside it meanwhile).  Runs of an interrupted call (kept there)
        or of the finished study in ``out`` (the same cells, seeds and options) with the
        same code version are reused, not run again; another study there is refused
        unless the CLI's ``--overwrite``.
    workers : int, optional
        Local worker processes (default one per CPU; 1 runs in this process).
    scheduler : str, optional
        A Dask scheduler address (``tcp://host:port``) or ``"local"`` for a LocalCluster.
    executor : Executor, optional
        Use this executor (overrides ``workers`` and ``scheduler``; not closed here).
    progress : callable or bool, optional
        ``progress(stage, done, total)`` as runs finish; None: a bar when the session is
        interactive, False: none (:mod:`discovery._api._progress`). Anything else is a
        :class:`~discovery.errors.VidiTypeError`.
    max_runs : int, optional
        Do at most this many missing runs, then aggregate what the files hold (a study in
        slices; the rest runs on the next call).
    figures : callable, optional
        ``figures(config, records, directory) -> paths``: draws the study's figures into
        the directory written as a whole (the report layer's
        :func:`reports.vibroimpact.study_figures.study_figures`, which ``vidi study``
        passes); None or False: no figures.  The study itself draws nothing.

    Returns
    -------
    StudyResult
    """
    t0 = time.perf_counter()
    if figures is not None and figures is not False and not callable(figures):
        raise VidiTypeError(
            "figures must be a callable figures(config, records, directory) -> paths (e.g. "
            "reports.vibroimpact.study_figures.study_figures) or None, "
            f"not {type(figures).__name__}"
        )
    cfg = load_study(config)
    cfg = StudyConfig(**{**cfg.__dict__, "fit": {**_FIT_DEFAULTS, **cfg.fit}})
    inputs = [cfg.source] if cfg.source and os.path.isfile(cfg.source) else []
    with running("study"):  # the directory is a study's, whatever ran before in this process
        out = check_output(out, inputs)
        overwrite = _RUN["overwrite"]
    earlier = _earlier_study(out)
    if earlier is not None and earlier != _identity(cfg) and not overwrite:
        raise InputError(
            f"--out {short(out)!r} holds a finished study of other cells, seeds or options; "
            "give this study its own directory, or add --overwrite to replace it (files you "
            "added there are kept)"
        )
    version = code_version()
    runs = cfg.runs(version)
    n_cells = len(cfg.cells)
    with _Work(out) as work:
        bad = []
        have = {}
        for r in runs:
            rec = _read_run(work.runs / f"{r['key']}.json", r, n_cells, bad)
            if rec is None and earlier is not None:
                rec = _read_run(out / "runs" / f"{r['key']}.json", r, n_cells, bad)
            if rec is not None:
                have[r["key"]] = rec
        for path, why in bad:
            _note(f"run file {short(path)!r} is not a run of this study ({why}); it is run again")
            if Path(path).parent == work.runs:
                Path(path).unlink(missing_ok=True)
        todo = [r for r in runs if r["key"] not in have]
        if max_runs is not None:
            todo = todo[: int(max_runs)]
        try:
            name, done, efficiency = work.run_missing(
                todo,
                have,
                runs,
                version,
                workers=workers,
                scheduler=scheduler,
                executor=executor,
                progress=progress,
            )
            records = [have[r["key"]] for r in runs if r["key"] in have]
            settings = {"workers": workers, "scheduler": scheduler, "max_runs": max_runs}
            seconds = time.perf_counter() - t0  # the runs' (the tables and figures follow)

            def result_of(cells, inclusion, paths):
                return StudyResult(
                    config=cfg,
                    runs=records,
                    cells=cells,
                    inclusion=inclusion,
                    out=out,
                    executed=done,
                    reused=len(records) - done,
                    seconds=seconds,
                    executor=name,
                    figures=tuple(out / Path(p).name for p in paths),
                    n_runs=len(runs),
                    parallel_efficiency=efficiency,
                    code_version=version,
                ).record_run({"command": "study"}, _provenance(cfg, settings))

            result = work.stage(
                out, inputs, cfg, records, figures=figures, result_of=result_of, version=version
            )
        except BaseException as exc:
            work.failed(exc, [r["key"] for r in runs], out)
            raise
        work.finish()
    return result


def _identity(cfg):
    """What makes two studies the same study: cells, seeds and fixed options."""
    return json.dumps(
        to_jsonable({"cells": cfg.cells, "seeds": cfg.seeds, "fit": cfg.fit, "record": cfg.record}),
        sort_keys=True,
    )


def _earlier_study(out):
    """The identity of the finished study in ``out`` (from its ``config.json``), else None;
    a study directory whose config cannot be read counts as another study."""
    p = Path(out)
    try:
        with open(p / MANIFEST, encoding="utf-8") as fh:
            man = json.load(fh)
    except (OSError, ValueError, RecursionError):
        return None
    if not isinstance(man, dict) or man.get("command") != "study":
        return None
    try:
        with open(p / "config.json", encoding="utf-8") as fh:
            data = json.load(fh)
        return json.dumps(
            to_jsonable({k: data[k] for k in ("cells", "seeds", "fit", "record")}),
            sort_keys=True,
        )
    except (OSError, ValueError, RecursionError, KeyError, TypeError):
        return ""
