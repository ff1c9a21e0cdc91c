"""Continuation sweeps of the regime chart: one point ``(nu, B)`` and one row of ``B``.

Each row of the chart (one ``B``) is swept in increasing ``nu``, every point starting
from the last state of the previous one (continuation, as an analog-computer sweep; the
first point of a row starts from ``y0``).  With ``sweeps=2`` the row is swept back in
decreasing ``nu`` as well, starting from the state the first sweep ended in (the
up-and-down sweep of a hysteresis experiment): both regimes are recorded, and a point
where one sweep ends on a stable periodic orbit and the other does not (another orbit,
or a non-periodic regime), also after ``recheck`` times the transient more from both
final states, is marked ``coexisting`` (the jump phenomenon near a resonance, two
coexisting subharmonics).  Two non-periodic results are not compared.

Each point: up to ``transient`` forcing periods of the stroboscopic map (compiled), with
an early exit as soon as the strobe points repeat after ``n <= max_period`` periods to
``closure`` (of the scale) over ``max(3 n, min_pairs)`` consecutive pairs, unless the run
may still be converging to an orbit of a divisor of ``n`` (a P1 orbit with a multiplier
near -1 repeats after 2 periods long before it repeats after 1).  The orbit's monodromy
matrix over ``n`` periods then gives its Floquet multipliers: a stable orbit (``|m| <
1``) is ``P<n>`` with the exponent ``log|m_1| / (n T)``; an unstable one repeated by
chance and the transient goes on.  Without an early exit, ``periods`` more periods with
the variational equations (Benettin): ``P<n>`` by the same recurrence test on their
strobe points (and a stable monodromy), else ``chaotic`` if the largest exponent exceeds
``chaos_threshold``, else ``beat`` (:func:`~discovery.ueda.classify_points`).
With ``early_exit=False`` every point takes the second path after the full transient.
The early exit halves the cost of a chart; the classes of chaotic and quasi-periodic
points are computed exactly as without it.

The settings are the chart's (:attr:`~discovery.ueda.regime_chart.Chart.settings`, a dict).
"""

import cmath
import math
import time
from dataclasses import dataclass

import numpy as np

from ..errors import IntegrationError
from ..numerics.tolerances import Tolerances
from . import _kernel as UK
from ._runs import Integration
from ._runs import check as _check
from .regimes import RegimeRules, classify_points
from .system import UedaSystem

__all__ = ["KINDS", "point", "sweep_row"]

KINDS = ("P1", "Pn", "beat", "chaotic")  # codes 0..3; -1 failed


def _floquet(M, logs):
    """Moduli of the two multipliers (largest first) of ``exp(logs) M``, as logs."""
    tr, det = M[0, 0] + M[1, 1], M[0, 0] * M[1, 1] - M[0, 1] * M[1, 0]
    r = cmath.sqrt(tr * tr - 4.0 * det)
    a, b = abs(0.5 * (tr + r)), abs(0.5 * (tr - r))
    big, small = max(a, b), min(a, b)
    return (
        math.log(big) + logs if big > 0 else -math.inf,
        math.log(small) + logs if small > 0 else -math.inf,
    )


@dataclass(frozen=True, eq=False)
class _Point:
    """Result of one point.

    Attributes
    ----------
    kind : int
        Index into :data:`KINDS` (``-1``: the integration failed).
    period : int
        ``n`` of a periodic point, else 0.
    lam : float
        The largest exponent.
    rot : float
        Rotation number of the strobe points (NaN for periodic points).
    y : ndarray of shape (2,) or None
        The final state.
    cost : int
        Forcing periods integrated.
    points : ndarray of shape (n, 2) or None
        The periodic orbit's strobe points, or the observed strobe points.
    """

    kind: int
    period: int
    lam: float
    rot: float
    y: np.ndarray | None
    cost: int
    points: np.ndarray | None

    @classmethod
    def periodic(cls, n, lam, y, *, cost, points):
        """A stable period-``n`` orbit (``P1`` or ``Pn``) with exponent ``lam``."""
        return cls(
            kind=0 if n == 1 else 1, period=n, lam=lam, rot=np.nan, y=y, cost=cost, points=points
        )


def _recurrence(strobe, inv_scale, max_period, closure, min_pairs):
    """The smallest ``n <= max_period`` whose last ``max(3 n, min_pairs)`` pairs
    ``|S_k - S_{k-n}| / scale`` are all below ``closure`` (0: none)."""
    s = strobe * inv_scale
    for n in range(1, max_period + 1):
        need = max(3 * n, min_pairs)
        if need + n > len(s):
            break
        tail = s[-(need + n) :]
        if np.max(np.abs(tail[n:] - tail[:-n])) < closure:
            return n
    return 0


def _stable_orbit(run, y, n):
    """``log|m_1| / (n T)`` of the period-``n`` orbit through ``y`` (its monodromy over
    ``n`` periods of the :class:`~discovery.ueda._runs.Integration` ``run``); NaN when it
    is not stable (``|m_1| >= 1``)."""
    T = run.period
    status, t, M, logs, _ = UK.monodromy_run(
        y, run.params, T, n, run.control(n), run.tol.atol_variational
    )
    _check(status, t, "the variational equations")
    log1, _ = _floquet(M, logs)
    return log1 / (n * T) if log1 < 0.0 else np.nan


def point(system, y, s, tol, buffers=None):
    """The regime at one ``(nu, B)`` from the state ``y`` at the forcing's phase 0.

    Parameters
    ----------
    system : UedaSystem
    y : ndarray of shape (2,)
    s : dict
        The chart's settings (:attr:`Chart.settings`).
    tol : Tolerances
    buffers : (ndarray of shape (transient, 2), ndarray of int), optional
        Strobe and run buffers of the transient, reused from point to point.

    Returns
    -------
    _Point
    """
    run = Integration.of(system, tol)
    T, p = run.period, run.params
    scale = system.scales()
    inv = 1.0 / scale
    n_tr, n_obs, P, closure = s["transient"], s["periods"], s["max_period"], s["closure"]
    if buffers is None:
        buffers = (np.empty((max(n_tr, 1), 2)), np.zeros(P + 1, dtype=np.int64))
    strobe, lengths = buffers
    y = np.asarray(y, dtype=float)
    cost = 0
    if n_tr > 0:
        rule = (P if s["early_exit"] else 0, s["min_pairs"], closure, inv)
        status, t, y, done, n = UK.scan_run(
            y, p, T, n_tr, rule, run.control(n_tr), (strobe, lengths)
        )
        _check(status, t, "the stroboscopic map")
        cost += done
        if n > 0:
            lam = _stable_orbit(run, y, n)
            cost += n
            if np.isfinite(lam):  # a stable orbit: P<n>
                points = strobe[done - n : done].copy()
                return _Point.periodic(n, lam, y, cost=cost, points=points)
            # an unstable orbit repeating by chance: the rest of the transient
            status, t, y, more, _ = UK.scan_run(
                y, p, T, n_tr - done, (0, 1, closure, inv), run.control(n_tr), (strobe, lengths)
            )
            _check(status, t, "the stroboscopic map")
            cost += more
    logs = np.empty((n_obs, 2))
    trace = np.empty(n_obs)
    obs = np.empty((n_obs, 2))
    status, t, yf, _ = UK.variational_run(
        0.0,
        y,
        p,
        T,
        n_obs,
        run.control(n_obs),
        tol.atol_variational,
        (logs, trace, obs),
    )
    _check(status, t, "the variational equations")
    cost += n_obs
    n = _recurrence(obs, inv, P, closure, s["min_pairs"])
    if n > 0:
        lam = _stable_orbit(run, yf, n)
        cost += n
        if np.isfinite(lam):
            return _Point.periodic(n, lam, yf, cost=cost, points=obs[-n:])
    lam = float(logs[:, 0].sum() / (n_obs * T))
    rules = RegimeRules(max_period=0, chaos_threshold=s["chaos_threshold"])
    reg = classify_points(obs, scale, lam, 0.0, rules=rules)
    return _Point(
        kind=KINDS.index(reg.kind),
        period=0,
        lam=lam,
        rot=reg.evidence["rotation_number"],
        y=yf,
        cost=cost,
        points=obs,
    )


def _same_orbit(a, b, T, scale, closure):
    """Whether two points' results are the same periodic orbit (``False`` when either is
    not periodic): the same period, and every strobe point of one orbit within ``tol``
    of the other's (in any phase), ``tol = max(10 closure, 3 (e_a + e_b))`` where ``e =
    closure / (1 - |m_1|)`` bounds how far a run whose points repeat to ``closure`` can be
    from its orbit (slow convergence near a bifurcation widens it)."""
    if not a.period or a.kind != b.kind or a.period != b.period:
        return False

    def err(r):
        m = math.exp(min(r.lam * r.period * T, 0.0))
        return closure / max(1.0 - m, 1e-12)

    A, Bp = a.points / scale, b.points / scale
    tol = max(10.0 * closure, 3.0 * (err(a) + err(b)))
    return max(float(np.min(np.max(np.abs(Bp - q), axis=1))) for q in A) <= tol


_FAILED = _Point(kind=-1, period=0, lam=np.nan, rot=np.nan, y=None, cost=0, points=None)


@dataclass(frozen=True, eq=False)
class _Row:
    """One row of the chart, swept: what its points share.

    Attributes
    ----------
    base : UedaSystem
        The chart's template system.
    B : float
        The row's forcing amplitude.
    settings : dict
        The chart's settings (:attr:`Chart.settings`).
    tol : Tolerances
    buffers : (ndarray, ndarray)
        The transient's strobe and run buffers, reused from point to point.
    """

    base: UedaSystem
    B: float
    settings: dict
    tol: Tolerances
    buffers: tuple

    @classmethod
    def of(cls, base, B, settings):
        """The row ``B`` of a chart of ``base`` with ``settings``."""
        s = settings
        return cls(
            base=base,
            B=B,
            settings=s,
            tol=Tolerances(rtol=s["rtol"], hmax_fraction=s["hmax_fraction"]),
            buffers=(
                np.empty((max(s["transient"], 1), 2)),
                np.zeros(s["max_period"] + 1, dtype=np.int64),
            ),
        )

    def system(self, nu):
        """The system at ``(nu, B)``."""
        return self.base.with_params(nu=float(nu), B=float(self.B))

    def sweep(self, nus, y):
        """The points at ``nus`` in turn, each from the last state of the one before (a
        failed point restarts the next from ``y0``): ``([_Point], final state)``."""
        out = []
        for nu in nus:
            try:
                r = point(self.system(nu), y, self.settings, self.tol, self.buffers)
            except IntegrationError:
                out.append(_FAILED)
                y = np.array(self.settings["y0"], dtype=float)
                continue
            out.append(r)
            y = r.y
        return out, y

    def coexisting(self, nu, u, d):
        """Whether the two sweeps ended on different attractors at ``nu``: at least one
        on a stable periodic orbit and the other not on it - as recorded and again after
        ``recheck`` times the transient more from both final states (a slow transient is
        not coexistence).  Two non-periodic results are not compared (a few dozen strobe
        points do not tell two quasi-periodic or chaotic sets apart reliably)."""
        s = self.settings
        if u.kind < 0 or d.kind < 0 or not (u.period or d.period):
            return False
        system = self.system(nu)
        T, scale = system.period, system.scales()
        if _same_orbit(u, d, T, scale, s["closure"]):
            return False
        if s["recheck"] <= 0 or s["transient"] <= 0:
            return True
        longer = dict(s, transient=s["transient"] * s["recheck"])
        try:
            u2, d2 = (point(system, r.y, longer, self.tol) for r in (u, d))
        except IntegrationError:
            return True
        return bool(u2.period or d2.period) and not _same_orbit(u2, d2, T, scale, s["closure"])


def sweep_row(ctx, job):
    """One row of the chart (a task of the executor); ``ctx`` is ``(system, settings)``,
    ``job`` is ``(B, nus)``."""
    b, nus = job
    c0 = time.process_time()
    base, s = ctx
    row = _Row.of(base, b, s)
    up, y = row.sweep(nus, np.array(s["y0"], dtype=float))

    def pack(r):
        return (r.kind, r.period, r.lam, r.rot, r.cost)

    down = coex = None
    if s["sweeps"] == 2:
        dn, _ = row.sweep(nus[::-1], y)
        dn = dn[::-1]
        coex = [row.coexisting(nu, u, d) for nu, u, d in zip(nus, up, dn, strict=True)]
        down = [pack(r) for r in dn]
    return [pack(r) for r in up], down, coex, time.process_time() - c0
