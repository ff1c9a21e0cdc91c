"""Steady-state impact-force histories aligned at the impact onset.

An :class:`Impulse` is the force over one steady-state cycle (``n`` drive periods)
starting at the main impact onset ``t* = 0``.  It is piecewise linear between its
points; a time that appears twice marks a jump (left limit, then right limit), so
the force jump of a viscous contact at onset is represented exactly: the first
point is the right limit ``F(0+)``.

Two constructors:

* :func:`impulse_from_steady_state`: from a simulated periodic orbit, with the
  onset and every switching event located exactly by the integrator;
* :func:`impulse_from_samples`: from a sampled (measured) record, with a noise
  level estimated from the data, a threshold from it, a sub-sample onset time,
  and averaging over all complete cycles in the record.
"""

import math
from dataclasses import dataclass

import numpy as np
from scipy.ndimage import uniform_filter1d

from ..._printing import fmt, readable
from ..._validate import Array, Real, params
from ...errors import InputError, NoContactError

__all__ = [
    "Impulse",
    "impulse_from_samples",
    "estimate_noise",
    "own_period",
    "check_drive_period",
]


@readable
@dataclass(frozen=True)
class Impulse:
    """Force over one cycle from the impact onset.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Times since the onset [s], non-decreasing, from 0 to ``duration``; a
        repeated time is a jump (left then right limit).
    F : ndarray of shape (n,)
        Force [N].
    duration : float
        Cycle length ``n_periods * T`` [s].
    support : ndarray of shape (k, 2)
        Intervals ``[start, end)`` [s] where the force is positive.
    n_periods : int
        Drive periods per cycle.
    onset : float
        Absolute time of the onset [s] in the source record or simulation.
    threshold : float
        Force level [N] that defined the support (0 for an exact simulation).
    noise : float
        Estimated noise standard deviation [N] (0 for a simulation).
    n_cycles : int
        Cycles averaged.
    onsets : ndarray of shape (m,)
        Times [s] since the main onset of every contact onset in the cycle (the first
        is 0): the cyclic sequence of impacts used to align two orbits.
    """

    t: np.ndarray
    F: np.ndarray
    duration: float
    support: np.ndarray
    n_periods: int
    onset: float
    threshold: float = 0.0
    noise: float = 0.0
    n_cycles: int = 1
    onsets: np.ndarray = None

    def __post_init__(self):
        if self.onsets is None:
            starts = self.support[:, 0] if len(self.support) else np.zeros(1)
            object.__setattr__(self, "onsets", np.asarray(starts, dtype=float))

    @property
    def impacts(self):
        """Contact onsets per cycle."""
        return int(len(self.onsets))

    @property
    def contact_time(self):
        """Total time with positive force per cycle [s]."""
        return float(np.sum(self.support[:, 1] - self.support[:, 0])) if len(self.support) else 0.0

    @property
    def peak(self):
        """Largest force [N]."""
        return float(np.max(self.F))

    def evaluate(self, tq, side="right"):
        """Force at times ``tq`` (periodic in ``duration``), one-sided at jumps.

        Parameters
        ----------
        tq : array_like
            Query times since the onset [s].
        side : {"right", "left"}
            Which limit to take where the force jumps.
        """
        from ...numerics.piecewise import periodic_values  # numba: not for `vidi --help`

        return periodic_values(self.t, self.F, self.duration, tq, side)

    def resampled_like(self, other):
        """This impulse seen through ``other``'s sampling (the simulated impulse
        "sampled like the measurement"): its values at ``other.t``, and its support
        found from those values by the same threshold and edge rules as ``other``'s."""
        reps = max(1, int(round(other.duration / self.duration)))
        vals = self.evaluate(other.t, "left")
        vals[0] = self.evaluate(0.0, "right")
        if other.threshold > 0:
            support = _sampled_support(
                other.t,
                vals,
                other.threshold,
                other.duration / other.n_periods,
                noise=other.noise / np.sqrt(max(other.n_cycles, 1)),
            )
        else:
            support = self.periodic_support(reps * self.duration)
        onsets = np.concatenate([self.onsets + k * self.duration for k in range(reps)])
        return Impulse(
            t=other.t.copy(),
            F=vals,
            duration=reps * self.duration,
            support=support,
            n_periods=reps * self.n_periods,
            onset=self.onset,
            threshold=other.threshold,
            onsets=onsets,
        )

    def rotated(self, delta):
        """The same periodic force seen from ``delta`` [s] later: ``t* = delta``.

        Used to put another impact of a multi-impact orbit at ``t* = 0``; a jump at
        ``delta`` (a located onset) is kept exactly, and the cycle's own boundary becomes
        an interior point (a jump if ``F(0-) != F(0+)``).
        """
        W = self.duration
        delta = float(np.mod(delta, W))
        if delta == 0.0:
            return self
        t, F = self.t, self.F
        i_l = int(np.searchsorted(t, delta, "left"))  # first point at or after delta
        i_r = int(np.searchsorted(t, delta, "right"))  # first point after delta
        if i_r - i_l >= 2:  # a jump: left limit at i_l, right limit at i_r - 1
            head_t, head_F = t[i_r - 1 :] - delta, F[i_r - 1 :]
            tail_t, tail_F = t[: i_l + 1] + (W - delta), F[: i_l + 1]
        else:
            f_d = self.evaluate(delta)
            head_t = np.concatenate([[0.0], t[i_r:] - delta])
            head_F = np.concatenate([[f_d], F[i_r:]])
            tail_t = np.concatenate([t[:i_l] + (W - delta), [W]])
            tail_F = np.concatenate([F[:i_l], [f_d]])
        sup = []
        for a, b in self.support:
            a, b = a - delta, b - delta
            if b <= 0:
                a, b = a + W, b + W
            if a < 0:
                sup += [(0.0, b), (a + W, W)]
            else:
                sup.append((a, b))
        sup = np.array(sorted(sup), dtype=float).reshape(-1, 2)
        return Impulse(
            t=np.concatenate([head_t, tail_t]),
            F=np.concatenate([head_F, tail_F]),
            duration=W,
            support=sup,
            n_periods=self.n_periods,
            onset=self.onset + delta,
            threshold=self.threshold,
            noise=self.noise,
            n_cycles=self.n_cycles,
            onsets=np.sort(np.mod(self.onsets - delta, W)),
        )

    def periodic_support(self, length):
        """Support intervals repeated over ``[0, length]``, ndarray of shape (m, 2)."""
        reps = int(round(length / self.duration))
        if not np.isclose(reps * self.duration, length, rtol=1e-9) or reps < 1:
            raise InputError(
                f"length {length!r} must be a whole number of cycles of {self.duration!r} s"
            )
        return (
            np.concatenate([self.support + k * self.duration for k in range(reps)])
            if len(self.support)
            else np.zeros((0, 2))
        )

    def _lines(self):
        contact = float(np.sum(np.diff(self.support, axis=1))) if len(self.support) else 0.0
        out = [
            f"impulse over {self.n_periods} period(s) ({fmt(self.duration)} s): peak "
            f"{fmt(np.max(self.F) if len(self.F) else None)} N, in contact {fmt(contact)} s "
            f"in {len(self.support)} interval(s), {len(self.onsets)} impact(s) per cycle"
        ]
        out.append(
            f"  onset at {fmt(self.onset, 6)} s, {self.t.size} samples, "
            + (
                "exact (simulated)"
                if self.noise == 0 and self.threshold == 0
                else f"noise {fmt(self.noise, 3)} N, contact threshold {fmt(self.threshold, 3)} "
                f"N, {self.n_cycles} cycle(s) averaged"
            )
        )
        return out


def estimate_noise(x, order=1):
    """Robust noise standard deviation of a sampled signal (MAD of differences).

    Differences of order ``k`` cancel a smooth trend (a polynomial of degree < k)
    while white noise of variance ``s^2`` gives them variance ``C(2k, k) s^2``; the
    median absolute deviation makes the estimate robust to the few differences that
    straddle a jump.  Order 1 suits mostly-flat signals (a force record), order 3
    smooth ones (positions).
    """
    d = np.diff(np.asarray(x, dtype=float), n=order)
    if d.size < 2:
        return 0.0
    return float(
        1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(math.comb(2 * order, order))
    )


def _refine_onset(t, zeta, s, t_on, max_back):
    """Onset as the zero up-crossing of zeta at or before sample ``s`` (searched back
    at most ``max_back`` samples): a quadratic through the three samples before the
    crossing (free flight, smooth) extrapolated into the crossing interval, O(dt^3)."""
    k = min(s, len(t) - 1)
    stop = max(3, k - int(max_back))
    while k > stop and zeta[k - 1] > 0.0:
        k -= 1
    if not (k >= 3 and zeta[k - 1] <= 0.0 < zeta[k]):
        return t_on
    a, b, c = np.polyfit(t[k - 3 : k] - t[k - 1], zeta[k - 3 : k], 2)
    roots = np.roots([a, b, c]) if a != 0 else np.array([-c / b])
    h = t[k] - t[k - 1]
    ok = [r.real for r in roots if abs(r.imag) < 1e-12 and -1e-9 * h <= r.real <= h]
    if ok:
        return t[k - 1] + min(ok)
    return t[k - 1] + (0.0 - zeta[k - 1]) / (zeta[k] - zeta[k - 1]) * h


def _merge_unseparated(t, zeta, runs):
    """Runs of force whose gap has no separation are one contact: when ``zeta`` never
    goes clearly below zero between them (by three times its noise), the force only
    dipped below the threshold within a contact (a near-loss), and the second run is
    neither a new impact nor, however large, the main one (its "onset" would be a
    point inside the contact)."""
    if len(runs) < 2:
        return runs
    sz = estimate_noise(zeta, order=3)
    out = [runs[0]]
    for r in runs[1:]:
        t_on, t_off, s = out[-1]
        a, b = int(np.searchsorted(t, t_off)), r[2]
        if b > a and np.min(zeta[a:b]) > -3.0 * sz:
            out[-1] = (t_on, r[1], s)
        else:
            out.append(r)
    return out


def _bracket_onset(t, F, run, thr):
    """The ``zeta`` onset of ``run = (t_on, t_off, s)`` (onset, loss, first sample above
    ``thr``) kept where the force allows it: not after sample ``s``, the first
    one above the threshold (the contact has begun there), and, when the force *jumps*
    at ``s`` (from at most half the threshold to a quarter of the contact's peak or
    more: a viscous contact's ``F(0+)``), not before sample ``s - 1`` either (the force
    was still zero there).  A noisy ``zeta`` can be a sample or two off; a force jump
    brackets the onset within one sample."""
    t_on, t_off, s = run
    hi = t[s]
    lo = -np.inf
    if s >= 1:
        e = max(int(np.searchsorted(t, t_off)), s + 1)
        if F[s - 1] <= 0.5 * thr and F[s] >= 0.25 * float(np.max(F[s:e])):
            lo = t[s - 1]
    return float(min(max(t_on, lo), hi))


def _edge_params(t, period, min_samples=3):
    """Debounce length and edge extrapolation bound [samples] for a sampling."""
    dt = float(np.median(np.diff(t)))
    return max(min_samples, int(0.01 * period / dt)), max(4.0, 0.02 * period / dt)


def _sampled_support(tau, F, thr, period, *, noise=0.0, extrapolate=True):
    """Support of a cycle sampled at ``tau`` (starting at the onset, ``tau[0] = 0``).

    When its noise is not negligible (``noise > thr / 100``) the cycle is first smoothed
    by a moving average over 1 % of a period, so noise near a flat tail does not stretch
    the support by chance crossings of the threshold (the measured and the simulated
    cycle go through the same operator; a smoothed edge moves by up to half a window)."""
    min_len, max_extrap = _edge_params(tau, period)
    dt = tau[2] - tau[1]
    width = max(1, int(0.01 * period / dt)) | 1 if noise > thr / 100.0 else 1
    Fs = uniform_filter1d(np.asarray(F, dtype=float), width, mode="nearest")
    Fs[0] = F[0]
    t_ext = np.concatenate([[-dt], tau, [tau[-1] + dt]])
    f_ext = np.concatenate([[0.0], Fs, [0.0]])
    runs = _edges(
        t_ext,
        f_ext,
        thr,
        min_len,
        max_extrap=max_extrap if extrapolate else None,
        noise=noise / np.sqrt(width),
    )
    sup = [(max(a, 0.0), min(b, tau[-1])) for a, b, _ in runs]
    return np.array(sup, dtype=float).reshape(-1, 2)


def _edges(t, F, thr, min_len, *, max_extrap=4.0, noise=0.0):
    """Sub-sample start/end times of the runs where F > thr (runs shorter than
    ``min_len`` samples dropped unless they last 3 samples and peak above ``3 thr``;
    gaps shorter than ``min_len``, or not going below ``thr - 3 noise``, closed).

    An edge whose step between samples clearly exceeds the noise (``> 3 noise``) is
    extrapolated along its slope to zero force, by at most ``max_extrap`` samples, so
    the part of a smooth rise or fall below the threshold is not cut off; a flat,
    noisy edge has no meaningful slope and ends at its threshold crossing."""
    above = F > thr
    idx = np.flatnonzero(np.diff(above.astype(np.int8)))
    starts = list(idx[~above[idx]] + 1)
    ends = list(idx[above[idx]] + 1)
    if above[0]:
        starts.insert(0, 0)
    if above[-1]:
        ends.append(len(F))
    runs = [[s, e] for s, e in zip(starts, ends, strict=True)]
    merged = []
    for r in runs:
        # a gap is closed when it is short, or when it never goes clearly below the
        # threshold (a dip of the force within the noise of it: noise must not decide
        # whether a contact is one or two)
        if merged and (
            r[0] - merged[-1][1] < min_len
            or (noise > 0 and np.min(F[merged[-1][1] : r[0]]) > thr - 3.0 * noise)
        ):
            merged[-1][1] = r[1]
        else:
            merged.append(r)
    # short runs are threshold flicker, unless the force clearly stands out: a contact
    # shorter than the debounce length (< 1 % of a period) is still a contact
    runs = [
        r
        for r in merged
        if r[1] - r[0] >= min_len or (r[1] - r[0] >= 3 and np.max(F[r[0] : r[1]]) >= 3.0 * thr)
    ]
    out = []
    for s, e in runs:
        if s == 0 or e >= len(F):
            continue  # incomplete at the record's ends
        f0, f1 = F[s - 1], F[s]
        steep = max_extrap is not None and f1 - f0 > 3.0 * noise
        lo = -max_extrap if steep else 0.0
        frac = ((0.0 if steep else thr) - f0) / (f1 - f0) if f1 > f0 else 1.0
        t_on = t[s - 1] + float(np.clip(frac, lo, 1.0)) * (t[s] - t[s - 1])
        g0, g1 = F[e - 1], F[e]
        steep = max_extrap is not None and g0 - g1 > 3.0 * noise
        hi = 1.0 + max_extrap if steep else 1.0
        frac = ((0.0 if steep else thr) - g0) / (g1 - g0) if g1 < g0 else 0.0
        t_off = t[e - 1] + float(np.clip(frac, 0.0, hi)) * (t[e] - t[e - 1])
        if out and t_on <= out[-1][1]:  # extrapolated edges met: one contact
            out[-1] = (out[-1][0], max(out[-1][1], t_off), out[-1][2])
        else:
            out.append((t_on, t_off, s))
    return out


def _checked_record(t, F, period, n_periods):
    """``t, F`` as float arrays, refused in one line when they cannot be a record."""
    t = np.asarray(t, dtype=float)
    F = np.asarray(F, dtype=float)
    if not (
        isinstance(period, int | float | np.floating | np.integer)
        and np.isfinite(period)
        and period > 0
    ):
        raise InputError(f"period must be a positive number of seconds; got {period!r}")
    if t.ndim != 1 or F.shape != t.shape or t.size < 2:
        raise InputError(
            f"t and F must be 1-D arrays of the same length (at least 2 samples); "
            f"got shapes {t.shape} and {F.shape}"
        )
    if not (np.all(np.isfinite(t)) and np.all(np.isfinite(F)) and np.all(np.diff(t) > 0)):
        raise InputError("t must be finite and strictly increasing, and F finite")
    if n_periods is not None and not (isinstance(n_periods, int | np.integer) and n_periods >= 1):
        raise InputError(f"n_periods must be a positive integer; got {n_periods!r}")
    return t, F


def _contact_runs(t, F, thr, sigma, period, *, min_samples, zeta):
    """The contacts ``[(onset, loss, first sample), ...]`` above ``thr`` (gaps shorter than
    1 % of a period are noise flicker inside one contact; a contact whose peak barely clears
    the threshold is noise); with ``zeta``, contacts not separated by a free flight merged
    and onsets refined on the penetration."""
    min_len, max_extrap = _edge_params(t, period, min_samples)
    runs = _edges(t, F, thr, min_len, max_extrap=max_extrap, noise=sigma)
    if runs:
        # a contact whose peak barely clears the threshold is noise, not an impact
        pk = np.array([np.max(F[s : int(np.searchsorted(t, off)) + 1]) for _, off, s in runs])
        runs = [r for r, p in zip(runs, pk, strict=True) if p >= max(3 * thr, 0.02 * pk.max())]
    if zeta is not None:
        zeta = np.asarray(zeta, dtype=float)
        runs = _merge_unseparated(t, zeta, runs)
        back = 0.25 * period / float(np.median(np.diff(t)))
        runs = [
            (_bracket_onset(t, F, (_refine_onset(t, zeta, s, t_on, back), t_off, s), thr), t_off, s)
            for t_on, t_off, s in runs
        ]
    return runs


def _recurring(onsets, ref_j, W, period):
    """The main impacts: walking back one cycle at a time from ``ref_j`` while an impact
    recurs at the same drive phase; which of these cycles are steady is decided on their
    whole force history (:func:`_steady_tail`): a sampled impulse of a short contact varies
    by several per cent with where the samples fall, so it is no test of steadiness."""
    mains = [ref_j]
    k = 1
    while True:
        target = onsets[ref_j] - k * W
        j = int(np.argmin(np.abs(onsets - target)))
        if abs(onsets[j] - target) > 0.02 * period:
            break
        mains.insert(0, j)
        k += 1
    return mains


@dataclass(frozen=True)
class _CycleFrame:
    """What every cycle of one record is cut with.

    Attributes
    ----------
    tau : ndarray of shape (m,)
        Time axis since a cycle's onset [s], from 0 to ``W``.
    W : float
        Cycle length ``n_periods * period`` [s].
    thr : float
        Contact threshold [N].
    exact_onset : bool
        Whether the onsets were refined on ``zeta`` (see :func:`_first_after`).
    onsets : ndarray of shape (k,)
        Every contact onset in the record [s].
    period : float
        Drive period [s].
    """

    tau: np.ndarray
    W: float
    thr: float
    exact_onset: bool
    onsets: np.ndarray
    period: float


def _cycle(t, F, t_on, frame):
    """The force of the cycle starting at ``t_on`` on the time axis ``frame.tau`` since
    its onset."""
    tau, W, onsets, period = frame.tau, frame.W, frame.onsets, frame.period
    s = _first_after(t, F, t_on, frame.thr, frame.exact_onset)
    vals = np.interp(t_on + tau, t, F)
    # right limit at the onset: extrapolate the first samples after it, and do not
    # interpolate across a jump between the onset and sample s
    # (quadratic through samples s, s+1, s+2; a force is never negative)
    coef = np.polyfit(t[s : s + 3] - t_on, F[s : s + 3], 2)
    head = tau < t[s] - t_on
    vals[head] = np.maximum(np.polyval(coef, tau[head]), 0.0)
    # at the cycle's end hold the last sample before the next onset (left limit): the
    # next cycle's own onset when it was recorded (the cycles' onsets differ by up to
    # a sample or two: noise, sampling), else one cycle after this one
    last = int(np.searchsorted(t, t_on + W - (t[s] - t_on), "right")) - 1
    nxt = onsets[(onsets > t_on + W - 0.02 * period) & (onsets < t_on + W + 0.02 * period)]
    if nxt.size:
        last = min(last, int(np.searchsorted(t, nxt.min(), "left")) - 1)
    last = min(last, len(t) - 1)
    tail = t_on + tau > t[last]
    vals[tail] = F[last]
    return vals


@params(
    t=Array(1),
    F=Array(1),
    period=Real(0, open_low=True),
    zeta=(None, Array(1)),
    n_periods=(None, Real(1, integer=True)),
    threshold=(None, Real(0)),
    max_period=Real(1, 64, integer=True),
    min_samples=Real(1, integer=True),
)
def impulse_from_samples(
    t, F, period, *, zeta=None, n_periods=None, threshold=None, max_period=4, min_samples=3
):
    """Steady-state impulse from a sampled force record (measured or simulated).

    Parameters
    ----------
    t : ndarray of shape (n,)
        Sample times [s], strictly increasing, uniform.
    F : ndarray of shape (n,)
        Force samples [N].
    zeta : ndarray of shape (n,), optional
        Interpenetration ``w1 - w2`` [m].  When given, each onset is the
        interpolated zero up-crossing of ``zeta`` (exact to O(dt^2)); from the
        force alone the onset of a force *jump* is only known to within a sample.
    period : float
        Drive period ``T`` [s].
    n_periods : int, optional
        Cycle length in periods; by default the smallest ``n <= max_period`` for
        which consecutive cycles agree within the noise.
    threshold : float, optional
        Contact threshold [N]; default ``max(5 sigma, 1e-3 * max F)`` with sigma
        from :func:`estimate_noise`.
    max_period : int
    min_samples : int
        Shortest contact (and shortest gap) in samples; shorter runs are noise.

    Returns
    -------
    Impulse
        Averaged over every complete cycle; ``F(0+)`` estimated by extrapolating
        the first two samples after the onset back to it.
    """
    t, F = _checked_record(t, F, period, n_periods)
    dt = float(np.median(np.diff(t)))
    sigma = estimate_noise(F)
    thr = max(5.0 * sigma, 1e-3 * float(np.max(F))) if threshold is None else float(threshold)
    runs = _contact_runs(t, F, thr, sigma, period, min_samples=min_samples, zeta=zeta)
    if not runs:
        raise NoContactError(
            "no contact found in the force record (no run of samples above "
            f"the threshold {thr:.3g} N); check the F column and its units"
        )
    # peak force per run to find the main impact and the cycle length
    # each contact's impulse (integral of F): unlike the sampled peak it does not depend
    # on where the samples fall after a force jump; its noise is sigma dt sqrt(samples)
    spans = [(s, int(np.searchsorted(t, off)) + 1) for _, off, s in runs]
    peaks = np.array([np.sum(F[a:b]) * dt for a, b in spans])
    onsets = np.array([r[0] for r in runs])
    # the steady state is at the end of a record (which may start with a run-up): the
    # cycle length comes from its second half, the reference impact from its last cycle
    n = n_periods or _cycle_periods(t, F, period, max_period)
    W = n * period
    complete = np.flatnonzero(onsets + W <= t[-1] + 0.5 * dt)
    if complete.size == 0:
        raise InputError(
            f"the record is shorter than one cycle ({W:.4g} s) after the first "
            "impact; record more periods"
        )
    last = complete[onsets[complete] >= onsets[complete[-1]] - W + 0.25 * period]
    ref_j = int(last[np.argmax(peaks[last])])
    # walk back one cycle at a time while an impact recurs at the same drive phase; which
    # of these cycles are steady is decided on their whole force history (_steady_tail):
    # a sampled impulse of a short contact varies by several per cent with where the
    # samples fall, so it is no test of steadiness
    mains = _recurring(onsets, ref_j, W, period)
    # time axis: the first cycle's own sample offsets from its onset (no re-interpolation
    # of that cycle; the others are interpolated onto it, exactly when fs*T is whole)
    t_on0 = runs[mains[0]][0]
    inside = t[_first_after(t, F, t_on0, thr, zeta is not None) :] - t_on0
    tau = np.concatenate([[0.0], inside[inside < W], [W]])
    frame = _CycleFrame(tau, W, thr, zeta is not None, onsets, period)
    stack = [_cycle(t, F, runs[j][0], frame) for j in mains]
    steady = _steady_tail(np.array(stack), sigma)
    stack = [stack[i] for i in steady]
    mains = [mains[i] for i in steady]
    Fm = np.mean(stack, axis=0)
    # the support of the averaged cycle, whose noise is sigma / sqrt(cycles)
    thr_avg = (
        thr
        if threshold is not None
        else max(5.0 * sigma / np.sqrt(len(mains)), 1e-3 * float(np.max(F)))
    )
    support = _sampled_support(tau, Fm, thr_avg, period, noise=sigma / np.sqrt(len(mains)))
    # the cyclic sequence of impacts, from the last steady cycle
    j_last = mains[-1]
    rel = onsets - onsets[j_last]
    cyc = np.sort(rel[(rel >= 0) & (rel < W - 0.02 * period)])
    return Impulse(
        t=tau,
        F=Fm,
        duration=W,
        support=support,
        n_periods=n,
        onset=float(onsets[mains[0]]),
        threshold=thr_avg,
        noise=sigma,
        n_cycles=len(mains),
        onsets=cyc,
    )


def _steady_tail(stack, sigma):
    """Indices of the steady cycles of ``stack`` (n_cycles, m), from the end of the record.

    A cycle is steady when its mean square deviation from the median of the last five
    cycles is what the noise explains (with a six-sigma allowance for the estimate and
    0.5 % of the peak for sampling effects), or at most four times the typical
    deviation of those last cycles (onset jitter at a force jump misaligns every cycle
    a little).  Walking back from the end, an isolated deviating cycle is left out of
    the average; three deviating cycles in a row mark the end of the run-up."""
    n, m = stack.shape
    last = min(5, n)
    ref = np.median(stack[-last:], axis=0)
    peak = float(np.max(np.abs(ref))) or 1.0
    dev = np.mean((stack - ref) ** 2, axis=1)
    expected = 2.0 * sigma**2 * (1.0 + 6.0 * np.sqrt(2.0 / m)) + (0.005 * peak) ** 2
    limit = max(expected, 4.0 * float(np.median(dev[-last:])))
    keep, misses = [], 0
    for k in range(n - 1, -1, -1):
        if dev[k] <= limit:
            keep.append(k)
            misses = 0
        else:
            misses += 1
            if misses == 3:
                break
    return sorted(keep) or [n - 1]


def _first_after(t, F, t_on, thr, exact_onset):
    """Index of the first sample inside the contact.

    After an onset estimated from the force, the first one above half the threshold
    (a sample before a force jump is still pre-contact).  After a ``zeta`` onset, the
    first sample after it, unless the force *jumps* from below half the threshold to
    above it within the next three samples: a noisy ``zeta`` can put the onset a sample
    or two early, and the zero force before the jump must not be taken for ``F(0+)``
    (a smooth rise keeps its small first samples)."""
    k = int(np.searchsorted(t, t_on, "right"))
    if not exact_onset:
        while k < len(F) - 3 and F[k] <= 0.5 * thr:
            k += 1
        return k
    for j in range(k, min(k + 3, len(F) - 3)):
        if F[j] > thr:
            return j if j > k and F[j - 1] <= 0.5 * thr else k
    return k


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


def check_drive_period(t, F, period, source=""):
    """Refuse a record whose force repeats at a period that is no whole number of the
    scenario's drive periods (a record of another machine or drive frequency, or a time
    column in other units): everything downstream would be meaningless.  A record without a
    clear period (strength below 0.3: chaos, too short) passes."""
    lag, strength = own_period(t, F, period)
    if not (np.isfinite(lag) and strength >= 0.3):
        return
    r = lag / period
    if abs(r - round(r)) > 0.03:
        where = f" of {source}" if source else ""
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
