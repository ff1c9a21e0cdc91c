"""Stroboscopic points, Lyapunov exponents, the classification of steady states and the
coexisting attractors of Ueda's oscillators (compiled kernels, frozen results).

The stroboscopic map samples the state at ``t = 2 pi k / nu`` (the forcing's phase 0).
Exponents are per unit time.  Integrator settings are the vibro-impact system's
:class:`discovery.vibroimpact.dynamics.Tolerances` (``rtol``, absolute tolerance ``rtol *
atol_scale * scale``, ``max_steps``, largest step ``hmax_fraction`` of a period).
"""

from dataclasses import dataclass, field

import numpy as np

from .._printing import fmt, generic_lines, readable
from .._result import Result, part
from .._validate import Array, Real, params
from ..errors import IntegrationError
from ..numerics.tolerances import Tolerances
from . import _kernel as UK
from ._runs import budget as _budget
from ._runs import check as _check
from ._runs import initial_state as _y0
from ._runs import setup as _setup
from .periodic import periodic_orbit
from .system import UedaSystem

__all__ = [
    "Lyapunov",
    "Regime",
    "Attractor",
    "Basins",
    "strobe_points",
    "trajectory",
    "lyapunov",
    "lyapunov_two_trajectory",
    "classify",
    "attractor",
    "basins",
    "rotation_number",
    "REGIMES",
]

REGIMES = ("P1", "Pn", "beat", "chaotic")


@params(
    system=UedaSystem,
    y0=(None, Array(1)),
    n=Real(1, integer=True),
    transient=Real(0, integer=True),
    t0=Real(),
    tolerances=(Tolerances, None),
)
def strobe_points(system, y0=None, n=200, *, transient=200, t0=0.0, tolerances=None):
    """The stroboscopic points after a transient.

    Parameters
    ----------
    system : UedaSystem
    y0 : (x, v), optional
        State at ``t0`` (default ``(0.1, 0)``).
    n : int
        Points returned.
    transient : int
        Periods integrated first.
    t0 : float
        Start time (a multiple of the period keeps the strobe phase at 0).

    Returns
    -------
    points : ndarray of shape (n, 2)
    y_final : ndarray of shape (2,)
        The last point (the state at ``t0 + (transient + n) T``).
    """
    tol, T, atol, hmax = _setup(system, tolerances)
    out = np.empty((int(n), 2))
    status, t, y, _, _ = UK.strobe_run(
        float(t0),
        _y0(y0),
        system.params(),
        T,
        int(transient),
        int(n),
        tol.rtol,
        atol,
        hmax,
        _budget(tol, int(n) + int(transient)),
        np.empty(0),
        np.empty((2, 0)),
        out,
    )
    _check(status, t, "the stroboscopic map")
    return out, y


def _after(system, y0, transient, tol):
    """The state after ``transient`` periods from ``y0`` at ``t = 0``."""
    if int(transient) <= 0:
        return _y0(y0)
    return strobe_points(system, y0, 1, transient=int(transient) - 1, tolerances=tol)[1]


@params(
    system=UedaSystem,
    y0=Array(1),
    t_span=Array(1),
    n_samples=Real(2, integer=True),
    tolerances=(Tolerances, None),
)
def trajectory(system, y0, t_span, n_samples=4000, *, tolerances=None):
    """``(t, x, v)`` sampled uniformly on ``t_span`` (dense output, no extra steps)."""
    tol, T, atol, hmax = _setup(system, tolerances)
    t0, t1 = float(t_span[0]), float(t_span[1])
    te = np.linspace(t0, t1, int(n_samples))
    out = np.empty((2, te.size))
    n_per = max(1, int(np.ceil((t1 - t0) / T - 1e-9)))
    strobe = np.empty((n_per, 2))
    status, t, _, _, k = UK.strobe_run(
        t0,
        _y0(y0),
        system.params(),
        T,
        0,
        n_per,
        tol.rtol,
        atol,
        hmax,
        _budget(tol, n_per),
        te,
        out,
        strobe,
    )
    _check(status, t, "the trajectory")
    return te[:k], out[0, :k], out[1, :k]


# ------------------------------------------------------------------ Lyapunov exponents
@readable
@dataclass(frozen=True, eq=False)
class Lyapunov(Result):
    """The two Lyapunov exponents [1/unit time] of one trajectory.

    Attributes
    ----------
    value, second : float
        Largest and second exponent (Benettin: variational equations, Gram-Schmidt (QR)
        at every strobe time).
    stderr, second_stderr : float
        Standard errors from batch means (``batches`` consecutive batches of periods).
    sum : float
        ``value + second``.
    trace_mean : float
        Time average of the Jacobian's trace ``mu (1 - gamma x^2) - k`` along the same
        trajectory (integrated with it); equals ``sum`` up to the integration error.
    n_periods, batches : int
    rtol : float
    method : str
    batch_values : ndarray of shape (batches,)
        Largest exponent of each batch.
    """

    KIND = "ueda-lyapunov"
    _LOAD = {"batch_values": lambda d: np.array(d.get("batch_values", []), float)}

    value: float
    stderr: float
    second: float
    second_stderr: float
    sum: float
    trace_mean: float
    n_periods: int
    batches: int
    rtol: float
    method: str
    batch_values: np.ndarray = field(repr=False)

    def as_dict(self):
        return {
            "value": self.value,
            "stderr": self.stderr,
            "second": self.second,
            "second_stderr": self.second_stderr,
            "sum": self.sum,
            "trace_mean": self.trace_mean,
            "sum_minus_trace": self.sum - self.trace_mean,
            "n_periods": self.n_periods,
            "batches": self.batches,
            "rtol": self.rtol,
            "method": self.method,
            "units": "per unit time",
        }

    def _lines(self):
        return [
            f"Lyapunov exponents {fmt(self.value, 4)} +- {fmt(self.stderr, 2)} and "
            f"{fmt(self.second, 4)} +- {fmt(self.second_stderr, 2)} per unit time",
            f"  sum {fmt(self.sum, 4)} against the mean trace {fmt(self.trace_mean, 4)}; "
            f"{self.n_periods} periods in {self.batches} batches, rtol {fmt(self.rtol, 2)} "
            f"({self.method})",
        ]


def _batch_stats(per_period, T, batches):
    n = per_period.shape[0]
    nb = max(2, min(int(batches), n))
    m = n // nb
    b = per_period[: nb * m].reshape(nb, m, *per_period.shape[1:]).sum(axis=1) / (m * T)
    return b, b.std(axis=0, ddof=1) / np.sqrt(nb)


def _variational(system, y, t0, periods, tol, T, atol, hmax):
    n = int(periods)
    logs, trace, strobe = np.empty((n, 2)), np.empty(n), np.empty((n, 2))
    status, t, yf, _ = UK.variational_run(
        float(t0),
        y,
        system.params(),
        T,
        n,
        tol.rtol,
        atol,
        tol.atol_variational,
        hmax,
        _budget(tol, n),
        logs,
        trace,
        strobe,
    )
    _check(status, t, "the variational equations")
    return logs, trace, strobe, yf


@params(
    system=UedaSystem,
    y0=(None, Array(1)),
    transient=Real(0, integer=True),
    periods=Real(1, integer=True),
    batches=Real(1, integer=True),
    tolerances=(Tolerances, None),
)
def lyapunov(
    system, y0=None, *, transient=200, periods=4000, batches=20, tolerances=None, _run=None
):
    """The largest two Lyapunov exponents by the variational equations (Benettin).

    Parameters
    ----------
    system : UedaSystem
    y0 : (x, v), optional
        Initial state (default ``(0.1, 0)``); the transient is discarded.
    transient, periods : int
        Drive periods discarded, then averaged over.
    batches : int
        Batches for the standard error (batch means; the batches must be longer than
        the correlation time of the local stretching rates).
    tolerances : Tolerances, optional

    Returns
    -------
    Lyapunov
    """
    tol, T, atol, hmax = _setup(system, tolerances)
    if _run is None:
        y = _after(system, y0, transient, tol)
        logs, trace, _, _ = _variational(system, y, 0.0, periods, tol, T, atol, hmax)
    else:
        logs, trace = _run
    n = logs.shape[0]
    bv, se = _batch_stats(logs, T, batches)
    lam = logs.sum(axis=0) / (n * T)
    return Lyapunov(
        value=float(lam[0]),
        stderr=float(se[0]),
        second=float(lam[1]),
        second_stderr=float(se[1]),
        sum=float(lam.sum()),
        trace_mean=float(trace.sum() / (n * T)),
        n_periods=n,
        batches=int(bv.shape[0]),
        rtol=tol.rtol,
        method="variational equations, Gram-Schmidt (QR) every period",
        batch_values=bv[:, 0].copy(),
    )


def lyapunov_two_trajectory(
    system, y0=None, *, transient=200, periods=4000, batches=20, d0=1e-7, tolerances=None
):
    """The largest exponent from two trajectories ``d0`` apart (relative to the scale),
    renormalised every period (Benettin/Wolf): ``(value, stderr)`` per unit time."""
    tol, T, atol, hmax = _setup(system, tolerances)
    y = _after(system, y0, transient, tol)
    n = int(periods)
    logs = np.empty(n)
    d = float(d0) * float(system.scales()[0])
    status, t, _, _ = UK.pair_run(
        0.0, y, system.params(), T, n, d, tol.rtol, atol, hmax, _budget(tol, n), logs
    )
    _check(status, t, "the two-trajectory run")
    _, se = _batch_stats(logs, T, batches)
    return float(logs.sum() / (n * T)), float(se)


# ------------------------------------------------------------------ classification
def rotation_number(points):
    """Mean turn per iterate (in turns) of the points around their centre, and the
    fraction of turns in the dominant direction (1 for an invariant closed curve
    traversed monotonically)."""
    p = np.asarray(points, dtype=float)
    c = p.mean(axis=0)
    s = p.std(axis=0)
    s[s == 0] = 1.0
    ang = np.arctan2((p[:, 1] - c[1]) / s[1], (p[:, 0] - c[0]) / s[0])
    d = np.angle(np.exp(1j * np.diff(ang)))
    rho = float(np.mean(d) / (2 * np.pi))
    mono = float(max(np.mean(d > 0), np.mean(d < 0))) if d.size else float("nan")
    return abs(rho), mono


@readable
@dataclass(frozen=True)
class Regime:
    """The kind of steady state, with its evidence.

    Attributes
    ----------
    regime : str
        ``"P1"`` (entrained: synchronised with the forcing), ``"P<n>"`` (subharmonic of
        period ``n`` forcing periods), ``"beat"`` (quasi-periodic: an invariant closed
        curve of the stroboscopic map) or ``"chaotic"``.
    kind : str
        ``"P1"``, ``"Pn"``, ``"beat"`` or ``"chaotic"`` (the chart's classes).
    period : int
        ``n`` for periodic regimes, else 0.
    evidence : dict
        ``recurrence`` (max distance ``|S_{k+n} - S_k|`` / scale over the last points,
        per ``n``), ``lyapunov``, ``lyapunov_threshold``, ``rotation_number`` and
        ``monotone_fraction`` (beat), ``rule`` (the sentence that decided).  When the
        orbit was polished by shooting (:func:`classify`, or :func:`classify_points`
        with a ``period_map``): ``floquet_multipliers_abs``, ``newton_residual`` and
        ``shooting`` (:meth:`~discovery.ueda.periodic.PeriodicOrbit.as_dict`).
    """

    regime: str
    kind: str
    period: int
    evidence: dict

    def as_dict(self):
        return {
            "regime": self.regime,
            "kind": self.kind,
            "period": self.period,
            "evidence": self.evidence,
        }

    def _lines(self):
        rule = self.evidence.get("rule")
        return [f"regime {self.regime}" + (f": {rule}" if rule else "")]


def classify_points(
    strobe,
    scale,
    lam,
    lam_stderr=0.0,
    *,
    max_period=8,
    closure=1e-5,
    chaos_threshold=0.01,
    period_map=None,
    shooting_tol=1e-8,
):
    """Classify from stroboscopic points and the largest exponent (see :class:`Regime`).

    Rules, in order: the smallest ``n <= max_period`` whose recurrence distance is below
    ``closure`` gives ``P<n>``; else a largest exponent above ``max(chaos_threshold,
    3 stderr)`` gives ``chaotic``; else ``beat`` (exponent near 0), with the rotation
    number of the points around their centre.

    With a ``period_map`` (a :class:`~discovery.ueda.periodic.UedaMap` of the
    system the points came from) a recurring orbit is polished by shooting from the last
    point (:func:`~discovery.ueda.periodic.periodic_orbit`, Newton tolerance
    ``shooting_tol``) and is periodic only if Newton converges to a stable orbit (all
    Floquet multipliers inside the unit circle); its period is then the smallest one
    shooting finds.  Otherwise the exponent rules decide.  Without one (the default, as
    in the chart), the recurrence alone decides.
    """
    s = np.asarray(strobe, dtype=float)
    m = min(len(s) - 1, 3 * max_period)
    tail = s[-(m + 1) :] / scale
    rec = {}
    for n in range(1, max_period + 1):
        if n < len(tail):
            rec[n] = float(np.max(np.abs(tail[n:] - tail[:-n])))
    ev = {
        "recurrence": rec,
        "lyapunov": float(lam),
        "lyapunov_stderr": float(lam_stderr),
        "closure": closure,
    }
    for n, d in rec.items():
        if d < closure:
            rule = (
                f"the strobe points repeat after {n} period(s) to {d:.1e} of the "
                f"scale (< {closure:g})"
            )
            if period_map is None:
                ev["rule"] = rule
                return Regime(f"P{n}", "P1" if n == 1 else "Pn", n, ev)
            orb = _shoot(period_map, s[-1], n, shooting_tol, ev)
            if orb is not None and orb.converged and orb.stable:
                n = orb.n_periods
                big = float(np.max(np.abs(orb.multipliers)))
                ev["rule"] = (
                    f"{rule}; shooting converged (residual {orb.residual:.1e}) to a "
                    f"stable period-{n} orbit, largest |Floquet multiplier| "
                    f"{big:.4g} < 1"
                )
                return Regime(f"P{n}", "P1" if n == 1 else "Pn", n, ev)
            why = (
                "shooting failed"
                if orb is None
                else "shooting did not converge"
                if not orb.converged
                else "the orbit shooting converged to is unstable"
            )
            ev["periodic_rejected"] = f"{rule}, but {why}"
            break
    thr = max(chaos_threshold, 3.0 * lam_stderr)
    ev["lyapunov_threshold"] = thr
    rho, mono = rotation_number(s)
    ev["rotation_number"] = rho
    ev["monotone_fraction"] = mono
    if lam > thr:
        ev["rule"] = f"no period <= {max_period}; largest exponent {lam:.3g} > {thr:.3g}"
        return Regime("chaotic", "chaotic", 0, ev)
    ev["rule"] = (
        f"no period <= {max_period}; largest exponent {lam:.3g} <= {thr:.3g} (near "
        f"0): an invariant closed curve, rotation number {rho:.4f}"
    )
    return Regime("beat", "beat", 0, ev)


def _shoot(period_map, y, n, tol, ev):
    """Shooting for the period-``n`` orbit near ``y``; its evidence into ``ev``."""

    try:
        orb = periodic_orbit(period_map.system, y, n, tol=tol, period_map=period_map)
    except IntegrationError as exc:
        ev["shooting"] = {"n_periods": int(n), "error": str(exc)}
        return None
    ev["shooting"] = orb.as_dict()
    ev["floquet_multipliers_abs"] = [float(abs(m)) for m in orb.multipliers]
    ev["newton_residual"] = float(orb.residual)
    return orb


def classify(system, y0=None, *, transient=300, periods=400, tolerances=None, shoot=True, **rules):
    """The regime reached from ``y0``: ``(Regime, Lyapunov, strobe points)``.

    ``shoot`` (default): a recurring orbit is polished by shooting and called periodic
    only if it converges to a stable orbit; its Floquet multipliers and Newton residual
    are in the evidence (see :func:`classify_points`).  ``rules`` are passed on to it.
    """
    tol, T, atol, hmax = _setup(system, tolerances)
    y = _after(system, y0, transient, tol)
    logs, trace, strobe, _ = _variational(system, y, 0.0, periods, tol, T, atol, hmax)
    lyap = lyapunov(
        system, tolerances=tol, batches=min(20, max(2, int(periods) // 20)), _run=(logs, trace)
    )
    if shoot and rules.get("period_map") is None:
        from .periodic import UedaMap

        rules["period_map"] = UedaMap(system, tol)
    reg = classify_points(strobe, system.scales(), lyap.value, lyap.stderr, **rules)
    return reg, lyap, strobe


# ------------------------------------------------------------------ one attractor
@readable
@dataclass(frozen=True, eq=False)
class Attractor(Result):
    """An attractor reached from one initial state.

    Attributes
    ----------
    system : UedaSystem
    regime : Regime
    lyapunov : Lyapunov
    strobe : ndarray of shape (n, 2)
        Stroboscopic points ``(x, x')`` at ``t = 2 pi k / nu`` after the transient.
    t, x, v : ndarray
        A stretch of trajectory on the attractor (for the phase-plane figure).
    y0 : ndarray of shape (2,)
        The initial state.
    transient : int
    seconds : float
    """

    KIND = "ueda-attractor"
    _LOAD = {
        "system": lambda d: UedaSystem.from_dict(d["system"]),
        "lyapunov": lambda d: part(Lyapunov, d["lyapunov"]),
        "regime": lambda d: None,
        "strobe": lambda d: None,
        "t": lambda d: None,
        "x": lambda d: None,
        "v": lambda d: None,
        "y0": lambda d: np.array(d["y0"], float),
        "transient": lambda d: d["transient_periods"],
    }

    system: UedaSystem
    regime: Regime
    lyapunov: Lyapunov
    strobe: np.ndarray = field(repr=False)
    t: np.ndarray = field(repr=False)
    x: np.ndarray = field(repr=False)
    v: np.ndarray = field(repr=False)
    y0: np.ndarray
    transient: int
    seconds: float

    @property
    def n_points(self):
        return int(self.strobe.shape[0])

    def as_dict(self):
        s = self.strobe
        return {
            "system": self.system.as_dict(),
            "regime": self.regime.regime,
            "classification": self.regime.as_dict(),
            "lyapunov": self.lyapunov.as_dict(),
            "strobe_x_range": [float(s[:, 0].min()), float(s[:, 0].max())],
            "strobe_y_range": [float(s[:, 1].min()), float(s[:, 1].max())],
            "n_points": self.n_points,
            "y0": [float(v) for v in self.y0],
            "transient_periods": self.transient,
            "seconds": self.seconds,
        }

    def _lines(self):
        return generic_lines(self)


@params(
    system=UedaSystem,
    y0=(None, Array(1)),
    transient=Real(0, integer=True),
    periods=Real(1, integer=True),
    batches=Real(1, integer=True),
    trajectory_periods=Real(0, integer=True),
    tolerances=(Tolerances, None),
)
def attractor(
    system,
    y0=None,
    *,
    transient=500,
    periods=5000,
    batches=20,
    trajectory_periods=30,
    tolerances=None,
):
    """The attractor reached from ``y0``: strobe points, exponents, regime, a trajectory.

    The strobe points are those of the Lyapunov run (one trajectory, ``periods``
    points).
    """
    import time

    t_start = time.perf_counter()
    tol, T, atol, hmax = _setup(system, tolerances)
    y_init = _y0(y0)
    y = _after(system, y_init, transient, tol)
    logs, trace, strobe, yf = _variational(system, y, 0.0, periods, tol, T, atol, hmax)
    lyap = lyapunov(system, tolerances=tol, batches=batches, _run=(logs, trace))
    from .periodic import UedaMap

    # a recurring orbit is polished by shooting: its Floquet multipliers are the evidence
    reg = classify_points(
        strobe, system.scales(), lyap.value, lyap.stderr, period_map=UedaMap(system, tol)
    )
    n_tr = int(trajectory_periods)
    t, x, v = trajectory(system, yf, (0.0, n_tr * T), n_samples=200 * n_tr, tolerances=tol)
    return Attractor(
        system=system,
        regime=reg,
        lyapunov=lyap,
        strobe=strobe,
        t=t,
        x=x,
        v=v,
        y0=y_init,
        transient=int(transient),
        seconds=time.perf_counter() - t_start,
    )


# ------------------------------------------------------------------ coexisting attractors
@readable
@dataclass(frozen=True)
class Basins:
    """Coexisting attractors found from a grid of initial states.

    Attributes
    ----------
    system : UedaSystem
    x0, v0 : ndarray
        The grid's axes.
    label : ndarray of shape (len(v0), len(x0))
        Index of the attractor each initial state reaches.
    attractors : list of dict
        ``regime``, ``fraction`` (of the grid), ``lyapunov``, ``centre`` and ``points``
        (strobe points of a representative), ``example_y0``.
    """

    system: UedaSystem
    x0: np.ndarray
    v0: np.ndarray
    label: np.ndarray
    attractors: list

    def as_dict(self):
        return {
            "grid": [int(self.x0.size), int(self.v0.size)],
            "x0_range": [float(self.x0[0]), float(self.x0[-1])],
            "v0_range": [float(self.v0[0]), float(self.v0[-1])],
            "attractors": [{k: v for k, v in a.items() if k != "points"} for a in self.attractors],
        }

    def _lines(self):
        out = [
            f"{len(self.attractors)} attractor(s) from a {self.x0.size}x{self.v0.size} grid of "
            f"initial states (x0 {fmt(self.x0[0], 3)} to {fmt(self.x0[-1], 3)}, v0 "
            f"{fmt(self.v0[0], 3)} to {fmt(self.v0[-1], 3)})"
        ]
        for i, a in enumerate(self.attractors):
            out.append(
                f"  {i}: {a.get('regime')}, {100 * float(a.get('fraction', 0)):.1f} % of the "
                f"grid, largest Lyapunov exponent {fmt(a.get('lyapunov'), 3)}"
            )
        return out


def _same_attractor(a, b, reg_a, reg_b, scale, tol=1e-3):
    if reg_a.regime != reg_b.regime:
        return False
    if reg_a.period:  # periodic: the same cycle of points, in any phase
        A, Bp = a[-reg_a.period :] / scale, b[-reg_b.period :] / scale
        return all(np.min(np.max(np.abs(Bp - p), axis=1)) < tol for p in A)
    # beat / chaotic: the same set - the points of each lie as close to the other's as
    # they lie to their own neighbours (median nearest-neighbour distances)
    a, b = a[-400:] / scale, b[-400:] / scale

    def nn(p, q, same=False):
        d = np.sqrt(((p[:, None, :] - q[None, :, :]) ** 2).sum(axis=2))
        if same:
            np.fill_diagonal(d, np.inf)
        return np.median(d.min(axis=1))

    own = max(nn(a, a, True), nn(b, b, True), tol)
    return bool(max(nn(a, b), nn(b, a)) < 3.0 * own)


@params(
    system=UedaSystem,
    x_range=Array(1),
    v_range=Array(1),
    n=Real(1, integer=True),
    transient=Real(0, integer=True),
    periods=Real(1, integer=True),
    tolerances=(Tolerances, None),
)
def basins(
    system,
    x_range=(-1.0, 1.0),
    v_range=(-1.0, 1.0),
    n=10,
    *,
    transient=300,
    periods=200,
    tolerances=None,
):
    """Attractors reached from an ``n x n`` grid of initial states, with basin fractions."""
    x0 = np.linspace(*x_range, int(n))
    v0 = np.linspace(*v_range, int(n))
    label = np.full((v0.size, x0.size), -1, dtype=int)
    found = []  # (regime, strobe, lyap, example)
    scale = system.scales()
    for i, vv in enumerate(v0):
        for j, xx in enumerate(x0):
            reg, lyap, strobe = classify(
                system, (xx, vv), transient=transient, periods=periods, tolerances=tolerances
            )
            for k, (r, s, _, _) in enumerate(found):
                if _same_attractor(s, strobe, r, reg, scale):
                    label[i, j] = k
                    break
            else:
                found.append((reg, strobe, lyap, (float(xx), float(vv))))
                label[i, j] = len(found) - 1
    total = label.size
    atts = []
    for k, (r, s, lyap, ex) in enumerate(found):
        atts.append(
            {
                "regime": r.regime,
                "fraction": float(np.sum(label == k) / total),
                "lyapunov": lyap.value,
                "lyapunov_stderr": lyap.stderr,
                "centre": [float(c) for c in s.mean(axis=0)],
                "example_y0": list(ex),
                "points": s[-min(len(s), 400) :],
            }
        )
    return Basins(system=system, x0=x0, v0=v0, label=label, attractors=atts)
