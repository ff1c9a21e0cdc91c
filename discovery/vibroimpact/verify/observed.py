"""A block's simulated force as an observation model sees it: the history between the
samples, with each contact onset's jump placed at the run's event time, seen through the
model (a sensor's lag) from the sensor's state the record shows at the block's start, and
its derivatives along the law's coefficients."""

from dataclasses import replace

import numpy as np

from ..data.impulse import Impulse

__all__ = ["observed", "observed_derivatives"]


def observed(fold, Fs, observe, onsets=None, *, active=None, record=None):
    """A block's history at its sample times seen through the observation model.

    The history is piecewise linear between the samples, except at the run's contact
    ``onsets`` (its event times): there the force jumps from 0 to its value just after
    the onset (the next two samples' line, extrapolated back; a force that starts from 0
    has none).  Between two samples a jump would be a ramp across the sampling interval,
    whose response through a sensor's lag is delayed by where the onset falls in it: on
    a sampling commensurate with the drive, the same fraction of a sample every period,
    which biased the lag fitted by 0.4 sampling intervals.  ``active`` (see
    :func:`_with_jumps`) makes it linear in ``Fs`` for a derivative.

    The sensor's state at the block's first sample is the force before it, which the run
    (started from the machine's measured state there) does not have.  With ``record``
    (the block's recorded force) and a model that can start from a state
    (``observe.starts``), it is estimated from the record, as the machine's state is: the
    observed history is the response from rest plus the free response of a start ``G0``
    (each from the closed form), with ``G0`` the least-squares fit of their sum to the
    record (a block cut inside a contact starts with a loaded sensor: taken as periodic,
    the block's history began from the sensor's state at its end, and a short-contact
    record's true model read I2 0.095 without noise).  Given ``record`` zeros, it is the
    derivative of that history along ``Fs``.  Without ``record`` the block is taken as one
    periodic signal; ``observe.at(impulse, times)``, when the model has it, gives those
    values without the observed impulse."""
    td = fold.td
    t, F, _ = _with_jumps(td, Fs, onsets, active)
    L = fold.end - fold.origin
    at = getattr(observe, "at", None)
    tq = td - fold.origin
    if record is not None and getattr(observe, "starts", False):
        imp = Impulse(
            t=t - fold.origin,
            F=F,
            duration=L,
            support=np.zeros((0, 2)),
            n_periods=fold.n_periods * fold.n_cycles,
            onset=fold.origin,
        )
        rest = at(imp, tq, 0.0)
        # the free response of a unit start: the sensor's own decay (no force, no rounding
        # of the loaded response's difference)
        free = at(replace(imp, F=np.zeros_like(imp.F)), tq, 1.0)
        g0 = float(free @ (np.asarray(record, dtype=float) - rest)) / max(
            float(free @ free), 1e-300
        )
        return rest + g0 * free
    imp = Impulse(
        t=np.concatenate([[0.0], t - fold.origin, [L]]),
        F=np.concatenate([[Fs[-1]], F, [Fs[-1]]]),
        duration=L,
        support=np.zeros((0, 2)),
        n_periods=fold.n_periods * fold.n_cycles,
        onset=fold.origin,
    )
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
    none = np.zeros_like(blk.F)  # the record does not move with the coefficients
    dH = np.array([observed(fold, d, observe, onsets, active=active, record=none) for d in dF])
    dH = dH.reshape(dF.shape)
    if active is None:
        return dH
    eps = 1e-4 * float(fold.td[1] - fold.td[0])
    for j in range(onsets.size):
        moved = np.array(onsets, dtype=float)
        moved[j] += eps
        up = observed(fold, F, observe, moved, record=blk.F)
        moved[j] -= 2 * eps
        down = observed(fold, F, observe, moved, record=blk.F)
        dH += np.outer(d_on[j], (up - down) / (2 * eps))
    return dH
