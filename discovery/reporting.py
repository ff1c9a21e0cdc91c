"""``report``: the LaTeX report of a result or a run directory (see :mod:`reports.document`)."""

from pathlib import Path

from reports.document import Report, compile_tex, render
from reports.document import report as _report
from reports.run import run_document

__all__ = ["Report", "report", "render", "compile_tex"]


def report(run, *, out=None, snippet=None, compile=True, timeout=300):
    """Write ``report.tex`` of a result and compile ``report.pdf``.

    Parameters
    ----------
    run : Result or str or Path
        A result object (``VerifyResult``, ``DiscoveryResult``, ...) or a run directory:
        the ``--out`` of any ``vidi`` command that writes a ``summary.json``, or a
        directory a result was saved into (``result.save(dir)``).
    out : str or Path, optional
        With a result object: the directory of the report.  When it holds no result, the
        result is saved there first (``summary.json``); when it holds this result (a run
        directory with its figures), the report uses its figures; another result there is
        refused.  A report from a result equals the report from its directory.
    snippet, compile, timeout
        See :func:`reports.document.report`.

    Returns
    -------
    Report

    Notes
    -----
    A directory whose ``summary.json`` has a ``schema_version`` is read through
    :func:`discovery.load` (its version and kind checked); one written before results had
    a schema version is reported from its keys as before.
    """
    from ._api._result import Result, command_of, load
    from ._api._validate import Choice, Real, check
    from .errors import InputError, VidiTypeError

    check("report: snippet", snippet, (None, Choice("model", "table", "criteria", "figure")))
    check("report: timeout", timeout, Real(1))
    check("report: compile", compile, bool)  # "no" is text, not False
    if isinstance(run, Result):
        if out is None:
            raise InputError(
                "report: a result object needs out=DIR, the directory to write its report "
                "into (it is saved there when the directory holds no result)"
            )
        doc = command_of(run.to_dict())
        if "command" not in doc:
            raise InputError(f"report: no report for a {doc.get('result')!r} result on its own")
        if not (Path(out) / "summary.json").exists():
            run.save(out)
        elif command_of(_saved(out) or {}) != doc:
            raise InputError(
                f"report: {str(out)!r} holds another result; give an empty directory or the "
                "result's own run directory"
            )
        # a live result (not loaded) is read back from its document, as its directory is
        summary = run_document(doc, result=run if run.loaded else None)
        return _report(out, snippet=snippet, compile=compile, timeout=timeout, summary=summary)
    if out is not None:
        raise InputError("report: out= is for a result object; a run directory gets its report")
    if not isinstance(run, str | bytes) and not hasattr(run, "__fspath__"):
        raise VidiTypeError(
            f"report: run must be a result or a run directory; got {type(run).__name__}"
        )
    doc = _saved(run)
    summary = None
    if isinstance(doc, dict) and "schema_version" in doc:
        # its version and kind checked, every field readable: the report reads this result
        summary = run_document(command_of(doc), result=load(run))
    return _report(run, snippet=snippet, compile=compile, timeout=timeout, summary=summary)


def _saved(run_dir):
    """The ``summary.json`` of a directory, ``None`` when there is none or it is no JSON
    (the report's own reading says why)."""
    from ._files._jsonable import load_json

    return load_json(Path(run_dir) / "summary.json")[0]
