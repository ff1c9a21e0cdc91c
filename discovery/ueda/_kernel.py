"""Compiled integrators of Ueda's forced oscillators, on the shared Dormand–Prince blocks.

One equation covers both built-in models::

    x'' - (mu (1 - gamma x^2) - k) x' + x^3 = B cos(nu t)

(``negres``: ``k = 0``; ``duffing``: ``mu = 0``).  Parameter array
``p = [mu, gamma, k, B, nu]``.  The right-hand sides are written here; the method
(stages, error norm, dense output, step control, landing exactly on strobe times) is
:func:`discovery.numerics._dopri.make_smooth_advance`, the same source the
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

The entries' arguments come in bundles, as the vibro-impact kernel's: ``ctl`` ``(rtol,
atol, hmax, max_steps)``, the step control (``atol`` the state's two absolute tolerances,
``max_steps`` the run's budget: :meth:`discovery.ueda._runs.Integration.control`), and
the output arrays of each entry in one tuple.
"""

import numpy as np
from numba import njit

from ..numerics._dopri import make_segments
from ..numerics.status import OK
from .system import UEDA

__all__ = [
    "strobe_run",
    "variational_run",
    "pair_run",
    "scan_run",
    "monodromy_run",
]


#: ``p[0]``: which vector field (Ueda's equation or a discovered polynomial model);
#: ``p[1]``: the bound on ``|x|`` and ``|x'|`` beyond which a run stops as diverged (status 2);
#: ``p[2:]``: the vector field's own parameters (``[mu, gamma, k, B, nu]``, or the
#: polynomial's ``[c_0..c_9, forcing B, nu]``).


@njit(cache=True, inline="always")
def _accel(t, x, v, p):
    return (p[2] * (1.0 - p[3] * x * x) - p[4]) * v - x * x * x + p[5] * np.cos(p[6] * t)


@njit(cache=True, inline="always")
def _model_poly(x, v, p):
    """``sum_j c_j x^i v^j`` and its partial derivatives (the MONOMIALS' order of
    :mod:`discovery.ueda.polynomial`; ``c = p[2:12]``)."""
    x2 = x * x
    v2 = v * v
    a = (
        p[2]
        + p[3] * x
        + p[4] * v
        + p[5] * x2
        + p[6] * x * v
        + p[7] * v2
        + p[8] * x2 * x
        + p[9] * x2 * v
        + p[10] * x * v2
        + p[11] * v2 * v
    )
    ax = p[3] + 2.0 * p[5] * x + p[6] * v + 3.0 * p[8] * x2 + 2.0 * p[9] * x * v + p[10] * v2
    av = p[4] + p[6] * x + 2.0 * p[7] * v + p[9] * x2 + 2.0 * p[10] * x * v + 3.0 * p[11] * v2
    return a, ax, av


@njit(cache=True, inline="always")
def _accel_any(t, x, v, p):
    if p[0] == UEDA:
        return _accel(t, x, v, p)
    a, _, _ = _model_poly(x, v, p)
    return a + p[12] * np.cos(p[13] * t)


@njit(cache=True, inline="always")
def _rhs2(t, y, p, out):
    out[0] = y[1]
    out[1] = _accel_any(t, y[0], y[1], p)


@njit(cache=True, inline="always")
def _rhs7(t, y, p, out):
    x = y[0]
    v = y[1]
    if p[0] == UEDA:
        damp = p[2] * (1.0 - p[3] * x * x) - p[4]
        a10 = -2.0 * p[2] * p[3] * x * v - 3.0 * x * x  # d(accel)/dx
        out[0] = v
        out[1] = damp * v - x * x * x + p[5] * np.cos(p[6] * t)
        out[2] = y[3]
        out[3] = a10 * y[2] + damp * y[3]
        out[4] = y[5]
        out[5] = a10 * y[4] + damp * y[5]
        out[6] = damp  # trace of the Jacobian [[0, 1], [a10, damp]]
    else:
        a, ax, av = _model_poly(x, v, p)
        out[0] = v
        out[1] = a + p[12] * np.cos(p[13] * t)
        out[2] = y[3]
        out[3] = ax * y[2] + av * y[3]
        out[4] = y[5]
        out[5] = ax * y[4] + av * y[5]
        out[6] = av  # trace of [[0, 1], [ax, av]]


@njit(cache=True, inline="always")
def _rhs4(t, y, p, out):
    out[0] = y[1]
    out[1] = _accel_any(t, y[0], y[1], p)
    out[2] = y[3]
    out[3] = _accel_any(t, y[2], y[3], p)


@njit(cache=True, inline="always")
def _diverged(y, p):
    return abs(y[0]) > p[1] or abs(y[1]) > p[1]


_start2, _adv2, _to2 = make_segments(_rhs2, 2, 2)
_start7, _adv7, _to7 = make_segments(_rhs7, 7, 2)
_start4, _adv4, _to4 = make_segments(_rhs4, 4, 2)


@njit(cache=True, inline="always")
def _tangent_start(y0, ctl, atol_tangent):
    """The variational state at a segment's start (the state, the tangent vectors the
    identity, the trace integral 0) and its step control (the state's absolute tolerances,
    ``atol_tangent`` the rest's)."""
    rtol, atol_state, hmax, max_steps = ctl
    y = np.zeros(7)
    y[0] = y0[0]
    y[1] = y0[1]
    y[2] = 1.0
    y[5] = 1.0
    atol = np.empty(7)
    atol[0] = atol_state[0]
    atol[1] = atol_state[1]
    for j in range(2, 7):
        atol[j] = atol_tangent
    return y, (rtol, atol, hmax, max_steps)


@njit(cache=True)
def strobe_run(t0, y0, p, T, n_trans, n_strobe, ctl, samples, out_strobe):
    """``n_trans`` periods of transient, then ``n_strobe`` periods, the state at each
    period's end in ``out_strobe[k]`` (steps land on strobe times exactly); dense output
    at ``t_eval`` (absolute times) in ``out_eval``, ``samples`` ``(t_eval, out_eval)``.
    Returns ``(status, t, y, n_steps, k_eval)``."""
    t_eval, out_eval = samples
    y = y0.copy()
    K, ytmp, ynew, _, _ = _start2(t0, y, p)
    t, h, n_steps, status = t0, T / 50.0, 0, OK
    k_eval = 0
    while k_eval < t_eval.shape[0] and t_eval[k_eval] <= t0:
        out_eval[0, k_eval] = y[0]
        out_eval[1, k_eval] = y[1]
        k_eval += 1
    for k in range(n_trans + n_strobe):
        t_end = t0 + (k + 1) * T
        status, t, h, k_eval, n_steps = _adv2(
            t, y, t_end, h, p, ctl, n_steps, (K, ytmp, ynew), samples, k_eval
        )
        if status != OK:
            break
        if _diverged(y, p):
            status = 2
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
def variational_run(t0, y0, p, T, n_seg, ctl, atol_tangent, out):
    """Benettin's method over ``n_seg`` periods: the state and two tangent vectors
    (started orthonormal), Gram-Schmidt at every strobe time; ``atol_tangent`` the
    tangent vectors' absolute tolerance.  ``out`` ``(out_logs, out_trace, out_strobe)``:
    ``out_logs[k]`` gets ``(log r11, log r22)`` of segment ``k``, ``out_trace[k]`` the
    integral of the Jacobian's trace over it, ``out_strobe[k]`` the state at its end.
    Returns ``(status, t, y, n_steps)``."""
    t, h, n_steps, status = t0, T / 50.0, 0, OK
    out_logs, out_trace, out_strobe = out
    y, ctl7 = _tangent_start(y0, ctl, atol_tangent)
    W = _start7(t0, y, p)
    for k in range(n_seg):
        status, t, h, n_steps = _to7(t, y, t0 + (k + 1) * T, h, p, ctl7, n_steps, W)
        if status != OK:
            break
        if _diverged(y, p):
            status = 2
            break
        renormalise(y, k, out_logs, out_trace, out_strobe)
        _rhs7(t, y, p, W[0][0])  # the tangent vectors changed
    return status, t, y[:2].copy(), n_steps


@njit(cache=True)
def pair_run(t0, y0, p, T, n_seg, d0, ctl, out_logs):
    """Two trajectories ``d0`` apart (along ``(1, 1)/sqrt 2`` in ``(x, v)``), one system;
    at every strobe time the separation ``d`` is measured, ``log(d / d0)`` stored and
    the second trajectory put back at distance ``d0`` along it.  Returns
    ``(status, t, y, n_steps)``."""
    t, h, n_steps, status = t0, T / 50.0, 0, OK
    y = np.empty(4)
    s = d0 / np.sqrt(2.0)
    y[0] = y0[0]
    y[1] = y0[1]
    y[2] = y0[0] + s
    y[3] = y0[1] + s
    rtol, atol, hmax, max_steps = ctl
    at = np.empty(4)
    at[0] = atol[0]
    at[1] = atol[1]
    at[2] = atol[0]
    at[3] = atol[1]
    ctl4 = (rtol, at, hmax, max_steps)
    W = _start4(t0, y, p)
    for k in range(n_seg):
        status, t, h, n_steps = _to4(t, y, t0 + (k + 1) * T, h, p, ctl4, n_steps, W)
        if status != OK:
            break
        dx = y[2] - y[0]
        dv = y[3] - y[1]
        d = np.sqrt(dx * dx + dv * dv)
        out_logs[k] = np.log(d / d0)
        y[2] = y[0] + dx * d0 / d
        y[3] = y[1] + dv * d0 / d
        _rhs4(t, y, p, W[0][0])
    return status, t, y[:2].copy(), n_steps


@njit(cache=True)
def scan_run(y0, p, T, n_max, rule, ctl, out):
    """Up to ``n_max`` periods of the stroboscopic map from ``(0, y0)`` (the same steps
    as :func:`strobe_run`), the strobe points in ``out_strobe``, stopping early when they
    repeat by ``rule`` ``(max_period, min_pairs, closure, inv_scale)``; ``out``
    ``(out_strobe, run)``.  ``run[n]`` counts the consecutive latest pairs ``|S_k - S_{k-n}| /
    scale < closure`` (max norm); the smallest ``n`` with ``run[n] >= max(3 n,
    min_pairs)`` ends the run unless the run may still be converging to an orbit of a
    divisor ``d`` of ``n``: ``d`` is closing too (``run[d] > 0``), or its differences
    ``|S_k - S_{k-d}|`` shrank by more than 10 % over the last ``max(3 n, min_pairs)``
    periods (e.g. a P1 orbit with a multiplier near -1 repeats after 2 periods long
    before it repeats after 1).  Returns ``(status, t, y, periods done, n or 0)``."""
    max_period, min_pairs, closure, inv_scale = rule
    out_strobe, run = out
    y = y0.copy()
    for n in range(max_period + 1):
        run[n] = 0
    W = _start2(0.0, y, p)
    t, h, n_steps, status = 0.0, T / 50.0, 0, OK
    found = 0
    k = 0
    while k < n_max:
        status, t, h, n_steps = _to2(t, y, (k + 1) * T, h, p, ctl, n_steps, W)
        if status != OK:
            break
        out_strobe[k, 0] = y[0]
        out_strobe[k, 1] = y[1]
        for n in range(1, min(k, max_period) + 1):
            if _gap(out_strobe, k, n, inv_scale) < closure:
                run[n] += 1
            else:
                run[n] = 0
        for n in range(1, max_period + 1):
            need = max(3 * n, min_pairs)
            if run[n] >= need:
                found = n
                for d in range(1, n):
                    if n % d == 0 and (
                        run[d] > 0
                        or _gap(out_strobe, k, d, inv_scale)
                        < 0.9 * _gap(out_strobe, k - need, d, inv_scale)
                    ):
                        found = 0
                break
        k += 1
        if found > 0:
            break
    return status, t, y, k, found


@njit(cache=True, inline="always")
def _gap(s, k, n, inv_scale):
    """``max |S_k - S_{k-n}| / scale``."""
    return max(abs(s[k, 0] - s[k - n, 0]) * inv_scale[0], abs(s[k, 1] - s[k - n, 1]) * inv_scale[1])


@njit(cache=True)
def monodromy_run(y0, p, T, n, ctl, atol_tangent):
    """The variational equations over ``n`` periods from ``(0, y0)`` without
    orthonormalisation (the tangent matrix only rescaled by its largest entry every
    period).  Returns ``(status, t, M, log of the scale factors, trace integral)``: the
    monodromy matrix is ``exp(log) M``."""
    t, h, n_steps, status = 0.0, T / 50.0, 0, OK
    logs = 0.0
    y, ctl7 = _tangent_start(y0, ctl, atol_tangent)
    W = _start7(0.0, y, p)
    for k in range(n):
        status, t, h, n_steps = _to7(t, y, (k + 1) * T, h, p, ctl7, n_steps, W)
        if status != OK:
            break
        m = max(max(abs(y[2]), abs(y[3])), max(abs(y[4]), abs(y[5])))
        if m > 0.0:
            for j in range(2, 6):
                y[j] /= m
            logs += np.log(m)
        _rhs7(t, y, p, W[0][0])  # the tangent vectors changed
    M = np.empty((2, 2))
    M[0, 0] = y[2]
    M[1, 0] = y[3]
    M[0, 1] = y[4]
    M[1, 1] = y[5]
    return status, t, M, logs, y[6]
