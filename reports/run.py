"""The run a report is written from: its typed result and what only its summary holds."""

from __future__ import annotations

from dataclasses import dataclass, field

__all__ = ["RunDocument", "run_document"]


@dataclass(frozen=True)
class RunDocument:
    """A run as its report reads it.

    Attributes
    ----------
    summary : dict
        The run's ``summary.json`` as written (the result's ``to_dict()`` with the command
        line's keys): the one place for what the result object does not type, such as the
        command, its provenance (``created``, ``versions``, ``git``, ``platform``,
        ``inputs``, ``settings``), the input file names and the scenario as given.
    result : Result
        The typed result the summary describes (``VerifyResult``, ``DiscoveryResult``,
        ...), read on first use: a summary written before results had a schema version is
        read as the result of its command's kind, and one that does not read is one
        :class:`~discovery.errors.InputError` naming the field.
    """

    summary: dict
    _result: list = field(default_factory=list, repr=False, compare=False)

    @property
    def command(self):
        return self.summary.get("command")

    @property
    def result(self):
        if not self._result:
            self._result.append(_typed(self.summary))
        return self._result[0]


def run_document(run, result=None):
    """``run`` (a summary dict or a :class:`RunDocument`) as a :class:`RunDocument`;
    ``result``: its typed result when the caller has it already."""
    if isinstance(run, RunDocument):
        return run
    doc = RunDocument(run)
    if result is not None:
        doc._result.append(result)
    return doc


def _typed(summary):
    from discovery import Result

    result = Result.from_summary(summary)
    if result is None:
        from discovery.errors import InputError

        raise InputError(f"a {summary.get('command')!r} run has no result to report")
    return result
