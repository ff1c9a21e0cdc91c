"""Records for studies and tests, made by the independent scipy path from rest.

A study must never fit records made by the kernel that fits them: :func:`field_record`
simulates with :func:`discovery.vibroimpact.dynamics.reference.reference_simulate` (scipy's DOP853
restarted at every contact event, written separately from the compiled kernel) **from
rest**, through a transient, and samples the next ``periods`` drive periods with noise on
every channel relative to that channel's own range: the force gets ``force_noise`` of its
peak, each position and velocity ``motion_noise`` of its range (so the penetration, a
small difference of two large motions, is noisy, as in a real record).

The transient (:func:`transient_periods`) is as long as the slowest Floquet mode of the
orbit needs to decay to ``1e-4`` (30 to 600 periods; 600 when the orbit is not periodic):
the compiled kernel's steady state only sets this length, the data are the scipy path's.
It is integrated at ``rtol = 1e-8`` in 50-period pieces (only its end matters and the orbit
attracts), the recorded span at ``rtol = 1e-10``.  Noise-free records are cached in the
process (``lru_cache``): other noise levels and seeds of the same record are free.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np

from ..._api._settings import Settings, option, takes
from ..._api._validate import Real, params
from ...errors import InputError, IntegrationError, VidiError
from ..data.measurement import MAX_SAMPLES, Measurement
from ..dynamics.reference import reference_simulate
from ..model.law import ForceLaw
from ..model.scenario import Scenario

__all__ = [
    "field_record",
    "clean_record",
    "noisy_measurement",
    "transient_periods",
    "auto_transient",
    "TRANSIENT_MIN",
    "TRANSIENT_MAX",
]

TRANSIENT_DECAY = 1e-4
TRANSIENT_MIN, TRANSIENT_MAX = 30, 600
RTOL_TRANSIENT, RTOL_RECORD = 1e-8, 1e-10
TRANSIENT_CHUNK = 50  # periods per reference call in the transient


def transient_periods(max_multiplier):
    """Periods for the slowest Floquet mode to decay to ``1e-4``: ``ceil(log(1e-4) /
    log|mu|max)``, at least 30, at most 600 (600 for ``|mu| >= 1`` or unknown)."""
    mu = float(max_multiplier)
    if not (0.0 <= mu < 1.0):
        return TRANSIENT_MAX
    if mu == 0.0:
        return TRANSIENT_MIN
    n = math.ceil(math.log(TRANSIENT_DECAY) / math.log(mu))
    return int(min(TRANSIENT_MAX, max(TRANSIENT_MIN, n)))


def auto_transient(scenario, law):
    """The transient [drive periods] of a record of ``law`` from rest: the periodic steady
    state's largest |multiplier| decays to 1e-4 (per orbit: a period-n orbit decays once
    every n drive periods); 600 when there is no periodic orbit."""
    from ..dynamics.steady_states import steady_state

    try:
        ss = steady_state(scenario, law)
    except VidiError:
        return TRANSIENT_MAX
    if not ss.periodic:
        return TRANSIENT_MAX
    mult = float(np.max(np.abs(ss.multipliers)))
    return int(min(TRANSIENT_MAX, max(ss.n_periods, 1) * transient_periods(mult)))


def after_transient(scenario, law, transient):
    """``(state, scenario)`` after ``transient`` periods from rest by the scipy path, as
    :func:`clean_record` integrates a record's transient (in chunks at
    :data:`RTOL_TRANSIENT`): a machine that sheds mass at each impact goes on from each
    chunk with the mass it ended with, and the scenario returned has the mass left."""
    T = scenario.period
    y0 = scenario.initial_state()
    for k in range(0, transient, TRANSIENT_CHUNK):
        k1 = min(transient, k + TRANSIENT_CHUNK)
        run = reference_simulate(scenario, law, (k * T, k1 * T), y0=y0, rtol=RTOL_TRANSIENT)
        y0 = run["y_final"]
        if run["m2_final"] != scenario.m2:
            scenario = scenario.replace(m2=run["m2_final"])
    return y0, scenario


@lru_cache(maxsize=32)
def clean_record(scenario, law, periods, fs, transient, *, record_transient=False):
    """Noise-free scipy-path record ``(t, y (4, n), F, events, m2)`` (read-only arrays; ``m2``
    the moulding's mass at the first sample): from
    rest, ``transient`` periods, then ``periods`` periods sampled at ``fs`` (with
    ``record_transient`` the run-up is recorded too).  The transient is integrated in
    chunks; a machine that sheds mass at each impact goes on from each chunk with the
    mass it ended with."""
    T = scenario.period
    t_rec = transient * T
    t_end = (transient + periods) * T
    y0 = scenario.initial_state()
    if record_transient:
        n = int(round(t_end * fs))
        t = np.arange(n) / fs
        out = reference_simulate(scenario, law, (0.0, t_end), y0=y0, t_eval=t, rtol=RTOL_RECORD)
    else:
        y0, scenario = after_transient(scenario, law, transient)
        n = int(round(periods * T * fs))
        t = t_rec + np.arange(n) / fs
        out = reference_simulate(scenario, law, (t_rec, t_end), y0=y0, t_eval=t, rtol=RTOL_RECORD)
    y, F = out["y"], out["force"]
    if not (np.all(np.isfinite(y)) and np.all(np.isfinite(F))):
        raise IntegrationError("the reference simulation left samples unset")
    for a in (t, y, F):
        a.setflags(write=False)
    events = tuple((float(te), kind) for te, kind, _ in out["events"])
    return t, y, F, events, scenario.m2


def noisy_measurement(
    clean, *, force_noise, motion_noise, seed, velocities=True, source="", notes=()
):
    """A :class:`~discovery.vibroimpact.data.measurement.Measurement` of the noise-free record
    ``clean = (t, y, F, ...)`` (as :func:`clean_record` returns it) with noise on every
    channel: ``F`` gets ``N(0, force_noise * max|F|)``, ``w1, w2, v1, v2`` each
    ``N(0, motion_noise * (max - min))`` of that channel, drawn by
    ``numpy.random.default_rng(seed)`` in the order F, w1, w2, v1, v2."""
    t, y, F = clean[:3]
    rng = np.random.default_rng(seed)
    n = t.size
    F = F + rng.normal(0.0, force_noise * float(np.max(np.abs(F))), n)
    ch = {}
    for name, row in (("w1", 0), ("w2", 2), ("v1", 1), ("v2", 3)):
        x = y[row]
        ch[name] = x + rng.normal(0.0, motion_noise * float(np.ptp(x)), n)
    if not velocities:
        del ch["v1"], ch["v2"]
    channels = {k: ch[k] for k in ("w1", "v1", "w2", "v2") if k in ch}
    return Measurement(np.array(t, dtype=float), F, channels, source=source, notes=tuple(notes))


@dataclass(frozen=True, repr=False)
class FieldRecordSettings(Settings):
    """The options of :func:`field_record` (each is also a keyword of it)."""

    periods: int = option(12, Real(1, 1e5, integer=True))
    fs: float = option(10000.0, Real(0, 1e8, open_low=True))
    transient: object = option(None, (None, Real(0, 1e5, integer=True)))
    force_noise: float = option(0.01, Real(0, 1))
    motion_noise: float = option(0.001, Real(0, 1))
    seed: int = option(0, Real(0, integer=True))
    velocities: bool = option(True)


@takes(FieldRecordSettings)
@params(scenario=Scenario, law=ForceLaw)
def field_record(scenario, law, *, settings=None, **options):
    """A noisy record of ``law`` in ``scenario`` made by the scipy path from rest.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
        The true law.
    settings : FieldRecordSettings, optional
        The options below in one object; keywords override its fields.
    periods : int
        Drive periods recorded after the transient.
    fs : float
        Sampling rate [Hz].
    transient : int, optional
        Periods from rest before recording (default :func:`auto_transient`).
    force_noise, motion_noise : float
        Noise relative to each channel's range (see :func:`noisy_measurement`).
    seed : int
        Seed of the noise.
    velocities : bool
        Include ``v1`` and ``v2``.

    Returns
    -------
    Measurement
        Times on the drive's clock; the first sample is at ``transient * T``.
    """
    s = FieldRecordSettings.of("field_record", settings, options)
    n = s.periods * scenario.period * s.fs
    if not n <= MAX_SAMPLES:
        raise InputError(
            f"field_record: periods = {s.periods} at fs = {s.fs:g} Hz is {n:.3g} samples; the "
            f"limit is {MAX_SAMPLES:.0e}: lower fs or periods"
        )
    transient = auto_transient(scenario, law) if s.transient is None else s.transient
    transient, periods = int(transient), int(s.periods)
    clean = clean_record(scenario, law, periods, float(s.fs), transient)
    notes = (
        f"reference_simulate from rest; transient {transient} periods "
        f"(rtol {RTOL_TRANSIENT:g}), recorded at rtol {RTOL_RECORD:g}",
        f"noise: force {s.force_noise:g} of max|F|, motion {s.motion_noise:g} of each "
        f"channel's range, seed {s.seed}",
    )
    return noisy_measurement(
        clean,
        force_noise=s.force_noise,
        motion_noise=s.motion_noise,
        seed=s.seed,
        velocities=s.velocities,
        source=f"reference:{scenario.name}",
        notes=notes,
    )
