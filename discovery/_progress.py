"""Progress of long runs: one callback protocol for the API, one reporter for the CLI.

A long API function takes ``progress=None``, a callable ``progress(stage, done, total)``
(``total`` may be None) it calls as the work advances; :func:`tick` does the calling. The
CLI passes a :class:`Reporter`: a tqdm bar with an ETA on stderr when stderr is a terminal,
one plain line per stage otherwise (logs and pipes), nothing with ``--quiet``.
"""

from __future__ import annotations

import sys

__all__ = ["tick", "Reporter"]


def tick(progress, stage, done, total=None):
    """Report ``done`` of ``total`` in ``stage`` to ``progress`` (when there is one)."""
    if progress is not None:
        progress(stage, int(done), None if total is None else int(total))


class Reporter:
    """The CLI's progress: a bar per stage on a terminal, a line per stage elsewhere."""

    def __init__(self, quiet=False, stream=None, bar=None):
        self.stream = sys.stderr if stream is None else stream
        self.quiet = bool(quiet)
        isatty = getattr(self.stream, "isatty", lambda: False)
        self.bar = bool(isatty()) if bar is None else bool(bar)
        self.stage = None
        self._bar = None

    def __call__(self, stage, done, total=None):
        if self.quiet:
            return
        if stage != self.stage:
            self.close()
            self.stage = stage
            if self.bar:
                from tqdm import tqdm

                self._bar = tqdm(
                    total=total,
                    desc=stage,
                    file=self.stream,
                    leave=False,
                    dynamic_ncols=True,
                    mininterval=0.2,
                )
            else:
                print(f"{stage} ...", file=self.stream, flush=True)
        if self._bar is not None:
            if total is not None and self._bar.total != total:
                self._bar.total = total
            self._bar.n = min(done, total) if total else done
            self._bar.refresh()

    def close(self):
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()
        return False
