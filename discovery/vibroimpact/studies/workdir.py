"""A study's work directory ``.DIR.vidi-study`` beside its output ``DIR`` (:class:`_Work`):
locked against a second study, the missing runs done into it one file each, and the whole
study (runs, ``config.json``, tables, figures, summary) staged from it and put in place of
``DIR`` in one step."""

from __future__ import annotations

import contextlib
import fcntl
import json
import os
import shutil
import time
from pathlib import Path

from ..._api._progress import tick
from ..._files._io import OutputDir, atomic_write_text, running, short, to_jsonable
from ...errors import InputError
from ...numerics.executor import make_executor
from ..dynamics.warmup import compile_kernels
from .aggregate import aggregate, run_rows, to_csv
from .result import _config_dict
from .run import run_cost, run_one


def _write_config(out, cfg, version):
    """``config.json``: the study as run (its cells, seeds and settings, the code version)."""
    atomic_write_text(
        out / "config.json",
        json.dumps(to_jsonable(_config_dict(cfg, version)), indent=1, allow_nan=True),
    )


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


class _Work:
    """The study's work directory ``.DIR.vidi-study`` beside ``DIR``: its runs as they land,
    locked against a second study into the same ``DIR``; kept when the study stops with
    runs in it (so the same command continues), removed when it holds none or the study
    was put in place."""

    def __init__(self, out):
        target = Path(os.path.abspath(out))
        self.target = target
        self.path = target.parent / f".{target.name}.vidi-study"
        self.runs = self.path / "runs"
        self._lock = None

    def __enter__(self):
        self._parents = []
        p = self.path.parent
        while not p.exists():
            self._parents.append(p)
            p = p.parent
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self.runs.mkdir(parents=True, exist_ok=True)
            fd = os.open(self.path / ".lock", os.O_RDWR | os.O_CREAT, 0o666)
        except OSError as exc:
            raise InputError(
                f"cannot create the study's work directory {short(self.path)!r} "
                f"({exc.strerror}); choose a writable location"
            ) from None
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            os.close(fd)
            raise InputError(
                f"another study is writing to {short(self.target)!r} now; wait for it to "
                "finish, or give this one its own --out"
            ) from None
        self._lock = fd
        return self

    def n_runs(self, keys=None):
        """Run files in the work directory (of ``keys`` only, when given)."""
        try:
            names = {f.name for f in self.runs.iterdir() if f.suffix == ".json"}
        except OSError:
            return 0
        return len(names if keys is None else names & {f"{k}.json" for k in keys})

    def failed(self, exc, keys, out):
        """Say what was kept: the interrupt's message names the work directory and how to
        continue; a study that stopped with no run kept leaves nothing behind."""
        kept = self.n_runs(keys)
        total = len(keys)
        where = (
            f"{short(out)!r} is unchanged"
            if self.target.exists()
            else f"nothing was written to {short(out)!r}"
        )

        def note(resume):
            if not kept:
                return f"no run was kept; {where}"
            return (
                f"{kept} finished run(s) of {total} kept in {short(self.path)!r}; {resume}; {where}"
            )

        with contextlib.suppress(Exception):
            exc.vidi_note = note("run the same command again to continue")  # the CLI's line
        if isinstance(exc, KeyboardInterrupt) and hasattr(exc, "add_note"):
            # the API's traceback ends with what was kept and how to go on
            exc.add_note(
                "study: " + note("call study() again with the same config and out to continue")
            )
        if not self.n_runs():  # nothing of this or an earlier interrupted study there
            self._remove()

    def finish(self):
        self._remove()

    def _remove(self):
        shutil.rmtree(self.path, ignore_errors=True)
        if not self.target.exists():
            for d in self._parents:  # folders made for a study that left nothing
                with contextlib.suppress(OSError):
                    d.rmdir()

    def __exit__(self, *exc):
        if self._lock is not None:
            with contextlib.suppress(OSError):
                os.close(self._lock)
        return False

    def run_missing(self, todo, have, runs, version, *, workers, scheduler, executor, progress):
        """Run ``todo`` on the executor, longest first (:func:`run_cost`), one file per finished
        run in :attr:`runs` (its record also goes into ``have``; ``runs`` is the study's every
        run, for the progress); returns the executor's name, the number of runs done and the
        parallel efficiency (the runs' seconds over the wall time times the workers; None when
        nothing ran).  ``workers``, ``scheduler``, ``executor`` and ``progress`` are
        :func:`study`'s."""
        own = executor is None
        ex = make_executor(workers, scheduler, warm=compile_kernels) if own else executor
        name = repr(ex)
        # the longest runs first, so no worker is left with one long run at the end (the
        # results do not depend on the order: one file per run, tables from the files)
        todo = sorted(todo, key=run_cost, reverse=True)
        t0, busy = time.perf_counter(), 0.0
        try:
            done = 0
            tick(progress, "study: runs", len(have), len(runs))
            for _, res in ex.run(run_one, todo):
                busy += float(res.get("seconds", 0.0))
                res["code_version"] = version
                res = to_jsonable(res)
                atomic_write_text(
                    self.runs / f"{res['key']}.json", json.dumps(res, indent=1, allow_nan=True)
                )
                have[res["key"]] = res
                done += 1
                tick(progress, "study: runs", len(have), len(runs))
        finally:
            if own:
                ex.close()
        wall = time.perf_counter() - t0
        slots = max(1, min(int(getattr(ex, "workers", 1) or 1), len(todo)))
        # the runs' own seconds over the wall time the workers were held
        efficiency = busy / (wall * slots) if done and wall > 0 else None
        return name, done, efficiency

    def stage(self, out, inputs, cfg, records, *, figures, result_of, version):
        """Write the whole study (runs, config, tables, figures, summary) into a staging
        directory and put it in place of ``out`` as a whole (a run's file from this work
        directory, else from ``out``); returns the result (``result_of(cells, inclusion, figure
        paths)``), whose ``to_dict()`` is the summary."""
        with running("study"), OutputDir(out, inputs) as od:
            stage = od.stage
            os.mkdir(stage / "runs")
            for rec in records:
                name = f"{rec['key']}.json"
                src = self.runs / name
                if not src.is_file():
                    src = Path(out) / "runs" / name
                try:
                    os.link(src, stage / "runs" / name)
                except OSError:
                    shutil.copyfile(src, stage / "runs" / name)
            _write_config(stage, cfg, version)
            cells, inclusion = _write_tables(stage, cfg, records)
            paths = ()
            if figures and records:
                paths = tuple(figures(cfg, records, stage))
            result = result_of(cells, inclusion, paths)
            result.write_into(od)
        return result
