"""A record's periods from its force history: its own period (:func:`own_period`), the
check that it is a whole number of drive periods (:func:`check_drive_period`), and the
cycle length of its steady part in drive periods (:func:`_cycle_periods`)."""

import numpy as np

from ...errors import InputError

__all__ = ["own_period", "check_drive_period"]


def own_period(t, F, period, max_periods=4.5):
    """The record's own period from its force history: the lag of the autocorrelation's
    highest peak between half a drive period and ``max_periods`` periods.

    Returns
    -------
    (lag, strength) : (float, float)
        Lag [s] and the normalised autocorrelation there (1: exactly periodic).
    """
    t = np.asarray(t, dtype=float)
    x = np.asarray(F, dtype=float)
    x = x - x.mean()
    dt = float(np.median(np.diff(t)))
    n = x.size
    lo, hi = int(0.5 * period / dt), min(int(max_periods * period / dt), n // 2)
    if hi <= lo + 2 or not np.any(x):
        return float("nan"), 0.0
    m = 1 << int(np.ceil(np.log2(2 * n)))
    X = np.fft.rfft(x, m)
    ac = np.fft.irfft(X * np.conj(X), m)[:n]
    ac = ac / ac[0]
    k = lo + int(np.argmax(ac[lo:hi]))
    return k * dt, float(ac[k])


MIN_SAMPLES_PER_PERIOD = 20
"""The fewest samples per drive period a record may have (the field-like corpus has 192 to
836): below it no impact is resolved, and a time column in milliseconds lands there."""


def _line(t, x, frequency):
    """The power of ``x``'s line at ``frequency`` [Hz] (its mean and trend removed)."""
    x = np.asarray(x, dtype=float)
    x = x - np.polyval(np.polyfit(t - t[0], x, 1), t - t[0])
    return float(abs(np.sum(x * np.exp(-2j * np.pi * frequency * t))) ** 2)


def check_drive_period(t, F, period, source="", motion=None):
    """Refuse a record sampled too coarsely to resolve a drive period (fewer than
    :data:`MIN_SAMPLES_PER_PERIOD` samples in one, e.g. a time column in milliseconds) or
    made at another drive frequency (a record of another machine, or a time column in
    other units): everything downstream would be meaningless.

    The force's own period is the first witness: a record whose force repeats at a whole
    number of drive periods passes, and so does one without a clear period (strength below
    0.3: chaos, too short).  When it repeats at another period, the drive line decides:
    the frame's motion ``motion`` (``w1``; the force without it) is driven at the drive's
    frequency, so a record whose line at the scenario's frequency is at least as strong as
    at the one the force's period suggests was made by that drive.  Its force does not
    repeat over the record (a transient from rest still settling, or chaos), which the
    verdict judges over the record's span."""
    where = f" of {source}" if source else ""
    dt = float(np.median(np.diff(np.asarray(t, dtype=float))))
    if period / dt < MIN_SAMPLES_PER_PERIOD:
        raise InputError(
            f"the record{where} has {period / dt:.3g} samples per drive period (sampled at "
            f"{1 / dt:.4g} Hz for a {1 / period:.4g} Hz drive; at least "
            f"{MIN_SAMPLES_PER_PERIOD} are needed): check that the t column is in seconds, "
            "and the scenario's frequency"
        )
    lag, strength = own_period(t, F, period)
    if not (np.isfinite(lag) and strength >= 0.3):
        return
    r = lag / period
    if abs(r - round(r)) > 0.03:
        other = round(r) / lag if round(r) else 1 / lag
        x = F if motion is None else motion
        if _line(t, x, 1 / period) >= _line(t, x, other):
            return  # the drive is the scenario's: the force has not settled
        raise InputError(
            f"the force{where} repeats every {lag:.4g} s ({r:.3g} of the scenario's drive "
            f"period {period:.4g} s, i.e. a drive of {round(r) / lag if round(r) else 1 / lag:.4g}"
            f" Hz rather than {1 / period:.4g} Hz); give the scenario of the machine that made "
            "the record (its frequency), or check the t column's units"
        )


def _cycle_periods(t, F, period, max_period):
    """Smallest ``n`` (drive periods) after which the second half of the record repeats.

    ``D(n)`` is the mean square difference between ``F(t)`` and ``F(t + nT)`` over the
    record's second half (the steady part).  Pure noise gives ``2 sigma^2`` for every
    ``n``, a transient that is still decaying adds a drift growing with ``n``, and a
    wrong period adds the difference between its cycles.  ``n`` is the smallest period
    with ``D(n) <= 1.5 min D + R / 2``, where ``R``, the mean square difference of
    consecutive samples, bounds the error of interpolating between samples (different
    ``n`` fall at different sub-sample offsets).  So a slowly settling P1 record is
    never read as P2, and a period doubling is resolved once its two cycles differ by
    more than about a sample's worth of force change.
    """
    dt = float(np.median(np.diff(t)))
    half = t >= t[0] + 0.5 * (t[-1] - t[0])
    D = {}
    for n in range(1, max_period + 1):
        sel = half & (t + n * period <= t[-1])
        if sel.sum() < max(8, 0.5 * period / dt):
            break
        d = np.interp(t[sel] + n * period, t, F) - F[sel]
        D[n] = float(np.mean(d * d))
    if not D:
        raise InputError(
            "the record is shorter than one cycle in its second half (it needs "
            f"at least 3 drive periods, {3 * period:.4g} s); record more periods"
        )
    R = float(np.mean(np.diff(F[half]) ** 2))
    limit = 1.5 * min(D.values()) + 0.5 * R
    return min(n for n, v in D.items() if v <= limit)
