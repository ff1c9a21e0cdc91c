"""Verification: a law simulated to its steady state and compared with a record.

record -> :class:`Reference` (steady cycle, noise floor, measured state) ->
:func:`evaluate` (simulate, align, criteria, consistency) -> :func:`verify`.
"""

from ..._startup._lazy import lazy_package

# names are imported on first use: the criteria beside them stay cheap to import
_EXPORTS = {
    "CONSISTENCY_CRITERIA": "consistency",
    "CONSISTENCY_FACTOR": "consistency",
    "CONSISTENCY_FACTORS": "consistency",
    "CONSISTENCY_SLACK": "consistency",
    "CONSISTENCY_SPREAD": "consistency",
    "Evaluation": "evaluation",
    "align": "evaluation",
    "consistency_limits": "consistency",
    "evaluate": "evaluation",
    "noise_floor": "noise_bootstrap",
    "NoiseFloorSettings": "noise_bootstrap",
    "Reference": "reference",
    "VerifyResult": "verdict",
    "VerifySettings": "verdict",
    "verify": "verdict",
}

__all__ = [
    "Reference",
    "Evaluation",
    "evaluate",
    "align",
    "noise_floor",
    "NoiseFloorSettings",
    "verify",
    "VerifyResult",
    "VerifySettings",
    "CONSISTENCY_CRITERIA",
    "CONSISTENCY_FACTOR",
    "CONSISTENCY_FACTORS",
    "CONSISTENCY_SLACK",
    "CONSISTENCY_SPREAD",
    "consistency_limits",
]

lazy_package(__name__, _EXPORTS)
