"""A block's simulated force as an observation model sees it: the history between the
samples, with each contact onset's jump placed at the run's event time, seen through the
model (a sensor's lag), and its derivatives along the law's coefficients."""

import numpy as np

from ..data.impulse import Impulse

__all__ = ["observed", "observed_derivatives"]


def observed(fold, Fs, observe, onsets=None, active=None):
    """A block's history at its sample times seen through the observation model (the
    block taken as one periodic signal); ``observe.at(impulse, times)``, when the model
    has it, gives those values without the observed impulse.

    The history is piecewise linear between the samples, except at the run's contact
    ``onsets`` (its event times): there the force jumps from 0 to its value just after
    the onset (the next two samples' line, extrapolated back; a force that starts from 0
    has none).  Between two samples a jump would be a ramp across the sampling interval,
    whose response through a sensor's lag is delayed by where the onset falls in it: on
    a sampling commensurate with the drive, the same fraction of a sample every period,
    which biased the lag fitted by 0.4 sampling intervals.  ``active`` (see
    :func:`_with_jumps`) makes it linear in ``Fs`` for a derivative."""
    td = fold.td
    t, F, _ = _with_jumps(td, Fs, onsets, active)
    L = fold.end - fold.origin
    imp = Impulse(
        t=np.concatenate([[0.0], t - fold.origin, [L]]),
        F=np.concatenate([[Fs[-1]], F, [Fs[-1]]]),
        duration=L,
        support=np.zeros((0, 2)),
        n_periods=fold.n_periods * fold.n_cycles,
        onset=fold.origin,
    )
    at = getattr(observe, "at", None)
    tq = td - fold.origin
    return at(imp, tq) if at is not None else observe(imp).evaluate(tq)


def _with_jumps(td, Fs, onsets, active=None):
    """The knots ``(t, F, active)`` of a sampled history with a jump at each onset inside
    it (see :func:`observed`); ``active`` says which onsets' jumps are above 0 (given: the
    jumps of another history, so that this one's knots are linear in ``Fs``)."""
    if onsets is None or td.size < 4:
        return td, Fs, None
    on = np.asarray(onsets, dtype=float)
    on = on[(on > td[0]) & (on < td[-3])]
    if not on.size:
        return td, Fs, None
    i = np.searchsorted(td, on, side="right") - 1  # the sample at or before each onset
    slope = (Fs[i + 2] - Fs[i + 1]) / (td[i + 2] - td[i + 1])
    after = Fs[i + 1] + slope * (on - td[i + 1])
    active = after > 0.0 if active is None else active
    after = np.where(active, after, 0.0)
    at = np.where(on > td[i], i + 1, i)  # an onset on a sample replaces nothing
    t = np.insert(np.insert(td, at, on), at + np.arange(on.size) + 1, on)
    F = np.insert(np.insert(Fs, at, 0.0), at + np.arange(on.size) + 1, after)
    return t, F, active


def observed_derivatives(blk, run, observe):
    """The derivatives of :func:`observed` along the coefficients: the observation of each
    derivative (the jumps' values linear in it), and each onset's time derivative times the
    observed history's change with that onset's time (central differences of 1e-4 of a
    sample, the history itself fixed).  ``run``: the block's sensitivity run ``(F, dF,
    onsets, d_onsets)``."""
    F, dF, onsets, d_on = run
    fold = blk.fold
    _, _, active = _with_jumps(fold.td, F, onsets)
    dH = np.array([observed(fold, d, observe, onsets, active) for d in dF]).reshape(dF.shape)
    if active is None:
        return dH
    eps = 1e-4 * float(fold.td[1] - fold.td[0])
    for j in range(onsets.size):
        moved = np.array(onsets, dtype=float)
        moved[j] += eps
        up = observed(fold, F, observe, moved)
        moved[j] -= 2 * eps
        down = observed(fold, F, observe, moved)
        dH += np.outer(d_on[j], (up - down) / (2 * eps))
    return dH
