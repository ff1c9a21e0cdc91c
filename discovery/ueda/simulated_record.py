"""What a simulated record of an oscillator is (``U.summary.json`` beside ``U.csv`` of
``vidi ueda simulate``), as a result."""

import hashlib
from dataclasses import dataclass, field

import numpy as np

from .._api._result import Result
from .system import UedaSystem

__all__ = ["SimulatedUedaRecord"]


@dataclass(frozen=True, eq=False)
class SimulatedUedaRecord(Result):
    """The summary of a record ``t, x`` of an oscillator.

    Attributes
    ----------
    system : UedaSystem
    samples, periods, samples_per_period : int
    noise : dict
        ``fraction_of_range`` (the setting), ``sd`` (the noise's standard deviation) and
        ``x_range`` (of the clean record).
    integrator : str
    seconds : float
    outputs : dict
        ``{file name: {"sha256": ...}}`` of the record's CSV text.
    """

    system: UedaSystem
    samples: int
    periods: int
    samples_per_period: int
    noise: dict = field(default_factory=dict)
    integrator: str = ""
    seconds: float = 0.0
    outputs: dict = field(default_factory=dict)

    KIND = "ueda-simulate"
    _LOAD = {"system": lambda d: UedaSystem.from_dict(d["system"])}

    @classmethod
    def of(cls, system, clean, noise, csv_name, csv_text, **settings):
        """The summary of ``csv_text`` (written as ``csv_name``), a record of ``system``
        whose clean signal is ``clean``, with noise ``noise`` x its range; ``settings``:
        ``samples``, ``periods``, ``samples_per_period``, ``integrator``, ``seconds``."""
        clean = np.asarray(clean, dtype=float)
        digest = hashlib.sha256(csv_text.encode()).hexdigest()
        return cls(
            system=system,
            noise={
                "fraction_of_range": noise,
                "sd": float(noise * np.ptp(clean)),
                "x_range": [float(clean.min()), float(clean.max())],
            },
            outputs={csv_name: {"sha256": digest}},
            **settings,
        )

    def as_dict(self):
        return {
            "system": self.system.as_dict(),
            "samples": self.samples,
            "periods": self.periods,
            "samples_per_period": self.samples_per_period,
            "noise": self.noise,
            "integrator": self.integrator,
            "seconds": self.seconds,
            "outputs": self.outputs,
        }

    def __str__(self):
        return (
            f"simulated record of {self.system.model} ({self.samples} samples, "
            f"{self.periods} periods)"
        )
