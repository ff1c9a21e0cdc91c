"""The saved outputs of the surveys: one JSON-lines *run file* per survey run.

Not a test module.  A run file's first line is ``{"run": {...}}``: the survey, the command
that ran it, the git commit and the code version (:func:`code_version`, the hash of the
package's source) of the code that made the rows, and when it started; every other line is
one of the survey's rows.  The measured tables of the documentation are rendered from these
files (:mod:`tests.tables`), so each table says which code made it.  Survey outputs kept for
the tables live in ``docs/_measured/`` (``make surveys`` writes them there).
"""

import datetime as dt
import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
MEASURED = ROOT / "docs" / "_measured"


def git(*args):
    try:
        out = subprocess.run(
            ["git", *args], cwd=ROOT, capture_output=True, text=True, timeout=30, check=True
        )
    except (OSError, subprocess.SubprocessError):
        return None
    return out.stdout.strip()


def stamp(survey, argv=None, command=None):
    """The header of a run started now: the survey, its command (``python -m
    tests.SURVEY ARGV`` unless ``command`` says otherwise), the commit (with ``+dirty`` when
    the package's source differs from it) and the code version."""
    from discovery.vibroimpact.studies.run_files import code_version

    commit = git("rev-parse", "--short", "HEAD")
    if commit and git("status", "--porcelain", "--", "discovery", "constraints"):
        commit += "+dirty"
    argv = sys.argv[1:] if argv is None else argv
    return {
        "survey": survey,
        "command": command or " ".join(["python -m", f"tests.{survey}", *argv]),
        "commit": commit,
        "code": code_version(),
        "started": dt.datetime.now(dt.UTC).strftime("%Y-%m-%dT%H:%MZ"),
    }


class RunFile:
    """A run file being written: the header first (a new file replaces an old one, or
    ``append`` continues it; ``header``'s items are added to it, such as the machine), then
    each row as soon as it is made."""

    def __init__(self, path, survey, argv=None, append=False, command=None, **header):
        self.path = Path(path)
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fresh = not (append and self.path.exists() and self.path.stat().st_size)
        if fresh:
            with open(self.path, "w") as fh:
                run = {**stamp(survey, argv, command), **header}
                print(json.dumps({"run": run}), file=fh, flush=True)

    def write(self, row):
        with open(self.path, "a") as fh:
            print(json.dumps(row, default=float), file=fh, flush=True)


def write_pooled(out, fn, jobs, workers):
    """``fn(job)`` for every job on ``workers`` spawned processes, each result's rows (a
    list) written to the run file ``out`` and printed as they come."""
    from multiprocessing import get_context

    with get_context("spawn").Pool(workers) as pool:
        for result in pool.imap_unordered(fn, jobs):
            for row in result:
                out.write(row)
                print(json.dumps(row), flush=True)


def rows(paths):
    """Every row of the run files ``paths``, in order."""
    return [r for p in paths for r in read(p)[1]]


def read(path):
    """``(header, rows)`` of a run file (a file without a header: ``{}``; lines that are
    not JSON objects, such as warnings captured with the rows, are skipped)."""
    header, rows = {}, []
    with open(path) as fh:
        for line in fh:
            if not line.startswith("{"):
                continue
            item = json.loads(line)
            if "run" in item and len(item) == 1:
                header = item["run"]
            else:
                rows.append(item)
    return header, rows
