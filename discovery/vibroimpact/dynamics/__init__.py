"""Dynamics of the two-body system: compiled integration, scipy reference, steady states;
the shooting and Floquet multipliers shared with Ueda's oscillators (:mod:`.shooting`)."""

from ...numerics.shooting import PeriodMap, floquet_multipliers, newton_orbit, smallest_period
from .simulation import (
    EVENT_NAMES,
    MODE_NAMES,
    SimulateSettings,
    Tolerances,
    Trajectory,
    simulate,
)

__all__ = [
    "simulate",
    "SimulateSettings",
    "Trajectory",
    "Tolerances",
    "MODE_NAMES",
    "EVENT_NAMES",
    "PeriodMap",
    "newton_orbit",
    "floquet_multipliers",
    "smallest_period",
]
