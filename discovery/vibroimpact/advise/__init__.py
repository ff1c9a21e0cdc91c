"""Advice on the next experiment: the operating point (drive amplitude, frequency, moulding
mass) where the records the candidate laws predict differ most, by the verdict's own rule.

candidates (:mod:`.candidates`) -> every grid point (:mod:`.separation`) -> coarse grid and
refinement (:mod:`.search`) -> :class:`AdviseResult` (:mod:`.result`); the loop of fit,
advice and record until one law remains (:mod:`.campaign_loop`).
"""

from ..._startup._lazy import lazy_package

_EXPORTS = {
    "advise": "search",
    "campaign": "campaign_loop",
    "CampaignSettings": "campaign_loop",
    "CampaignResult": "campaign_loop",
    "CampaignStep": "campaign_loop",
    "NextRecord": "campaign_loop",
    "AdviseSettings": "search",
    "AdviseResult": "result",
    "Knobs": "candidates",
    "NoiseModel": "candidates",
    "SafeRegion": "candidates",
    "candidates_from_fit": "candidates",
    "fit_scenario_changed": "candidates",
    "contact_candidates": "candidates",
    "Point": "separation",
    "PairSeparation": "separation",
    "Prediction": "separation",
    "evaluate_point": "separation",
}

__all__ = [
    "advise",
    "campaign",
    "CampaignSettings",
    "CampaignResult",
    "CampaignStep",
    "NextRecord",
    "AdviseSettings",
    "AdviseResult",
    "Knobs",
    "NoiseModel",
    "SafeRegion",
    "candidates_from_fit",
    "fit_scenario_changed",
    "contact_candidates",
    "Point",
    "PairSeparation",
    "Prediction",
    "evaluate_point",
]

lazy_package(__name__, _EXPORTS)
