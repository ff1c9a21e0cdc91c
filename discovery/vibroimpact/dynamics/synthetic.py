"""Synthetic records: a law simulated (compiled kernel or the independent scipy path) and
sampled like a measurement, with noise on every channel."""

import hashlib
from dataclasses import dataclass, field

import numpy as np

from ..._api._result import Result
from ..._api._settings import Settings, option, takes
from ..._api._validate import Choice, Real, params
from ...errors import InputError
from ..data.measurement import MAX_SAMPLES, STATE_COLUMNS, Measurement
from ..model.law import ForceLaw
from ..model.scenario import Scenario
from .simulation import simulate
from .steady_states import steady_state

__all__ = ["synthesize", "SimulatedRecord"]


@dataclass(frozen=True, eq=False)
class SimulatedRecord(Result):
    """What a synthetic record is (``D.summary.json`` beside ``D.csv`` of ``vidi
    simulate``).

    Attributes
    ----------
    scenario : dict
        The scenario (:meth:`Scenario.as_dict`).
    law : ForceLaw
    samples : int
    seconds : float
    outputs : dict
        ``{file name: {"sha256": ...}}`` of the record's CSV text, so a summary and a
        record from two runs are not taken for a pair.
    """

    scenario: dict
    law: ForceLaw
    samples: int
    seconds: float = 0.0
    outputs: dict = field(default_factory=dict)

    KIND = "simulate"
    _LOAD = {"law": lambda d: ForceLaw.parse(d["law"])}

    @classmethod
    def of(cls, scenario, law, csv_name, csv_text, *, samples, seconds=0.0):
        """The summary of the record ``csv_text`` written as ``csv_name``.

        Parameters
        ----------
        scenario : Scenario
        law : ForceLaw
        csv_name : str
            The record's file name.
        csv_text : str
            The record's CSV text (its SHA-256 goes into ``outputs``).
        samples : int
            Samples in the record.
        seconds : float
            Time taken to make it [s].
        """
        digest = hashlib.sha256(csv_text.encode()).hexdigest()
        return cls(scenario.as_dict(), law, samples, seconds, {csv_name: {"sha256": digest}})

    def as_dict(self):
        return {
            "scenario": self.scenario,
            "law": self.law.to_text(),
            "samples": self.samples,
            "seconds": self.seconds,
            "outputs": self.outputs,
        }

    def __str__(self):
        return f"simulated record of {self.law} ({self.samples} samples)"


@dataclass(frozen=True, repr=False)
class SynthesizeSettings(Settings):
    """The options of :func:`synthesize` (each is also a keyword of it; see its parameters)."""

    periods: int = option(20, Real(1, integer=True))
    fs: float = option(20000.0, Real(0, open_low=True))
    noise: float = option(0.0, Real(0, 1))
    seed: int = option(0, Real(0, integer=True))
    ss: object = option(None)
    from_rest: bool = option(False)
    position_noise: float = option(0.0, Real(0, 1))
    velocities: bool = option(True)
    integrator: str = option("compiled", Choice("compiled", "scipy"))


@takes(SynthesizeSettings)
@params(scenario=Scenario, law=ForceLaw)
def synthesize(scenario, law, *, settings=None, **options):
    """A synthetic measurement of ``law`` sampled at ``fs``.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    settings : SynthesizeSettings, optional
        The options below in one object; keywords override its fields.
    periods : int
        Drive periods recorded.
    fs : float
        Sampling rate [Hz].
    noise : float
        Gaussian noise on ``F`` with standard deviation ``noise * max F``.
    seed : int
        Seed of ``numpy.random.default_rng`` for all noise.
    ss : SteadyState, optional
        Precomputed steady state.
    from_rest : bool
        Record from the scenario's initial state (the run-up, with impacts at many
        velocities, then the steady state) instead of from a time on the periodic
        orbit.  Either way the drive phase at ``t = 0`` is zero.
    position_noise : float
        Gaussian noise on ``w1`` and ``w2`` with standard deviation
        ``position_noise * max(w1 - w2)`` (a fraction of the largest penetration).
    velocities : bool
        Include the ``v1``, ``v2`` channels.
    integrator : {"compiled", "scipy"}
        ``"scipy"``: the independent slow path (:func:`~discovery.vibroimpact.dynamics.reference.
        reference_simulate`, scipy's DOP853 restarted at every contact event), for records
        that the compiled kernel which fits them did not make.

    Returns
    -------
    Measurement
    """
    s = SynthesizeSettings.of("synthesize", settings, options)
    if not s.periods * scenario.period * s.fs <= MAX_SAMPLES:
        raise InputError(
            f"synthesize: periods = {s.periods} at fs = {s.fs:g} Hz is "
            f"{s.periods * scenario.period * s.fs:.3g} samples; the limit is {MAX_SAMPLES:.0e}"
        )
    n = int(round(s.periods * scenario.period * s.fs))
    t = np.arange(n) / s.fs
    if s.from_rest:
        span, y0, t_eval, zmax0, v0 = (0.0, t[-1]), None, t, 0.0, 0.0
    else:
        ss = s.ss or steady_state(scenario, law)
        if not ss.periodic:
            raise InputError(
                f"law '{law}' has no periodic steady state in scenario "
                f"{scenario.name!r} ({ss.regime}); choose another law or scenario, "
                "or record from rest"
            )
        span, y0, t_eval, zmax0 = (ss.t0, ss.t0 + t[-1]), ss.y0, ss.t0 + t, ss.zeta_max0
        v0 = ss.impact_v0
    if s.integrator == "scipy":
        if zmax0 and law.permanent_set:
            raise InputError(
                "the scipy path records a law with a permanent set from rest "
                "only; add from_rest=True (--from-rest)"
            )
        from .reference import reference_simulate

        out = reference_simulate(scenario, law, span, y0=y0, t_eval=t_eval, rtol=1e-9, impact_v0=v0)
        force, states = out["force"], out["y"]
    else:
        tr = simulate(scenario, law, span, y0=y0, t_eval=t_eval, zeta_max0=zmax0, impact_v0=v0)
        force, states = tr.force, tr.y
    rng = np.random.default_rng(s.seed)
    F = force.copy()
    if s.noise > 0:
        F = F + rng.normal(0.0, s.noise * float(np.max(F)), size=F.shape)
    ch = dict(zip(STATE_COLUMNS, (v.copy() for v in states), strict=True))
    if s.position_noise > 0:
        sd = s.position_noise * float(np.max(ch["w1"] - ch["w2"]))  # of the largest penetration
        ch["w1"] += rng.normal(0.0, sd, n)
        ch["w2"] += rng.normal(0.0, sd, n)
    if not s.velocities:
        del ch["v1"], ch["v2"]
    return Measurement(
        t,
        F,
        ch,
        source=f"synthetic:{scenario.name}" + (" (scipy path)" if s.integrator == "scipy" else ""),
    )
