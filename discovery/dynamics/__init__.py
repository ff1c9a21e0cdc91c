"""Dynamics of the two-body system: compiled integration, scipy reference, steady states."""

from .simulate import EVENT_NAMES, MODE_NAMES, Tolerances, Trajectory, simulate

__all__ = ["simulate", "Trajectory", "Tolerances", "MODE_NAMES", "EVENT_NAMES"]
