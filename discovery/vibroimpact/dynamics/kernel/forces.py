"""The contact force of each mode (the law's loading and unloading branches, a permanent
set, velocity terms scaled by the impact velocity), its partial derivatives, and the
two-body system's right-hand side through one Dormand-Prince step.

``law`` is ``(p, coef, ea, eb, br)``: the parameter vector (:mod:`.codes`) and the law's
terms ``coef_i z^ea_i zd^eb_i`` on branch ``br_i`` (0 loading, 1 unloading).  The leaves
called at every Runge-Kutta stage (the force, the right-hand side) are inlined and take
those arrays one by one."""

import numpy as np
from numba import njit

from ....numerics._dopri import C as _C
from .codes import DP, LOAD, P_K3, P_SET, P_V0, P_V0MIN, P_VSCALE, P_ZMAX, UNLOAD, borrowed_njit

_stage, _combine = DP.stage, DP.combine


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
    impact's approach velocity (``p[P_VSCALE] = 1``), not below the floor ``p[P_V0MIN]``,
    else 1."""
    if p[P_VSCALE] == 0.0:
        return 1.0
    return 1.0 / max(p[P_V0], p[P_V0MIN], 1e-12)


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


@borrowed_njit
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


@borrowed_njit
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


@borrowed_njit
def rhs_at(t, y, mode, law, out):
    """:func:`_rhs` as a call (for the once-per-event saltation: inlined there it would be
    typed again at each site, which costs compile time, not run time)."""
    p, coef, ea, eb, br = law
    _rhs(t, y, mode, p, coef, ea, eb, br, out)


@borrowed_njit
def _rk_step(t, y, h, mode, law, K, ytmp, ynew):
    """One DP5 step from (t, y) with K[0] = f(t, y) already set; fills K[1:7], ynew
    (the method's stages from :mod:`._dopri`, this system's right-hand side)."""
    p, coef, ea, eb, br = law
    for s in range(1, 6):
        _stage(s, y, h, K, ytmp)
        _rhs(t + _C[s] * h, ytmp, mode, p, coef, ea, eb, br, K[s])
    _combine(y, h, K, ynew)
    _rhs(t + h, ynew, mode, p, coef, ea, eb, br, K[6])
