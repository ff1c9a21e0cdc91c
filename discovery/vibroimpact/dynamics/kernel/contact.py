"""A contact phase (loading or unloading) in closed form, from the modal decomposition of
its mode (:mod:`.contact_modes`).

Every switching function of the two modes is linear in the state, ``h = gz z + gv zd``
(loss ``z``, unload ``zd`` or reload ``-zd``, release ``F``), and its first root is proven
as the flight's onset: over ``[a, a + H]``, ``|h''| <= K = sum_j |G_j| (|lambda_j| |d_j|
max(e^(Re lambda_j a), e^(Re lambda_j (a + H))) + w^2 (|A_j| + |A'_j|) / 2)`` with ``G_j =
g . v_j`` and ``d_j = u_j'(0)`` (``u_j'' = lambda_j e^(lambda_j s) d_j``, ``q_sj'' = -w^2
q_sj``), so ``h >= h(a) + h'(a) tau - K tau^2 / 2`` there and no interval is passed unless
that stays positive over it for every function.  A mode with a growing eigenvalue (``Re
lambda > 0``, a law with negative coefficients) caps the intervals at ``1 / Re lambda``.
The first root is polished by safeguarded Newton on the closed form; the event is recorded at
the last point of the phase (every switching function still >= 0) within the time's
resolution of it.

Sensitivities move by the transition matrix, ``S <- Re(V diag(e^(lambda s)) V^-1) S``, and
a law coefficient's column gains the response to its force term (``z`` or ``zd``, the
derivative of the mode's force in it), integrated in modal form (:func:`_contact_forced`);
they jump by the saltation matrix at the events as after an integrated step.  The
coefficients' columns need the mode's eigenvalues away from 0 (a frame without a spring
has a zero one: its contacts are then integrated in a run that carries them).
"""

import numpy as np
from numba import njit

from .codes import LOAD, borrowed_njit
from .contact_modes import _contact_g
from .flight import _FLIGHT_ITERS, _SAMPLE_ANCHOR, _SAMPLE_SLIP, _newton_probe
from .forces import force_partials


@njit(cache=True, inline="always")
def _phi1(x, ex):
    """``(e^x - 1) / x`` (1 at 0) for a complex ``x`` with ``ex = e^x``, without cancellation
    near 0."""
    if x.real * x.real + x.imag * x.imag < 1e-4:  # |x| < 1e-2 without a hypot
        return 1.0 + x * (1.0 + x * (1.0 + x * (1.0 + x * (1.0 + x / 6.0) / 5.0) / 4.0) / 3.0) / 2.0
    return (ex - 1.0) / x


@borrowed_njit
def _contact_start(t0, y, mi, w, E, qm):
    """The phase's modal data from ``(t0, y)``: ``qm[j] = (u_j(0), d_j)``, ``d_j = lambda_j
    u_j(0) + beta_cj`` (``u_j``'s rate at the start)."""
    ew = np.cos(w * t0) + 1j * np.sin(w * t0)
    for j in range(4):
        q = 0j
        for r in range(4):
            q += E[mi, j, 4 + r] * y[r]
        u0 = q + 0.5j * (E[mi, j, 10] * ew - E[mi, j, 11] * np.conj(ew))
        qm[j, 0] = u0
        qm[j, 1] = E[mi, j, 8] * u0 + E[mi, j, 9]


@borrowed_njit
def _contact_state(s, t0, w, mi, E, qm, out, ex):
    """The state ``s`` after the phase's start (at ``t0``) into ``out`` (``ex``: a work
    array of 4 complex numbers, left holding ``e^(lambda_j s)``)."""
    tt = t0 + s
    _contact_exps(s, w, mi, E, ex)
    _contact_state_at(s, np.cos(w * tt) + 1j * np.sin(w * tt), ex, mi, E, qm, out)


@borrowed_njit
def _contact_state_at(s, ew, ex, mi, E, qm, out):
    """:func:`_contact_state` from the exponentials at ``s``: ``ew = e^(i w (t0 + s))``,
    ``ex[j] = e^(lambda_j s)``."""
    a0, a1, a2, a3 = 0j, 0j, 0j, 0j
    for j in range(4):
        x = E[mi, j, 8] * s
        q = ex[j] * qm[j, 0] + E[mi, j, 9] * s * _phi1(x, ex[j])
        q -= 0.5j * (E[mi, j, 10] * ew - E[mi, j, 11] * np.conj(ew))
        a0 += E[mi, j, 0] * q
        a1 += E[mi, j, 1] * q
        a2 += E[mi, j, 2] * q
        a3 += E[mi, j, 3] * q
    out[0], out[1], out[2], out[3] = a0.real, a1.real, a2.real, a3.real


@borrowed_njit
def _contact_phi(ex, mi, E, out):
    """The mode's transition matrix ``Phi(s) = V diag(e^(lambda s)) V^-1`` into ``out``
    (``ex[j] = e^(lambda_j s)``)."""
    for r in range(4):
        for q in range(4):
            out[r, q] = 0.0
    for j in range(4):
        ej = ex[j]
        for r in range(4):
            vr = E[mi, j, r] * ej
            for q in range(4):
                out[r, q] += (vr * E[mi, j, 4 + q]).real


@borrowed_njit
def _eint(lj, mu, ej, emu, s):
    """``int_0^s e^(lambda (s - u)) e^(mu u) du`` from ``ej = e^(lambda s)``, ``emu = e^(mu
    s)`` (``s e^(lambda s) phi1((mu - lambda) s)`` near ``mu = lambda``)."""
    d = mu - lj
    x = d * s
    if x.real * x.real + x.imag * x.imag < 1e-4:  # |x| < 1e-2 without a hypot
        return s * ej * _phi1(x, 0j)
    return (emu - ej) / d


@borrowed_njit
def _contact_forced(s, t0, w, mi, E, qm, m1, m2, ex, ews, W):
    """``W[0]``, ``W[1]``: the state's response at ``s`` of the phase (zero at its start) to a
    force ``z``, and to a force ``zd``, added to the contact's: ``int_0^s Phi(s - u) e_F z(u)
    du`` with ``e_F = (0, -1/m1, 0, 1/m2)``, a coefficient's column's forced part.  In modal
    form each mode ``j`` integrates ``e^(lambda_j (s - u))`` against the modal solution's
    exponentials, constant and drive (``E(lambda, mu) = int e^(lambda (s - u)) e^(mu u) du``);
    the constant part ``beta s phi1(lambda s) = beta (e^(lambda s) - 1) / lambda`` needs a
    mode's ``|lambda|`` away from 0 (the caller's check).  ``ex[j] = e^(lambda_j s)`` and
    ``ews = e^(i w s)`` are given."""
    ew0 = np.cos(w * t0) + 1j * np.sin(w * t0)
    for r in range(4):
        W[0, r] = 0.0
        W[1, r] = 0.0
    for j in range(4):
        lj, ej = E[mi, j, 8], ex[j]
        e0 = _eint(lj, 0j, ej, 1.0 + 0j, s)
        ep = _eint(lj, 1j * w, ej, ews, s)
        em = _eint(lj, -1j * w, ej, np.conj(ews), s)
        iz, iv = 0j, 0j
        for q in range(4):
            lq = E[mi, q, 8]
            el = _eint(lj, lq, ej, ex[q], s)
            drive = E[mi, q, 10] * ew0 * ep - E[mi, q, 11] * np.conj(ew0) * em
            iq = qm[q, 0] * el + E[mi, q, 9] * (el - e0) / lq - 0.5j * drive
            iz += (E[mi, q, 0] - E[mi, q, 2]) * iq
            iv += (E[mi, q, 1] - E[mi, q, 3]) * iq
        eps = E[mi, j, 7] / m2 - E[mi, j, 5] / m1
        for r in range(4):
            W[0, r] += (E[mi, j, r] * eps * iz).real
            W[1, r] += (E[mi, j, r] * eps * iv).real


@borrowed_njit
def _contact_sens(s, phase, p, S, spar, sw, ews, force, y, out_dF, k):
    """Through ``s`` of the phase ``(t0, mi, E, qm)`` (``ex[j] = e^(lambda_j s)`` in its work
    arrays ``sw`` ``(gcol, phi, W, ex, eh)``, ``ews = e^(i w s)``): ``S <- Phi(s) S``, plus
    ``gcol[0, j] W[0] + gcol[1, j] W[1]`` for a coefficient's column ``j`` (``dF/dc = gcol[0,
    j] z + gcol[1, j] zd`` in this mode, :func:`_contact_forced`); with ``k >= 0`` instead
    the force's (``force = (kF, cF)``: ``kF z + cF zd``) and the penetration's derivatives
    at ``s`` (the state ``y`` there) into ``out_dF[:, k]``, ``S`` kept."""
    t0, mi, E, qm = phase
    gcol, phi, W, ex, _ = sw
    kF, cF = force
    _contact_phi(ex, mi, E, phi)
    m = S.shape[1]
    for j in range(m):
        if spar[j] >= 0:
            _contact_forced(s, t0, p[5], mi, E, qm, p[0], p[1], ex, ews, W)
            break
    for j in range(m):
        a0, a1, a2, a3 = S[0, j], S[1, j], S[2, j], S[3, j]
        b0 = phi[0, 0] * a0 + phi[0, 1] * a1 + phi[0, 2] * a2 + phi[0, 3] * a3
        b1 = phi[1, 0] * a0 + phi[1, 1] * a1 + phi[1, 2] * a2 + phi[1, 3] * a3
        b2 = phi[2, 0] * a0 + phi[2, 1] * a1 + phi[2, 2] * a2 + phi[2, 3] * a3
        b3 = phi[3, 0] * a0 + phi[3, 1] * a1 + phi[3, 2] * a2 + phi[3, 3] * a3
        direct = 0.0
        if spar[j] >= 0:
            gz, gv = gcol[0, j], gcol[1, j]
            b0 += gz * W[0, 0] + gv * W[1, 0]
            b1 += gz * W[0, 1] + gv * W[1, 1]
            b2 += gz * W[0, 2] + gv * W[1, 2]
            b3 += gz * W[0, 3] + gv * W[1, 3]
            direct = gz * (y[0] - y[2]) + gv * (y[1] - y[3])
        if k >= 0:
            out_dF[j, k] = kF * (b0 - b2) + cF * (b1 - b3) + direct
            out_dF[m + j, k] = b0 - b2
        else:
            S[0, j], S[1, j], S[2, j], S[3, j] = b0, b1, b2, b3


@borrowed_njit
def _contact_h(i, mode, kc, t, y, p):
    """Switching function ``i`` of a contact mode and its rate at ``(t, y)``."""
    gz, gv = _contact_g(mode, kc, i)
    k, c = (kc[0], kc[1]) if mode == LOAD else (kc[2], kc[3])
    z, zd = y[0] - y[2], y[1] - y[3]
    f = k * z + c * zd
    a1 = -(p[3] * y[1] + p[2] * y[0] + p[4] * np.sin(p[5] * t) + p[0] * p[6] + f) / p[0]
    a2 = f / p[1] - p[6]
    return gz * z + gv * zd, gz * zd + gv * (a1 - a2)


@njit(cache=True, inline="always")
def _contact_gap(f, fd, K):
    """The positive root of ``f + fd tau - K tau^2 / 2`` (``f >= 0``): how far a function at
    ``f`` with rate ``fd`` and curvature at least ``-K`` stays positive."""
    if not K > 1e-300:
        K = 1e-300
    if f <= 0.0 and fd <= 0.0:
        return 0.0
    disc = np.sqrt(fd * fd + 2.0 * K * f)
    return (fd + disc) / K if fd > 0.0 else 2.0 * f / (disc - fd)


@njit(cache=True, inline="always")
def _time_res(t, w):
    """The time resolution at ``t``: a few units in the last place of the absolute time, and
    at least 1e-15 of the drive period."""
    return 4.0e-16 * max(abs(t), 2.0 * np.pi / w)


@borrowed_njit
def _contact_polish(i, mode, a, b, hb, hdb, phase, p, kc, ybuf, ex):
    """The first root of switching function ``i`` in ``[a, b]`` (``h(a) >= 0 > h(b) = hb``,
    rate ``hdb``; no root in ``[a, b)`` but the crossing's): safeguarded Newton to the
    time's resolution.  The point returned is the last one on the function's side (``h >=
    0``), within that resolution of the root: a phase's event state keeps every function of
    its mode at ``>= 0`` (the penetration and the force have their signs up to the end of
    the contact, as its left limits must), and the next mode starts a hair across its own
    surface at most, leaving it.  ``phase``: ``(t0, mi, E, qm)``."""
    t0, mi, E, qm = phase
    w = p[5]
    lo, hi = a, b
    s, hs, hds = b, hb, hdb
    for _ in range(200):
        res = _time_res(t0 + hi, w)
        if hi - lo <= res:
            break
        c = _newton_probe(lo, hi, s, hs, hds, hds < 0.0, hs < 0.0, res)
        _contact_state(c, t0, w, mi, E, qm, ybuf, ex)
        hc, hdc = _contact_h(i, mode, kc, t0 + c, ybuf, p)
        lo, hi = (lo, c) if hc < 0.0 else (c, hi)
        s, hs, hds = c, hc, hdc
    return lo


@borrowed_njit
def _contact_growth(mi, a, hcap, E, cb):
    """The largest ``|e^(lambda_j s)|`` over ``[a, a + hcap]`` of each eigenvalue into
    ``cb[3]`` (at ``a`` for a decaying one, whose end value is the smaller), shared by the
    three switching functions' curvature bounds."""
    for j in range(4):
        re = E[mi, j, 8].real
        e = np.exp(re * a)
        cb[3, j] = e if re <= 0.0 else max(e, np.exp(re * (a + hcap)))


@borrowed_njit
def _contact_bound(i, mi, R, cb):
    """The curvature bound ``K`` of switching function ``i`` over the interval whose
    exponentials' bounds :func:`_contact_growth` left in ``cb[3]``."""
    K = R[mi, 1 + i]
    for j in range(4):
        K += cb[i, j] * cb[3, j]
    return K


@borrowed_njit
def _contact_search(mode, phase, s_end, p, kc, R, cb, f, fd, ybuf, ex):
    """The first event in ``(0, s_end]`` of the contact phase ``(t0, mi, E, qm)`` set up (the
    switching functions' values ``f >= 0`` and rates ``fd`` at its start): ``(s, index)``,
    ``index`` the function that fires at ``s``, -1 for none up to ``s = s_end``, -2 if the
    safeguard's interval budget ran out at ``s`` (no event before it)."""
    t0, mi, E, qm = phase
    w = p[5]
    a = 0.0
    grow = R[mi, 4]
    for _ in range(_FLIGHT_ITERS):
        hcap = s_end - a
        if grow > 0.0:
            hcap = min(hcap, 1.0 / grow)
        H = hcap
        _contact_growth(mi, a, hcap, E, cb)
        for i in range(3):
            H = min(H, _contact_gap(f[i], fd[i], _contact_bound(i, mi, R, cb)))
        if a + H >= s_end:
            return s_end, -1
        b = min(a + max(H, _time_res(t0 + a, w)), s_end)
        _contact_state(b, t0, w, mi, E, qm, ybuf, ex)
        best_s, best_i = np.inf, -1
        for i in range(3):
            hb, hdb = _contact_h(i, mode, kc, t0 + b, ybuf, p)
            f[i], fd[i] = hb, hdb
        for i in range(3):
            if f[i] < 0.0:
                si = _contact_polish(i, mode, a, b, f[i], fd[i], phase, p, kc, ybuf, ex)
                # near-ties go to the lower index (loss before release at once)
                if si < best_s - 2.0 * _time_res(t0 + si, w):
                    best_s, best_i = si, i
        if best_i >= 0:
            return best_s, best_i
        if b >= s_end:
            return s_end, -1
        a = b
    return a, -2


@borrowed_njit
def _contact(t, t1, y, mode, law, atol, phases, ybuf, dc, sens, samples, k_eval):
    """One contact phase (loading or unloading) from ``(t, y)`` in closed form: ``(code,
    t_new, k_eval, index)``.

    ``code`` 0: no event up to ``t1`` (``y`` advanced to it); 1: switching function ``index``
    fires at ``t_new`` (advanced to it: the caller records the event); 3: not here (the mode
    has no closed form, or a switching function starts across its surface by more than a
    hair of the absolute tolerances, or not leaving it: the integrator's steps); 4: advanced
    to ``t_new`` without an event, the integrator's steps next (the safeguard's interval
    budget ran out).  Writes the state, force and mode at ``t_eval[k_eval:]`` up to
    ``t_new`` (``samples``: ``(t_eval, out_y, out_f, out_mode)``; and the force's
    derivatives with ``out_dF``); ``S`` moves with the state (``sens``: ``(S, spar, sscale,
    out_dF, ev_tau)``).  ``phases``: the closed-form phases' arrays, :func:`~.loop.integrate`'s.  A
    law coefficient's column needs the mode's eigenvalues away from 0 (``|lambda| > 1e-3
    w``), else the integrator's steps."""
    p, coef, ea, eb, br = law
    _, kc, E, R, qm, sw, cb, f, fd = phases
    S, spar = sens[0], sens[1]
    mi = 0 if mode == LOAD else 1
    if R[mi, 0] == 0.0:
        return 3, t, k_eval, -1
    gcol, phi, W, ex, _ = sw
    m = S.shape[1]
    for j in range(m):
        if spar[j] >= 0 and not R[mi, 5] > 1e-3 * p[5]:
            return 3, t, k_eval, -1
    if m:
        # dF/dc of each coefficient's column in this mode: gcol[0] z + gcol[1] zd
        force_partials(mode, 1.0, 0.0, coef, ea, eb, br, dc)
        for j in range(m):
            gcol[0, j] = dc[spar[j]] if spar[j] >= 0 else 0.0
        force_partials(mode, 0.0, 1.0, coef, ea, eb, br, dc)
        for j in range(m):
            gcol[1, j] = dc[spar[j]] if spar[j] >= 0 else 0.0
    for i in range(3):
        h, hd = _contact_h(i, mode, kc, t, y, p)
        f[i], fd[i] = h, hd
        if h > 0.0:
            continue
        gz, gv = _contact_g(mode, kc, i)
        if h < -(abs(gz) * atol[0] + abs(gv) * atol[1]) or not hd > 0.0:
            return 3, t, k_eval, -1
        f[i] = 0.0  # a hair across, leaving: on the surface
    w = p[5]
    _contact_start(t, y, mi, w, E, qm)
    for i in range(3):
        gz, gv = _contact_g(mode, kc, i)
        for j in range(4):
            G = gz * (E[mi, j, 0] - E[mi, j, 2]) + gv * (E[mi, j, 1] - E[mi, j, 3])
            cb[i, j] = abs(G) * abs(E[mi, j, 8]) * abs(qm[j, 1])
    phase = (t, mi, E, qm)
    s, index = _contact_search(mode, phase, t1 - t, p, kc, R, cb, f, fd, ybuf, ex)
    code = 1 if index >= 0 else (0 if index == -1 else 4)
    t_new = t1 if code == 0 else t + s
    force = (kc[2 * mi], kc[2 * mi + 1])
    k_eval = _contact_samples(t_new, phase, mode, force, p, sens, sw, ybuf, samples, k_eval)
    _contact_state(s, t, w, mi, E, qm, ybuf, ex)  # ex: e^(lambda_j s) for the sensitivities
    for j in range(4):
        y[j] = ybuf[j]
    if m:
        ews = np.cos(w * s) + 1j * np.sin(w * s)
        _contact_sens(s, phase, p, S, spar, sw, ews, force, ybuf, sens[3], -1)
    return code, t_new, k_eval, index


@borrowed_njit
def _contact_exps(s, w, mi, E, ex):
    """``ex[j] = e^(lambda_j s)`` of the contact mode ``mi``."""
    for j in range(4):
        ex[j] = np.exp(E[mi, j, 8] * s)


@borrowed_njit
def _contact_samples(t_new, phase, mode, force, p, sens, sw, ybuf, samples, k_eval):
    """The dense output of the contact phase ``(t, mi, E, qm)`` (started at ``t``, its modal
    data ``qm``, its force ``force = (k, c)``: ``k z + c zd``) at the samples
    ``t_eval[k_eval:]`` up to ``t_new`` (``samples``: ``(t_eval, out_y, out_f, out_mode)``):
    the state, the force, the mode and (with ``out_dF`` of ``sens``) the force's and the
    penetration's derivatives; returns the next sample's index.  Evenly spaced samples
    advance the exponentials by their semigroup (``e^(lambda (s + h)) = e^(lambda s)
    e^(lambda h)``, the drive's phase rotated by ``w h``) between anchors evaluated
    directly, as the free flight's samples
    (:func:`~.flight._flight_samples`)."""
    t_eval, out_y, out_f, out_mode = samples
    if k_eval >= t_eval.shape[0] or t_eval[k_eval] > t_new:
        return k_eval  # no sample in the phase
    t, mi, E, qm = phase
    k, c = force
    S, spar, out_dF = sens[0], sens[1], sens[3]
    w = p[5]
    ex, eh = sw[3], sw[4]
    want_df = out_dF.shape[1] > 0
    slip = _SAMPLE_SLIP * 2.0 * np.pi / w
    ew0 = np.cos(w * t) + 1j * np.sin(w * t)
    h = 0.0
    run = _SAMPLE_ANCHOR
    se0 = 0.0
    ews = 0j
    ewh = 0j
    while k_eval < t_eval.shape[0] and t_eval[k_eval] <= t_new:
        se = max(t_eval[k_eval] - t, 0.0)
        if run < _SAMPLE_ANCHOR and h > 0.0 and abs(se - (se0 + run * h)) <= slip:
            for j in range(4):
                ex[j] *= eh[j]
            ews *= ewh
            run += 1
        else:
            _contact_exps(se, w, mi, E, ex)
            ews = np.cos(w * se) + 1j * np.sin(w * se)
            se0, run = se, 1
            hn = t_eval[k_eval + 1] - t_eval[k_eval] if k_eval + 1 < t_eval.shape[0] else 0.0
            if hn != h:
                h = hn
                if h > 0.0:
                    _contact_exps(h, w, mi, E, eh)
                    ewh = np.cos(w * h) + 1j * np.sin(w * h)
        _contact_state_at(se, ew0 * ews, ex, mi, E, qm, ybuf)
        for j in range(4):
            out_y[j, k_eval] = ybuf[j]
        out_f[k_eval] = k * (ybuf[0] - ybuf[2]) + c * (ybuf[1] - ybuf[3])
        out_mode[k_eval] = mode
        if want_df:
            _contact_sens(se, phase, p, S, spar, sw, ews, force, ybuf, out_dF, k_eval)
        k_eval += 1
    return k_eval
