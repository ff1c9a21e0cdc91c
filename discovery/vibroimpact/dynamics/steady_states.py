"""Periodic steady states: stroboscopic map, shooting, Floquet multipliers.

The stroboscopic map ``Phi`` advances a state by one drive period ``T`` (the drive
phase is fixed, so states are sampled at ``t = kT``).  After a short transient the
recurrence of the strobe points suggests a period ``n``; a damped Newton method
on ``Phi^n(y) - y = 0`` (finite-difference Jacobian, which includes the event
saltation automatically) then converges to the periodic orbit, whose Floquet
multipliers are the eigenvalues of that Jacobian.  An orbit is accepted only when
it converged and is stable; otherwise a long transient is integrated and the
search repeated, and if that fails too the result says "nonperiodic" with the
evidence.

The recurrence, the Newton shooting, the period reduction and the Floquet multipliers
are :mod:`discovery.numerics.shooting` (shared with Ueda's oscillators);
:class:`StroboscopicMap` is this system's period map for it.
"""

import dataclasses
from dataclasses import dataclass, field

import numpy as np

from ..._api._printing import fmt, readable
from ..._api._result import Result
from ..._api._settings import Settings, option, takes
from ..._api._validate import Array, Instance, Real, params
from ..._startup._compile import announce_compile
from ...errors import InputError, IntegrationError
from ...numerics import counts
from ...numerics.shooting import (
    floquet_multipliers,
    is_stable,
    newton_orbit,
    recurrence,
    smallest_period,
)
from ...numerics.status import OK
from ...numerics.status import message as status_message
from ..model.law import ForceLaw
from ..model.scenario import Scenario
from .kernel import codes as K
from .kernel.entries import in_range, set_up_modes, strobe
from .kernel.loop import integrate
from .memory_map import MemoryMap, orbit_multipliers
from .simulation import (
    _HINTS,
    Tolerances,
    _atol,
    contact_modes,
    kernel_params,
    no_sensitivities,
    scratch,
    simulate,
)

__all__ = ["SteadyState", "steady_state", "StroboscopicMap"]


def _event_arrays(room):
    """The kernel's event arrays ``(t, kind, y, modes)`` with room for ``room`` events."""
    return (
        np.empty(room),
        np.empty(room, dtype=np.int64),
        np.empty((room, 4)),
        np.empty((room, 2), dtype=np.int64),
    )


class StroboscopicMap:
    """The period map of one scenario and law (a thin, fast wrapper on the kernel).

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    tolerances : Tolerances, optional
    """

    def __init__(self, scenario, law, tolerances=None):
        announce_compile("vibro-impact")  # the contact modes' set-up may compile the kernel
        self.scenario = scenario
        self.law = law
        self.tol = tolerances or Tolerances.default()
        self._p = kernel_params(scenario, law, self.tol)
        self._coef, self._ea, self._eb, self._br = law.kernel_arrays()
        self._atol = _atol(scenario, self.tol)
        self._T = scenario.period
        self._hmax = self._T * self.tol.hmax_fraction
        # the kernel's arguments every run takes: the law, the tolerances, no output times
        self._arrays = (self._coef, self._ea, self._eb, self._br)
        self._ctl = (self.tol.rtol, self._atol, self._T / 100.0, self._hmax, self.tol.max_steps)
        self._no_samples = (
            np.zeros(0),
            np.empty((4, 0)),
            np.empty(0),
            np.empty(0, dtype=np.int64),
        )
        self._no_events = _event_arrays(0)
        x, v = scenario.scales()
        self.scale = np.array([x, v, x, v])
        self.n_calls = 0
        self.n_periods = 0
        self.n_steps = 0
        # a law with a permanent set unloads from the contact's largest penetration, which
        # the four states do not hold: the map carries it from one call's end to the next
        # start (exact at a fixed point; Jacobian probes hold it fixed)
        # (a law scaled by each impact's approach velocity carries that velocity the same way)
        self._memory = law.has_memory
        self.zeta_max = 0.0
        self.impact_v0 = 0.0
        self._no_sens = no_sensitivities()
        # the contact modes' closed form, set up here once for all the map's runs
        self._modes = contact_modes()
        self._use_contact = set_up_modes((self._p, *self._arrays), self._atol, self._modes)
        self._bound = 1e6 * self.scale.max() + 1e3
        self._state_dirs = np.full(4, -1, dtype=np.int64)
        # exact Jacobians (one run with the variational equations) unless the law has a
        # permanent set; ``n_exact`` counts them
        self.exact = not self._memory
        self.n_exact = 0

    def advance(self, y, n=1, t0=0.0, remember=True):
        """State after ``n`` periods from ``y`` at time ``t0`` (a multiple of ``T``).

        For a law with a permanent set, a start inside a contact unloads from
        :attr:`zeta_max`, the largest penetration the previous call ended with; with
        ``remember`` this call's own end value replaces it."""
        return self._run(y, n, t0, remember, self._no_sens)

    def onsets(self, y, n=1):
        """The contact onsets over ``n`` periods from ``y`` (with the contact memory the
        map holds, which the run leaves as it is): the impacts of an orbit through
        ``y``.  Not one of the search's evaluations: :attr:`n_calls` stays as it was."""
        calls, room = self.n_calls, 8 * n
        while True:
            events = _event_arrays(room)
            n_ev = self._run(y, n, 0.0, False, self._no_sens, events=events)[1]
            if n_ev <= room:
                self.n_calls = calls
                return int(np.sum(events[1][:n_ev] == K.EV_ONSET))
            room = n_ev

    def _prepared(self, m_s):
        """A run's parameters (a copy, holding the map's contact memory) and the kernel's
        work arrays for ``m_s`` sensitivities (the process's scratch arrays)."""
        p = self._p.copy()
        if self._memory:
            p[K.P_ZMAX] = self.zeta_max
            p[K.P_V0] = self.impact_v0
        work = scratch(m_s, self._coef.shape[0], self._modes)
        return p, work

    def _run(self, y, n, t0, remember, sens, *, events=None):
        p, work = self._prepared(sens[0].shape[1])
        yf = np.array(y, dtype=float)  # advanced in place
        out = (self._no_samples, self._no_events if events is None else events, sens)
        status, tf, _, steps, n_ev, _ = integrate(
            t0,
            t0 + n * self._T,
            yf,
            -1,
            (p, *self._arrays),
            self._ctl,
            out,
            self._use_contact,
            work,
        )
        self._account(1, n, steps, p if remember else None)
        self._check(status, tf, in_range(yf, self._bound))
        return yf if events is None else (yf, n_ev)

    def strobe(self, y, n):
        """The strobe points ``y, Phi(y), ..., Phi^n(y)``, ndarray of shape (n + 1, 4):
        bitwise those of ``n`` calls of :meth:`advance`, from one call of the kernel."""
        points = np.empty((n + 1, 4))
        points[0] = y
        p, work = self._prepared(0)
        status, k, tf, steps, inside = strobe(
            points,
            np.empty(4),
            self._p,
            self._memory,
            self._bound,
            (0.0, -1, self._T),
            (p, *self._arrays),
            self._ctl,
            (self._no_samples, self._no_events, self._no_sens),
            self._use_contact,
            work,
        )
        self._account(k, k, steps, p)
        self._check(status, tf, inside)
        return points

    def _account(self, calls, periods, steps, p):
        """Count a run's calls, periods and steps, and keep the contact memory its end
        holds (``p``; None to keep the map's)."""
        self.n_calls += calls
        self.n_periods += periods
        self.n_steps += steps
        if self._memory and p is not None:
            self.zeta_max = float(p[K.P_ZMAX])
            self.impact_v0 = float(p[K.P_V0])

    def _check(self, status, tf, inside):
        """Raise IntegrationError for a run that failed (``status``) or left the
        physical range (not ``inside``), at time ``tf``."""
        if status != OK:
            raise IntegrationError(
                f"simulation of law '{self.law}' stopped at t = {tf:.6g} s: "
                f"{status_message(status, _HINTS)}"
            )
        if not inside:
            raise IntegrationError(
                f"simulation of law '{self.law}' left the physical range at t = {tf:.6g} s "
                "(a displacement over 1e6 times the drive's scale); the law or the scenario "
                "may be unphysical (negative or huge coefficients, a moulding thrown away)"
            )

    def jacobian(self, y, n=1, fy=None):
        """Jacobian of ``Phi^n`` at ``y``, ndarray of shape (4, 4): exact (the variational
        equations through the steps, the saltation matrix at every event), from one
        simulation.  A law with a permanent set (whose unloading memory the four states do
        not hold), or a run whose exact Jacobian is not finite (a grazing contact), takes
        finite differences instead (four more simulations, from ``fy`` when given)."""
        return self.advance_jacobian(y, n, fy)[1]

    def advance_jacobian(self, y, n=1, fy=None):
        """``(Phi^n(y), d Phi^n / d y)`` from one run with the variational equations (see
        :meth:`jacobian`).  Its steps also control the Jacobian's error, so its state
        differs from :meth:`advance`'s within the integrator's tolerance (2.6e-10 of the
        scales on the paper's orbit); Newton's reported residual is this run's.  The
        Jacobian's error needs that control: along the state's own steps the light
        scenario's Jacobian is 7e-5 off and its multipliers 3e-5.  Where the Jacobian
        takes differences the state is the plain run's (``fy`` when given)."""
        if self.exact:
            S = np.eye(4)
            f = self._run(y, n, 0.0, False, (S, self._state_dirs, self.scale, *self._no_sens[3:]))
            self.n_exact += 1
            if np.all(np.isfinite(S)):
                return f, S
        fy = self.advance(y, n) if fy is None else fy
        return fy, self.fd_jacobian(y, n, fy)

    def fd_jacobian(self, y, n=1, fy=None):
        """Finite-difference Jacobian of ``Phi^n`` at ``y`` (forward steps of ``1e-6``
        of each state's scale)."""
        fy = self.advance(y, n) if fy is None else fy
        J = np.empty((4, 4))
        for j in range(4):
            d = 1e-6 * self.scale[j]
            yp = np.array(y, dtype=float)
            yp[j] += d
            J[:, j] = (self.advance(yp, n, remember=False) - fy) / d
        return J


@readable
@dataclass(frozen=True, eq=False)
class SteadyState(Result):
    """A periodic steady state of the two-body system (or the evidence that none was found).

    Attributes
    ----------
    regime : str
        ``"P1"``, ``"P2"``, ... (period in drive periods) or ``"nonperiodic"``.
    n_periods : int
        Period ``n`` of the orbit in drive periods (0 when nonperiodic).
    y0 : ndarray of shape (4,)
        State on the orbit at ``t0`` (a multiple of the drive period).
    t0 : float
        Time [s] at which ``y0`` holds.
    impacts : int
        Contact onsets per orbit (``n`` periods).
    multipliers : ndarray of shape (4,), complex
        Floquet multipliers (eigenvalues of the Jacobian of ``Phi^n``).
    residual : float
        ``max |Phi^n(y0) - y0| / scale`` at the solution, ``Phi`` the run Newton took
        (with the variational equations, :meth:`StroboscopicMap.advance_jacobian`; a
        plain run differs within the integrator's tolerance).
    n_simulations : int
        Period-map evaluations used.
    evidence : dict
        How the decision was reached (recurrence distances, Newton history).
    zeta_max0 : float
        For a law with a permanent set: the largest penetration of the contact under way
        at ``y0`` (its unloading memory; pass it to :func:`simulate` as ``zeta_max0``).
    impact_v0 : float
        For a law scaled by each impact's approach velocity: that velocity of the contact
        under way at ``y0`` (pass it to :func:`simulate` as ``impact_v0``; 0 when none).
    """

    regime: str
    n_periods: int
    y0: np.ndarray
    t0: float
    impacts: int
    multipliers: np.ndarray
    residual: float
    n_simulations: int
    evidence: dict = field(default_factory=dict)
    zeta_max0: float = 0.0
    impact_v0: float = 0.0

    KIND = "steady"
    _LOAD = {
        "y0": lambda d: np.array(d["y0"], float),
        # [re, im] pairs; a part that is not finite was written as null
        "multipliers": lambda d: np.array(
            [complex(*(np.nan if v is None else v for v in m)) for m in d["multipliers"]]
        ),
        "residual": lambda d: np.nan if d.get("residual") is None else d["residual"],
        "evidence": lambda d: {},  # how the decision was reached: not in the document
    }

    @property
    def periodic(self):
        return self.n_periods > 0

    @property
    def impacts_per_period(self):
        return self.impacts / self.n_periods if self.n_periods else float("nan")

    def as_dict(self):
        return {
            "regime": self.regime,
            "n_periods": self.n_periods,
            "impacts": self.impacts,
            "impacts_per_period": self.impacts_per_period,
            "multipliers_abs": [float(abs(m)) for m in self.multipliers],
            "residual": self.residual,
            "n_simulations": self.n_simulations,
            "y0": self.y0,
            "t0": self.t0,
            "multipliers": [[float(m.real), float(m.imag)] for m in np.asarray(self.multipliers)],
            "zeta_max0": self.zeta_max0,
        }

    def _lines(self):
        d = self.as_dict()
        mult = np.abs(np.asarray(self.multipliers)) if self.multipliers is not None else []
        return [
            f"steady state {d.get('regime')}: {d.get('impacts')} impact(s) per orbit, "
            f"max |Floquet multiplier| {fmt(np.max(mult) if len(mult) else None)}, "
            f"residual {fmt(d.get('residual'), 2)}"
        ]


def _strobe_recurrence(pm, y, max_period, full=False):
    """Strobe points from ``y`` and their recurrence distance per period ``n``: ``(last
    strobe point, periods advanced, {n: distance}, the one-period distance)``; when the
    points already recur after one period (and not ``full``), only two periods are
    advanced."""
    strobe = pm.strobe(y, 2)
    quick = max(np.max(np.abs(strobe[k + 1] - strobe[k]) / pm.scale) for k in (0, 1))
    if quick < 1e-2 and not full:
        # fast path: the strobe points already recur after one period
        return strobe[-1].copy(), 2, {1: float(quick)}, quick
    strobe = np.concatenate([strobe, pm.strobe(strobe[-1], 2 * max_period)[1:]])
    return (
        strobe[-1].copy(),
        2 * max_period + 2,
        recurrence(strobe, pm.scale, max_period),
        quick,
    )


def _orbit(pm, y, n, t0, *, tol, max_newton, attempt):
    """Newton shooting for a period-``n`` orbit from ``y`` (at time ``t0`` [s]) on the
    stroboscopic map ``pm`` of a scenario and law: the steady state when it converges to a
    stable orbit (reduced to its smallest period) that the motion from ``y`` reaches
    (:func:`_reached`), else ``None``.  A law with contact memory is shot on its
    :class:`MemoryMap` (the memory ``pm`` holds after ``y``'s run is the start's).  Every
    try is recorded in ``attempt`` (one of the evidence's attempts, which the caller puts
    into the steady state); ``tol`` and ``max_newton`` are Newton's (see
    :func:`steady_state`)."""
    shot = MemoryMap(pm) if pm.law.has_memory else pm
    start = shot.extend(y) if shot is not pm else np.asarray(y, dtype=float)
    found = _shoot(pm, shot, start, n, t0, tol=tol, max_newton=max_newton, attempt=attempt)
    if found is None and shot is not pm:
        # Newton's runs left their own memory in the map: the motion goes on with y's
        pm.zeta_max, pm.impact_v0 = float(start[4]), float(start[5])
    return found


def _shoot(pm, shot, start, n, t0, *, tol, max_newton, attempt):
    """:func:`_orbit` on the map ``shot`` (``pm`` or its :class:`MemoryMap`) from the
    (extended) state ``start``."""
    hist = []
    y_orb, res, J, ok = newton_orbit(shot, start, n, tol=tol, max_iter=max_newton, history=hist)
    mult = orbit_multipliers(shot, y_orb, n, J)
    stable = bool(ok and is_stable(mult))
    tried = {
        "n": n,
        "newton_residuals": hist,
        "converged": ok,
        "max_multiplier": float(np.max(np.abs(mult))),
        "stable": stable,
    }
    attempt["tried"].append(tried)
    if not stable:
        return None
    reduced = smallest_period(shot, y_orb, n, tol, max_newton) if n > 1 else None
    if reduced is not None:
        m, y_orb, res, J, hist_m = reduced
        attempt["tried"].append(
            {
                "n": m,
                "reduced_from": n,
                "newton_residuals": hist_m,
                "converged": True,
                "stable": True,
            }
        )
        n, mult = m, orbit_multipliers(shot, y_orb, m, J)
    tried["reached"], tried["reach_runs"] = _reached(shot, start, y_orb, n)
    if not tried["reached"]:
        return None
    zmax, v0 = 0.0, 0.0
    if shot is not pm:
        zmax, v0 = float(y_orb[4]), float(y_orb[5])
        y_orb = y_orb[:4]
        pm.zeta_max, pm.impact_v0 = zmax, v0
    impacts = pm.onsets(y_orb, n)
    return SteadyState(
        regime=f"P{n}",
        n_periods=n,
        y0=y_orb,
        t0=t0,
        impacts=impacts,
        multipliers=mult,
        residual=float(res),
        n_simulations=pm.n_calls,
        evidence={},
        zeta_max0=zmax,
        impact_v0=v0,
    )


#: how close [relative to the scales] a motion must come to an orbit to have reached it,
#: and the most periods (in runs of ``_REACH_RUN``) followed to see it come that close
_REACH_DISTANCE, _REACH_PERIODS, _REACH_RUN = 1e-3, 2000, 50


def _reached(shot, start, z_orb, n):
    """Whether the motion from ``start`` reaches the period-``n`` orbit through ``z_orb``:
    whether it comes within ``_REACH_DISTANCE`` of one of the orbit's points within
    ``_REACH_PERIODS`` periods, or is then still closing in on it (closer after each of
    the last four runs of ``_REACH_RUN`` periods, and less than half as far as at the
    start).  Newton can converge to a stable orbit that coexists with the attractor the
    motion is on (a chaotic one); a motion may also wander through a chaotic transient of
    hundreds of periods before it settles on the orbit Newton found (measured: 500
    periods, then 400 more to come within 1e-3 at 0.94 per orbit), so nothing short of
    the motion's own arrival decides (a run costs 20-50 ms per 1000 periods).  Returns
    ``(reached, runs)``, ``runs`` the runs of the motion it took."""
    points = [np.asarray(z_orb, dtype=float)]
    for _ in range(n - 1):
        points.append(shot.advance(points[-1], 1))
    scale = np.asarray(shot.scale[:4])

    def distance(z):
        return min(float(np.max(np.abs(z[:4] - q[:4]) / scale)) for q in points)

    z = np.asarray(start, dtype=float)
    d = [distance(z)]
    while d[-1] >= _REACH_DISTANCE:
        if len(d) > _REACH_PERIODS // _REACH_RUN:
            # still on its way (a multiplier near 1 in modulus): closer after each of the
            # last runs, and well closer than at the start
            last = d[-5:]
            return bool(np.all(np.diff(last) < 0)) and d[-1] < 0.5 * d[0], len(d) - 1
        z = shot.advance(z, _REACH_RUN)
        d.append(distance(z))
    return True, len(d) - 1


@dataclass(frozen=True, repr=False)
class SteadyStateSettings(Settings):
    """The options of :func:`steady_state` (each is also a keyword of it; see its parameters)."""

    transient: int = option(30, Real(0, integer=True))
    max_period: int = option(8, Real(1, 64, integer=True))
    tol: float = option(1e-8, Real(0, 1, open_low=True))
    max_newton: int = option(12, Real(1, integer=True))
    long_transient: int = option(300, Real(0, integer=True))
    tolerances: object = option(None, (Tolerances, None))
    y_start: object = option(None, (None, Array(1)))
    t_start: float = option(0.0, Real())
    guess: object = option(
        None, (None, Instance("discovery.vibroimpact.dynamics.steady_states", "SteadyState"))
    )


@takes(SteadyStateSettings)
@params(scenario=Scenario, law=ForceLaw)
def steady_state(scenario, law, *, settings=None, **options):
    """Find the periodic steady state reached from a given (or the scenario's) state.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
    settings : SteadyStateSettings, optional
        The options below in one object; keywords override its fields.
    transient : int
        Drive periods integrated before the period search.
    max_period : int
        Largest orbit period (in drive periods) looked for.
    tol : float
        Newton tolerance on ``max |Phi^n(y) - y| / scale``.
    max_newton : int
        Newton iterations per attempt.
    long_transient : int
        Periods of the fallback transient when the first search fails.
    tolerances : Tolerances, optional
        Integrator settings.
    y_start : array_like of shape (4,), optional
        Initial state ``(w1, v1, w2, v2)`` (default the scenario's).  To follow the
        attractor a machine is on, pass its measured state (see
        :meth:`~discovery.vibroimpact.data.measurement.Measurement.state_at`).
    guess : SteadyState, optional
        Continuation: the periodic orbit of a nearby law (a neighbouring landscape point).
        Newton starts from its orbit with its period; the orbit is taken when Newton
        converges within ``CONTINUATION_NEWTON`` iterations to a stable orbit whose period
        does not reduce; otherwise the search from ``y_start`` runs as without a guess.
        Where attractors coexist, the continued orbit is the one on the guess's branch.
    t_start : float
        Time [s] at which ``y_start`` holds, on the drive's clock (the drive is
        ``A sin(2 pi f t)``, phase 0 at ``t = 0``); it need not be a multiple of ``T``.

    Returns
    -------
    SteadyState
        ``regime == "nonperiodic"`` when no stable periodic orbit was found.

    Raises
    ------
    IntegrationError
        When a simulation fails (blow-up, step budget): a failure is never reported
        as the physical regime "nonperiodic".
    """
    s = SteadyStateSettings.of("steady_state", settings, options)
    if scenario.mass_loss > 0:
        raise InputError(
            f"scenario {scenario.name!r} sheds {scenario.mass_loss:g} of the "
            "moulding's mass per impact, so it has no periodic steady state; "
            "simulate it from rest (vidi simulate --from-rest) or set "
            "mass_loss = 0"
        )
    pm = StroboscopicMap(scenario, law, s.tolerances)
    try:
        return _steady_from(scenario, law, s, pm)
    finally:  # the work is counted whatever the outcome (:mod:`discovery.numerics.counts`)
        counts.count("steady_states")
        counts.count("period_maps", pm.n_calls)


def _steady_from(scenario, law, s, pm):
    """:func:`steady_state`'s search with the settings ``s`` on the period map ``pm``."""
    if s.guess is not None and s.guess.periodic and not law.has_memory:
        cont = _continued(scenario, law, pm, s.guess, s.tol)
        if cont is not None:
            return cont
    y = scenario.initial_state() if s.y_start is None else np.asarray(s.y_start, dtype=float)
    T = scenario.period
    evidence = {"attempts": [], "t_start": float(s.t_start)}
    k0 = int(np.ceil(s.t_start / T - 1e-9))
    if abs(s.t_start - k0 * T) > 1e-12 * T:
        # integrate to the next strobe time (drive phase 0)
        tr = simulate(scenario, law, (s.t_start, k0 * T), y0=y, tolerances=pm.tol)
        y = tr.y_final
    t_done = k0
    for phase, n_trans in (("transient", s.transient), ("long-transient", s.long_transient)):
        y = pm.advance(y, n_trans)
        t_done += n_trans
        y, periods, dist, quick = _strobe_recurrence(pm, y, s.max_period)
        t_done += periods
        attempt = {"phase": phase, "recurrence": dist, "tried": []}
        evidence["attempts"].append(attempt)
        found = _search(pm, y, t_done * T, s, attempt, quick=quick < 1e-2)
        if found is None and quick < 1e-2:
            # the one-period recurrence was close, yet no orbit of period 1-3 is: the
            # strobe points over ``max_period`` periods say which period to try
            y, periods, dist, _ = _strobe_recurrence(pm, y, s.max_period, full=True)
            t_done += periods
            attempt = {"phase": phase, "recurrence": dist, "tried": []}
            evidence["attempts"].append(attempt)
            found = _search(pm, y, t_done * T, s, attempt)
        if found is not None:
            return dataclasses.replace(found, evidence=evidence)
    return SteadyState(
        regime="nonperiodic",
        n_periods=0,
        y0=y,
        t0=t_done * T,
        impacts=0,
        multipliers=np.full(4, np.nan + 0j),
        residual=float("nan"),
        n_simulations=pm.n_calls,
        evidence=evidence,
    )


def _period_order(dist):
    """The periods to try, best first, from the strobe points' recurrence ``dist`` (``{n:
    distance}``): the periods whose points recur within 1e-2 and within 10 times the
    closest recurrence, shortest first (a period-``n`` orbit also recurs at ``2n``, and a
    P1 near a flip reads closer at 2; the period reduction then finds the shortest), then
    the rest by distance."""
    best = min(dist.values())

    def key(n):
        close = dist[n] <= 1e-2 and dist[n] <= max(10.0 * best, 1e-9)
        return (0, n) if close else (1, dist[n])

    return sorted(dist, key=key)


def _search(pm, y, t0, s, attempt, *, quick=False):
    """The steady state from Newton on the three most likely periods (:func:`_period_order`;
    ``quick``: the strobe points already recur after one period, so periods 1, 2, 3) from
    the strobe point ``y`` at time ``t0``, or None."""
    order = [1, 2, 3] if quick else _period_order(attempt["recurrence"])
    for n in [n for n in order if n <= s.max_period][:3]:
        found = _orbit(
            pm,
            y,
            n,
            t0,
            tol=s.tol,
            max_newton=s.max_newton,
            attempt=attempt,
        )
        if found is not None:
            return found
    return None


CONTINUATION_NEWTON = 4
"""Newton iterations a continuation may take before the cold search runs instead."""


def _continued(scenario, law, pm, guess, tol):
    """The orbit continued from ``guess`` (see :func:`steady_state`), or None."""
    n = guess.n_periods
    hist = []
    try:
        y_orb, res, J, ok = newton_orbit(
            pm,
            np.asarray(guess.y0, dtype=float),
            n,
            tol=tol,
            max_iter=CONTINUATION_NEWTON,
            history=hist,
        )
    except IntegrationError:
        return None
    mult = floquet_multipliers(J, len(y_orb))
    if not (ok and is_stable(mult)):
        return None
    if n > 1 and smallest_period(pm, y_orb, n, tol, CONTINUATION_NEWTON) is not None:
        return None  # the period reduces here: let the cold search decide
    evidence = {
        "attempts": [],
        "t_start": float(guess.t0),
        "continued_from": {"regime": guess.regime, "newton_residuals": hist},
    }
    impacts = pm.onsets(y_orb, n)
    return SteadyState(
        regime=f"P{n}",
        n_periods=n,
        y0=y_orb,
        t0=guess.t0,
        impacts=impacts,
        multipliers=mult,
        residual=float(res),
        n_simulations=pm.n_calls,
        evidence=evidence,
        zeta_max0=0.0,
    )
