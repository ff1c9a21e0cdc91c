"""The classification of the steady states of Ueda's oscillators: periodic (``P1``,
``P<n>``), quasi-periodic (``beat``) or chaotic, from stroboscopic points and the largest
Lyapunov exponent, a recurring orbit polished by shooting.
"""

from dataclasses import dataclass

import numpy as np

from .._api._printing import readable
from ..errors import IntegrationError
from ._runs import Integration
from .exponents import Lyapunov, variational_run
from .periodic import UedaMap, periodic_orbit
from .strobe import state_after

__all__ = ["REGIMES", "RegimeRules", "Regime", "rotation_number", "classify_points", "classify"]

REGIMES = ("P1", "Pn", "beat", "chaotic")


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


@dataclass(frozen=True)
class RegimeRules:
    """The thresholds of :func:`classify_points`.

    Parameters
    ----------
    max_period : int
        The longest period recognised, in forcing periods.
    closure : float
        Recurrence distance (relative to the scale) below which the strobe points repeat.
    chaos_threshold : float
        A largest exponent above ``max(chaos_threshold, 3 stderr)`` is chaos.
    shooting_tol : float
        Newton tolerance of the shooting that polishes a recurring orbit.
    """

    max_period: int = 8
    closure: float = 1e-5
    chaos_threshold: float = 0.01
    shooting_tol: float = 1e-8


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

    @classmethod
    def from_dict(cls, d):
        """The regime of :meth:`as_dict`'s document (its evidence as the document holds
        it: text keys, lists for arrays)."""
        return cls(regime=d["regime"], kind=d["kind"], period=d["period"], evidence=d["evidence"])

    def _lines(self):
        rule = self.evidence.get("rule")
        return [f"regime {self.regime}" + (f": {rule}" if rule else "")]


def classify_points(strobe, scale, lam, lam_stderr=0.0, *, rules=None, period_map=None):
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

    Parameters
    ----------
    strobe : array_like of shape (n_points, 2)
        Stroboscopic points ``(x, x')``.
    scale : array_like of shape (2,)
        Characteristic size of ``x`` and ``x'`` (distances are relative to it).
    lam, lam_stderr : float
        The largest Lyapunov exponent [1/unit time] and its standard error.
    rules : RegimeRules, optional
        The thresholds (default :class:`RegimeRules`).
    period_map : UedaMap, optional
        The system's period map, for shooting.

    Returns
    -------
    Regime
    """
    rules = RegimeRules() if rules is None else rules
    max_period, closure = rules.max_period, rules.closure
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
            orb = _shoot(period_map, s[-1], n, rules.shooting_tol, ev)
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
    thr = max(rules.chaos_threshold, 3.0 * lam_stderr)
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


def classify(
    system,
    y0=None,
    *,
    transient=300,
    periods=400,
    tolerances=None,
    shoot=True,
    period_map=None,
    **rules,
):
    """The regime reached from ``y0``: ``(Regime, Lyapunov, strobe points)``.

    ``shoot`` (default): a recurring orbit is polished by shooting (with ``period_map``,
    by default the system's :class:`~discovery.ueda.periodic.UedaMap`) and called
    periodic only if it converges to a stable orbit; its Floquet multipliers and Newton
    residual are in the evidence (see :func:`classify_points`).  ``rules`` are the
    fields of :class:`RegimeRules` (``max_period``, ``closure``, ``chaos_threshold``,
    ``shooting_tol``).
    """
    rules = RegimeRules(**rules)
    run = Integration.of(system, tolerances)
    y = state_after(system, y0, transient, run.tol)
    logs, trace, strobe, _ = variational_run(run, y, periods)
    batches = min(20, max(2, int(periods) // 20))
    lyap = Lyapunov.from_logs(logs, trace, run.period, batches=batches, rtol=run.tol.rtol)
    if shoot and period_map is None:
        period_map = UedaMap(system, run.tol)
    reg = classify_points(
        strobe, system.scales(), lyap.value, lyap.stderr, rules=rules, period_map=period_map
    )
    return reg, lyap, strobe
