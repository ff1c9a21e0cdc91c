"""Compiled event-driven Dormand–Prince 5(4) integrator for the two-body system (the
method's stages, error norm, dense output and step control are shared with every system:
:mod:`discovery.numerics._dopri`).

The right-hand side is smooth inside each *contact mode*; the mode changes only
at located events, and no step straddles an event: a step in which a switching
function changes sign is re-taken with its length cut to the root (found on the
dense output), so every step integrates one smooth vector field.

Modes
    FREE     no force (``zeta <= 0``)
    LOAD     ``F = P(zeta, dzeta)``       (``zeta > 0``, ``dzeta > 0``)
    UNLOAD   ``F = P(zeta, 0)``           (``zeta > 0``, ``dzeta <= 0``)
    CLIPPED  ``F = 0`` with ``zeta > 0``  (``P`` would be adhesive, < 0)

Switching functions ``h`` are written so that an event fires when ``h`` goes from
``>= 0`` to ``< 0`` over a step (direction built in):

    FREE:    onset       h = -zeta
    LOAD:    loss        h = zeta,  unload  h = dzeta,   release h = P(zeta, dzeta)
    UNLOAD:  loss        h = zeta,  reload  h = -dzeta,  release h = P(zeta, 0)
    CLIPPED: loss        h = zeta,  resume  h = -P(zeta, max(dzeta, 0))

Inside a mode the force is extended smoothly past the switching surface (odd
extension of fractional powers) because Runge–Kutta stages may sample slightly
beyond it.

Detection (per accepted step, see :func:`_first_crossing`): each function is
sampled on the dense output at ``theta = 0, 1/3, 2/3, 1``; an event needs a value
``> 0`` before one ``< 0``.  Right after an event a function may start a hair on
the wrong side (the re-taken step ends within rounding of the surface, not on its
side): it is then neither skipped nor fired at once, but the point where the flow
leaves the surface is searched for, so a contact loss followed by a re-contact
inside the next step is seen (and a function that starts across but comes back is
not fired).  In the free and clipped modes the contact surface is also checked at
the interior extremum of ``zeta`` (a graze between samples).  Mode switches that
hardly advance time (zero-length ones, or over a thousand events in a row each
within ``1e-3 hmax`` of the last) stop the run as chattering.

Free flight: by default (``p[P_FLIGHT] = 1``, :attr:`Tolerances.free_flight` ``"closed"``)
the free mode is not stepped: the flight is advanced in closed form to the first root of
the exact penetration, bracketed by a proven bound (:func:`_flight`).  Supports with a cubic
term, ``k1 <= 0`` or ``c1 < 0``, and a start across the surface that is not closing take the
integrator's steps, as does every free flight with ``p[P_FLIGHT] = 0`` (the cross-check
path).

Contact: by default (``p[P_CONTACT] = 1``, :attr:`Tolerances.contact` ``"closed"``, only
with closed-form flights) a linear law's loading and unloading phases (``F = k z + c zd``,
nothing else acting during the contact) are not stepped either: each is advanced by its
modal solution to the first root of its switching functions, bracketed by a proven bound
(:func:`_contact`).  Other laws, the clipped mode, a mode whose eigenvectors are
ill-conditioned, a start across a switching surface, a law coefficient's sensitivities in
a mode with a zero eigenvalue (``k1 = 0``) and every contact with ``p[P_CONTACT] = 0`` take
the integrator's steps; the sensitivities follow the closed form too.

Compilation: numba inlines an ``inline="always"`` function in its own IR and types the
body again at every call site, so a chain of inlined functions costs compile time by the
product of their call sites.  Only the leaves called at every Runge-Kutta stage (the force
law, the right-hand side, the shared Dormand-Prince blocks) are inlined; the step, the
switching functions, the dense-output probe and the event record are compiled once each
and called (a call per step or per event, not per stage): a cold compile takes about 30 s
on two cores instead of 160 s with everything inlined, at the same run time (``bench/``).
Those calls pass their arrays borrowed: every function that allocates nothing is compiled
without numba's reference counting (:data:`_borrowed_njit`), :func:`_integrate` included:
its callers make the work arrays (:func:`work_arrays`, kept from run to run) and the
contact modes (:func:`set_up_modes`) and pass them in.  With the counts, their atomic
increments and decrements took about half of a period's time (sampled); without them the
arithmetic is the same, bit for bit.

The entries called from Python are :func:`_integrate`, :func:`strobe`, :func:`work_arrays`,
:func:`set_up_modes` and the small checks; none calls :func:`_integrate` with a constant
argument: LLVM then inlines the loop into the caller and optimises it again (:func:`strobe`
took 12 s of the cold compile that way, 2 s with its constants passed in).
"""

import numpy as np
from numba import njit

from ..._compile import borrowing_options
from ...numerics._dopri import MIN_FACTOR as _MIN_FACTOR
from ...numerics._dopri import C as _C
from ...numerics._dopri import blocks
from ...numerics._dopri import dense_weights as _dense_weights
from ...numerics._dopri import step_factor as _step_factor
from ...numerics._tableau import A as _A
from ...numerics._tableau import B as _B
from ...numerics._tableau import E as _E
from ...numerics.status import BLOW_UP, CHATTER, OK, STEP_BUDGET, STEP_UNDERFLOW

# Every function here that allocates nothing takes its arrays borrowed: compiled without
# numba's reference counting (``_nrt=False``, where this numba has the option:
# :func:`~discovery._compile.borrowing_options`), a call passes its arrays without an atomic
# increment and decrement of each one's count.  A function that allocates (the work arrays,
# a contact mode's set-up) keeps the counts; numba refuses to compile an allocation in a
# borrowing function.
_borrowed_njit = njit(cache=True, **borrowing_options())

# the shared Dormand-Prince blocks for this system's four states (w1, v1, w2, v2)
_D = blocks(4)
_stage, _combine, _dense, _error_norm = _D.stage, _D.combine, _D.dense, _D.error_norm

FREE, LOAD, UNLOAD, CLIPPED = 0, 1, 2, 3
EV_ONSET, EV_LOSS, EV_UNLOAD, EV_RELOAD, EV_RELEASE, EV_RESUME = 1, 2, 3, 4, 5, 6

# the parameter vector ``p``: the scenario's m1, m2, k1, c1, A, omega, g (0-6), the
# supports' cubic stiffness, the mass fraction shed per impact, the law's permanent-set
# fraction, one contact state: the current contact's largest penetration, and the choice of
# the free-flight path (``p[P_FLIGHT] = 1``: in closed form where it applies, 0: the
# integrator's steps throughout).  The kernel updates m2 and z_max in place (callers pass a
# copy: :func:`kernel_params`).  A law whose velocity terms are scaled by each impact's
# approach velocity (``p[P_VSCALE] = 1``: Lankarani-Nikravesh, Flores) divides their
# coefficients by ``p[P_V0]``, the current contact's penetration rate at its onset (a
# second contact state, set at every onset).  ``p[P_CONTACT] = 1`` advances the contact in
# closed form where it applies (0: the integrator's steps).
P_K3, P_LOSS, P_SET, P_ZMAX, P_FLIGHT, P_V0, P_VSCALE = 7, 8, 9, 10, 11, 12, 13
P_CONTACT, N_PARAMS = 14, 15

# chattering: more than _ZENO_EVENTS located events in a row, each within
# _ZENO_GAP * hmax of the previous one (mode switches that hardly advance time)
_ZENO_EVENTS, _ZENO_GAP = 1000, 1e-3


@_borrowed_njit
def _zeno_run(t, t_last_ev, hmax, short_run):
    """The count of events in a row each within ``_ZENO_GAP * hmax`` of the previous one,
    after an event at ``t`` (chattering beyond ``_ZENO_EVENTS``)."""
    return short_run + 1 if t - t_last_ev < _ZENO_GAP * hmax else 0


@njit(cache=True, inline="always")
def _pw(x, p):
    if p == 0.0:
        return 1.0
    if p == 1.0:
        return x
    if p == 2.0:
        return x * x
    if p == 3.0:
        return x * x * x
    if x >= 0.0:
        return x**p
    return -((-x) ** p)


@njit(cache=True, inline="always")
def _vscale(p):
    """The factor of the velocity terms' coefficients: ``1 / v0`` for a law scaled by each
    impact's approach velocity (``p[P_VSCALE] = 1``), else 1."""
    if p[P_VSCALE] == 0.0:
        return 1.0
    return 1.0 / max(p[P_V0], 1e-12)


@njit(cache=True, inline="always")
def poly(z, zd, p, coef, ea, eb, br):
    """Loading branch ``P(z, zd) = sum c_i z^a_i zd^b_i`` over the loading terms
    (``br_i = 0``; odd extension for negative arguments; velocity terms over ``v0`` for a
    law scaled by the impact velocity)."""
    s = 0.0
    f = _vscale(p)
    for i in range(coef.shape[0]):
        if br[i] == 0.0:
            c = coef[i] * f if eb[i] > 0.0 else coef[i]
            s += c * _pw(z, ea[i]) * _pw(zd, eb[i])
    return s


@njit(cache=True, inline="always")
def _elastic_set(z, p, coef, ea, eb, br):
    """``P(u, 0)`` at the unloading penetration ``u = (z - s z_max) / (1 - s)``."""
    rho = p[P_SET]
    u = (z - rho * p[P_ZMAX]) / (1.0 - rho)
    s = 0.0
    for i in range(coef.shape[0]):
        if br[i] == 0.0:
            s += coef[i] * _pw(u, ea[i]) * _pw(0.0, eb[i])
    return s


@njit(cache=True, inline="always")
def load_force(z, v, p, coef, ea, eb, br):
    """Loading branch: ``P(z, v)``; with a permanent set, a contact that reloads below its
    largest penetration so far follows its elastic unloading line ``P(u, 0)`` (plus the
    velocity terms) back up to ``z_max`` (Walton-Braun), continuous there."""
    if p[P_SET] == 0.0 or z >= p[P_ZMAX]:
        return poly(z, v, p, coef, ea, eb, br)
    return _reload_set(z, v, p, coef, ea, eb, br)


@_borrowed_njit
def _reload_set(z, v, p, coef, ea, eb, br):
    """The loading branch below ``z_max`` with a permanent set: a call, not inlined (the
    rare branch, typed once instead of at each of the step's seven stages)."""
    return (
        poly(z, v, p, coef, ea, eb, br)
        - poly(z, 0.0, p, coef, ea, eb, br)
        + _elastic_set(z, p, coef, ea, eb, br)
    )


@njit(cache=True, inline="always")
def unload_force(z, v, p, coef, ea, eb, br):
    """Unloading branch (``dzeta <= 0``): the elastic part ``P(u, 0)`` at the unloading
    penetration ``u = (z - s z_max) / (1 - s)`` (``s`` the permanent-set fraction, ``z_max``
    the contact's largest penetration: ``u = z`` without a set), plus the unloading terms
    (``br_i = 1``) ``c_i z^a_i dzeta^b_i`` at the signed velocity (odd extension: they
    lower the force while the bodies separate).  With neither it is the paper's
    ``P(z, 0)``, term for term."""
    rho = p[P_SET]
    u = z if rho == 0.0 else (z - rho * p[P_ZMAX]) / (1.0 - rho)
    s = 0.0
    f = _vscale(p)
    for i in range(coef.shape[0]):
        if br[i] == 0.0:
            s += coef[i] * _pw(u, ea[i]) * _pw(0.0, eb[i])
        else:
            s += coef[i] * f * _pw(z, ea[i]) * _pw(v, eb[i])
    return s


@njit(cache=True, inline="always")
def branch_force(z, v, p, coef, ea, eb, br):
    """The branch force at ``(z, v)``: loading for ``v > 0``, unloading otherwise (the
    clipped mode's resume function)."""
    if v > 0.0:
        return load_force(z, v, p, coef, ea, eb, br)
    return unload_force(z, v, p, coef, ea, eb, br)


@njit(cache=True, inline="always")
def mode_force(mode, z, v, p, coef, ea, eb, br):
    """Contact force [N] in a given mode at penetration ``z`` and its rate ``v``."""
    if mode == LOAD:
        return load_force(z, v, p, coef, ea, eb, br)
    if mode == UNLOAD:
        return unload_force(z, v, p, coef, ea, eb, br)
    return 0.0


@njit(cache=True, inline="always")
def _dpw(x, p):
    """Derivative of :func:`_pw` in ``x`` (``p |x|^(p-1)`` for the odd extension)."""
    if p == 0.0:
        return 0.0
    if p == 1.0:
        return 1.0
    if p == 2.0:
        return 2.0 * x
    if p == 3.0:
        return 3.0 * x * x
    if x == 0.0:
        return 0.0 if p > 1.0 else np.inf
    return p * abs(x) ** (p - 1.0)


@_borrowed_njit
def force_partials(mode, z, v, coef, ea, eb, br, dc):
    """``(dF/dz, dF/dv)`` of the mode's force at ``(z, v)``, and ``dc[i] = dF/dc_i`` (a law
    without a permanent set: the sensitivities are not carried for one)."""
    return _partials(mode, z, v, coef, ea, eb, br, dc)


@njit(cache=True, inline="always")
def _partials(mode, z, v, coef, ea, eb, br, dc):
    """:func:`force_partials` inlined: in the sensitivities' right-hand side, at every stage
    of every step (as a call there, a sensitivity run took a fifth longer)."""
    fz = 0.0
    fv = 0.0
    for i in range(coef.shape[0]):
        dc[i] = 0.0
        if mode == LOAD and br[i] == 0.0:
            pz, pv = _pw(z, ea[i]), _pw(v, eb[i])
            dc[i] = pz * pv
            fz += coef[i] * _dpw(z, ea[i]) * pv
            fv += coef[i] * pz * _dpw(v, eb[i])
        elif mode == UNLOAD:
            vv = 0.0 if br[i] == 0.0 else v
            pz, pv = _pw(z, ea[i]), _pw(vv, eb[i])
            dc[i] = pz * pv
            fz += coef[i] * _dpw(z, ea[i]) * pv
            if br[i] != 0.0:
                fv += coef[i] * pz * _dpw(v, eb[i])
    return fz, fv


@_borrowed_njit
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


@njit(cache=True, inline="always")
def _rhs(t, y, mode, p, coef, ea, eb, br, out):
    z = y[0] - y[2]
    v = y[1] - y[3]
    f = mode_force(mode, z, v, p, coef, ea, eb, br)
    out[0] = y[1]
    out[1] = (
        -(
            p[3] * y[1]
            + p[2] * y[0]
            + p[P_K3] * y[0] * y[0] * y[0]
            + p[4] * np.sin(p[5] * t)
            + p[0] * p[6]
            + f
        )
        / p[0]
    )
    out[2] = y[3]
    out[3] = f / p[1] - p[6]


@_borrowed_njit
def _rhs_at(t, y, mode, law, out):
    """:func:`_rhs` as a call (for the once-per-event saltation: inlined there it would be
    typed again at each site, which costs compile time, not run time)."""
    p, coef, ea, eb, br = law
    _rhs(t, y, mode, p, coef, ea, eb, br, out)


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
def _rk_step(t, y, h, mode, law, K, ytmp, ynew):
    """One DP5 step from (t, y) with K[0] = f(t, y) already set; fills K[1:7], ynew
    (the method's stages from :mod:`._dopri`, this system's right-hand side)."""
    p, coef, ea, eb, br = law
    for s in range(1, 6):
        _stage(s, y, h, K, ytmp)
        _rhs(t + _C[s] * h, ytmp, mode, p, coef, ea, eb, br, K[s])
    _combine(y, h, K, ynew)
    _rhs(t + h, ynew, mode, p, coef, ea, eb, br, K[6])


# ---- sensitivities: ``S`` (4, m), column j the derivative of the state along a direction
# of the start (``spar[j] < 0``) or of the law's coefficient ``spar[j]``.  They follow the
# discrete Runge-Kutta map of each accepted step (the step's own stages, so at the end of a
# step they are the exact derivative of its result at fixed step length), and jump by the
# saltation matrix at every located event.


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


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
def _event_time_sens(t, y, mode, index, law, S, spar, sw):
    """Before an event: the vector field ``fminus`` of the mode left, and ``tau[j]``, the
    derivative of the event time along column ``j``: ``-(grad h . S_j + dh/dq_j) /
    (grad h . f-)`` for the switching function ``index`` that fired."""
    _, coef, ea, eb, br = law
    dc, fminus, tau = sw[3], sw[4], sw[6]
    _rhs_at(t, y, mode, law, fminus)
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


@_borrowed_njit
def _saltation(t, y, mode, law, S, sw, n_ev, ev_tau):
    """After an event into ``mode``: ``S_j += (f- - f+) tau_j``, and the event's time
    derivatives kept in ``ev_tau`` (if there is room)."""
    fminus, fplus, tau = sw[4], sw[5], sw[6]
    _rhs_at(t, y, mode, law, fplus)
    for j in range(S.shape[1]):
        for r in range(4):
            S[r, j] += (fminus[r] - fplus[r]) * tau[j]
        if n_ev < ev_tau.shape[0]:
            ev_tau[n_ev, j] = tau[j]


@_borrowed_njit
def _locate(y, K, h, mode, law, index, th_lo, th_hi, h_lo, h_hi, ybuf, hbuf):
    """Root in ``theta`` of switching function ``index`` on the dense output (Illinois)."""
    a, b, fa, fb = th_lo, th_hi, h_lo, h_hi
    side = 0
    for _ in range(100):
        c = (a * fb - b * fa) / (fb - fa)
        if not (a < c < b):
            c = 0.5 * (a + b)
        _dense(y, K, h, c, ybuf)
        _switching(mode, ybuf, law, hbuf)
        fc = hbuf[index]
        if fc < 0.0:
            b, fb = c, fc
            if side == -1:
                fa *= 0.5
            side = -1
        else:
            a, fa = c, fc
            if side == 1:
                fb *= 0.5
            side = 1
        if b - a <= 1e-15 * max(1.0, b):
            break
    return b


@_borrowed_njit
def _h_at(y, K, h, mode, law, index, theta, ybuf, hbuf):
    """Switching function ``index`` on the dense output at ``theta``."""
    _dense(y, K, h, theta, ybuf)
    _switching(mode, ybuf, law, hbuf)
    return hbuf[index]


@_borrowed_njit
def _rate_root(y, K, h, s, d0, d1, ybuf):
    """``theta`` where ``s * dzeta`` on the dense output goes from ``d0 < 0`` to ``d1 > 0``:
    the interior minimum of the switching function ``s * zeta`` (Illinois)."""
    a, b, fa, fb = 0.0, 1.0, d0, d1
    side = 0
    for _ in range(60):
        c = (a * fb - b * fa) / (fb - fa)
        if not (a < c < b):
            c = 0.5 * (a + b)
        _dense(y, K, h, c, ybuf)
        fc = s * (ybuf[1] - ybuf[3])
        if fc < 0.0:
            a, fa = c, fc
            if side == -1:
                fb *= 0.5
            side = -1
        else:
            b, fb = c, fc
            if side == 1:
                fa *= 0.5
            side = 1
        if b - a <= 1e-12:
            break
    return 0.5 * (a + b)


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
def _take_event(t, y, mode, index, law, n_ev, events, sens, sw):
    """Event ``n_ev`` of switching function ``index`` at ``(t, y)``: with sensitivities its
    time derivatives (:func:`_event_time_sens`), its record (:func:`_record_event`) and the
    saltation into the mode after it (:func:`_saltation`); returns that mode."""
    S, spar, ev_tau = sens[0], sens[1], sens[4]
    m_s = S.shape[1]
    if m_s:
        _event_time_sens(t, y, mode, index, law, S, spar, sw)
    mode = _record_event(t, y, mode, index, law, n_ev, events)
    if m_s:
        _saltation(t, y, mode, law, S, sw, n_ev, ev_tau)
    return mode


# ---- free flight in closed form.  Between contacts (mode FREE, no force) the two bodies
# obey linear equations: the moulding falls freely, ``w2 = w2a + v2a s - g s^2 / 2``, and
# the frame (supports without a cubic term) is a damped oscillator driven by ``A sin(w t)``:
# ``x(t) = x_p(t) + Phi(s) (x_a - x_p(t_a))`` with ``x = (w1, v1)``, ``x_p = (w_p, w_p')``,
# ``w_p = w_s + P sin(w t) + Q cos(w t)`` its periodic particular solution (``w_s = -m1 g /
# k1``) and ``Phi(s) = exp(M s)`` its transition matrix, ``M = [[0, 1], [-k1/m1, -c1/m1]]``.
# The flight is advanced exactly to the next contact onset, the first root of the
# penetration ``z = w1 - w2`` (from below), or to the end of the run.
#
# The root is bracketed safely: over ``[a, a + H]`` the penetration is bounded above by
# ``z(a) + z'(a) tau + B tau^2 / 2`` with ``B`` an upper bound of ``z'' = w1'' + g`` for all
# later times: ``g + w^2 |(P, Q)| + (w0 + 2 alpha) sqrt(E(a))`` with ``E = w0^2 u^2 + u'^2``
# the energy of the homogeneous part ``u = w1 - w_p`` (``w0^2 = k1/m1``, ``alpha = c1 /
# 2 m1``), which never grows (``E' = -4 alpha u'^2``), and ``|u''| <= w0^2 |u| + 2 alpha
# |u'| <= (w0 + 2 alpha) sqrt(E)``.  ``H`` is the bound's positive root, so ``[a, a + H)``
# holds no root; the next interval starts at its end.  Far from the surface the intervals
# are long; approaching a crossing they shrink quadratically onto it from below (Newton's
# rate with the curvature bound), and a tangency (a graze) is passed in a bounded number
# of intervals.  The first point found across is polished to the time's resolution.
#
# The free flight's sensitivities are its transition matrix: ``S <- blockdiag(Phi(s),
# [[1, s], [0, 1]]) S`` (the law does not act; the coefficient columns move with the
# state's); the onset's saltation is applied as after an integrated step.

_FLIGHT_ITERS = 4000  # intervals per flight before the integrator takes over (a safeguard)
_NF = 16  # the flight's constants, :func:`_flight_setup`
_SAMPLE_SLIP = 1e-12  # evenly spaced samples: on their grid within this many drive periods
_SAMPLE_ANCHOR = 256  # samples advanced by the semigroup between two evaluated in closed form


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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
        c = s - zs / ds if ds > 0.0 else 0.5 * (lo + hi)
        if not (lo < c < hi):
            c = 0.5 * (lo + hi)
        if abs(c - s) <= res:
            # Newton has converged from one side: probe just across to close the bracket
            c = s - res if zs > 0.0 else s + res
            if not (lo < c < hi):
                c = 0.5 * (lo + hi)
        _flight_state(c, fl, ybuf)
        zc, dc = ybuf[0] - ybuf[2], ybuf[1] - ybuf[3]
        if zc > 0.0:
            hi = c
        else:
            lo = c
        s, zs, ds = c, zc, dc
    return hi


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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


# ---- the contact in closed form.  With a linear law (loading ``F = k z + c zd``, unloading
# ``F = k' z + c' zd``: terms ``z`` and ``zd`` only) and nothing else acting during the
# contact (no cubic support, mass loss, permanent set or impact-scaled terms), the loading and
# the unloading modes are linear systems ``y' = M y + b_c + b_s sin(w t)`` (``b_c`` gravity,
# ``b_s`` the drive on the frame).  With ``M = V diag(lambda) V^-1`` the modal coordinates
# ``q = V^-1 y`` decouple: ``q_j' = lambda_j q_j + beta_cj + beta_sj sin(w t)``, and ``q_j =
# u_j + q_sj(t)`` with the periodic part ``q_sj = (A_j e^(iwt) - A'_j e^(-iwt)) / 2i`` (``A_j =
# beta_sj / (iw - lambda_j)``, ``A'_j = beta_sj / (-iw - lambda_j)``) and ``u_j(s) =
# e^(lambda_j s) u_j(0) + beta_cj s phi1(lambda_j s)`` (``phi1(x) = (e^x - 1) / x``: a zero
# eigenvalue, a frame with ``k1 = 0``, needs no special case).  The decomposition is made once
# per run and mode (:func:`_contact_eig`: the eigenvalues are the roots of the two-mass
# system's quartic ``det(lambda^2 Mass + lambda C + K)``, whose coefficients have no
# cancellation, the eigenvectors its 2x2 null vectors; no LAPACK call, a few microseconds),
# and checked in the state scaled by the absolute tolerances; a mode whose eigenpairs miss
# their residual, whose scaled eigenvectors are ill-conditioned (condition above
# ``_CONTACT_COND``: near a defective, critically damped pair, or a free frame ``k1 = c1 =
# 0``) or with an eigenvalue within ``1e-9 w`` of the drive's ``+-iw`` (an undamped
# resonance) is integrated instead.
#
# Every switching function of the two modes is linear in the state, ``h = gz z + gv zd``
# (loss ``z``, unload ``zd`` or reload ``-zd``, release ``F``), and its first root is proven
# as the flight's onset: over ``[a, a + H]``, ``|h''| <= K = sum_j |G_j| (|lambda_j| |d_j|
# max(e^(Re lambda_j a), e^(Re lambda_j (a + H))) + w^2 (|A_j| + |A'_j|) / 2)`` with ``G_j =
# g . v_j`` and ``d_j = u_j'(0)`` (``u_j'' = lambda_j e^(lambda_j s) d_j``, ``q_sj'' = -w^2
# q_sj``), so ``h >= h(a) + h'(a) tau - K tau^2 / 2`` there and no interval is passed unless
# that stays positive over it for every function.  A mode with a growing eigenvalue (``Re
# lambda > 0``, a law with negative coefficients) caps the intervals at ``1 / Re lambda``.
# The first root is polished by safeguarded Newton on the closed form; the event is recorded at
# the last point of the phase (every switching function still >= 0) within the time's
# resolution of it.
#
# Sensitivities move by the transition matrix, ``S <- Re(V diag(e^(lambda s)) V^-1) S``, and
# a law coefficient's column gains the response to its force term (``z`` or ``zd``, the
# derivative of the mode's force in it), integrated in modal form (:func:`_contact_forced`);
# they jump by the saltation matrix at the events as after an integrated step.  The
# coefficients' columns need the mode's eigenvalues away from 0 (a frame without a spring
# has a zero one: its contacts are then integrated in a run that carries them).

_CONTACT_COND = 1e5  # the largest condition number of a mode's scaled eigenvectors
_NE = 12  # a mode's complex constants per eigenvalue, :func:`_contact_setup`
_NR = 6  # a mode's real constants, :func:`_contact_setup`


@_borrowed_njit
def _contact_law(law, kc):
    """Whether the contact has the closed form: requested (``p[P_CONTACT] = 1``), a linear
    law and nothing else acting during the contact (see above); fills ``kc`` with the
    loading force's ``(k, c)``, then the unloading force's."""
    p, coef, ea, eb, br = law
    if p[P_CONTACT] == 0.0 or p[P_K3] != 0.0 or p[P_LOSS] != 0.0:
        return False
    if p[P_SET] != 0.0 or p[P_VSCALE] != 0.0:
        return False
    if not (p[0] > 0.0 and p[1] > 0.0 and p[5] > 0.0):
        return False
    for j in range(4):
        kc[j] = 0.0
    for i in range(coef.shape[0]):
        if ea[i] == 1.0 and eb[i] == 0.0:
            if br[i] == 0.0:
                kc[0] += coef[i]  # the elastic part acts in both branches
            kc[2] += coef[i]
        elif ea[i] == 0.0 and eb[i] == 1.0:
            kc[1 if br[i] == 0.0 else 3] += coef[i]
        else:
            return False
    for j in range(4):
        if not np.isfinite(kc[j]):
            return False
    return True


@njit(cache=True, inline="always")
def _contact_g(mode, kc, i):
    """Switching function ``i`` of a contact mode as ``(gz, gv)``: ``h = gz z + gv zd``
    (loss, unload or reload, release: as :func:`_switching`)."""
    if i == 0:
        return 1.0, 0.0
    if i == 1:
        return 0.0, (1.0 if mode == LOAD else -1.0)
    if mode == LOAD:
        return kc[0], kc[1]
    return kc[2], kc[3]


@njit(cache=True)
def _cinv4(A, out):
    """``out = A^-1`` of a complex 4x4 by Gauss-Jordan with partial pivoting; False if a
    pivot vanishes (singular to working precision)."""
    W = A.copy()
    for r in range(4):
        for c in range(4):
            out[r, c] = 1.0 if r == c else 0.0
    for c in range(4):
        piv, big = c, abs(W[c, c])
        for r in range(c + 1, 4):
            if abs(W[r, c]) > big:
                piv, big = r, abs(W[r, c])
        if not big > 1e-300:
            return False
        for k in range(4):
            W[c, k], W[piv, k] = W[piv, k], W[c, k]
            out[c, k], out[piv, k] = out[piv, k], out[c, k]
        d = W[c, c]
        for k in range(4):
            W[c, k] /= d
            out[c, k] /= d
        for r in range(4):
            if r != c:
                m = W[r, c]
                for k in range(4):
                    W[r, k] -= m * W[c, k]
                    out[r, k] -= m * out[c, k]
    return True


@njit(cache=True)
def _contact_matrix(p, k, c, dsc, Ms):
    """``Ms = D^-1 M D``: the contact mode's system matrix (force ``k z + c zd``) in the state
    scaled by ``D = diag(dsc)``; False if not finite."""
    m1, m2, k1, c1 = p[0], p[1], p[2], p[3]
    M = np.zeros((4, 4))
    M[0, 1] = 1.0
    M[1, 0], M[1, 1], M[1, 2], M[1, 3] = -(k1 + k) / m1, -(c1 + c) / m1, k / m1, c / m1
    M[2, 3] = 1.0
    M[3, 0], M[3, 1], M[3, 2], M[3, 3] = k / m2, c / m2, -k / m2, -c / m2
    for r in range(4):
        for q in range(4):
            if not np.isfinite(M[r, q]):
                return False
            Ms[r, q] = M[r, q] * dsc[q] / dsc[r]
    return True


@njit(cache=True)
def _quartic_roots(a3, a2, a1, a0, z):
    """The roots of ``x^4 + a3 x^3 + a2 x^2 + a1 x + a0`` into ``z`` (complex, 4): the
    Aberth-Ehrlich iteration on the polynomial scaled to roots of order 1 at most (the caller
    checks the eigenpairs they give)."""
    r = max(abs(a3), np.sqrt(abs(a2)), abs(a1) ** (1.0 / 3.0), np.sqrt(np.sqrt(abs(a0))))
    if not r > 0.0:
        for k in range(4):
            z[k] = 0.0
        return
    b3, b2, b1, b0 = a3 / r, a2 / r**2, a1 / r**3, a0 / r**4
    # the starts: the roots' sizes as the coefficients' ratios suggest (exact for widely
    # separated roots), at spread angles
    z[0] = abs(b3)
    z[1] = abs(b2 / b3) if b3 != 0.0 else 1.0
    z[2] = abs(b1 / b2) if b2 != 0.0 else 1.0
    z[3] = abs(b0 / b1) if b1 != 0.0 else 1e-3
    for k in range(4):
        rad = min(max(z[k].real, 1e-8), 2.0)
        z[k] = rad * np.exp(1j * (0.4 + 1.6 * k))
    last = np.inf
    for _ in range(100):
        big = 0.0
        for k in range(4):
            x = z[k]
            f = (((x + b3) * x + b2) * x + b1) * x + b0
            df = ((4.0 * x + 3.0 * b3) * x + 2.0 * b2) * x + b1
            if f == 0.0:
                continue
            s = 0j
            for j in range(4):
                if j != k:
                    s += 1.0 / (x - z[j])
            ratio = f / df if df != 0.0 else f
            step = ratio / (1.0 - ratio * s)
            z[k] = x - step
            big = max(big, abs(step) / max(abs(z[k]), 1e-12))
        # converged: the steps at rounding level, or no longer shrinking once small
        if big < 4e-16 or (big < 1e-9 and big >= 0.5 * last):
            break
        last = big
    for k in range(4):
        z[k] *= r


@njit(cache=True)
def _contact_eig(p, k, c, lam, V):
    """The eigenvalues ``lam`` and eigenvectors ``V`` (columns, in the state's order) of a
    contact mode's system (force ``k z + c zd``): the roots of ``det(lambda^2 Mass + lambda C +
    K)``, whose coefficients are sums of non-negative terms for non-negative parameters
    (``k1 k / (m1 m2)``, ...: no cancellation), and each root's null vector ``x`` of that
    2x2 matrix, ``v = (x1, lambda x1, x2, lambda x2)``."""
    m1, m2, k1, c1 = p[0], p[1], p[2], p[3]
    a3 = (c1 + c) / m1 + c / m2
    a2 = (k1 + k) / m1 + k / m2 + c1 * c / (m1 * m2)
    a1 = (c1 * k + c * k1) / (m1 * m2)
    a0 = k1 * k / (m1 * m2)
    _quartic_roots(a3, a2, a1, a0, lam)
    for j in range(4):
        la = lam[j]
        q11 = la * la + la * (c1 + c) / m1 + (k1 + k) / m1
        q12 = -(la * c + k) / m1
        q21 = -(la * c + k) / m2
        q22 = la * la + la * c / m2 + k / m2
        if abs(q11) + abs(q12) >= abs(q21) + abs(q22):
            x1, x2 = -q12, q11
        else:
            x1, x2 = q22, -q21
        V[0, j], V[1, j], V[2, j], V[3, j] = x1, la * x1, x2, la * x2


@njit(cache=True)
def _contact_eig_scaled(p, k, c, dsc, Ms, lam, Vs):
    """The eigen-decomposition of ``Ms`` (:func:`_contact_matrix`) by :func:`_contact_eig`,
    its eigenvectors scaled by ``D^-1`` and normalised; False if a pair misses ``Ms v = lambda
    v`` by more than 1e-12 of ``|Ms|``."""
    _contact_eig(p, k, c, lam, Vs)
    nm = 0.0
    for r in range(4):
        for q in range(4):
            nm += abs(Ms[r, q]) ** 2
    nm = np.sqrt(nm)
    for j in range(4):
        n = 0.0
        for r in range(4):
            Vs[r, j] /= dsc[r]
            n += abs(Vs[r, j]) ** 2
        n = np.sqrt(n)
        if not n > 0.0:
            return False
        for r in range(4):
            Vs[r, j] /= n
        res = 0.0
        for r in range(4):
            acc = -lam[j] * Vs[r, j]
            for q in range(4):
                acc += Ms[r, q] * Vs[q, j]
            res += abs(acc) ** 2
        if not np.sqrt(res) <= 1e-12 * nm:
            return False
    return True


@njit(cache=True)
def _contact_setup(p, kc, mode, dsc, E, R):
    """The closed form's constants of a contact mode (``mi = 0`` loading, 1 unloading): for
    each eigenvalue ``j``, ``E[mi, j]`` holds its eigenvector ``v_j`` (4), the row ``j`` of
    ``V^-1`` (4), ``lambda_j``, ``beta_cj``, ``A_j``, ``A'_j``; ``R[mi]`` holds 1 where the
    mode has the closed form (else 0 and nothing else), the periodic parts' curvature bound
    of its three switching functions, the largest ``Re lambda`` and the smallest
    ``|lambda|``."""
    mi = 0 if mode == LOAD else 1
    R[mi, 0] = 0.0
    w, g = p[5], p[6]
    Ms = np.empty((4, 4), dtype=np.complex128)
    if not _contact_matrix(p, kc[2 * mi], kc[2 * mi + 1], dsc, Ms):
        return
    lam = np.empty(4, dtype=np.complex128)
    Vs = np.empty((4, 4), dtype=np.complex128)
    if not _contact_eig_scaled(p, kc[2 * mi], kc[2 * mi + 1], dsc, Ms, lam, Vs):
        return
    Vis = np.empty((4, 4), dtype=np.complex128)
    if not _cinv4(Vs, Vis):
        return
    n1, n2 = 0.0, 0.0
    for r in range(4):
        for q in range(4):
            n1 += abs(Vs[r, q]) ** 2
            n2 += abs(Vis[r, q]) ** 2
    if not np.sqrt(n1 * n2) <= _CONTACT_COND:
        return
    grow = -np.inf
    for j in range(4):
        la = lam[j]
        dp, dm = 1j * w - la, -1j * w - la
        if not (abs(dp) > 1e-9 * w and abs(dm) > 1e-9 * w):
            return
        for r in range(4):
            E[mi, j, r] = Vs[r, j] * dsc[r]
            E[mi, j, 4 + r] = Vis[j, r] / dsc[r]
        beta_s = -E[mi, j, 5] * p[4] / p[0]  # the drive -A sin(w t) / m1 on v1
        E[mi, j, 8] = la
        E[mi, j, 9] = -g * (E[mi, j, 5] + E[mi, j, 7])  # gravity on v1 and v2
        E[mi, j, 10] = beta_s / dp
        E[mi, j, 11] = beta_s / dm
        grow = max(grow, la.real)
    for i in range(3):
        gz, gv = _contact_g(mode, kc, i)
        kf = 0.0
        for j in range(4):
            G = gz * (E[mi, j, 0] - E[mi, j, 2]) + gv * (E[mi, j, 1] - E[mi, j, 3])
            kf += abs(G) * (abs(E[mi, j, 10]) + abs(E[mi, j, 11]))
        R[mi, 1 + i] = 0.5 * w * w * kf
    R[mi, 4] = grow
    R[mi, 5] = min(abs(lam[0]), abs(lam[1]), abs(lam[2]), abs(lam[3]))
    R[mi, 0] = 1.0


@njit(cache=True, inline="always")
def _phi1(x, ex):
    """``(e^x - 1) / x`` (1 at 0) for a complex ``x`` with ``ex = e^x``, without cancellation
    near 0."""
    if x.real * x.real + x.imag * x.imag < 1e-4:  # |x| < 1e-2 without a hypot
        return 1.0 + x * (1.0 + x * (1.0 + x * (1.0 + x * (1.0 + x / 6.0) / 5.0) / 4.0) / 3.0) / 2.0
    return (ex - 1.0) / x


@_borrowed_njit
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


@_borrowed_njit
def _contact_state(s, t0, w, mi, E, qm, out, ex):
    """The state ``s`` after the phase's start (at ``t0``) into ``out`` (``ex``: a work
    array of 4 complex numbers, left holding ``e^(lambda_j s)``)."""
    tt = t0 + s
    _contact_exps(s, w, mi, E, ex)
    _contact_state_at(s, np.cos(w * tt) + 1j * np.sin(w * tt), ex, mi, E, qm, out)


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
def _eint(lj, mu, ej, emu, s):
    """``int_0^s e^(lambda (s - u)) e^(mu u) du`` from ``ej = e^(lambda s)``, ``emu = e^(mu
    s)`` (``s e^(lambda s) phi1((mu - lambda) s)`` near ``mu = lambda``)."""
    d = mu - lj
    x = d * s
    if x.real * x.real + x.imag * x.imag < 1e-4:  # |x| < 1e-2 without a hypot
        return s * ej * _phi1(x, 0j)
    return (emu - ej) / d


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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


@_borrowed_njit
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
        c = s - hs / hds if hds < 0.0 else 0.5 * (lo + hi)
        if not (lo < c < hi):
            c = 0.5 * (lo + hi)
        if abs(c - s) <= res:
            # Newton has converged from one side: probe just across to close the bracket
            c = s - res if hs < 0.0 else s + res
            if not (lo < c < hi):
                c = 0.5 * (lo + hi)
        _contact_state(c, t0, w, mi, E, qm, ybuf, ex)
        hc, hdc = _contact_h(i, mode, kc, t0 + c, ybuf, p)
        if hc < 0.0:
            hi = c
        else:
            lo = c
        s, hs, hds = c, hc, hdc
    return lo


@_borrowed_njit
def _contact_growth(mi, a, hcap, E, cb):
    """The largest ``|e^(lambda_j s)|`` over ``[a, a + hcap]`` of each eigenvalue into
    ``cb[3]`` (at ``a`` for a decaying one, whose end value is the smaller), shared by the
    three switching functions' curvature bounds."""
    for j in range(4):
        re = E[mi, j, 8].real
        e = np.exp(re * a)
        cb[3, j] = e if re <= 0.0 else max(e, np.exp(re * (a + hcap)))


@_borrowed_njit
def _contact_bound(i, mi, R, cb):
    """The curvature bound ``K`` of switching function ``i`` over the interval whose
    exponentials' bounds :func:`_contact_growth` left in ``cb[3]``."""
    K = R[mi, 1 + i]
    for j in range(4):
        K += cb[i, j] * cb[3, j]
    return K


@_borrowed_njit
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


@_borrowed_njit
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
    out_dF, ev_tau)``).  ``phases``: the closed-form phases' arrays, :func:`_integrate`'s.  A
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


@_borrowed_njit
def _contact_exps(s, w, mi, E, ex):
    """``ex[j] = e^(lambda_j s)`` of the contact mode ``mi``."""
    for j in range(4):
        ex[j] = np.exp(E[mi, j, 8] * s)


@_borrowed_njit
def _contact_samples(t_new, phase, mode, force, p, sens, sw, ybuf, samples, k_eval):
    """The dense output of the contact phase ``(t, mi, E, qm)`` (started at ``t``, its modal
    data ``qm``, its force ``force = (k, c)``: ``k z + c zd``) at the samples
    ``t_eval[k_eval:]`` up to ``t_new`` (``samples``: ``(t_eval, out_y, out_f, out_mode)``):
    the state, the force, the mode and (with ``out_dF`` of ``sens``) the force's and the
    penetration's derivatives; returns the next sample's index.  Evenly spaced samples
    advance the exponentials by their semigroup (``e^(lambda (s + h)) = e^(lambda s)
    e^(lambda h)``, the drive's phase rotated by ``w h``) between anchors evaluated
    directly, as the free flight's samples
    (:func:`_flight_samples`)."""
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


@njit(cache=True)
def work_arrays(m_s, n_coef):
    """The work arrays of :func:`_integrate`: ``(steps, sens, phases)``, those of the
    steps, of ``m_s`` sensitivities (a law of ``n_coef`` coefficients) and of the
    closed-form phases, less the contact modes (``phases`` here is ``(fl, qm, sw, cb, fc,
    fcd)``; :func:`_integrate` takes ``(fl, kc, E, R, qm, sw, cb, fc, fcd)``).  Scratch
    space: a run reads nothing in them that it did not write, so its callers keep them
    for the next run (:func:`~discovery.vibroimpact.dynamics.simulation.scratch`)."""
    steps = (
        np.empty(4),
        np.empty(4),
        np.empty(4),
        np.empty((7, 4)),
        np.empty(3),
        np.empty(3),
        np.empty(3),
        np.empty(3),
        np.empty(3),
    )
    sens = (
        np.empty((7, 4, m_s)),
        np.empty((4, m_s)),
        np.empty((4, m_s)),
        np.empty(n_coef),
        np.empty(4),
        np.empty(4),
        np.empty(m_s),
    )
    phases = (
        np.empty(_NF),
        np.empty((4, 2), dtype=np.complex128),
        # the closed-form sensitivities' work arrays (:func:`_contact_sens`)
        (
            np.empty((2, m_s)),
            np.empty((4, 4)),
            np.empty((2, 4)),
            np.empty(4, dtype=np.complex128),
            np.empty(4, dtype=np.complex128),
        ),
        np.empty((4, 4)),
        np.empty(3),
        np.empty(3),
    )
    return steps, sens, phases


@_borrowed_njit
def sorted_within(t, lo, hi):
    """Whether ``t`` is sorted (non-decreasing) and within ``[lo, hi]`` (false for a
    NaN)."""
    prev = lo
    for k in range(t.shape[0]):
        if not t[k] >= prev:
            return False
        prev = t[k]
    return prev <= hi


@njit(cache=True)
def set_up_modes(law, atol, modes):
    """Whether a contact mode has the closed form (:func:`_contact`; not with
    sensitivities), setting the ``modes`` ``(kc, E, R, made)``
    (:func:`~discovery.vibroimpact.dynamics.simulation.contact_modes`) up when ``made[0]``
    is 0 (then 1 where a mode has the closed form, 2 where none has): a caller that
    integrates the same law and scenario again passes them back, and the set-up (the
    eigendecomposition of both modes, 4.6 us) is made once.  ``law``: ``(p, coef, ea, eb,
    br)``, as :func:`_integrate` takes it."""
    p = law[0]
    kc, E, R, made = modes
    if made[0] == 0.0:
        use_contact = _contact_law(law, kc)
        if use_contact:
            _contact_setup(p, kc, LOAD, atol, E, R)
            _contact_setup(p, kc, UNLOAD, atol, E, R)
            use_contact = R[0, 0] != 0.0 or R[1, 0] != 0.0
        made[0] = 1.0 if use_contact else 2.0
    return made[0] == 1.0


@_borrowed_njit
def in_range(y, bound):
    """Whether every ``|y[j]| < bound`` (false for a NaN)."""
    for j in range(y.shape[0]):
        if not abs(y[j]) < bound:
            return False
    return True


@_borrowed_njit
def strobe(points, y, p_base, memory, bound, clock, law, ctl, out, use_contact, work):
    """Strobe points: ``points[k] = Phi(points[k - 1])`` for ``k >= 1`` (``points[0]`` the
    start), each period one run of :func:`_integrate` from ``t0`` (mode ``mode0``, ``clock =
    (t0, mode0, period)``; ``law``'s ``p`` a fresh copy of ``p_base``) exactly as a separate
    call, so the points are bitwise those of one call per period; ``ctl``, ``out``,
    ``use_contact`` and ``work`` as :func:`_integrate` takes them.  With ``memory`` (a law
    with a permanent set) each run starts with the contact memory (``p[P_ZMAX]``,
    ``p[P_V0]``) the previous one ended with, the first with ``p``'s.  ``y`` is the run's
    state (work array).  Returns ``(status, k, t, n_steps, inside)``: the last period run
    (``k``, its status and end time ``t``), the steps of all runs, and whether its end state
    is within ``bound`` (:func:`in_range`)."""
    t0, mode0, period = clock
    p = law[0]
    n_steps = 0
    status = OK
    t = 0.0
    inside = True
    k = 0
    while k < points.shape[0] - 1:
        k += 1
        zmax, v0 = p[P_ZMAX], p[P_V0]
        for j in range(p.shape[0]):
            p[j] = p_base[j]
        if memory:
            p[P_ZMAX], p[P_V0] = zmax, v0
        for j in range(4):
            y[j] = points[k - 1, j]
        status, t, _, ns, _, _ = _integrate(
            t0, t0 + period, y, mode0, law, ctl, out, use_contact, work
        )
        n_steps += ns
        for j in range(4):
            points[k, j] = y[j]
        inside = in_range(y, bound)
        if status != OK or not inside:
            break
    return status, k, t, n_steps, inside


@_borrowed_njit
def _integrate(t0, t1, y, mode0, law, ctl, out, use_contact, work):
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
    (:func:`set_up_modes`); ``work`` ``(steps, sens, phases)``: the work arrays
    (:func:`work_arrays`), ``phases`` those of the phases with the contact modes, ``(fl, kc,
    E, R, qm, sw, cb, fc, fcd)``.  Every array is borrowed."""
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
    # free flight in closed form where it applies (:func:`_flight`); ``hold``: the
    # integrator's steps until one is accepted (a start across the surface, not closing)
    use_flight = _flight_ok(p)
    hold = False
    while t < t1:
        if n_steps >= max_steps:
            status = STEP_BUDGET
            break
        if use_flight and mode == FREE and not hold:
            code, t_new, k_eval = _flight(
                t, t1, y, p, atol[0], fl, ybuf, S, samples, k_eval, out_dF
            )
            if code == 3:
                hold = True
            else:
                if code != 2:
                    n_steps += 1
                    t = t_new
                    need_f = True
                    need_h0 = True
                    if not (
                        np.isfinite(y[0])
                        and np.isfinite(y[1])
                        and np.isfinite(y[2])
                        and np.isfinite(y[3])
                    ):
                        status = BLOW_UP
                        break
                if code == 0:
                    continue
                if code == 4:
                    hold = True
                    continue
                if code == 2:
                    zero_len += 1
                    if zero_len > 4:
                        status = CHATTER
                        break
                else:
                    zero_len = 0
                    short_run = _zeno_run(t, t_last_ev, hmax, short_run)
                    if short_run > _ZENO_EVENTS:
                        status = CHATTER
                        break
                    t_last_ev = t
                mode = _take_event(t, y, mode, 0, law, n_ev, events, sens, sw)
                n_ev += 1
                need_f = True
                need_h0 = True
                continue
        if use_contact and (mode == LOAD or mode == UNLOAD) and not hold:
            code, t_new, k_eval, idx = _contact(
                t, t1, y, mode, law, atol, phases, ybuf, dc, sens, samples, k_eval
            )
            if code == 3:
                hold = True
            else:
                n_steps += 1
                t = t_new
                need_f = True
                need_h0 = True
                if not (
                    np.isfinite(y[0])
                    and np.isfinite(y[1])
                    and np.isfinite(y[2])
                    and np.isfinite(y[3])
                ):
                    status = BLOW_UP
                    break
                if code == 4:
                    hold = True
                if code != 1:
                    continue
                zero_len = 0
                short_run = _zeno_run(t, t_last_ev, hmax, short_run)
                if short_run > _ZENO_EVENTS:
                    status = CHATTER
                    break
                t_last_ev = t
                mode = _take_event(t, y, mode, idx, law, n_ev, events, sens, sw)
                n_ev += 1
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
                mode = _take_event(t, y, mode, best_index, law, n_ev, events, sens, sw)
                n_ev += 1
                need_f = True
                need_h0 = True
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
        bad = False
        for j in range(4):
            if not np.isfinite(y[j]):
                bad = True
        if bad:
            status = BLOW_UP
            break
        if best_index >= 0:
            short_run = _zeno_run(t, t_last_ev, hmax, short_run)
            if short_run > _ZENO_EVENTS:
                status = CHATTER
                break
            t_last_ev = t
            mode = _take_event(t, y, mode, best_index, law, n_ev, events, sens, sw)
            n_ev += 1
            need_f = True
            need_h0 = True
            # keep the step size that worked before the cut
        else:
            for i in range(ns):
                hs0[i] = hs1[i]
            h = h * _step_factor(err)
    return status, t, mode, n_steps, n_ev, h
