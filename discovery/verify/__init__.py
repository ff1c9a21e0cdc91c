"""Verification: a law simulated to its steady state and compared with a record.

record -> :class:`Reference` (steady cycle, noise floor, measured state) ->
:func:`evaluate` (simulate, align, criteria, consistency) -> :func:`verify`.
"""

from .evaluate import (
    CONSISTENCY_CRITERIA,
    CONSISTENCY_FACTOR,
    CONSISTENCY_SLACK,
    Evaluation,
    align,
    consistency_limits,
    evaluate,
)
from .noise_floor import noise_floor
from .reference import Reference
from .verify import VerifyResult, verify

__all__ = [
    "Reference",
    "Evaluation",
    "evaluate",
    "align",
    "noise_floor",
    "verify",
    "VerifyResult",
    "CONSISTENCY_CRITERIA",
    "CONSISTENCY_FACTOR",
    "CONSISTENCY_SLACK",
    "consistency_limits",
]
