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

from dataclasses import dataclass

import numpy as np

from ..._api._printing import fmt, readable
from ..._api._validate import Array, Real, params
from ...errors import InputError, NoContactError
from .contact_edges import _contact_runs, _sampled_support
from .noise import estimate_noise
from .periods import _cycle_periods, check_drive_period, own_period

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
        side : {"right", "left"} or ndarray of bool
            Which limit to take where the force jumps; an array of ``tq``'s shape, true
            where the left limit is wanted, takes one per query.
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
        # numpy's isclose (rtol 1e-9, atol 1e-8) on two floats, without its array machinery
        if not abs(reps * self.duration - length) <= 1e-8 + 1e-9 * abs(length) or reps < 1:
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
