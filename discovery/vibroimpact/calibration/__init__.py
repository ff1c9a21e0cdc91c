"""The machine as the record shows it: the machine's parameters calibrated from a record's
own motions and measured force (the equations of motion in the weak form, intervals by the
record's cycles), and the units and signs a record contradicts."""

from .machine import CALIBRATED, calibrate
from .result import Calibration

__all__ = ["calibrate", "Calibration", "CALIBRATED"]
