"""A force sensor's dynamics between the contact force and the record: observation models
applied to a simulated force history before it is compared with the recorded one (the
sensor's lag, ``tau F' + F = F_true``), in closed form."""

import numpy as np

__all__ = ["first_order_lag", "first_order_lag_at", "observation", "OBSERVATIONS"]


def first_order_lag(impulse, tau):
    """The periodic force history seen through a first-order sensor ``tau F' + F = F_true``.

    Exact for the impulse as given (piecewise linear between its knots, jumps kept): the
    closed-form response of :mod:`discovery.numerics.lag`, written on a uniform grid of 16
    points per ``tau`` (at least 8192 and at most 2^18 per cycle; linear interpolation
    between them is within 0.05 % of the transient's size).  It is linear in the force.
    """
    if tau <= 0:
        return impulse
    from ...numerics.lag import lag_at, lag_at_knots  # numba: not for `vidi --help`

    W = impulse.duration
    t_in, F_in = impulse.t, impulse.F
    G_in = lag_at_knots(t_in, F_in, tau)
    n = int(min(2**18, max(8192, 2 ** np.ceil(np.log2(16 * W / tau)))))
    t = np.arange(n) * (W / n)
    G = lag_at(t_in, F_in, G_in, tau, t)
    on = G > 1e-9 * max(float(np.max(G)), 1e-300)
    starts = np.flatnonzero(np.diff(np.concatenate([[False], on]).astype(np.int8)) == 1)
    ends = np.flatnonzero(np.diff(np.concatenate([on, [False]]).astype(np.int8)) == -1)
    support = (
        np.column_stack([t[starts], np.minimum(t[ends] + W / n, W)])
        if starts.size
        else np.zeros((0, 2))
    )
    tt = np.concatenate([t, [W]])
    GG = np.concatenate([G, G[:1]])
    from ..data.impulse import Impulse

    return Impulse(
        t=tt,
        F=GG,
        duration=W,
        support=support,
        n_periods=impulse.n_periods,
        onset=impulse.onset,
        onsets=impulse.onsets,
    )


def first_order_lag_at(impulse, tau, tq, start=None):
    """:func:`first_order_lag` at the times ``tq`` since the onset (periodic), from the
    closed form itself: exact where the grid's interpolation is within 0.05 % of the
    transient, and without the grid (a record's block needs only its sample times).

    With ``start`` the signal is not periodic: the sensor's output is ``start`` at the
    impulse's first knot and ``tq`` lie between its first and last knots."""
    if tau <= 0:
        return impulse.evaluate(tq)
    from ...numerics.lag import lag_at, lag_at_knots, lag_from  # numba: not for `vidi --help`

    if start is not None:
        G = lag_from(impulse.t, impulse.F, tau, start)
        return lag_at(impulse.t, impulse.F, G, tau, np.asarray(tq, dtype=float))
    t0 = float(impulse.t[0])
    q = np.mod(np.asarray(tq, dtype=float) - t0, impulse.duration) + t0
    return lag_at(impulse.t, impulse.F, lag_at_knots(impulse.t, impulse.F, tau), tau, q)


#: the observation models by name: ``(impulse, parameter) -> impulse``
OBSERVATIONS = {"sensor_lag": first_order_lag}
#: their values at given times only (:func:`first_order_lag_at`)
_AT = {"sensor_lag": first_order_lag_at}
#: the observations linear in the force
_LINEAR = {"sensor_lag"}


def lag_note(tau):
    """The line that says every simulated force was read through a sensor's lag ``tau``
    [s] (:func:`discovery.verify`'s and :func:`discovery.discover`'s ``sensor_lag``)."""
    return (
        f"the simulated force is compared as a force sensor with a lag of "
        f"{tau * 1e3:.4g} ms sees it"
    )


def lag_observation(tau):
    """A first-order force sensor of time constant ``tau`` [s] as an observation model
    (:func:`observation`; None for 0): what ``verify``, ``discover`` and
    ``fit_contact_models`` read a simulated force through."""
    return observation({"sensor_lag": tau} if tau else None)


def observation(parameters):
    """The observation model ``Impulse -> Impulse`` of ``{name: parameter}`` (names of
    :data:`OBSERVATIONS`, e.g. ``{"sensor_lag": 2e-5}``), applied in the order of their
    names; None when there is none.  Its ``at(impulse, times)`` gives the observed force at
    those times only, and ``linear`` says whether it is linear in the force (identify's
    exact Jacobian applies it to the force's derivatives).  ``at(impulse, times, start)``
    starts the sensor at ``start`` on the impulse's first knot instead of taking the
    impulse as periodic, where ``starts`` says the model can (one observation with its own
    closed form)."""
    if not parameters:
        return None
    items = sorted(parameters.items())

    def apply(impulse):
        for name, value in items:
            impulse = OBSERVATIONS[name](impulse, value)
        return impulse

    closed = len(items) == 1 and items[0][0] in _AT

    def at(impulse, tq, start=None):
        # the observed force at times ``tq`` only: one observation's own closed form
        if closed:
            return _AT[items[0][0]](impulse, items[0][1], tq, start)
        return apply(impulse).evaluate(tq)

    apply.linear = all(name in _LINEAR for name, _ in items)
    apply.at = at
    apply.starts = closed
    return apply
