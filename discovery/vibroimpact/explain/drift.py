"""The drift channel: orbit by orbit across a record, for effects that change the machine
while it runs (the moulding shedding sand: ``mass_loss``).

A drifting record has no periodic steady state, and its averaged cycle hides the drift.
Here the record is cut into windows of one orbit (``n`` drive periods, the record's
regime) and each window's contact impulse ``J_w = integral of F dt`` is compared with the
model's.  Between window bounds in the middle of a free flight the moulding's momentum
balance is exact whatever the law: ``J_w = m2(w) (g W + dv_w)``, with the mass after the
impacts so far, ``m2(w) = m2 (1 - loss)^(impacts before w)``, and ``dv_w`` the moulding's
change of speed over the window, read in the free flight that holds each bound
(:func:`flight_speed`; zero on a periodic orbit, not in a slow transient, where it was
seen to trend by 1 % of the impulse over four windows).  The impulse weighs the moulding
window by window, and it does not depend on where the samples fall on a force jump (a
peak would).

The impacts are counted on the orbit as a circle (:func:`contacts_per_orbit`): a contact
that the averaged cycle cuts at its ends (its onset a little before the cycle's start in
some cycles) is one impact, not two.

The residual is measured minus predicted with its mean removed (a force calibration or
a wrong nominal mass only shifts the level; the drift channel sees the trend):

``r_w = (J_meas,w - J_pred,w) - mean``,  ``D = rms(r) / mean(J_meas)``.

Its noise is estimated from the record itself, from successive differences (the median
absolute deviation of ``diff(r)`` over ``sqrt 2``), which a smooth drift hardly changes,
and never below what the samples put into a window's impulse: the force's sample noise
(``sigma_F dt sqrt(samples)``) and the force's jumps at the contacts' edges, each known to
a sampling interval (``h dt / sqrt 12`` for a jump ``h``).  With fewer than
:data:`MIN_DIFFERENCE_WINDOWS` windows the differences are too few to trust (a 15-period
P3 record has four windows: its three differences read the noise 17 times too high on one
record, 4 times too low on another) and the samples alone set it.  ``D``'s floor is that
noise over the mean impulse.
"""

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar

from ...numerics.distributions import chi2_sf_one
from ..data.noise import estimate_noise
from ..verify.motion import contact_runs

__all__ = [
    "DriftRecord",
    "contacts_per_orbit",
    "edge_jumps",
    "flight_speed",
    "drift_residual",
    "drift_criterion",
    "drift_score",
    "fit_drift",
    "noise_of",
]


@dataclass(frozen=True)
class DriftRecord:
    """One record's orbit windows: measured contact impulses [N s], impacts before each
    window, and the moulding's change of speed over it [m/s] (zeros without its motion)."""

    impulses: np.ndarray
    impacts_before: np.ndarray
    window: float
    sigma: float = 0.0
    speed_change: np.ndarray | None = None

    @classmethod
    def from_measurement(cls, measurement, impulse, g=9.81):
        """Windows of one orbit (``impulse``: the record's averaged cycle) whose bounds lie
        in the middle of the orbit's longest free flight, so no contact is split between
        two windows (a window with a contact across a bound, where the record's orbit is
        out of step with its averaged cycle, is left out); each sample stands for one
        sampling interval; ``g`` the machine's gravity (the moulding's fall in flight)."""
        W = impulse.duration
        sup = np.asarray(impulse.support, dtype=float).reshape(-1, 2)
        flight = 0.0
        if len(sup):
            ends, starts = sup[:, 1], np.roll(sup[:, 0], -1)
            gaps = np.mod(starts - ends, W)
            i = int(np.argmax(gaps))
            phase = impulse.onset + ends[i] + 0.5 * gaps[i]
            flight = float(gaps[i])
        else:
            phase = impulse.onset
        t, F = measurement.t, measurement.F
        dt = float(np.median(np.diff(t)))
        k0 = int(np.ceil((t[0] - phase) / W - 1e-9))
        k1 = int(np.floor((t[-1] - phase) / W + 1e-9))
        impacts_per_orbit = contacts_per_orbit(impulse)
        free = F <= impulse.threshold  # no contact force: the moulding in flight
        contact = _contact_runs(~free)
        speeds = {}  # the moulding's speed at bound k, each bound read once

        def speed(k):
            if k not in speeds:
                speeds[k] = flight_speed(measurement, phase + k * W, 0.4 * flight, g, ~contact)
            return speeds[k]

        J, before, dv = [], [], []
        for k in range(k0, k1):
            a = phase + k * W
            m = (t >= a) & (t < a + W)
            if m.sum() < 0.9 * W / dt or _at(t, contact, a) or _at(t, contact, a + W):
                continue  # cut short, or a contact across a bound (the orbit out of step)
            J.append(float(np.sum(F[m]) * dt))
            before.append((k - k0) * impacts_per_orbit)
            dv.append(speed(k + 1) - speed(k))
        sample = float(estimate_noise(F)) * dt * np.sqrt(W / dt)
        # each jump known to a sampling interval, shared over the record's windows
        per_window = W / max(float(t[-1] - t[0]), W)
        jumps = dt * float(np.sqrt(per_window * np.sum(edge_jumps(F, impulse.threshold) ** 2) / 12))
        return cls(
            impulses=np.array(J),
            impacts_before=np.array(before, dtype=float),
            window=W,
            sigma=float(np.hypot(sample, jumps)),
            speed_change=np.array(dv),
        )

    @property
    def n_impacts(self):
        return float(self.impacts_before[-1]) if self.impacts_before.size else 0.0


def _contact_runs(above, shortest=3):
    """The samples in runs of at least ``shortest`` above the threshold (a contact; a lone
    sample above it is the noise's)."""
    above = np.asarray(above, dtype=bool)
    out = np.zeros(above.size, dtype=bool)
    for s, e in contact_runs(above, 1):
        out[s:e] = e - s >= shortest
    return out


def _at(t, flags, time):
    """Whether the samples on either side of ``time`` are flagged."""
    i = int(np.searchsorted(t, time))
    return bool(flags[max(i - 1, 0)] or flags[min(i, flags.size - 1)])


def contacts_per_orbit(impulse):
    """The contacts of an averaged cycle counted on the orbit as a circle: one that runs to
    the cycle's end and one that starts at its start are one contact cut by the fold."""
    sup = np.asarray(impulse.support, dtype=float).reshape(-1, 2)
    n = len(sup)
    if n < 2:
        return n
    step = float(np.median(np.diff(impulse.t))) if len(impulse.t) > 1 else 0.0
    cut = sup[0, 0] <= 0.5 * step and sup[-1, 1] >= impulse.duration - 0.5 * step
    return n - 1 if cut else n


def edge_jumps(F, threshold):
    """The force's jump at each contact's onset and end in a record [N]: its first and
    last values above ``threshold`` in each contact (a run of three samples or more above it:
    a lone sample above it is the noise's; a run the record cuts at its start or end has no
    edge there)."""
    on = _contact_runs(np.asarray(F, dtype=float) > threshold)
    if not on.any():
        return np.zeros(0)
    edges = np.flatnonzero(np.diff(on.astype(np.int8)))
    first = edges[~on[edges]] + 1  # off -> on: the first sample of a run
    last = edges[on[edges]]  # on -> off: the last sample of a run
    return np.abs(np.concatenate([F[first], F[last]]))


def flight_speed(measurement, at, half, g, free=None):
    """The moulding's speed at time ``at`` inside a free flight: its motion within ``half``
    seconds of it in the flight around it (the run of samples ``free`` of contact that
    holds ``at``, all by default), where it falls freely (``dv2/dt = -g``), fitted to the
    recorded speed ``v2`` (or, without it, to the position ``w2`` with its fall's
    curvature); 0 without either channel or samples.  The samples past a contact within
    ``half`` belong to another flight: survey draw 55's noisier record (a P4 transient) had
    a contact 2 ms after a window bound, and a reading across it put the window's impulse
    2 % off its momentum balance (the true model called drifting, D 3.5 times its floor)."""
    ch = getattr(measurement, "channels", {}) or {}
    t = measurement.t
    m = (t >= at - half) & (t <= at + half)
    if free is not None:
        m &= _run_around(np.asarray(free, dtype=bool), int(np.searchsorted(t, at)))
    if m.sum() < 3:
        return 0.0
    s = t[m] - at
    if "v2" in ch:
        return float(np.mean(ch["v2"][m] + g * s))
    if "w2" in ch:  # w2 + g s^2 / 2 = w2(at) + v2(at) s
        slope = np.polyfit(s, ch["w2"][m] + 0.5 * g * s**2, 1)[0]
        return float(slope)
    return 0.0


def _run_around(flags, i):
    """The run of ``flags`` that holds sample ``i`` (or the one before it), as a mask; none
    where neither is flagged."""
    out = np.zeros(flags.size, dtype=bool)
    i = min(i, flags.size - 1)
    if not flags[i]:
        i -= 1
    if i < 0 or not flags[i]:
        return out
    off = np.flatnonzero(~flags)
    a = off[off < i]
    b = off[off > i]
    out[(a[-1] + 1 if a.size else 0) : (b[0] if b.size else flags.size)] = True
    return out


def predicted(scenario, rec, loss):
    """The model's contact impulse of every window: ``m2 (1 - loss)^n (g W + dv)``."""
    dv = 0.0 if rec.speed_change is None else rec.speed_change
    return scenario.mass_after(rec.impacts_before, loss) * (scenario.g * rec.window + dv)


def drift_residual(scenario, rec, loss):
    """The de-levelled window residual ``r`` [N s]."""
    r = rec.impulses - predicted(scenario, rec, loss)
    return r - r.mean()


#: the fewest windows whose successive differences estimate the residual's noise
MIN_DIFFERENCE_WINDOWS = 8


def noise_of(r, floor=0.0):
    """Robust noise scale of a residual sequence: from its successive differences, never
    below ``floor`` (the sample noise's share of a window's impulse), which alone sets it
    when the sequence is shorter than :data:`MIN_DIFFERENCE_WINDOWS`."""
    d = np.diff(r)
    if r.size < MIN_DIFFERENCE_WINDOWS:
        est = floor if floor > 0 else (float(np.std(r)) if r.size else 0.0)
    else:
        est = float(1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(2.0))
    return max(est, floor, 1e-300)


def drift_criterion(r, rec):
    """``D = rms(r) / mean measured impulse`` and its noise floor ``noise(r) / mean``."""
    mean = max(float(np.mean(rec.impulses)), 1e-300)
    return float(np.sqrt(np.mean(r**2)) / mean), float(noise_of(r, rec.sigma) / mean)


def drift_score(pairs, loss, h):
    """Score test of a mass loss per impact on all records (``pairs``: ``(scenario,
    DriftRecord)``): ``LM = (s.r)^2 / (sigma^2 s.s)`` with ``s`` the de-levelled
    sensitivity of the prediction between ``loss + h`` and ``loss + 2 h`` and ``sigma``
    each record's own noise.  Returns ``(lm, p, direction)``."""
    num = den = 0.0
    for sc, rec in pairs:
        r = drift_residual(sc, rec, loss)
        s = drift_residual(sc, rec, loss + h) - drift_residual(sc, rec, loss + 2 * h)
        s = s / h  # d(prediction)/d(loss), de-levelled
        w = 1.0 / noise_of(r, rec.sigma) ** 2
        num += float(s @ r) * w
        den += float(s @ s) * w
    if den <= 0:
        return 0.0, 1.0, 0.0
    lm = num**2 / den
    return float(lm), chi2_sf_one(lm), float(num / den)


def fit_drift(pairs, h, hi=0.5):
    """The mass loss per impact minimising the drift residual (bounded 1-D fit, each
    record weighted by its noise at no loss)."""
    w = [1.0 / noise_of(drift_residual(sc, rec, 0.0), rec.sigma) ** 2 for sc, rec in pairs]

    def cost(loss):
        return sum(
            wi * float(np.sum(drift_residual(sc, rec, loss) ** 2))
            for wi, (sc, rec) in zip(w, pairs, strict=True)
        )

    # the cost is cheap (no simulation) but flat for large losses (the prediction decays
    # to nothing): a grid finds the basin, a bounded search polishes it
    grid = np.linspace(0.0, min(hi, 100 * h), 401)
    k = int(np.argmin([cost(x) for x in grid]))
    lo, up = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
    opt = minimize_scalar(
        cost, bounds=(lo, up), method="bounded", options={"xatol": 1e-4 * h, "maxiter": 60}
    )
    return float(opt.x) if opt.fun <= cost(grid[k]) else float(grid[k])
