"""The contact modes' switching functions and their events: the mode a state belongs to,
the first crossing of a switching function over an accepted step (on its dense output), and
the event's record and the mode after it (see :mod:`.` for the detection's rules)."""

from numba import njit

from .codes import (
    CLIPPED,
    DP,
    EV_LOSS,
    EV_ONSET,
    EV_RELEASE,
    EV_RELOAD,
    EV_RESUME,
    EV_UNLOAD,
    FREE,
    LOAD,
    P_LOSS,
    P_V0,
    P_ZMAX,
    UNLOAD,
    borrowed_njit,
)
from .forces import branch_force, load_force, unload_force

_dense = DP.dense


@borrowed_njit
def resolve_mode(y, law):
    """The mode a state belongs to (used at the start of an integration; a start inside
    an unloading phase takes its own penetration as the contact's largest)."""
    p, coef, ea, eb, br = law
    z = y[0] - y[2]
    v = y[1] - y[3]
    if z < 0.0 or (z == 0.0 and v <= 0.0):
        return FREE
    if p[P_V0] <= 0.0:
        # a start inside a contact whose onset the caller does not know: its own rate
        p[P_V0] = max(abs(v), 1e-12)
    if v > 0.0:
        return LOAD if load_force(max(z, 0.0), v, p, coef, ea, eb, br) >= 0.0 else CLIPPED
    p[P_ZMAX] = max(p[P_ZMAX], z)
    return UNLOAD if unload_force(z, v, p, coef, ea, eb, br) > 0.0 else CLIPPED


@borrowed_njit
def _switching(mode, y, law, h):
    """Fill ``h`` with the mode's switching functions; return how many."""
    p, coef, ea, eb, br = law
    z = y[0] - y[2]
    v = y[1] - y[3]
    if mode == FREE:
        h[0] = -z
        return 1
    h[0] = z
    if mode == LOAD:
        h[1] = v
        h[2] = load_force(z, v, p, coef, ea, eb, br)
        return 3
    if mode == UNLOAD:
        h[1] = -v
        h[2] = unload_force(z, v, p, coef, ea, eb, br)
        return 3
    h[1] = -branch_force(max(z, 0.0), v, p, coef, ea, eb, br)
    return 2


@borrowed_njit
def _event_kind(mode, index):
    if mode == FREE:
        return EV_ONSET
    if index == 0:
        return EV_LOSS
    if mode == LOAD:
        return EV_UNLOAD if index == 1 else EV_RELEASE
    if mode == UNLOAD:
        return EV_RELOAD if index == 1 else EV_RELEASE
    return EV_RESUME


@borrowed_njit
def _mode_after(kind, y, law):
    """The mode after an event, and the contact's state updates it brings (in ``p``): an
    onset starts a new contact (``z_max = 0``) and sheds the moulding's mass fraction
    ``p[P_LOSS]``; entering the unloading branch records the largest penetration."""
    p, coef, ea, eb, br = law
    z = max(y[0] - y[2], 0.0)
    v = y[1] - y[3]
    if kind == EV_LOSS:
        return FREE
    if kind == EV_ONSET:
        p[P_ZMAX] = 0.0
        p[P_V0] = max(v, 1e-12)  # the approach velocity of this impact
        p[1] *= 1.0 - p[P_LOSS]
    if kind == EV_RELEASE:
        return CLIPPED
    if kind == EV_RESUME:
        # the force crossed to positive at the located root: it is on again, even if the
        # re-taken step ended a whisker on the adhesive side
        if v > 0.0:
            return LOAD
        p[P_ZMAX] = max(p[P_ZMAX], z)
        return UNLOAD
    if kind == EV_UNLOAD or (kind == EV_ONSET and v <= 0.0):
        p[P_ZMAX] = max(p[P_ZMAX], z)
        return UNLOAD if unload_force(z, v, p, coef, ea, eb, br) >= 0.0 else CLIPPED
    # onset with dzeta > 0, or reload
    return LOAD if load_force(z, max(v, 0.0), p, coef, ea, eb, br) >= 0.0 else CLIPPED


@njit(cache=True, inline="always")
def _secant(a, b, fa, fb):
    """The secant's root of the bracket ``[a, b]`` (values ``fa``, ``fb`` of opposite signs),
    its midpoint where that root is not inside it."""
    c = (a * fb - b * fa) / (fb - fa)
    if not (a < c < b):
        c = 0.5 * (a + b)
    return c


@njit(cache=True, inline="always")
def _illinois(a, b, fa, fb, side, c, fc, left):
    """The bracket ``(a, b, fa, fb, side)`` after the value ``fc`` at ``c`` inside it: ``c``
    replaces ``a`` where ``left``, else ``b``; an end kept twice in a row has its value
    halved (Illinois); ``side`` says which end moved last (1: ``a``, -1: ``b``)."""
    if left:
        if side == 1:
            fb *= 0.5
        return c, b, fc, fb, 1
    if side == -1:
        fa *= 0.5
    return a, c, fa, fc, -1


@borrowed_njit
def _locate(y, K, h, mode, law, index, th_lo, th_hi, h_lo, h_hi, ybuf, hbuf):
    """Root in ``theta`` of switching function ``index`` on the dense output (Illinois)."""
    a, b, fa, fb = th_lo, th_hi, h_lo, h_hi
    side = 0
    for _ in range(100):
        c = _secant(a, b, fa, fb)
        _dense(y, K, h, c, ybuf)
        _switching(mode, ybuf, law, hbuf)
        fc = hbuf[index]
        a, b, fa, fb, side = _illinois(a, b, fa, fb, side, c, fc, not fc < 0.0)
        if b - a <= 1e-15 * max(1.0, b):
            break
    return b


@borrowed_njit
def _h_at(y, K, h, mode, law, index, theta, ybuf, hbuf):
    """Switching function ``index`` on the dense output at ``theta``."""
    _dense(y, K, h, theta, ybuf)
    _switching(mode, ybuf, law, hbuf)
    return hbuf[index]


@borrowed_njit
def _rate_root(y, K, h, s, d0, d1, ybuf):
    """``theta`` where ``s * dzeta`` on the dense output goes from ``d0 < 0`` to ``d1 > 0``:
    the interior minimum of the switching function ``s * zeta`` (Illinois)."""
    a, b, fa, fb = 0.0, 1.0, d0, d1
    side = 0
    for _ in range(60):
        c = _secant(a, b, fa, fb)
        _dense(y, K, h, c, ybuf)
        fc = s * (ybuf[1] - ybuf[3])
        a, b, fa, fb, side = _illinois(a, b, fa, fb, side, c, fc, fc < 0.0)
        if b - a <= 1e-12:
            break
    return 0.5 * (a + b)


@borrowed_njit
def _first_crossing(t, y, ynew, K, h, mode, law, i, hv, ybuf, hbuf):
    """``theta`` in ``[0, 1]`` of the first crossing of switching function ``i`` over the
    step (``0``: at once), or ``2`` if it stays on its side.

    ``hv = (h0, ha, hb, h1)`` are its values at ``theta = 0, 1/3, 2/3, 1``.  A crossing needs
    a value strictly on the function's side (``> 0``) before one across it (``< 0``):

    * the start does not count as on its side unless ``h0 > 0``: right after an event
      the state sits on the surface just crossed (and on any coinciding one) with a
      value that is zero only to within rounding, of either sign.  Such a function
      is never skipped (a state a hair across the surface, e.g. ``zeta = +1e-13``
      right after a contact loss, would otherwise hide a re-contact in the same step
      and then every later one: the mode would stay wrong for good); instead the
      point where the flow leaves the surface is searched for by halving towards
      the start; if there is none, the crossing is at once if the function moves
      further across (the first probe across is below ``h0``), and there is no event
      yet if it is coming back (a step cut to an event ends within its local error
      of the surface; at loose tolerances that can be well beyond rounding);
    * the contact surface ``zeta = 0`` in modes without a ``dzeta = 0`` surface
      (free, clipped) is also checked at the interior minimum of its function (where
      ``dzeta`` changes sign), so a graze that touches and leaves the surface between
      the probes is seen.
    """
    h0, ha, hb, h1 = hv
    third = 1.0 / 3.0
    pos_t, pos_f = -1.0, 0.0
    if h0 > 0.0:
        pos_t, pos_f = 0.0, h0
    neg_t, neg_f = -1.0, 0.0
    if ha < 0.0:
        neg_t, neg_f = third, ha
    else:
        if ha > 0.0:
            pos_t, pos_f = third, ha
        if hb < 0.0:
            neg_t, neg_f = 2.0 * third, hb
        else:
            if hb > 0.0:
                pos_t, pos_f = 2.0 * third, hb
            if h1 < 0.0:
                neg_t, neg_f = 1.0, h1
    if neg_t < 0.0 and i == 0 and (mode == FREE or mode == CLIPPED):
        s = -1.0 if mode == FREE else 1.0
        d0 = s * (y[1] - y[3])
        d1 = s * (ynew[1] - ynew[3])
        if d0 < 0.0 and d1 > 0.0:
            th = _rate_root(y, K, h, s, d0, d1, ybuf)
            fm = _h_at(y, K, h, mode, law, 0, th, ybuf, hbuf)
            if fm < 0.0:
                neg_t, neg_f = th, fm
                pos_t = -1.0
                if h0 > 0.0:
                    pos_t, pos_f = 0.0, h0
                if ha > 0.0 and third < th:
                    pos_t, pos_f = third, ha
                if hb > 0.0 and 2.0 * third < th:
                    pos_t, pos_f = 2.0 * third, hb
    if neg_t < 0.0:
        return 2.0
    if pos_t < 0.0:
        th, f_first = neg_t, neg_f
        while True:
            th *= 0.5
            if th * h <= 1e-15 * max(1.0, abs(t)):
                # across the surface from the start and nowhere on its side before the
                # probe: moving further across, it crosses now; coming back (a step cut
                # to an event ends within its error of the surface, not on it), not yet
                return 0.0 if f_first <= h0 else 2.0
            f = _h_at(y, K, h, mode, law, i, th, ybuf, hbuf)
            if f > 0.0:
                pos_t, pos_f = th, f
                break
            if f < 0.0:
                neg_t, neg_f = th, f
    return _locate(y, K, h, mode, law, i, pos_t, neg_t, pos_f, neg_f, ybuf, hbuf)


@borrowed_njit
def _record_event(t, y, mode, index, law, n_ev, events):
    """Store event ``n_ev`` (if there is room) in ``events`` ``(ev_t, ev_kind, ev_y,
    ev_modes)`` and return the mode after it."""
    ev_t, ev_kind, ev_y, ev_modes = events
    kind = _event_kind(mode, index)
    new_mode = _mode_after(kind, y, law)
    if n_ev < ev_t.shape[0]:
        ev_t[n_ev] = t
        ev_kind[n_ev] = kind
        ev_modes[n_ev, 0] = mode
        ev_modes[n_ev, 1] = new_mode
        for j in range(4):
            ev_y[n_ev, j] = y[j]
    return new_mode
