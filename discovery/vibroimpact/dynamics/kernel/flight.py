"""The free flight in closed form.

Between contacts (mode FREE, no force) the two bodies obey linear equations: the moulding falls
freely, ``w2 = w2a + v2a s - g s^2 / 2``, and the frame (supports without a cubic term) is a damped
oscillator driven by ``A sin(w t)``: ``x(t) = x_p(t) + Phi(s) (x_a - x_p(t_a))`` with ``x = (w1,
v1)``, ``x_p = (w_p, w_p')``, ``w_p = w_s + P sin(w t) + Q cos(w t)`` its periodic particular
solution (``w_s = -m1 g / k1``) and ``Phi(s) = exp(M s)`` its transition matrix, ``M = [[0, 1],
[-k1/m1, -c1/m1]]``. The flight is advanced exactly to the next contact onset, the first root of the
penetration ``z = w1 - w2`` (from below), or to the end of the run.

The root is bracketed safely: over ``[a, a + H]`` the penetration is bounded above by
``z(a) + z'(a) tau + B tau^2 / 2`` with ``B`` an upper bound of ``z'' = w1'' + g`` for all
later times: ``g + w^2 |(P, Q)| + (w0 + 2 alpha) sqrt(E(a))`` with ``E = w0^2 u^2 + u'^2``
the energy of the homogeneous part ``u = w1 - w_p`` (``w0^2 = k1/m1``, ``alpha = c1 /
2 m1``), which never grows (``E' = -4 alpha u'^2``), and ``|u''| <= w0^2 |u| + 2 alpha
|u'| <= (w0 + 2 alpha) sqrt(E)``.  ``H`` is the bound's positive root, so ``[a, a + H)``
holds no root; the next interval starts at its end.  Far from the surface the intervals
are long; approaching a crossing they shrink quadratically onto it from below (Newton's
rate with the curvature bound), and a tangency (a graze) is passed in a bounded number
of intervals.  The first point found across is polished to the time's resolution.

The free flight's sensitivities are its transition matrix: ``S <- blockdiag(Phi(s),
[[1, s], [0, 1]]) S`` (the law does not act; the coefficient columns move with the
state's); the onset's saltation is applied as after an integrated step.
"""

import numpy as np
from numba import njit

from .codes import FREE, P_FLIGHT, P_K3, borrowed_njit

_FLIGHT_ITERS = 4000  # intervals per flight before the integrator takes over (a safeguard)
_NF = 16  # the flight's constants, :func:`_flight_setup`
_SAMPLE_SLIP = 1e-12  # evenly spaced samples: on their grid within this many drive periods
_SAMPLE_ANCHOR = 256  # samples advanced by the semigroup between two evaluated in closed form


@borrowed_njit
def _flight_ok(p):
    """Whether the free flight has the closed form (requested, linear supports with ``k1 >
    0``, ``c1 >= 0``, and a periodic particular solution)."""
    if p[P_FLIGHT] == 0.0 or p[P_K3] != 0.0:
        return False
    m1, k1, c1, w = p[0], p[2], p[3], p[5]
    if not (m1 > 0.0 and k1 > 0.0 and c1 >= 0.0 and w > 0.0):
        return False
    a, b = k1 - m1 * w * w, c1 * w
    return a * a + b * b > 0.0 and np.isfinite(a) and np.isfinite(b)


@borrowed_njit
def _flight_setup(t0, y, p, fl):
    """The flight's constants from ``(t0, y)`` into ``fl``: alpha, w0^2, w0^2 - alpha^2,
    w_s, P, Q, w, g, t0, u(t0), u'(t0), w2(t0), v2(t0), the bound's constant part
    ``g + w^2 |(P, Q)|``, ``w0 + 2 alpha``, ``w0``."""
    m1, k1, c1, A, w, g = p[0], p[2], p[3], p[4], p[5], p[6]
    al = 0.5 * c1 / m1
    w0sq = k1 / m1
    a, b = k1 - m1 * w * w, c1 * w
    det = a * a + b * b
    P = -A * a / det
    Q = A * b / det
    ws = -m1 * g / k1
    sn, cs = np.sin(w * t0), np.cos(w * t0)
    fl[0], fl[1], fl[2] = al, w0sq, w0sq - al * al
    fl[3], fl[4], fl[5], fl[6], fl[7], fl[8] = ws, P, Q, w, g, t0
    fl[9] = y[0] - (ws + P * sn + Q * cs)
    fl[10] = y[1] - w * (P * cs - Q * sn)
    fl[11], fl[12] = y[2], y[3]
    fl[13] = g + w * w * np.sqrt(P * P + Q * Q)
    fl[14] = np.sqrt(w0sq) + 2.0 * al
    fl[15] = np.sqrt(w0sq)


@borrowed_njit
def _flight_phi(s, fl):
    """The frame's transition matrix ``Phi(s)`` (four entries, row by row)."""
    al, w0sq, q = fl[0], fl[1], fl[2]
    e = np.exp(-al * s)
    if q > 0.0:
        r = np.sqrt(q)
        eC = e * np.cos(r * s)
        eS = e * np.sin(r * s) / r
    elif q < 0.0:
        r = np.sqrt(-q)
        if r * s < 1.0:
            eC = e * np.cosh(r * s)
            eS = e * np.sinh(r * s) / r
        else:
            # overdamped, long flight: e^(-alpha s) cosh(r s) without overflow
            ep, em = np.exp((r - al) * s), np.exp(-(r + al) * s)
            eC = 0.5 * (ep + em)
            eS = 0.5 * (ep - em) / r
    else:
        eC = e
        eS = e * s
    return eC + al * eS, eS, -w0sq * eS, eC - al * eS


@borrowed_njit
def _flight_state(s, fl, out):
    """The state ``s`` after the flight's start into ``out``; returns ``(u, u')``, the
    frame's homogeneous part."""
    f00, f01, f10, f11 = _flight_phi(s, fl)
    u = f00 * fl[9] + f01 * fl[10]
    ud = f10 * fl[9] + f11 * fl[10]
    w = fl[6]
    tt = fl[8] + s
    sn, cs = np.sin(w * tt), np.cos(w * tt)
    out[0] = fl[3] + fl[4] * sn + fl[5] * cs + u
    out[1] = w * (fl[4] * cs - fl[5] * sn) + ud
    out[2] = fl[11] + s * (fl[12] - 0.5 * fl[7] * s)
    out[3] = fl[12] - fl[7] * s
    return u, ud


@njit(cache=True, inline="always")
def _flight_res(fl, s):
    """The time resolution at ``s`` after the flight's start: a few units in the last place
    of the absolute time, and at least 1e-15 of the drive period."""
    return 4.0e-16 * max(abs(fl[8] + s), 2.0 * np.pi / fl[6])


@njit(cache=True, inline="always")
def _newton_probe(lo, hi, s, fs, dfs, heads, across, res):
    """The next point of a safeguarded Newton iteration for a root in ``[lo, hi]`` from ``s``
    (value ``fs``, rate ``dfs``): Newton's where the rate ``heads`` to the root and that point
    is inside, else the midpoint; where Newton has converged from one side (it moved by
    ``res`` or less), a probe ``res`` away towards the other side (``across``: ``s`` is across
    the root) to close the bracket.  Shared by the flight's and the contact's polish."""
    c = s - fs / dfs if heads else 0.5 * (lo + hi)
    if not (lo < c < hi):
        c = 0.5 * (lo + hi)
    if abs(c - s) <= res:
        c = s - res if across else s + res
        if not (lo < c < hi):
            c = 0.5 * (lo + hi)
    return c


@borrowed_njit
def _flight_polish(a, b, fl, ybuf):
    """The first root of the penetration in ``[a, b]`` (``z(a) <= 0 < z(b)``, no root in
    ``[a, b)`` but the crossing's): safeguarded Newton to the time's resolution; the point
    returned is across (``z > 0``), as a located event's."""
    lo, hi = a, b
    _flight_state(hi, fl, ybuf)
    zs, ds = ybuf[0] - ybuf[2], ybuf[1] - ybuf[3]
    s = hi
    for _ in range(200):
        res = _flight_res(fl, hi)
        if hi - lo <= res:
            break
        c = _newton_probe(lo, hi, s, zs, ds, ds > 0.0, zs > 0.0, res)
        _flight_state(c, fl, ybuf)
        zc, dc = ybuf[0] - ybuf[2], ybuf[1] - ybuf[3]
        lo, hi = (lo, c) if zc > 0.0 else (c, hi)
        s, zs, ds = c, zc, dc
    return hi


@borrowed_njit
def _flight_search(z0, d0, s_end, fl, ybuf):
    """The first onset in ``(0, s_end]`` of the flight set up in ``fl`` (the start's
    penetration ``z0 <= 0``, its rate ``d0``): ``(s, code)``, ``code`` 1 for an onset at
    ``s``, 0 for none up to ``s = s_end``, 4 if the safeguard's interval budget ran out at
    ``s`` (no onset before it)."""
    a, z, d = 0.0, z0, d0
    u, ud = fl[9], fl[10]
    w0sq, kE, Bc = fl[1], fl[14], fl[13]
    for _ in range(_FLIGHT_ITERS):
        B = Bc + kE * np.sqrt(w0sq * u * u + ud * ud)
        if not B > 1e-300:
            B = 1e-300
        zz = -z if z < 0.0 else 0.0
        disc = np.sqrt(d * d + 2.0 * B * zz)
        H = 2.0 * zz / (d + disc) if d > 0.0 else (disc - d) / B
        if a + H >= s_end:
            return s_end, 0
        H = max(H, _flight_res(fl, a))
        b = min(a + H, s_end)
        u, ud = _flight_state(b, fl, ybuf)
        zb, db = ybuf[0] - ybuf[2], ybuf[1] - ybuf[3]
        if zb > 0.0:
            return _flight_polish(a, b, fl, ybuf), 1
        if b >= s_end:
            return s_end, 0
        a, z, d = b, zb, db
    return a, 4


@borrowed_njit
def _flight_samples(t, t_new, fl, S, samples, k_eval, out_dF):
    """The dense output of the flight set up in ``fl`` (started at ``t``) at the samples
    ``t_eval[k_eval:]`` up to ``t_new`` (``samples``: ``(t_eval, out_y, out_f, out_mode)``):
    the state, no force, the free mode and the penetration's derivatives (the transition
    matrix applied to ``S``, into ``out_dF``); returns the next sample's index.

    Evenly spaced samples (a record's) advance by the flight's semigroup instead of
    evaluating each in closed form: ``u(s + h) = Phi(h) u(s)``, the drive's phase rotated
    by ``w h``, and ``Phi(s + h) = Phi(h) Phi(s)`` for the derivatives, from one evaluation
    of ``Phi(h)``, with ``h`` the spacing after a sample evaluated in closed form (an
    anchor).  A sample off that grid by more than ``_SAMPLE_SLIP`` drive periods, and
    every ``_SAMPLE_ANCHOR``-th sample, is an anchor again; the recurrence's rounding
    stays at a few units of 1e-14 of the state's scale (tested against the closed form at
    every sample)."""
    t_eval, out_y, out_f, out_mode = samples
    n_eval = t_eval.shape[0]
    want_df = out_dF.shape[1] > 0
    m = S.shape[1]
    w = fl[6]
    slip = _SAMPLE_SLIP * 2.0 * np.pi / w
    h = 0.0
    run = _SAMPLE_ANCHOR
    se0 = 0.0
    u = ud = sn = cs = 0.0
    g00 = g01 = g10 = g11 = 0.0
    f00 = f01 = f10 = f11 = cw = sw = 0.0
    while k_eval < n_eval and t_eval[k_eval] <= t_new:
        se = max(t_eval[k_eval] - t, 0.0)
        if run < _SAMPLE_ANCHOR and h > 0.0 and abs(se - (se0 + run * h)) <= slip:
            # one step of the evenly spaced samples
            u, ud = f00 * u + f01 * ud, f10 * u + f11 * ud
            sn, cs = sn * cw + cs * sw, cs * cw - sn * sw
            if want_df:
                g00, g01, g10, g11 = (
                    f00 * g00 + f01 * g10,
                    f00 * g01 + f01 * g11,
                    f10 * g00 + f11 * g10,
                    f10 * g01 + f11 * g11,
                )
            run += 1
        else:
            # an anchor: in closed form, and the grid's spacing from here
            g00, g01, g10, g11 = _flight_phi(se, fl)
            u = g00 * fl[9] + g01 * fl[10]
            ud = g10 * fl[9] + g11 * fl[10]
            tt = fl[8] + se
            sn, cs = np.sin(w * tt), np.cos(w * tt)
            se0, run = se, 1
            hn = t_eval[k_eval + 1] - t_eval[k_eval] if k_eval + 1 < n_eval else 0.0
            if hn != h:
                h = hn
                if h > 0.0:
                    f00, f01, f10, f11 = _flight_phi(h, fl)
                    cw, sw = np.cos(w * h), np.sin(w * h)
        out_y[0, k_eval] = fl[3] + fl[4] * sn + fl[5] * cs + u
        out_y[1, k_eval] = w * (fl[4] * cs - fl[5] * sn) + ud
        out_y[2, k_eval] = fl[11] + se * (fl[12] - 0.5 * fl[7] * se)
        out_y[3, k_eval] = fl[12] - fl[7] * se
        out_f[k_eval] = 0.0
        out_mode[k_eval] = FREE
        if want_df:
            # no force in flight; the penetration's derivatives by the transition matrix
            for j in range(m):
                out_dF[j, k_eval] = 0.0
                out_dF[m + j, k_eval] = (g00 * S[0, j] + g01 * S[1, j]) - (S[2, j] + se * S[3, j])
        k_eval += 1
    return k_eval


@borrowed_njit
def _flight(t, t1, y, p, hair, fl, ybuf, S, samples, k_eval, out_dF):
    """One free flight from ``(t, y)`` in closed form: ``(code, t_new, k_eval)``.

    ``code`` 0: no onset up to ``t1`` (``y`` and ``S`` advanced to it); 1: an onset at
    ``t_new`` (advanced to it: the caller records the event); 2: an onset at once (the start
    is across the surface and moving further across, as the integrator's); 3: not here (the
    start is across the surface by more than ``hair`` and not closing: the integrator's
    steps); 4: advanced to ``t_new`` without an onset, the integrator's steps next (the
    safeguard's interval budget ran out).  Writes the dense output at ``t_eval[k_eval:]`` up
    to ``t_new`` (``samples``, :func:`_flight_samples`; free: no force, no force
    derivatives)."""
    z0 = y[0] - y[2]
    d0 = y[1] - y[3]
    if z0 >= 0.0 and d0 >= 0.0:
        # on or across the surface: an onset at once if moving further across (at rest on
        # it, if the relative acceleration ``w1'' + g`` presses the bodies together)
        if d0 > 0.0:
            return 2, t, k_eval
        acc = -(p[3] * y[1] + p[2] * y[0] + p[4] * np.sin(p[5] * t) + p[0] * p[6]) / p[0]
        if acc + p[6] >= 0.0:
            return 2, t, k_eval
    if z0 > 0.0 and (z0 > hair or d0 == 0.0):
        return 3, t, k_eval
    _flight_setup(t, y, p, fl)
    s_end = t1 - t
    s, code = _flight_search(min(z0, 0.0), d0, s_end, fl, ybuf)
    t_new = t1 if code == 0 else t + s
    k_eval = _flight_samples(t, t_new, fl, S, samples, k_eval, out_dF)
    if s > 0.0:
        _flight_state(s, fl, ybuf)
        for j in range(4):
            y[j] = ybuf[j]
        f00, f01, f10, f11 = _flight_phi(s, fl)
        for j in range(S.shape[1]):
            a0, a1, a2, a3 = S[0, j], S[1, j], S[2, j], S[3, j]
            S[0, j] = f00 * a0 + f01 * a1
            S[1, j] = f10 * a0 + f11 * a1
            S[2, j] = a2 + s * a3
    return code, t_new, k_eval
