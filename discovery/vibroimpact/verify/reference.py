"""The measured side of a verification: the record's steady cycle, its noise floor and
the machine's state, prepared once and compared with any number of simulated laws.
"""

from dataclasses import dataclass, field

import numpy as np

from ...errors import InputError
from ..data.noise import estimate_noise
from ..data.periods import check_drive_period
from .criteria import CRITERIA
from .noise_bootstrap import noise_floor
from .span_floor import span_floor
from .trajectory import BLOCK_CYCLES, record_span

__all__ = ["Reference"]


@dataclass(frozen=True)
class Reference:
    """What a simulated law is compared with.

    Attributes
    ----------
    impulse : Impulse
        The measured steady cycle ``F_E`` (averaged over its steady cycles).
    noise : dict
        The record's noise model: ``F`` [N] and ``zeta`` [m] standard deviations (``zeta``
        ``None`` without positions), ``impact_velocity`` [m/s], ``dt`` [s], ``n_cycles``;
        empty for an exact (noise-free) reference.
    start : ndarray of shape (4,) or None
        The machine's measured state ``(w1, v1, w2, v2)`` at ``start_time``: the
        simulation starts there, so it reaches the attractor the machine is on.
    start_time : float
        Drive-clock time [s] of ``start``.
    time_offset : float
        Added to the record's ``t`` to get the drive's clock (``A sin(2 pi f (t +
        offset))``); 0 when the record follows the convention ``t = 0`` at phase 0.
    n_boot, seed : int
        Bootstrap replicates and seed of the noise floor.
    source : str
    span : RecordSpan or None
        With positions recorded: the record's span on the drive's phase and the machine's
        states (:mod:`~discovery.vibroimpact.verify.trajectory`); laws are then simulated from those
        states across the span and compared block by block.  ``impulse`` is then the last
        block's folded cycle.
    cycle : Impulse or None
        The record's cycle aligned at each cycle's own onset
        (:func:`~discovery.vibroimpact.data.impulse.impulse_from_samples`), which sets the cycle
        length and the main onset; the comparison itself uses it only without positions.
    blocks : tuple of Impulse
        With a span: the measured folded cycle of each of its blocks (the last is
        ``impulse``).
    no_span : str
        A record without a span: why (``"the record has no positions"``, ``"no free flight
        of the record ends before its first compared cycle"``); a law is then compared with
        its steady orbit, where the penetration (I5) is not compared.
    """

    impulse: object
    noise: dict = field(default_factory=dict)
    start: np.ndarray | None = None
    start_time: float = 0.0
    time_offset: float = 0.0
    n_boot: int = 16
    seed: int = 0
    source: str = ""
    span: object = None
    cycle: object = None
    blocks: tuple = ()
    no_span: str = ""
    _source: object = field(default=None, repr=False, compare=False)

    @property
    def regime(self):
        return f"P{self.impulse.n_periods}"

    @property
    def impacts(self):
        """Contacts per measured cycle (above the noise threshold); with a record span,
        those of the cycles aligned at their onsets, whose near-losses are merged on the
        penetration (a dip of the force within its noise is no new impact)."""
        if self.span is not None and self.cycle is not None:
            return int(len(self.cycle.support))
        return int(len(self.impulse.support))

    def measured(self):
        """What a summary states of the record (its ``measured`` block, which the reports'
        Data tables read): periods and cycles, contacts per cycle, noise, threshold, peak
        force and contact time."""
        E = self.impulse
        return {
            "n_periods": E.n_periods,
            "n_cycles": E.n_cycles,
            "impacts": self.impacts,
            "noise": dict(self.noise),
            "threshold": E.threshold,
            "peak": E.peak,
            "contact_time": E.contact_time,
        }

    def shortened(self):
        """The same record compared cycle by cycle: blocks of one cycle, each simulated
        from the state just before it (``None`` without a record span, or when the blocks
        are one cycle already).  An optimiser far from the answer starts here: a law's
        timing error cannot accumulate over a block, so the output error's basin is wider
        (multiple shooting)."""
        if (
            self.span is None
            or self._source is None
            or all(b.fold.n_cycles == 1 for b in self.span.blocks)
        ):
            return None
        cache = self.__dict__.setdefault("_shortened", {})
        if "ref" not in cache:
            m, sc = self._source
            cache["ref"] = Reference.from_measurement(
                m,
                sc,
                time_offset=self.time_offset,
                n_boot=self.n_boot,
                seed=self.seed,
                block_cycles=1,
            )
        return cache["ref"]

    def floor_for(self, stand_in, *, scenario=None, law=None, tolerances=None, observe=None):
        """Noise floor of every criterion if ``stand_in`` (an exact impulse aligned with
        the measured cycle) were the truth: see :func:`~discovery.vibroimpact.verify.noise_floor`;
        with a record span (and ``scenario``, ``law``), through the span's own processing
        (:func:`~discovery.vibroimpact.verify.span_floor.span_floor`)."""
        if self.span is not None and law is not None:
            return span_floor(
                scenario,
                law,
                self.span,
                stand_in,
                n_boot=self.n_boot,
                seed=self.seed,
                tolerances=tolerances,
                observe=observe,
            )
        if not self.noise:
            zero = {n: 0.0 for n in CRITERIA}
            return {"mean": zero, "q95": dict(zero), "n_boot": 0, "seed": self.seed}
        nz = self.noise
        return noise_floor(
            stand_in,
            self.impulse.duration / self.impulse.n_periods,
            nz["dt"],
            sigma_f=nz["F"],
            n_cycles=nz["n_cycles"],
            sigma_zeta=nz["zeta"],
            impact_velocity=nz["impact_velocity"],
            n_boot=self.n_boot,
            seed=self.seed,
        )

    @classmethod
    def exact(cls, impulse, source="simulation"):
        """A noise-free reference (e.g. the exact impulse of a scenario's own law)."""
        return cls(impulse=impulse, source=source)

    @classmethod
    def from_measurement(
        cls,
        measurement,
        scenario,
        *,
        time_offset=0.0,
        n_boot=16,
        seed=0,
        use_state=True,
        block_cycles=BLOCK_CYCLES,
    ):
        """Prepare a record: steady cycle, noise model, measured state.

        Parameters
        ----------
        measurement : Measurement
        scenario : Scenario
        time_offset : float
            Drive-clock time [s] of the record's ``t = 0``.
        n_boot : int
            Bootstrap replicates of the noise floor.
        seed : int
            Seed of the bootstrap.
        use_state : bool
            Start simulations from the measured state when ``w1, w2`` are recorded.
        block_cycles : int
            Cycles per compared block of a record span.
        """
        if not np.isfinite(time_offset):
            raise InputError(f"time offset must be finite, got {time_offset!r}")
        T = scenario.period
        check_drive_period(
            measurement.t,
            measurement.F,
            T,
            measurement.source,
            motion=measurement.channels.get("w1"),
        )
        E = measurement.impulse(T)
        t = measurement.t
        dt = float(np.median(np.diff(t)))
        zeta = measurement.zeta
        noise = {
            "F": estimate_noise(measurement.F),
            "zeta": None,
            "impact_velocity": None,
            "dt": dt,
            "n_cycles": E.n_cycles,
        }
        if zeta is not None:
            noise["zeta"] = estimate_noise(zeta, order=3)
            noise["impact_velocity"] = _impact_velocity(t, zeta, E, T, dt)
        start, t_start, span, cycle, blocks = None, 0.0, None, E, ()
        why = ["the record has no positions"] if zeta is None else []
        if not use_state and zeta is not None:
            why.append("its simulations do not start from the measured states")
        if use_state and zeta is not None:
            span = record_span(
                measurement,
                scenario,
                E,
                time_offset=time_offset,
                block_cycles=block_cycles,
                why=why,
            )
            if span is None:
                start, t_start = measurement.state_at_strobe(T, time_offset)
            else:
                last = span.blocks[-1]
                start, t_start = last.state.y, last.state.t
                blocks = tuple(span.measured(onset_record_time=E.onset))
                E = blocks[-1]
                noise["n_cycles"] = span.n_cycles
        return cls(
            impulse=E,
            noise=noise,
            start=start,
            start_time=t_start,
            time_offset=float(time_offset),
            n_boot=int(n_boot),
            seed=int(seed),
            source=measurement.source,
            span=span,
            cycle=cycle,
            blocks=blocks,
            no_span="" if span is not None else (why[0] if why else ""),
            _source=(measurement, scenario),
        )


def _impact_velocity(t, zeta, E, period, dt):
    """Median slope of ``zeta`` at the main onsets of the steady cycles [m/s]."""
    slopes = []
    m = max(2, int(0.002 * period / dt))
    for c in range(E.n_cycles):
        k = int(np.searchsorted(t, E.onset + c * E.duration))
        if m <= k < t.size - m:
            a, _ = np.polyfit(t[k - m : k + m] - t[k], zeta[k - m : k + m], 1)
            slopes.append(a)
    return float(np.median(slopes)) if slopes else None
