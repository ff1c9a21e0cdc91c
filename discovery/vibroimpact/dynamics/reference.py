"""Independent slow path: scipy ``solve_ivp`` restarted at every contact event.

Written separately from the compiled kernel (its own right-hand side, force
evaluation and mode logic in plain numpy) so that agreement between the two is
evidence, not tautology.  Used by the tests and the benchmarks only.

Modes and switching surfaces are those of the kernel (``free``, ``load``,
``unload``, ``clipped``; onset/loss ``zeta = 0``, unload/reload ``dzeta = 0``,
release/resume ``P = 0``).  Restarting at events needs care where a segment starts
*on* a switching surface (it always does: the event that ended the previous segment
put it there, and coinciding surfaces, e.g. ``P(zeta, 0) = k zeta`` and ``zeta``,
put it on several):

* a surface function whose value at the start is within rounding of zero (less than
  its rate of change times ``1e-12`` of the time scale) takes the sign of where the
  flow goes next (a short Heun step of the mode's vector field), not its rounded
  value: if that is across the surface the event happens at once (a zero-length
  segment); otherwise the function is held on its side for an instant, so scipy
  neither fires it at the start (an exact 0 counts as a crossing) nor misses a
  crossing back within the first step (a contact loss followed by a re-contact);
* of several events at the same instant the lowest index wins (the kernel's rule:
  contact loss before the force reaching zero);
* a contact mode is never entered with ``zeta <= 0`` (after a release or resume
  that ends a hair past the loss), and the reported force is evaluated at
  ``max(zeta, 0)``, so the contact is never adhesive.

A run of more than ``_MAX_ZERO_LENGTH`` zero-length segments at one instant raises
:class:`~discovery.errors.IntegrationError` (chattering between modes), and so does a run
whose right-hand side is evaluated more than its budget (``max_nfev``, per 100 drive
periods of the span): the compiled kernel's step budget, so that a law made stiff
beyond what the machine's time scales need (e.g. a Lankarani-Nikravesh contact with a
tiny approach velocity: its damping is divided by it, though never by less than the
machine's floor, :meth:`~discovery.vibroimpact.model.scenario.Scenario.impact_v0_floor`)
stops with a clear message instead of taking steps of ``1e-8`` s for hours.
"""

from dataclasses import dataclass

import numpy as np
from scipy.integrate import solve_ivp

from ..._api._settings import Settings, option, takes
from ..._api._validate import Real
from ...errors import IntegrationError
from ...numerics.status import STEP_BUDGET
from ...numerics.status import message as status_message

__all__ = ["reference_simulate"]

_TREND_STEP = 1e-8  # Heun step for the trend of a surface function [periods]
_ON_SURFACE = 1e-12  # "on the surface": within this time [max(t, T)] of it at its rate
_HOLD = 10.0  # a held function keeps its start value for _HOLD x that time
_MAX_ZERO_LENGTH = 8  # zero-length segments in a row before raising
# right-hand-side evaluations per 100 drive periods of a run before raising: about the
# compiled kernel's default step budget (2e6 steps) in DOP853 steps (12 stages and 3
# for the dense output); an ordinary record spends 1e5 to 1e7
MAX_NFEV = 30_000_000


class _OverBudget(Exception):
    """The right-hand-side evaluation budget is used up."""


def _signed_pow(x, a):
    return np.sign(x) ** (a > 0) * abs(x) ** a


def _poly(law, z, zd):
    """The loading branch ``P`` (odd extension past the surfaces)."""
    return float(
        sum(
            c * _signed_pow(z, t.a) * _signed_pow(zd, t.b)
            for c, t in zip(law.coefficients, law.terms, strict=True)
        )
    )


def _load(law, z, v, zmax):
    """The loading branch: ``P``, or below the contact's largest penetration with a set,
    the elastic unloading line plus ``P``'s velocity part (Walton-Braun reloading)."""
    s = law.permanent_set
    if not s or z >= zmax:
        return _poly(law, z, v)
    return _poly(law, z, v) - _poly(law, z, 0.0) + _poly(law, (z - s * zmax) / (1.0 - s), 0.0)


def _unload(law, z, v, zmax):
    """The unloading branch: ``P(u, 0)`` at the unloading penetration ``u`` (the permanent
    set) plus the unloading terms at the signed velocity."""
    s = law.permanent_set
    u = (z - s * zmax) / (1.0 - s) if s else z
    return _poly(law, u, 0.0) + float(
        sum(
            c * _signed_pow(z, t.a) * _signed_pow(v, t.b)
            for c, t in zip(law.unloading_coefficients, law.unloading, strict=True)
        )
    )


def _force(law, mode, z, v, zmax, *, clamp=False):
    """Contact force of a mode.  Inside the integration the vector field is extended
    smoothly past the loss surface (odd extension of ``P``: a Runge-Kutta step that
    straddles the loss samples it there, and a kink would spoil the step's accuracy,
    ~1e-5 of the ranges after a run-up instead of ~1e-8); the force *reported*
    (``clamp``) is that at ``max(zeta, 0)``, never adhesive."""
    if clamp:
        z = max(z, 0.0)
    if mode == "load":
        return _load(law, z, v, zmax)
    if mode == "unload":
        return _unload(law, z, v, zmax)
    return 0.0


def _mode_of(law, y, state):
    z, v = y[0] - y[2], y[1] - y[3]
    if z < 0 or (z == 0 and v <= 0):
        return "free"
    if law.impact_scaled and state.get("law") is None:
        # a start inside a contact whose onset is not known: its own penetration rate
        state["law"] = law.at_impact(max(abs(v), state["v0_floor"]))
    law = state.get("law") or law
    if v > 0:
        return "load" if _load(law, max(z, 0.0), v, state["zmax"]) >= 0 else "clipped"
    state["zmax"] = max(state["zmax"], z)
    return "unload" if _unload(law, z, v, state["zmax"]) > 0 else "clipped"


def _events(law, mode, state):
    """(function, direction, next-mode rule) for each switching surface of a mode."""
    zeta = lambda t, y: y[0] - y[2]  # noqa: E731
    dz = lambda t, y: y[1] - y[3]  # noqa: E731
    out = []
    if mode == "free":
        out.append((zeta, 1.0, "onset"))
    else:
        out.append((zeta, -1.0, "loss"))
    zmax = state["zmax"]
    if mode == "load":
        out += [
            (dz, -1.0, "unload"),
            (lambda t, y: _load(law, y[0] - y[2], y[1] - y[3], zmax), -1.0, "release"),
        ]
    elif mode == "unload":
        out += [
            (dz, 1.0, "reload"),
            (lambda t, y: _unload(law, y[0] - y[2], y[1] - y[3], zmax), -1.0, "release"),
        ]
    elif mode == "clipped":

        def resume(t, y):
            z, v = max(y[0] - y[2], 0.0), y[1] - y[3]
            return _load(law, z, v, zmax) if v > 0 else _unload(law, z, v, zmax)

        out.append((resume, 1.0, "resume"))
    return out


def _after(law, kind, y, state, loss):
    """The mode after an event; an onset starts a new contact (and sheds mass), entering
    the unloading branch records the contact's largest penetration."""
    z, v = y[0] - y[2], y[1] - y[3]
    if kind == "onset":
        state["zmax"] = 0.0
        state["m2"] *= 1.0 - loss
        if law.impact_scaled:  # this impact's own law: velocity terms over its v0
            state["law"] = law.at_impact(max(v, state["v0_floor"]))
    law = state.get("law") or law
    if kind == "loss":
        return "free"
    if kind in ("release", "resume") and z <= 0:
        return "free"  # the force reached 0 at (or a hair past) the contact loss
    z = max(z, 0.0)
    if kind == "release":
        return "clipped"
    if kind == "resume":  # the branch force crossed to positive: the force is on again
        if v > 0:
            return "load"
        state["zmax"] = max(state["zmax"], z)
        return "unload"
    if kind == "unload" or (kind == "onset" and v <= 0):
        state["zmax"] = max(state["zmax"], z)
        return "unload" if _unload(law, z, v, state["zmax"]) >= 0 else "clipped"
    return "load" if _load(law, z, max(v, 0.0), state["zmax"]) >= 0 else "clipped"


def _surface_start(evs, rhs, t, y, *, dt_trend, tau_on):
    """Each surface function's value at the start of a segment and where it goes.

    Returns ``(g0, on, trend)``: values, whether each is on its surface (within
    rounding: ``|g0| <= |rate| tau_on``), and the sign of its change along the flow
    over ``dt_trend`` (a Heun step, so a grazing start with zero rate sees the
    curvature)."""
    f0 = np.asarray(rhs(t, y), dtype=float)
    yp = y + dt_trend * f0
    y1 = y + 0.5 * dt_trend * (f0 + np.asarray(rhs(t + dt_trend, yp), dtype=float))
    g0 = np.array([fn(t, y) for fn, _, _ in evs])
    dg = np.array([fn(t + dt_trend, y1) for fn, _, _ in evs]) - g0
    on = np.abs(g0) <= np.abs(dg) * (tau_on / dt_trend)
    on |= g0 == 0.0
    return g0, on, np.sign(dg)


def _crossing_now(evs, on, trend):
    """Index of the lowest surface function on its surface and moving across it now."""
    for i, (_, direction, _) in enumerate(evs):
        if on[i] and trend[i] == direction:
            return i
    return None


def _make_rhs(scenario, law, mode, state):
    """The right-hand side in contact ``mode`` (the moulding's mass and the largest
    penetration as they are now)."""
    m1, k1, c1, A, om, g = (
        scenario.m1,
        scenario.k1,
        scenario.c1,
        scenario.A,
        scenario.omega,
        scenario.g,
    )
    k3 = scenario.k3
    zmax, m2 = state["zmax"], state["m2"]

    def rhs(tt, yy):
        f = _force(law, mode, yy[0] - yy[2], yy[1] - yy[3], zmax)
        return [
            yy[1],
            -(c1 * yy[1] + (k1 + k3 * yy[0] ** 2) * yy[0] + A * np.sin(om * tt) + m1 * g + f) / m1,
            yy[3],
            f / m2 - g,
        ]

    return rhs


def _held_events(evs, on, g0, t, tau_on):
    """The segment's terminal events for ``solve_ivp``.  A surface the state starts on is
    held on its side (where the flow takes it) for an instant: an exact 0 would count as a
    crossing at the start, a rounded value of the wrong sign would hide a crossing back
    within the first step."""
    fns = []
    for i, (fn, direction, _) in enumerate(evs):
        if on[i]:
            hold = -direction * max(abs(g0[i]), 1e-300)

            def ev(tt, yy, fn=fn, hold=hold, t_hold=t + _HOLD * tau_on):
                return hold if tt <= t_hold else fn(tt, yy)
        else:

            def ev(tt, yy, fn=fn):
                return fn(tt, yy)

        ev.terminal, ev.direction = True, direction
        fns.append(ev)
    return fns


@dataclass(frozen=True)
class _Samples:
    """The requested output times and the states and forces filled in at them.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Requested times [s].
    y : ndarray of shape (4, n)
        States there (NaN until a segment covers them).
    force : ndarray of shape (n,)
        Contact force [N] there (NaN until a segment covers them).
    """

    t: np.ndarray
    y: np.ndarray
    force: np.ndarray

    @classmethod
    def at(cls, te):
        """Empty samples at times ``te``."""
        return cls(te, np.full((4, te.size), np.nan), np.full(te.size, np.nan))

    def fill(self, sol, span, law, mode, zmax):
        """The states and contact force of the segment ``sol`` of ``mode`` (largest
        penetration ``zmax``) at the requested times it covers, ``span = (t_start,
        t_end)``."""
        mask = (self.t >= span[0]) & (self.t <= span[1])
        if mask.any():
            ys = sol.sol(self.t[mask])
            self.y[:, mask] = ys
            self.force[mask] = [
                _force(law, mode, w1 - w2, v1 - v2, zmax, clamp=True) for w1, v1, w2, v2 in ys.T
            ]


def _fired(sol, evs, rhs, t, y, *, period):
    """The kind of the event that ended the segment: the first in time; a lower-index
    surface reached at the same instant wins the tie (contact loss before the force
    reaching zero, as in the kernel)."""
    fired = [i for i, tev in enumerate(sol.t_events) if len(tev)]
    i = min(fired, key=lambda i: (sol.t_events[i][0], i))
    _, on_end, trend_end = _surface_start(
        evs,
        rhs,
        t,
        y,
        dt_trend=_TREND_STEP * period,
        tau_on=_ON_SURFACE * max(abs(t), period),
    )
    j = _crossing_now(evs[:i], on_end[:i], trend_end[:i])
    return evs[i if j is None else j][2]


class _Counted:
    """A right-hand side's evaluations counted against ``budget`` (:class:`_OverBudget`
    beyond it)."""

    def __init__(self, budget):
        self.budget, self.calls = budget, 0

    def __call__(self, f):
        def rhs(tt, yy):
            self.calls += 1
            if self.calls > self.budget:
                raise _OverBudget(tt)
            return f(tt, yy)

        return rhs

    def error(self, t_stop, t_first):
        """The :class:`~discovery.errors.IntegrationError` of a run stopped at ``t_stop``."""
        return IntegrationError(
            f"reference integration stopped at t = {t_stop:.6g} s: "
            f"{status_message(STEP_BUDGET)} ({self.calls - 1} right-hand-side evaluations "
            f"from t = {t_first:.6g} s; the law is too stiff for the machine, "
            "e.g. damping over an impact velocity near 0)"
        )


@dataclass(frozen=True, repr=False)
class ReferenceSimulateSettings(Settings):
    """The options of :func:`reference_simulate` (each is also a keyword of it)."""

    rtol: float = option(1e-10, Real(0, 1, open_low=True))
    atol: object = option(None)
    method: str = option("DOP853")
    max_events: int = option(100_000, Real(0, integer=True))
    impact_v0: float = option(0.0, Real(0))
    max_nfev: int = option(MAX_NFEV, Real(1, integer=True))


@takes(ReferenceSimulateSettings)
def reference_simulate(scenario, law, t_span, *, y0=None, t_eval=None, settings=None, **options):
    """Simulate with scipy, restarting at events.

    A law scaled by each impact's approach velocity (``law.impact_scaled``) is integrated
    as the plain law :meth:`ForceLaw.at_impact` makes at each onset (``impact_v0``: that
    velocity of a contact under way at the start; 0 takes the start's own rate).

    ``max_nfev`` right-hand-side evaluations per 100 drive periods of ``t_span`` (at least
    one allowance) are allowed: beyond them the run raises
    :class:`~discovery.errors.IntegrationError` (the step budget, like the kernel's).

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    t_span : (float, float)
        Start and end time [s].
    y0 : array_like of shape (4,), optional
        Initial ``w1, v1, w2, v2``; default :meth:`Scenario.initial_state`.
    t_eval : array_like, optional
        Output times.
    settings : ReferenceSimulateSettings, optional
        The options below in one object; keywords override its fields.
    rtol, atol, method
        scipy's ``solve_ivp`` settings (``atol`` default ``rtol * 1e-3`` of the state's
        scales).
    max_events : int
        Events allowed before the run raises.
    impact_v0, max_nfev
        As above.

    Returns
    -------
    dict
        ``t``, ``y`` (4, n), ``force`` at ``t_eval``; ``events`` list of
        ``(t, kind, y)``; ``y_final``; ``m2_final`` (the moulding's mass at the end: less
        than the scenario's after impacts with a ``mass_loss``); ``nfev``.
    """
    s = ReferenceSimulateSettings.of("reference_simulate", settings, options)
    # an impact-scaled law divides by no approach velocity below the machine's floor
    floor = scenario.impact_v0_floor()
    state = {"m2": scenario.m2, "zmax": 0.0, "law": law, "v0_floor": floor}
    if law.impact_scaled:
        state["law"] = law.at_impact(max(s.impact_v0, floor)) if s.impact_v0 > 0 else None
    T = scenario.period
    y = scenario.initial_state() if y0 is None else np.array(y0, dtype=float)
    atol = s.atol
    if atol is None:
        x, v = scenario.scales()
        atol = s.rtol * 1e-3 * np.array([x, v, x, v])
    t, t1 = float(t_span[0]), float(t_span[1])
    te = np.zeros(0) if t_eval is None else np.asarray(t_eval, dtype=float)
    samples = _Samples.at(te)
    mode = _mode_of(law, y, state)
    events, nfev, zero_length = [], 0, 0
    counted = _Counted(int(s.max_nfev) * (1 + int((t1 - t) / (100.0 * T))))

    def record(kind, yy):
        events.append((t, kind, yy.copy()))
        if len(events) > s.max_events:
            raise IntegrationError("reference integration: too many events")

    while t < t1:
        rhs = _make_rhs(scenario, state["law"], mode, state)
        evs = _events(state["law"], mode, state)
        tau_on = _ON_SURFACE * max(abs(t), T)
        g0, on, trend = _surface_start(evs, rhs, t, y, dt_trend=_TREND_STEP * T, tau_on=tau_on)
        i_now = _crossing_now(evs, on, trend)
        if i_now is not None:  # an event at the segment's start: a zero-length segment
            zero_length += 1
            if zero_length > _MAX_ZERO_LENGTH:
                raise IntegrationError(
                    f"reference integration: the contact mode chatters at "
                    f"t = {t!r} ({zero_length} switches at one instant)"
                )
            kind = evs[i_now][2]
            record(kind, y)
            mode = _after(law, kind, y, state, scenario.mass_loss)
            continue
        t_start = t
        try:
            # a trial stage can overflow (an impact-scaled law's damping at a fresh contact
            # with scipy's first step): the step control rejects it, and a run that cannot
            # go on fails below; the warnings would say nothing more
            with np.errstate(over="ignore", invalid="ignore"):
                sol = solve_ivp(
                    counted(rhs),
                    (t, t1),
                    y,
                    method=s.method,
                    rtol=s.rtol,
                    atol=atol,
                    events=_held_events(evs, on, g0, t, tau_on),
                    dense_output=True,
                    max_step=T * 0.02,
                )
        except _OverBudget as stop:
            raise counted.error(stop.args[0], float(t_span[0])) from None
        nfev += sol.nfev
        if sol.status == -1:
            raise IntegrationError(f"reference integration failed: {sol.message}")
        t_end = sol.t[-1]
        samples.fill(sol, (t_start, t_end), state["law"], mode, state["zmax"])
        y = sol.y[:, -1].copy()
        t = t_end
        if t_end - t_start > _HOLD * tau_on:
            zero_length = 0
        if sol.status == 1:
            kind = _fired(sol, evs, rhs, t, y, period=T)
            record(kind, y)
            mode = _after(law, kind, y, state, scenario.mass_loss)
    return {
        "t": te,
        "y": samples.y,
        "force": samples.force,
        "events": events,
        "y_final": y,
        "m2_final": state["m2"],
        "nfev": nfev,
    }
