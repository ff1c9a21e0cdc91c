"""Public entry point to the compiled integrator: :func:`simulate` and :class:`Trajectory`."""

from dataclasses import dataclass

import numpy as np

from ..._api._settings import Settings, option, takes
from ..._api._validate import Array, Choice, Real, params
from ..._startup._compile import announce_compile
from ...errors import InputError, IntegrationError
from ...numerics.status import BLOW_UP, STEP_BUDGET, STEP_UNDERFLOW
from ...numerics.status import message as status_message
from ...numerics.tolerances import Tolerances
from ..model.law import ForceLaw
from ..model.scenario import Scenario
from .kernel import codes as K
from .kernel.contact_modes import NE, NR
from .kernel.entries import set_up_modes, sorted_within, work_arrays
from .kernel.forces import mode_force
from .kernel.loop import integrate

__all__ = ["Trajectory", "simulate", "Tolerances", "MODE_NAMES", "EVENT_NAMES", "SENSITIVITIES"]

MODE_NAMES = {K.FREE: "free", K.LOAD: "load", K.UNLOAD: "unload", K.CLIPPED: "clipped"}
EVENT_NAMES = {
    K.EV_ONSET: "onset",
    K.EV_LOSS: "loss",
    K.EV_UNLOAD: "unload",
    K.EV_RELOAD: "reload",
    K.EV_RELEASE: "release",
    K.EV_RESUME: "resume",
}
# what to check when the vibro-impact kernel fails (after the meaning from .status)
_HINTS = {
    STEP_BUDGET: (
        " (a law too stiff or too fast for the machine: check the coefficients' "
        "units; API: Tolerances(max_steps=...))"
    ),
    BLOW_UP: "; check the law's coefficients and signs",
    STEP_UNDERFLOW: "; the law may be too stiff for this tolerance",
}


@dataclass(frozen=True)
class Trajectory:
    """Result of :func:`simulate`.

    Attributes
    ----------
    t : ndarray of shape (n,)
        Output times [s].
    y : ndarray of shape (4, n)
        States ``w1 [m], v1 [m/s], w2 [m], v2 [m/s]`` at ``t``.
    force : ndarray of shape (n,)
        Contact force [N] at ``t`` (left limit where ``t`` is an event time).
    mode : ndarray of shape (n,)
        Contact mode code at ``t`` (see ``MODE_NAMES``).
    event_t : ndarray of shape (n_events,)
        Event times [s].
    event_kind : ndarray of shape (n_events,)
        Event codes (see ``EVENT_NAMES``).
    event_y : ndarray of shape (n_events, 4)
        States at the events.
    event_modes : ndarray of shape (n_events, 2)
        Mode before and after each event.
    t_final, y_final, mode_final
        Where the integration stopped.
    n_steps : int
        Steps attempted.
    status : int
        0 on success; see ``message``.
    message : str
    zeta_max0, impact_v0 : float
        The contact memory at the start (see :func:`simulate`).
    impact_v0_floor : float
        The smallest approach velocity an impact-scaled law's velocity terms are divided by
        (:meth:`Scenario.impact_v0_floor`).
    sensitivity : ndarray of shape (4, m) or None
        With ``simulate(..., sensitivities=...)``: the derivatives of the final state along
        each of ``m`` directions, named in ``sensitivity_names``: ``"w1", "v1", "w2", "v2"``
        (the start's states: the columns are the Jacobian of the flow) and the law's
        coefficients (loading terms by name, unloading terms as ``"unloading: name"``).
    force_sensitivity : ndarray of shape (m, n) or None
        The force's derivatives at ``t`` along the same directions.
    penetration_sensitivity : ndarray of shape (m, n) or None
        The penetration's (``w1 - w2``) derivatives at ``t`` along the same directions.
    event_time_sensitivity : ndarray of shape (n_events, m) or None
        The events' time derivatives along the same directions (NaN at a graze).
    sensitivity_names : tuple of str
    """

    t: np.ndarray
    y: np.ndarray
    force: np.ndarray
    mode: np.ndarray
    event_t: np.ndarray
    event_kind: np.ndarray
    event_y: np.ndarray
    event_modes: np.ndarray
    t_final: float
    y_final: np.ndarray
    mode_final: int
    n_steps: int
    status: int
    message: str
    zeta_max0: float = 0.0
    impact_v0: float = 0.0
    impact_v0_floor: float = 0.0
    sensitivity: np.ndarray | None = None
    force_sensitivity: np.ndarray | None = None
    penetration_sensitivity: np.ndarray | None = None
    sensitivity_names: tuple = ()
    event_time_sensitivity: np.ndarray | None = None

    @property
    def success(self):
        return self.status == 0

    @property
    def zeta(self):
        """Interpenetration ``w1 - w2`` [m] at ``t``."""
        return self.y[0] - self.y[2]

    @property
    def dzeta(self):
        """Penetration velocity ``v1 - v2`` [m/s] at ``t``."""
        return self.y[1] - self.y[3]

    def event_forces(self, law):
        """Left and right limits of the force at each event, ndarray of shape (n_events, 2)."""
        coef, ea, eb, br = law.kernel_arrays()
        out = np.empty((len(self.event_t), 2))
        p = np.zeros(K.N_PARAMS)
        p[K.P_SET] = law.permanent_set
        p[K.P_ZMAX] = self.zeta_max0
        p[K.P_VSCALE] = 1.0 if law.impact_scaled else 0.0
        p[K.P_V0] = self.impact_v0
        p[K.P_V0MIN] = self.impact_v0_floor
        for k, (yk, (m0, m1)) in enumerate(zip(self.event_y, self.event_modes, strict=True)):
            z, v = yk[0] - yk[2], yk[1] - yk[3]
            if m0 == K.FREE:
                p[K.P_ZMAX] = 0.0
                p[K.P_V0] = max(v, 1e-12)
            p[K.P_ZMAX] = max(p[K.P_ZMAX], z)  # the largest penetration so far (events only)
            out[k, 0] = mode_force(m0, z, v, p, coef, ea, eb, br)
            out[k, 1] = mode_force(m1, z, v, p, coef, ea, eb, br)
        return out


def kernel_params(scenario, law, tolerances=None):
    """The compiled kernel's parameter vector (:data:`~discovery.vibroimpact.dynamics._kernel.P_K3`
    ...): the scenario's parameters, the law's permanent set, a fresh contact state and the
    free-flight and contact paths of ``tolerances`` (:attr:`Tolerances.free_flight`,
    :attr:`Tolerances.contact`; default closed form, the contact's only with closed-form
    flights).  The kernel updates the state slots in place: pass each integration its own
    copy."""
    p = np.zeros(K.N_PARAMS)
    base = scenario.params()
    p[: base.size] = base
    p[K.P_SET] = law.permanent_set
    p[K.P_VSCALE] = 1.0 if law.impact_scaled else 0.0
    closed = tolerances is None or tolerances.free_flight == "closed"
    p[K.P_FLIGHT] = 1.0 if closed else 0.0
    contact = tolerances is None or tolerances.contact == "closed"
    p[K.P_CONTACT] = 1.0 if closed and contact else 0.0
    p[K.P_V0MIN] = scenario.impact_v0_floor()
    return p


def _buffers(t_eval, max_events):
    """The kernel's outputs ``(samples, events)``: the output times ``t_eval`` with the
    state, force and mode there, and the events' times, kinds, states and modes."""
    n_eval = t_eval.shape[0]
    samples = (t_eval, np.empty((4, n_eval)), np.empty(n_eval), np.empty(n_eval, dtype=np.int64))
    events = (
        np.empty(max_events),
        np.empty(max_events, dtype=np.int64),
        np.empty((max_events, 4)),
        np.empty((max_events, 2), dtype=np.int64),
    )
    return samples, events


def no_sensitivities():
    """The kernel's sensitivity arguments for a run without them (``m = 0``)."""
    return (
        np.empty((4, 0)),
        np.empty(0, dtype=np.int64),
        np.empty(0),
        np.empty((0, 0)),
        np.empty((0, 0)),
    )


def contact_modes():
    """Fresh storage for the contact modes' closed form (the kernel's ``modes``): the first
    run sets it up, and a caller that runs the same law and scenario with the same
    tolerances again (a stroboscopic map) passes the same storage back, so the
    eigendecomposition of the two modes is made once."""
    return (
        np.zeros(4),
        np.zeros((2, 4, NE), dtype=np.complex128),
        np.zeros((2, NR)),
        np.zeros(1),
    )


def scratch(m_s, n_coef, modes):
    """The kernel's work arrays for a run with ``m_s`` sensitivities of a law of ``n_coef``
    coefficients and the contact ``modes``: ``(steps, sens, phases)`` as
    :func:`~discovery.vibroimpact.dynamics._kernel._integrate` takes them.  The arrays are
    scratch space (a run reads only what it wrote), made once per process and size and
    lent to every run: the kernel holds the GIL, so two runs never share them at once
    (making them took 8 us of a 50 us run)."""
    key = (m_s, n_coef)
    work = _SCRATCH.get(key)
    if work is None:
        if len(_SCRATCH) >= 64:
            _SCRATCH.clear()
        work = _SCRATCH[key] = work_arrays(m_s, n_coef)
    steps, sens, (fl, qm, sw, cb, fc, fcd) = work
    kc, E, R, _ = modes
    return steps, sens, (fl, kc, E, R, qm, sw, cb, fc, fcd)


_SCRATCH = {}  # (sensitivities, coefficients) -> the kernel's work arrays


SENSITIVITIES = ("state", "coefficients", "all")
_STATE_NAMES = ("w1", "v1", "w2", "v2")


def sensitivity_setup(scenario, law, which, *, n_eval=0, n_events=0, controlled=True, start=None):
    """The kernel's sensitivity arguments ``(S, spar, sscale, out_dF, ev_tau)`` and the
    columns' names for ``which`` (one of :data:`SENSITIVITIES`): the start's four states
    (``S`` the identity there) and/or the law's coefficients (``S`` zero there); with
    ``controlled`` their error is held to the state's tolerances; ``start`` (4, m) replaces
    the start's derivatives."""
    if law.permanent_set > 0:
        raise InputError(
            "sensitivities are not available for a law with a permanent set (its unloading "
            "memory is a state the kernel does not differentiate); leave `set:` out, or use "
            "finite differences"
        )
    if law.impact_scaled:
        raise InputError(
            "sensitivities are not available for a law scaled by each impact's approach "
            "velocity (that velocity is a contact state the kernel does not differentiate); "
            "use finite differences"
        )
    coef = np.array(law.coefficients + law.unloading_coefficients, dtype=float)
    names, spar, sscale = [], [], []
    x, v = scenario.scales()
    if which in ("state", "all"):
        names += list(_STATE_NAMES)
        spar += [-1] * 4
        sscale += [x, v, x, v]
    if which in ("coefficients", "all"):
        names += list(law.names) + [f"unloading: {t.name}" for t in law.unloading]
        spar += list(range(coef.size))
        sscale += [max(abs(c), 1e-300) for c in coef]
    m = len(names)
    S = np.zeros((4, m))
    if which in ("state", "all"):
        S[:, :4] = np.eye(4)
    if start is not None:
        S0 = np.asarray(start, dtype=float)
        if S0.shape != S.shape or not np.all(np.isfinite(S0)):
            raise InputError(
                f"sensitivity_start must be finite, of shape {S.shape} (4 states by the "
                f"columns {', '.join(names)}); got shape {S0.shape}"
            )
        S[:] = S0
    out_dF = np.empty((2 * m, n_eval))  # the force's derivatives, then the penetration's
    # every recorded event's row is written (the saltation after it) and the rest are cut
    # off: no fill (10 000 rows of NaN took 4-7 us a run)
    ev_tau = np.empty((n_events, m))
    sscale = np.array(sscale) if controlled else np.empty(0)
    return (S, np.array(spar, dtype=np.int64), sscale, out_dF, ev_tau), tuple(names)


def _atol(scenario, tol):
    x, v = scenario.scales()
    return tol.atol([x, v, x, v])


@dataclass(frozen=True)
class _RunSetup:
    """What every run of one law on one machine with one set of tolerances shares: the
    kernel's parameter vector before a run's contact state is set (each run takes a copy:
    the kernel writes its state slots), the law's arrays, the state's absolute
    tolerances, the contact modes' closed form (set up by the first run, read by the
    others) and whether a mode has it.  The runs are bitwise those made each with their
    own set-up (it is a function of these three alone); an evaluation's blocks and
    cycles, one run each, made it 13-25 times (a tenth of a cycle's run)."""

    params: np.ndarray
    arrays: tuple
    atol: np.ndarray
    modes: tuple
    use_contact: bool

    @classmethod
    def of(cls, scenario, law, tol):
        """The set-up of ``law`` on ``scenario`` with ``tol`` (kept while the same three
        objects are asked for again: :data:`_SETUPS`)."""
        key = (id(scenario), id(law), id(tol))
        held = _SETUPS.get(key)
        if held is not None:
            return held[1]
        params = kernel_params(scenario, law, tol)
        arrays = law.kernel_arrays()
        atol = _atol(scenario, tol)
        modes = contact_modes()
        use_contact = bool(set_up_modes((params.copy(), *arrays), atol, modes))
        setup = cls(params, arrays, atol, modes, use_contact)
        if len(_SETUPS) >= 32:
            _SETUPS.clear()
        # the three objects are held with their set-up: their ids are not reused while kept
        _SETUPS[key] = ((scenario, law, tol), setup)
        return setup


_SETUPS = {}  # (id(scenario), id(law), id(tolerances)) -> ((the three), _RunSetup)


@dataclass(frozen=True, repr=False)
class SimulateSettings(Settings):
    """The options of :func:`simulate` (each is also a keyword of it; see its parameters)."""

    tolerances: object = option(None, (Tolerances, None))
    max_events: int = option(10_000, Real(1, integer=True))
    mode0: object = option(None)
    throw: bool = option(True)
    zeta_max0: float = option(0.0, Real(0))
    impact_v0: float = option(0.0, Real(0))
    sensitivities: object = option(None, (None, Choice(*SENSITIVITIES)))
    control_sensitivities: bool = option(True, bool)
    sensitivity_start: object = option(None, (None, Array(2)))


@takes(SimulateSettings)
@params(
    scenario=Scenario,
    law=ForceLaw,
    t_span=Array(1),
    y0=(None, Array(1)),
    t_eval=(None, Array(1)),
)
def simulate(scenario, law, t_span, y0=None, t_eval=None, *, settings=None, **options):
    """Integrate the two-body vibro-impact system with a given contact law.

    Parameters
    ----------
    scenario : Scenario
        Machine parameters.
    law : ForceLaw
        Contact law ``F(zeta, dzeta)``.
    t_span : (float, float)
        Start and end time [s].
    y0 : array_like of shape (4,), optional
        Initial ``w1, v1, w2, v2``; default :meth:`Scenario.initial_state`.
    t_eval : array_like of shape (n,), optional
        Sorted output times within ``t_span`` (dense output, no extra steps).
    settings : SimulateSettings, optional
        The options below in one object; keywords override its fields.
    tolerances : Tolerances, optional
    max_events : int
        How many events to record (all are located regardless).
    mode0 : int, optional
        Contact mode at ``t0``; default resolves it from ``y0``.
    zeta_max0 : float
        The current contact's largest penetration so far at ``t0`` (its memory, which a
        law with a permanent set unloads from; :attr:`SteadyState.zeta_max0` for an orbit
        strobed inside a contact).  The default takes the start's own penetration.
    impact_v0 : float
        For a law scaled by each impact's approach velocity (Lankarani-Nikravesh, Flores):
        that velocity of the contact under way at ``t0`` (:attr:`SteadyState.impact_v0`);
        0 (default) takes the start's own penetration rate.
    throw : bool
        Raise :class:`IntegrationError` on failure (default) or return a
        trajectory whose ``status``/``message`` say what happened.
    sensitivities : {"state", "coefficients", "all"}, optional
        Also integrate the variational equations (the saltation matrix at every event):
        the derivatives of the final state, of the force at ``t`` and of the event times
        along the start's states, the law's coefficients or both, from one run (not for a
        law with a permanent set).  ``control_sensitivities`` (default) holds their error
        to the state's tolerances (the run takes its own steps); ``False`` keeps the
        state's steps (the motion is bitwise a plain run's; measured within 1e-3 of
        central differences near a Hertz onset, 1e-7 for integer powers).
        ``sensitivity_start`` (4, m) replaces the start's derivatives (default: identity
        for the states, zero for the coefficients), e.g. a periodic orbit's
        (:mod:`~discovery.vibroimpact.dynamics.orbit_sensitivity`).

    Returns
    -------
    Trajectory
    """
    s = SimulateSettings.of("simulate", settings, options)
    if y0 is not None and np.size(y0) != 4:
        raise InputError(f"simulate: y0 must be the 4 states (w1, v1, w2, v2); got {np.size(y0)}")
    tol = s.tolerances or Tolerances.default()
    t0, t1 = (float(v) for v in t_span)
    if not (np.isfinite(t0) and np.isfinite(t1) and t1 > t0):
        raise InputError(f"t_span must be two finite times with t1 > t0, got {t_span!r}")
    y0 = scenario.initial_state() if y0 is None else np.array(y0, dtype=float).reshape(4)
    te = np.zeros(0) if t_eval is None else np.ascontiguousarray(t_eval, dtype=float)
    announce_compile("vibro-impact")  # the check below is the kernel's first call
    if te.size and not sorted_within(te, t0 - 1e-12, t1 + 1e-12):
        raise InputError("t_eval must be sorted and inside t_span")
    samples, events = _buffers(te, s.max_events)
    _, out_y, out_f, out_m = samples
    ev_t, ev_k, ev_y, ev_m = events
    period = scenario.period
    setup = _RunSetup.of(scenario, law, tol)
    p = setup.params.copy()
    p[K.P_ZMAX] = float(s.zeta_max0)
    v0_start = float(s.impact_v0) if s.impact_v0 > 0 else abs(float(y0[1] - y0[3]))
    p[K.P_V0] = v0_start
    if s.sensitivities is None:
        sens, names = no_sensitivities(), ()
    else:
        sens, names = sensitivity_setup(
            scenario,
            law,
            s.sensitivities,
            n_eval=te.size,
            n_events=s.max_events,
            controlled=s.control_sensitivities,
            start=s.sensitivity_start,
        )
    coef = setup.arrays[0]
    atol, modes, use_contact = setup.atol, setup.modes, setup.use_contact
    law_arrays = (p, *setup.arrays)
    ctl = (tol.rtol, atol, period / 100.0, period * tol.hmax_fraction, tol.max_steps)
    yf = y0.copy()  # advanced in place
    status, tf, mf, n_steps, n_ev, _ = integrate(
        t0,
        t1,
        yf,
        -1 if s.mode0 is None else int(s.mode0),
        law_arrays,
        ctl,
        (samples, events, sens),
        use_contact,
        scratch(sens[0].shape[1], coef.shape[0], modes),
    )
    message = (
        "ok"
        if status == 0
        else (f"integration stopped at t = {tf:.6g} s: {status_message(status, _HINTS)}")
    )
    if status and s.throw:
        raise IntegrationError(message)
    n_keep = min(n_ev, s.max_events)
    ok_out = te <= tf if status else slice(None)
    return Trajectory(
        t=te[ok_out],
        y=out_y[:, ok_out],
        force=out_f[ok_out],
        mode=out_m[ok_out],
        event_t=ev_t[:n_keep].copy(),
        event_kind=ev_k[:n_keep].copy(),
        event_y=ev_y[:n_keep].copy(),
        event_modes=ev_m[:n_keep].copy(),
        t_final=float(tf),
        y_final=yf,
        mode_final=int(mf),
        n_steps=int(n_steps),
        status=int(status),
        message=message,
        zeta_max0=float(s.zeta_max0),
        impact_v0=v0_start,
        impact_v0_floor=float(p[K.P_V0MIN]),
        sensitivity=sens[0] if names else None,
        force_sensitivity=sens[3][: len(names), ok_out] if names else None,
        penetration_sensitivity=sens[3][len(names) :, ok_out] if names else None,
        event_time_sensitivity=sens[4][:n_keep] if names else None,
        sensitivity_names=names,
    )
