"""A first-order lag ``tau G' + G = F`` of a periodic, piecewise-linear signal, in closed form.

Between two knots ``F`` is linear with slope ``s``, so the response is the input shifted
by the lag plus a decaying transient::

    G(t_k + u) = F_k + s u - s tau + (G_k - F_k + s tau) exp(-u / tau)

One pass over the knots gives ``G`` at the end of the cycle as ``P G_0 + Q`` with
``P = exp(-W / tau)``; periodicity fixes ``G_0 = Q / (1 - P)``; a second pass gives every
knot.  A zero-length interval (a jump of ``F``) leaves ``G`` continuous.  Exact for the
signal as given (no resampling, no FFT); the response of a non-negative force is
non-negative.  :func:`lag_from` is the same pass from a given initial value (a signal that
is not periodic: a record's block, whose sensor starts where the record says).
"""

import numpy as np
from numba import njit

__all__ = ["lag_at_knots", "lag_from", "lag_at"]


@njit(cache=True)
def _pass(t, F, tau, g0, out):
    g = g0
    out[0] = g
    for k in range(t.shape[0] - 1):
        h = t[k + 1] - t[k]
        if h > 0.0:
            e = np.exp(-h / tau)
            s = (F[k + 1] - F[k]) / h
            g = e * g + (F[k + 1] - s * tau) - (F[k] - s * tau) * e
        out[k + 1] = g
    return g


def lag_at_knots(t, F, tau):
    """``G`` at the knots ``t`` (sorted, from the cycle's start to its end ``W``; repeated
    times are jumps) of the periodic response to ``F`` (values at the knots)."""
    t = np.ascontiguousarray(t, dtype=float)
    F = np.ascontiguousarray(F, dtype=float)
    out = np.empty(t.size)
    q = _pass(t, F, tau, 0.0, out)
    P = np.exp(-(t[-1] - t[0]) / tau)
    _pass(t, F, tau, q / (1.0 - P), out)
    return out


def lag_from(t, F, tau, g0):
    """``G`` at the knots ``t`` of the response to ``F`` that starts from ``G(t[0]) = g0``
    (an initial value, not a periodic signal)."""
    t = np.ascontiguousarray(t, dtype=float)
    F = np.ascontiguousarray(F, dtype=float)
    out = np.empty(t.size)
    _pass(t, F, tau, float(g0), out)
    return out


@njit(cache=True)
def _at(t, F, G, tau, tq, out):
    # the knot interval of each query by a walk from the previous one's (one pass over
    # the knots for sorted queries: a grid, or a record's sample times)
    last = t.shape[0] - 2
    i = 0
    for q in range(tq.shape[0]):
        x = tq[q]
        while i > 0 and t[i] > x:
            i -= 1
        while i < last and t[i + 1] <= x:
            i += 1
        h = t[i + 1] - t[i]
        s = (F[i + 1] - F[i]) / h if h > 0.0 else 0.0
        u = x - t[i]
        out[q] = F[i] + s * (u - tau) + (G[i] - F[i] + s * tau) * np.exp(-u / tau)


def lag_at(t, F, G, tau, tq):
    """The response at times ``tq`` in ``[t[0], t[-1]]`` from its knot values ``G`` (a
    query on a jump's knot takes the interval after it: ``G`` is continuous there)."""
    tq = np.ascontiguousarray(tq, dtype=float)
    out = np.empty(tq.size)
    _at(
        np.ascontiguousarray(t, dtype=float),
        np.ascontiguousarray(F, dtype=float),
        np.ascontiguousarray(G, dtype=float),
        float(tau),
        tq.ravel(),
        out,
    )
    return out.reshape(tq.shape)
