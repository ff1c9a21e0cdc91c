"""What a run directory holds and how vidi writes into it, for the layers above the package
(the reports): the manifest's name, atomic writes, whether the run that owns a staging
directory is still alive (its PID and start time), and files a forked child writes while the
command goes on (``hand_off``; ``finish_handed_off`` waits for them, ``handed_off`` names
them: :mod:`._files._handoff`)."""

from ._files._handoff import finish as finish_handed_off
from ._files._handoff import pending as handed_off
from ._files._handoff import write as hand_off
from ._files._io import MANIFEST, atomic_write_text
from ._files._staging import _alive as process_alive
from ._files._staging import _proc_start as process_start

__all__ = [
    "MANIFEST",
    "atomic_write_text",
    "process_alive",
    "process_start",
    "hand_off",
    "finish_handed_off",
    "handed_off",
]
