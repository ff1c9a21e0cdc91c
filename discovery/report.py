"""``report``: the LaTeX report of a run directory (see :mod:`reports.document`)."""

from reports.document import Report, compile_tex, render
from reports.document import report as _report

__all__ = ["Report", "report", "render", "compile_tex"]


def report(run_dir, *, snippet=None, compile=True, timeout=300):
    """Write ``run_dir/report.tex`` from a run's results and compile ``report.pdf``.

    See :func:`reports.document.report`; the run directory is the ``--out`` of any
    ``vidi`` command that writes a ``summary.json``.
    """
    from ._validate import Choice, Real, check

    check("report: snippet", snippet, (None, Choice("model", "table", "criteria", "figure")))
    check("report: timeout", timeout, Real(1))
    check("report: compile", compile, bool)  # "no" is text, not False
    if not isinstance(run_dir, str | bytes) and not hasattr(run_dir, "__fspath__"):
        from .errors import VidiTypeError

        raise VidiTypeError(f"report: run_dir must be a path; got {type(run_dir).__name__}")
    return _report(run_dir, snippet=snippet, compile=compile, timeout=timeout)
