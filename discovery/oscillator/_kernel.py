"""Compiled integrators of Ueda's forced oscillators, on the shared Dormand–Prince blocks.

One equation covers both built-in models::

    x'' - (mu (1 - gamma x^2) - k) x' + x^3 = B cos(nu t)

(``negres``: ``k = 0``; ``duffing``: ``mu = 0``).  Parameter array
``p = [mu, gamma, k, B, nu]``.  The right-hand sides are written here; the method
(stages, error norm, dense output, step control, landing exactly on strobe times) is
:func:`discovery.dynamics._dopri.make_smooth_advance`, the same source the
vibro-impact kernel's steps use.

Three state layouts, each its own compiled integrator (the state size is a compile-time
constant of the shared blocks):

* 2 states ``(x, v)``: trajectories and stroboscopic points;
* 7 states ``(x, v, u1, u2, trace)``: the variational equations for two tangent vectors
  ``u1, u2`` (Benettin's method, Gram-Schmidt at every strobe time) and the integral
  of the Jacobian's trace over the segment (the sum of the exponents, checked);
* 4 states ``(x, v, x', v')``: two nearby trajectories integrated as one system (one
  step sequence, so their local errors are correlated), renormalised at every strobe
  time (the two-trajectory estimate of the largest exponent).
"""

import numpy as np
from numba import njit

from ..dynamics._dopri import OK, make_smooth_advance

__all__ = ["strobe_run", "variational_run", "pair_run", "OK"]


@njit(cache=True, inline="always")
def _accel(t, x, v, p):
    return (p[0] * (1.0 - p[1] * x * x) - p[2]) * v - x * x * x + p[3] * np.cos(p[4] * t)


@njit(cache=True, inline="always")
def _rhs2(t, y, p, out):
    out[0] = y[1]
    out[1] = _accel(t, y[0], y[1], p)


@njit(cache=True, inline="always")
def _rhs7(t, y, p, out):
    x = y[0]
    v = y[1]
    damp = p[0] * (1.0 - p[1] * x * x) - p[2]
    a10 = -2.0 * p[0] * p[1] * x * v - 3.0 * x * x  # d(accel)/dx
    out[0] = v
    out[1] = damp * v - x * x * x + p[3] * np.cos(p[4] * t)
    out[2] = y[3]
    out[3] = a10 * y[2] + damp * y[3]
    out[4] = y[5]
    out[5] = a10 * y[4] + damp * y[5]
    out[6] = damp  # trace of the Jacobian [[0, 1], [a10, damp]]


@njit(cache=True, inline="always")
def _rhs4(t, y, p, out):
    out[0] = y[1]
    out[1] = _accel(t, y[0], y[1], p)
    out[2] = y[3]
    out[3] = _accel(t, y[2], y[3], p)


_adv2 = make_smooth_advance(_rhs2, 2, 2)
_adv7 = make_smooth_advance(_rhs7, 7, 2)
_adv4 = make_smooth_advance(_rhs4, 4, 2)


@njit(cache=True)
def strobe_run(
    t0, y0, p, T, n_trans, n_strobe, rtol, atol, hmax, max_steps, t_eval, out_eval, out_strobe
):
    """``n_trans`` periods of transient, then ``n_strobe`` periods, the state at each
    period's end in ``out_strobe[k]`` (steps land on strobe times exactly); dense output
    at ``t_eval`` (absolute times) in ``out_eval``.  Returns
    ``(status, t, y, n_steps, k_eval)``."""
    y = y0.copy()
    K = np.empty((7, 2))
    ytmp = np.empty(2)
    ynew = np.empty(2)
    _rhs2(t0, y, p, K[0])
    t = t0
    h = T / 50.0
    k_eval = 0
    n_steps = 0
    status = OK
    while k_eval < t_eval.shape[0] and t_eval[k_eval] <= t0:
        out_eval[0, k_eval] = y[0]
        out_eval[1, k_eval] = y[1]
        k_eval += 1
    for k in range(n_trans + n_strobe):
        t_end = t0 + (k + 1) * T
        status, t, h, k_eval, ns = _adv2(
            t,
            y,
            t_end,
            h,
            p,
            rtol,
            atol,
            hmax,
            max_steps - n_steps,
            K,
            ytmp,
            ynew,
            t_eval,
            k_eval,
            out_eval,
        )
        n_steps += ns
        if status != OK:
            break
        if k >= n_trans:
            out_strobe[k - n_trans, 0] = y[0]
            out_strobe[k - n_trans, 1] = y[1]
    return status, t, y, n_steps, k_eval


@njit(cache=True, inline="always")
def renormalise(y, k, out_logs, out_trace, out_strobe):
    """Benettin's step at strobe ``k`` on the variational state ``y`` (x, v, two tangent
    vectors, the trace integral): Gram-Schmidt (QR) of the tangent vectors, their log
    growths, the trace integral and the strobe point stored; the integral restarts."""
    r11 = np.sqrt(y[2] * y[2] + y[3] * y[3])
    y[2] /= r11
    y[3] /= r11
    r12 = y[2] * y[4] + y[3] * y[5]
    y[4] -= r12 * y[2]
    y[5] -= r12 * y[3]
    r22 = np.sqrt(y[4] * y[4] + y[5] * y[5])
    y[4] /= r22
    y[5] /= r22
    out_logs[k, 0] = np.log(r11)
    out_logs[k, 1] = np.log(r22)
    out_trace[k] = y[6]
    y[6] = 0.0
    out_strobe[k, 0] = y[0]
    out_strobe[k, 1] = y[1]


@njit(cache=True)
def variational_run(
    t0,
    y0,
    p,
    T,
    n_seg,
    rtol,
    atol_state,
    atol_tangent,
    hmax,
    max_steps,
    out_logs,
    out_trace,
    out_strobe,
):
    """Benettin's method over ``n_seg`` periods: the state and two tangent vectors
    (started orthonormal), Gram-Schmidt at every strobe time.  ``out_logs[k]`` gets
    ``(log r11, log r22)`` of segment ``k``, ``out_trace[k]`` the integral of the
    Jacobian's trace over it, ``out_strobe[k]`` the state at its end.  Returns
    ``(status, t, y, n_steps)``."""
    y = np.zeros(7)
    y[0] = y0[0]
    y[1] = y0[1]
    y[2] = 1.0
    y[5] = 1.0
    atol = np.empty(7)
    atol[0] = atol_state[0]
    atol[1] = atol_state[1]
    for j in range(2, 6):
        atol[j] = atol_tangent
    atol[6] = atol_tangent
    K = np.empty((7, 7))
    ytmp = np.empty(7)
    ynew = np.empty(7)
    empty_t = np.empty(0)
    empty_o = np.empty((2, 0))
    t = t0
    h = T / 50.0
    n_steps = 0
    status = OK
    _rhs7(t, y, p, K[0])
    for k in range(n_seg):
        t_end = t0 + (k + 1) * T
        status, t, h, _, ns = _adv7(
            t,
            y,
            t_end,
            h,
            p,
            rtol,
            atol,
            hmax,
            max_steps - n_steps,
            K,
            ytmp,
            ynew,
            empty_t,
            0,
            empty_o,
        )
        n_steps += ns
        if status != OK:
            break
        renormalise(y, k, out_logs, out_trace, out_strobe)
        _rhs7(t, y, p, K[0])  # the tangent vectors changed
    return status, t, y[:2].copy(), n_steps


@njit(cache=True)
def pair_run(t0, y0, p, T, n_seg, d0, rtol, atol, hmax, max_steps, out_logs):
    """Two trajectories ``d0`` apart (along ``(1, 1)/sqrt 2`` in ``(x, v)``), one system;
    at every strobe time the separation ``d`` is measured, ``log(d / d0)`` stored and
    the second trajectory put back at distance ``d0`` along it.  Returns
    ``(status, t, y, n_steps)``."""
    y = np.empty(4)
    s = d0 / np.sqrt(2.0)
    y[0] = y0[0]
    y[1] = y0[1]
    y[2] = y0[0] + s
    y[3] = y0[1] + s
    at = np.empty(4)
    at[0] = atol[0]
    at[1] = atol[1]
    at[2] = atol[0]
    at[3] = atol[1]
    K = np.empty((7, 4))
    ytmp = np.empty(4)
    ynew = np.empty(4)
    empty_t = np.empty(0)
    empty_o = np.empty((2, 0))
    t = t0
    h = T / 50.0
    n_steps = 0
    status = OK
    _rhs4(t, y, p, K[0])
    for k in range(n_seg):
        t_end = t0 + (k + 1) * T
        status, t, h, _, ns = _adv4(
            t,
            y,
            t_end,
            h,
            p,
            rtol,
            at,
            hmax,
            max_steps - n_steps,
            K,
            ytmp,
            ynew,
            empty_t,
            0,
            empty_o,
        )
        n_steps += ns
        if status != OK:
            break
        dx = y[2] - y[0]
        dv = y[3] - y[1]
        d = np.sqrt(dx * dx + dv * dv)
        out_logs[k] = np.log(d / d0)
        y[2] = y[0] + dx * d0 / d
        y[3] = y[1] + dv * d0 / d
        _rhs4(t, y, p, K[0])
    return status, t, y[:2].copy(), n_steps
