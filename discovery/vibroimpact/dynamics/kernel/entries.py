"""The kernel's entries called from Python besides :func:`~.loop.integrate`: the work
arrays, the contact modes' set-up, the stroboscopic runs (:func:`strobe`) and the small
checks."""

import numpy as np
from numba import njit

from ....numerics.status import OK
from .codes import LOAD, P_V0, P_ZMAX, UNLOAD, borrowed_njit
from .contact_modes import _contact_law, _contact_setup
from .flight import _NF
from .loop import integrate


@njit(cache=True)
def work_arrays(m_s, n_coef):
    """The work arrays of :func:`~.loop.integrate`: ``(steps, sens, phases)``, those of the
    steps, of ``m_s`` sensitivities (a law of ``n_coef`` coefficients) and of the
    closed-form phases, less the contact modes (``phases`` here is ``(fl, qm, sw, cb, fc,
    fcd)``; :func:`integrate` takes ``(fl, kc, E, R, qm, sw, cb, fc, fcd)``).  Scratch
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
        # the closed-form sensitivities' work arrays (:func:`~.contact._contact_sens`)
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


@borrowed_njit
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
    """Whether a contact mode has the closed form (:func:`~.contact._contact`; not with
    sensitivities), setting the ``modes`` ``(kc, E, R, made)``
    (:func:`~discovery.vibroimpact.dynamics.simulation.contact_modes`) up when ``made[0]``
    is 0 (then 1 where a mode has the closed form, 2 where none has): a caller that
    integrates the same law and scenario again passes them back, and the set-up (the
    eigendecomposition of both modes, 4.6 us) is made once.  ``law``: ``(p, coef, ea, eb,
    br)``, as :func:`integrate` takes it."""
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


@borrowed_njit
def in_range(y, bound):
    """Whether every ``|y[j]| < bound`` (false for a NaN)."""
    for j in range(y.shape[0]):
        if not abs(y[j]) < bound:
            return False
    return True


@borrowed_njit
def strobe(points, y, p_base, memory, bound, clock, law, ctl, out, use_contact, work):
    """Strobe points: ``points[k] = Phi(points[k - 1])`` for ``k >= 1`` (``points[0]`` the
    start), each period one run of :func:`integrate` from ``t0`` (mode ``mode0``, ``clock =
    (t0, mode0, period)``; ``law``'s ``p`` a fresh copy of ``p_base``) exactly as a separate
    call, so the points are bitwise those of one call per period; ``ctl``, ``out``,
    ``use_contact`` and ``work`` as :func:`integrate` takes them.  With ``memory`` (a law
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
        status, t, _, ns, _, _ = integrate(
            t0, t0 + period, y, mode0, law, ctl, out, use_contact, work
        )
        n_steps += ns
        for j in range(4):
            points[k, j] = y[j]
        inside = in_range(y, bound)
        if status != OK or not inside:
            break
    return status, k, t, n_steps, inside
