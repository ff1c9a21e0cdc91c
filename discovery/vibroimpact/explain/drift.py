"""The drift channel: orbit by orbit across a record, for effects that change the machine
while it runs (the moulding shedding sand: ``mass_loss``).

A drifting record has no periodic steady state, and its averaged cycle hides the drift.
Here the record is cut into windows of one orbit (``n`` drive periods, the record's
regime) and each window's contact impulse ``J_w = integral of F dt`` is compared with the
model's.  Over a periodic orbit the contact carries the moulding's weight exactly (its
momentum returns to its start: ``integral of (F - m2 g) dt = 0``), so whatever the law,
the model predicts ``J_w = m2(w) g n T`` with the mass after the impacts so far,
``m2(w) = m2 (1 - loss)^(impacts before w)``; a slow drift keeps the orbit quasi-steady.
The impulse weighs the moulding window by window, and it does not depend on where the
samples fall on a force jump (a peak would).

The residual is measured minus predicted with its mean removed (a force calibration or
a wrong nominal mass only shifts the level; the drift channel sees the trend):

``r_w = (J_meas,w - J_pred,w) - mean``,  ``D = rms(r) / mean(J_meas)``.

Its noise is estimated from the record itself, from successive differences (the median
absolute deviation of ``diff(r)`` over ``sqrt 2``), which a smooth drift hardly changes,
and never below what the force's own sample noise puts into a window's impulse
(``sigma_F dt sqrt(samples)``); with fewer than :data:`MIN_DIFFERENCE_WINDOWS` windows the
differences are too few to trust (a 15-period P3 record has four windows: its three
differences read the noise 17 times too high on one record, 4 times too low on another)
and the sample noise alone sets it.  ``D``'s floor is that noise over the mean impulse.
"""

from dataclasses import dataclass

import numpy as np
from scipy.optimize import minimize_scalar
from scipy.stats import chi2

from ..data.noise import estimate_noise

__all__ = [
    "DriftRecord",
    "drift_residual",
    "drift_criterion",
    "drift_score",
    "fit_drift",
    "noise_of",
]


@dataclass(frozen=True)
class DriftRecord:
    """One record's orbit windows: measured contact impulses [N s] and impacts before."""

    impulses: np.ndarray
    impacts_before: np.ndarray
    window: float
    sigma: float = 0.0

    @classmethod
    def from_measurement(cls, measurement, impulse):
        """Windows of one orbit (``impulse``: the record's averaged cycle) whose bounds lie
        in the middle of the orbit's longest free flight, so no contact is split between
        two windows; each sample stands for one sampling interval."""
        W = impulse.duration
        sup = np.asarray(impulse.support, dtype=float).reshape(-1, 2)
        if len(sup):
            ends, starts = sup[:, 1], np.roll(sup[:, 0], -1)
            gaps = np.mod(starts - ends, W)
            i = int(np.argmax(gaps))
            phase = impulse.onset + ends[i] + 0.5 * gaps[i]
        else:
            phase = impulse.onset
        t, F = measurement.t, measurement.F
        dt = float(np.median(np.diff(t)))
        k0 = int(np.ceil((t[0] - phase) / W - 1e-9))
        k1 = int(np.floor((t[-1] - phase) / W + 1e-9))
        impacts_per_orbit = len(impulse.onsets)
        J, before = [], []
        for k in range(k0, k1):
            a = phase + k * W
            m = (t >= a) & (t < a + W)
            if m.sum() < 0.9 * W / dt:
                continue
            J.append(float(np.sum(F[m]) * dt))
            before.append((k - k0) * impacts_per_orbit)
        sigma = float(estimate_noise(F)) * dt * np.sqrt(W / dt)
        return cls(
            impulses=np.array(J),
            impacts_before=np.array(before, dtype=float),
            window=W,
            sigma=sigma,
        )

    @property
    def n_impacts(self):
        return float(self.impacts_before[-1]) if self.impacts_before.size else 0.0


def predicted(scenario, rec, loss):
    """The model's contact impulse of every window: ``m2 (1 - loss)^n g W``."""
    return scenario.mass_after(rec.impacts_before, loss) * scenario.g * rec.window


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
    return float(lm), float(chi2.sf(lm, 1)), float(num / den)


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
