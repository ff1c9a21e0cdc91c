"""The kernel's loop: one run from ``t0`` to ``t1`` (:func:`integrate`), free flights and
contact phases in closed form where they apply, the integrator's steps elsewhere, every
event located and recorded (see :mod:`.` for the design)."""

import numpy as np
from numba import njit

from ....numerics._dopri import MIN_FACTOR as _MIN_FACTOR
from ....numerics._dopri import step_factor as _step_factor
from ....numerics.status import BLOW_UP, CHATTER, OK, STEP_BUDGET, STEP_UNDERFLOW
from .codes import DP, FREE, LOAD, UNLOAD, borrowed_njit
from .contact import _contact
from .events import _first_crossing, _record_event, _switching, resolve_mode
from .flight import _flight, _flight_ok
from .forces import _rhs, _rk_step, mode_force
from .sensitivities import (
    _dense_force_sens,
    _event_time_sens,
    _force_sens,
    _rk_sens,
    _saltation,
    _sens_error,
)

_dense, _error_norm = DP.dense, DP.error_norm

# chattering: more than _ZENO_EVENTS located events in a row, each within
# _ZENO_GAP * hmax of the previous one (mode switches that hardly advance time)
_ZENO_EVENTS, _ZENO_GAP = 1000, 1e-3


@borrowed_njit
def _zeno_run(t, t_last_ev, hmax, short_run):
    """After an event at ``t``: the count of events in a row each within ``_ZENO_GAP * hmax``
    of the previous one, ``t`` (the last event's time) and the run's status (chattering
    beyond ``_ZENO_EVENTS`` such events)."""
    run = short_run + 1 if t - t_last_ev < _ZENO_GAP * hmax else 0
    return run, t, CHATTER if run > _ZENO_EVENTS else OK


@njit(cache=True, inline="always")
def _finite(y):
    """Whether the state's four components are finite."""
    return np.isfinite(y[0]) and np.isfinite(y[1]) and np.isfinite(y[2]) and np.isfinite(y[3])


@njit(cache=True, inline="always")
def _take_event(t, y, mode, index, law, n_ev, events, sens, sw):
    """Event ``n_ev`` of switching function ``index`` at ``(t, y)``: with sensitivities its
    time derivatives (:func:`_event_time_sens`), its record (:func:`_record_event`) and the
    saltation into the mode after it (:func:`_saltation`); returns that mode and the count of
    events recorded, ``n_ev + 1``.  Inlined: the
    loop's calls pass literal indices, and a call of its own would be compiled once for each
    (five times, 3 s of the cold compile) where the three calls it makes are typed anyway."""
    S, spar, ev_tau = sens[0], sens[1], sens[4]
    m_s = S.shape[1]
    if m_s:
        _event_time_sens(t, y, mode, index, law, S, spar, sw)
    mode = _record_event(t, y, mode, index, law, n_ev, events)
    if m_s:
        _saltation(t, y, mode, law, S, sw, n_ev, ev_tau)
    return mode, n_ev + 1


@borrowed_njit
def integrate(t0, t1, y, mode0, law, ctl, out, use_contact, work):
    """Integrate from ``t0`` to ``t1``, advancing ``y`` in place; see
    :func:`discovery.vibroimpact.dynamics.simulate`.  Returns ``(status, t, mode, n_steps,
    n_events, h)``; ``mode0 < 0`` resolves the mode from ``y``.

    Writes the state, force and mode at each ``t_eval`` (sorted, within ``[t0, t1]``) and
    up to ``len(ev_t)`` events.

    Sensitivities (``S`` of shape (4, m), ``m = 0`` for none): ``S`` holds the
    derivatives of the start along ``m`` directions and is replaced by those of the end;
    column ``j`` also moves the law's coefficient ``spar[j]`` when ``spar[j] >= 0``;
    ``sscale[j]`` is the size of a perturbation along it: their error is then controlled
    as the state's, so the run takes its own steps (``sscale`` of size 0: the state's
    steps, and the state's results bitwise those of a run without sensitivities).  With
    ``out_dF`` of shape (m, len(t_eval)) the force's derivatives at ``t_eval`` are written
    too (shape (m, 0) for none), and with ``ev_tau`` of shape (len(ev_t), m) the events'
    time derivatives (shape (0, m) for none).  Not for a law with a permanent set.

    The arguments come in bundles: ``law`` ``(p, coef, ea, eb, br)``, the parameters and
    the law's arrays; ``ctl`` ``(rtol, atol, h0, hmax, max_steps)``, the step control;
    ``out`` ``(samples, events, sens)``, the outputs ``(t_eval, out_y, out_f, out_mode)``,
    ``(ev_t, ev_kind, ev_y, ev_modes)`` and the sensitivities ``(S, spar, sscale, out_dF,
    ev_tau)``; ``use_contact``: whether a contact mode has the closed form
    (:func:`~.entries.set_up_modes`); ``work`` ``(steps, sens, phases)``: the work arrays
    (:func:`~.entries.work_arrays`), ``phases`` those of the phases with the contact modes,
    ``(fl, kc, E, R, qm, sw, cb, fc, fcd)``.  Every array is borrowed."""
    p, coef, ea, eb, br = law
    rtol, atol, h0, hmax, max_steps = ctl
    samples, events, sens = out
    t_eval, out_y, out_f, out_mode = samples
    S, spar, sscale, out_dF, _ = sens
    steps, sw, phases = work
    ynew, ytmp, ybuf, K, hs0, hs1, hsa, hsb, hsm = steps
    KS, _, Snew, dc = sw[0], sw[1], sw[2], sw[3]
    fl = phases[0]
    need_h0 = True
    ns = 0
    t = t0
    m_s = S.shape[1]
    ctl_s = m_s > 0 and sscale.shape[0] > 0
    want_df = out_dF.shape[1] > 0
    mode = mode0 if mode0 >= 0 else resolve_mode(y, law)
    h = min(h0, hmax, t1 - t0)
    n_eval = t_eval.shape[0]
    k_eval = 0
    while k_eval < n_eval and t_eval[k_eval] <= t0:
        for j in range(4):
            out_y[j, k_eval] = y[j]
        out_f[k_eval] = mode_force(mode, y[0] - y[2], y[1] - y[3], p, coef, ea, eb, br)
        out_mode[k_eval] = mode
        if want_df:
            _force_sens(mode, y, law, sens, dc, k_eval)
        k_eval += 1
    n_ev = 0
    n_steps = 0
    zero_len = 0
    short_run = 0
    t_last_ev = -np.inf
    status = OK
    need_f = True
    # free flight in closed form where it applies (:func:`~.flight._flight`); ``hold``: the
    # integrator's steps until one is accepted (a start across the surface, not closing)
    use_flight = _flight_ok(p)
    hold = False
    while t < t1:
        if n_steps >= max_steps:
            status = STEP_BUDGET
            break
        # a phase in closed form: ``code`` as :func:`~.flight._flight`'s (a contact phase's
        # has no 2), 3 where none applies
        code, t_new, idx = 3, t, 0
        if use_flight and mode == FREE and not hold:
            code, t_new, k_eval = _flight(
                t, t1, y, p, atol[0], fl, ybuf, S, samples, k_eval, out_dF
            )
            hold = code == 3
        elif use_contact and (mode == LOAD or mode == UNLOAD) and not hold:
            code, t_new, k_eval, idx = _contact(
                t, t1, y, mode, law, atol, phases, ybuf, dc, sens, samples, k_eval
            )
            hold = code == 3
        if code != 3:
            if code != 2:
                n_steps += 1
                t = t_new
                need_f = True
                need_h0 = True
                if not _finite(y):
                    status = BLOW_UP
                    break
            if code == 0 or code == 4:
                hold = code == 4
                continue
            if code == 2:
                zero_len += 1
                if zero_len > 4:
                    status = CHATTER
                    break
            else:
                zero_len = 0
                short_run, t_last_ev, status = _zeno_run(t, t_last_ev, hmax, short_run)
                if status != OK:
                    break
            mode, n_ev = _take_event(t, y, mode, idx, law, n_ev, events, sens, sw)
            need_f = need_h0 = True
            continue
        if need_f:
            _rhs(t, y, mode, p, coef, ea, eb, br, K[0])
            need_f = False
        h = min(h, hmax, t1 - t)
        if h < 1e-14 * max(1.0, abs(t)) and t1 - t > h:
            status = STEP_UNDERFLOW
            break
        _rk_step(t, y, h, mode, law, K, ytmp, ynew)
        n_steps += 1
        err = _error_norm(y, ynew, K, h, rtol, atol)
        if ctl_s:
            # the sensitivities are held to the state's accuracy too (a fractional power
            # makes the variational equations stiffer than the state near an onset)
            _rk_sens(y, h, mode, law, K, ytmp, S, spar, sw)
            err = max(err, _sens_error(S, Snew, KS, h, rtol, atol, sscale))
        if not np.isfinite(err):
            h *= _MIN_FACTOR
            if h < 1e-14 * max(1.0, abs(t)):
                status = BLOW_UP
                break
            continue
        if err > 1.0:
            h *= _step_factor(err)
            continue
        # ---- accepted step: look for the earliest event in (t, t + h]
        if need_h0:
            ns = _switching(mode, y, law, hs0)
            need_h0 = False
        _switching(mode, ynew, law, hs1)
        best_theta = 2.0
        best_index = -1
        # probe the dense output at 1/3 and 2/3 too, so a brief excursion across a
        # switching surface inside one step is seen (once per step, for all functions)
        _dense(y, K, h, 1.0 / 3.0, ybuf)
        _switching(mode, ybuf, law, hsa)
        _dense(y, K, h, 2.0 / 3.0, ybuf)
        _switching(mode, ybuf, law, hsb)
        for i in range(ns):
            if hsa[i] >= 0.0 and hsb[i] >= 0.0 and hs1[i] >= 0.0:
                # fast path: no probe across the surface; only a graze of zeta = 0
                # between them is left to check (free and clipped modes only)
                if i != 0 or mode == LOAD or mode == UNLOAD:
                    continue
                s = -1.0 if mode == FREE else 1.0
                if not (s * (y[1] - y[3]) < 0.0 and s * (ynew[1] - ynew[3]) > 0.0):
                    continue
            hv = (hs0[i], hsa[i], hsb[i], hs1[i])
            th = _first_crossing(t, y, ynew, K, h, mode, law, i, hv, ybuf, hsm)
            # near-ties go to the lower index: contact loss (index 0) wins over the
            # force reaching zero at the same instant (e.g. P(zeta, 0) = k * zeta)
            if th < best_theta - 1e-9:
                best_theta, best_index = th, i
        if best_index >= 0:
            if best_theta == 0.0:
                zero_len += 1
                if zero_len > 4:
                    status = CHATTER
                    break
                mode, n_ev = _take_event(t, y, mode, best_index, law, n_ev, events, sens, sw)
                need_f = need_h0 = True
                continue
            # re-take the step so that it ends on the event
            h_ev = best_theta * h
            _rk_step(t, y, h_ev, mode, law, K, ytmp, ynew)
            h_used = h_ev
            if m_s:
                _rk_sens(y, h_used, mode, law, K, ytmp, S, spar, sw)
        else:
            h_used = h
            if m_s and not ctl_s:
                _rk_sens(y, h_used, mode, law, K, ytmp, S, spar, sw)
        zero_len = 0
        hold = False
        t_new = t + h_used if best_index >= 0 or h_used < t1 - t else t1
        # dense output at requested times inside (t, t_new]
        while k_eval < n_eval and t_eval[k_eval] <= t_new:
            theta = (t_eval[k_eval] - t) / h_used
            _dense(y, K, h_used, min(theta, 1.0), ybuf)
            for j in range(4):
                out_y[j, k_eval] = ybuf[j]
            out_f[k_eval] = mode_force(
                mode, ybuf[0] - ybuf[2], ybuf[1] - ybuf[3], p, coef, ea, eb, br
            )
            out_mode[k_eval] = mode
            if want_df:
                _dense_force_sens(mode, ybuf, h_used, min(theta, 1.0), law, sens, sw, k_eval)
            k_eval += 1
        for j in range(4):
            y[j] = ynew[j]
            K[0, j] = K[6, j]
        for r in range(4):
            for j in range(m_s):
                S[r, j] = Snew[r, j]
        t = t_new
        if not _finite(y):
            status = BLOW_UP
            break
        if best_index >= 0:
            short_run, t_last_ev, status = _zeno_run(t, t_last_ev, hmax, short_run)
            if status != OK:
                break
            mode, n_ev = _take_event(t, y, mode, best_index, law, n_ev, events, sens, sw)
            need_f = need_h0 = True
            # keep the step size that worked before the cut
        else:
            for i in range(ns):
                hs0[i] = hs1[i]
            h = h * _step_factor(err)
    return status, t, mode, n_steps, n_ev, h
