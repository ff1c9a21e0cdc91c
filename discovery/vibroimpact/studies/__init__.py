"""Model-term selection studies: which terms can a record like mine support, at my noise
level, record length and operating points, and which selection method should I trust?

study file -> :func:`load_study` (factors, their product, seeds) -> one run per cell and
seed (:func:`run_one`: records by the independent scipy path from rest, :func:`discover`,
scored against the truth) on an executor (:mod:`discovery.numerics.executor`) -> one file per run ->
aggregates from the files (:mod:`.aggregate`) -> tables and figures (:func:`study`).
"""

from ..._startup._lazy import lazy_package

_EXPORTS = {
    "StudyConfig": "config",
    "load_study": "config",
    "FACTORS": "config",
    "field_record": "records",
    "FieldRecordSettings": "records",
    "run_one": "run",
    "score": "run",
    "StudyResult": "result",
    "study": "driver",
    "wilson": "aggregate",
}

__all__ = [
    "study",
    "StudyResult",
    "StudyConfig",
    "load_study",
    "FACTORS",
    "field_record",
    "FieldRecordSettings",
    "run_one",
    "score",
    "wilson",
]

lazy_package(__name__, _EXPORTS)
