"""Sensitivities: the derivatives of the state along directions of the start and of the
law's coefficients through the integrator's steps and at the events.

``S`` (4, m), column j the derivative of the state along a direction of the start
(``spar[j] < 0``) or of the law's coefficient ``spar[j]``.  They follow the
discrete Runge-Kutta map of each accepted step (the step's own stages, so at the end of a
step they are the exact derivative of its result at fixed step length), and jump by the
saltation matrix at every located event.
"""

import numpy as np
from numba import njit

from ....numerics._dopri import dense_weights as _dense_weights
from ....numerics._tableau import A as _A
from ....numerics._tableau import B as _B
from ....numerics._tableau import E as _E
from .codes import CLIPPED, DP, FREE, LOAD, P_K3, UNLOAD, borrowed_njit
from .forces import _partials, force_partials, rhs_at

_stage, _combine = DP.stage, DP.combine


@njit(cache=True, inline="always")
def _dforce(fz, fv, dz, dv, j, spar, dc):
    """The force's derivative along column ``j``: the penetration's and its rate's
    derivatives ``dz``, ``dv`` along it, and the coefficient ``spar[j]`` when it is one."""
    df = fz * dz + fv * dv
    if spar[j] >= 0:
        df += dc[spar[j]]
    return df


@njit(cache=True, inline="always")
def _rhs_sens(y, mode, p, coef, ea, eb, br, S, spar, dc, out):
    """``out[:, j] = (df/dy) S[:, j] + df/dq_j`` at ``y`` in ``mode``."""
    fz, fv = _partials(mode, y[0] - y[2], y[1] - y[3], coef, ea, eb, br, dc)
    ky = p[2] + 3.0 * p[P_K3] * y[0] * y[0]
    for j in range(S.shape[1]):
        df = _dforce(fz, fv, S[0, j] - S[2, j], S[1, j] - S[3, j], j, spar, dc)
        out[0, j] = S[1, j]
        out[1, j] = -(p[3] * S[1, j] + ky * S[0, j] + df) / p[0]
        out[2, j] = S[3, j]
        out[3, j] = df / p[1]


@borrowed_njit
def _rk_sens(y, h, mode, law, K, ytmp, S, spar, sw):
    """The sensitivities through the step ``y -> ynew`` of length ``h`` whose stages are in
    ``K``: fills the stage derivatives ``KS`` (7, 4, m) and ``Snew`` (of the sensitivities'
    work arrays ``sw``, :func:`work_arrays`)."""
    p, coef, ea, eb, br = law
    KS, SS, Snew, dc = sw[0], sw[1], sw[2], sw[3]
    m = S.shape[1]
    _rhs_sens(y, mode, p, coef, ea, eb, br, S, spar, dc, KS[0])
    for s in range(1, 7):
        if s < 6:
            _stage(s, y, h, K, ytmp)
        else:
            _combine(y, h, K, ytmp)
        for r in range(4):
            for j in range(m):
                acc = 0.0
                for i in range(s):
                    acc += (_A[s, i] if s < 6 else _B[i]) * KS[i, r, j]
                SS[r, j] = S[r, j] + h * acc
        _rhs_sens(ytmp, mode, p, coef, ea, eb, br, SS, spar, dc, KS[s])
    for r in range(4):
        for j in range(m):
            Snew[r, j] = SS[r, j]


@borrowed_njit
def _sens_error(S, Snew, KS, h, rtol, atol, sscale):
    """The embedded error estimate of the sensitivities, scaled as the state's is: column
    ``j`` times ``sscale[j]`` (the size of a perturbation along it) is the response of the
    state, with the state's tolerances (RMS over the columns)."""
    acc = 0.0
    for r in range(4):
        for j in range(S.shape[1]):
            e = 0.0
            for i in range(7):
                e += _E[i] * KS[i, r, j]
            w = sscale[j]
            sc = atol[r] + rtol * w * max(abs(S[r, j]), abs(Snew[r, j]))
            q = h * e * w / sc
            acc += q * q
    return np.sqrt(acc / (4.0 * S.shape[1]))


@njit(cache=True, inline="always")
def _dense_diff(S, KS, h, w, r, j):
    """Row ``r`` minus row ``r + 2`` of column ``j`` of the dense sensitivities (the
    penetration's derivative for ``r = 0``, its rate's for ``r = 1``); ``w`` the dense
    output's weights."""
    w0, w2, w3, w4, w5, w6 = w
    return (
        S[r, j]
        - S[r + 2, j]
        + h
        * (
            w0 * (KS[0, r, j] - KS[0, r + 2, j])
            + w2 * (KS[2, r, j] - KS[2, r + 2, j])
            + w3 * (KS[3, r, j] - KS[3, r + 2, j])
            + w4 * (KS[4, r, j] - KS[4, r + 2, j])
            + w5 * (KS[5, r, j] - KS[5, r + 2, j])
            + w6 * (KS[6, r, j] - KS[6, r + 2, j])
        )
    )


@borrowed_njit
def _dense_force_sens(mode, y, h, theta, law, sens, sw, k):
    """``out_dF[j, k] = dF/dq_j`` at the dense output ``y`` (step fraction ``theta``): only
    the penetration's and its rate's sensitivities are interpolated, the two combinations of
    rows the force needs."""
    _, coef, ea, eb, br = law
    S, spar, out = sens[0], sens[1], sens[3]
    KS, dc = sw[0], sw[3]
    w = _dense_weights(theta)
    fz, fv = force_partials(mode, y[0] - y[2], y[1] - y[3], coef, ea, eb, br, dc)
    m = S.shape[1]
    for j in range(m):
        dz, dv = _dense_diff(S, KS, h, w, 0, j), _dense_diff(S, KS, h, w, 1, j)
        out[j, k] = _dforce(fz, fv, dz, dv, j, spar, dc)
        out[m + j, k] = dz


@borrowed_njit
def _force_sens(mode, y, law, sens, dc, k):
    """``out_dF[j, k] = dF/dq_j`` of the force at ``y`` (sensitivities ``S``) in ``mode``,
    and ``out_dF[m + j, k]`` the penetration's."""
    _, coef, ea, eb, br = law
    S, spar, out = sens[0], sens[1], sens[3]
    fz, fv = force_partials(mode, y[0] - y[2], y[1] - y[3], coef, ea, eb, br, dc)
    m = S.shape[1]
    for j in range(m):
        out[j, k] = _dforce(fz, fv, S[0, j] - S[2, j], S[1, j] - S[3, j], j, spar, dc)
        out[m + j, k] = S[0, j] - S[2, j]


@borrowed_njit
def _event_time_sens(t, y, mode, index, law, S, spar, sw):
    """Before an event: the vector field ``fminus`` of the mode left, and ``tau[j]``, the
    derivative of the event time along column ``j``: ``-(grad h . S_j + dh/dq_j) /
    (grad h . f-)`` for the switching function ``index`` that fired."""
    _, coef, ea, eb, br = law
    dc, fminus, tau = sw[3], sw[4], sw[6]
    rhs_at(t, y, mode, law, fminus)
    z = y[0] - y[2]
    v = y[1] - y[3]
    cs = 0.0
    if mode == FREE:
        gz, gv = -1.0, 0.0
    elif index == 0:
        gz, gv = 1.0, 0.0
    elif mode == CLIPPED:
        fz, fv = force_partials(LOAD if v > 0.0 else UNLOAD, max(z, 0.0), v, coef, ea, eb, br, dc)
        gz, gv, cs = -fz, -fv, -1.0
    elif index == 1:
        gz, gv = 0.0, (1.0 if mode == LOAD else -1.0)
    else:
        fz, fv = force_partials(mode, z, v, coef, ea, eb, br, dc)
        gz, gv, cs = fz, fv, 1.0
    den = gz * (fminus[0] - fminus[2]) + gv * (fminus[1] - fminus[3])
    for j in range(S.shape[1]):
        num = gz * (S[0, j] - S[2, j]) + gv * (S[1, j] - S[3, j])
        if cs != 0.0 and spar[j] >= 0:
            num += cs * dc[spar[j]]
        # a flow tangent to the surface (a graze) has no event-time derivative
        tau[j] = -num / den if den != 0.0 else np.nan


@borrowed_njit
def _saltation(t, y, mode, law, S, sw, n_ev, ev_tau):
    """After an event into ``mode``: ``S_j += (f- - f+) tau_j``, and the event's time
    derivatives kept in ``ev_tau`` (if there is room)."""
    fminus, fplus, tau = sw[4], sw[5], sw[6]
    rhs_at(t, y, mode, law, fplus)
    for j in range(S.shape[1]):
        for r in range(4):
            S[r, j] += (fminus[r] - fplus[r]) * tau[j]
        if n_ev < ev_tau.shape[0]:
            ev_tau[n_ev, j] = tau[j]
