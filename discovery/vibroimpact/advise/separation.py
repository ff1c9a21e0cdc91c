"""One operating point: every candidate simulated to its steady state, and every pair's
predicted records compared by the verdict's own rule.

For an ordered pair (``a`` true, ``b`` judged) the record ``a`` predicts at the point is its
exact steady-state impulse with the next record's noise model (force noise ``relative x``
``a``'s peak, the sampling step, the cycles recorded); ``b`` is judged against it by
:func:`~discovery.vibroimpact.verify.evaluation.evaluate` (the verdict's evaluation: simulate,
align, criteria, noise floor under ``b`` by the parametric bootstrap, consistency limits).
The *separation* of the direction is ``max_k I_k / limit_k`` over the verdict's consistency
criteria (I2 and I4 for a force record), so 1 is where the verdict starts to reject ``b``;
that of the pair is the smaller of its two directions (a record settles the pair only when
it rejects the false law whichever of the two is true).  A difference of regime (period or
contacts per orbit) rejects outright: the pair is *separated by regime*, and its criteria
ratio is still reported.

Without positions (a force record) the predicted record is noise-free (its noise enters
through the floor): a noisy record scores a wrong law higher on average (``E|d + n| >=
|d|``), so a separation >= 1 is a conservative prediction of a rejection.  With positions
(``NoiseModel.position``) the predicted records are synthetic measurements of ``a`` on its
orbit (:func:`~discovery.vibroimpact.dynamics.synthetic.synthesize`) prepared like any
record (:meth:`~discovery.vibroimpact.verify.reference.Reference.from_measurement`: its span,
the machine's states), and ``b`` is judged by the verdict's record-span comparison: I2, I4
and I5 (the penetration) of ``b`` against the noise-free one, over their limits from the
noisy one (force and position noise seeded by ``NoiseModel.seed``; the limits come from the
noise floor under ``b``).
"""

from dataclasses import dataclass, replace

import numpy as np

from ...errors import InputError, IntegrationError, VidiError
from ..dynamics.law_response import impulse_from_steady_state
from ..dynamics.simulation import simulate
from ..dynamics.steady_states import steady_state
from ..dynamics.synthetic import synthesize
from ..verify.evaluation import evaluate
from ..verify.reference import Reference

__all__ = [
    "Prediction",
    "PairSeparation",
    "Point",
    "evaluate_point",
    "point_job",
    "inseparable",
    "rank_key",
]


@dataclass(frozen=True)
class Prediction:
    """What one candidate predicts at a point.

    Attributes
    ----------
    status : str
        ``"ok"``, ``"nonperiodic"``, ``"no-contact"`` or ``"failed"``.
    regime : str
        ``"P1"``, ... (``""`` unless ok).
    impacts : int
        Contacts per orbit.
    peak_force : float
        Largest contact force [N] on the orbit (0 unless ok).
    max_penetration : float
        Largest penetration ``w1 - w2`` [m] on the orbit (0 unless ok).
    message : str
    max_rate : float
        Largest penetration rate [m/s] in contact on the orbit (0 unless ok).
    domain : float
        The rate up to which the candidate satisfies the paper's condition (6) at this
        point (:meth:`~discovery.vibroimpact.model.law.ForceLaw.dissipative_rate`; ``inf``
        when everywhere).
    """

    status: str
    regime: str = ""
    impacts: int = 0
    peak_force: float = 0.0
    max_penetration: float = 0.0
    message: str = ""
    max_rate: float = 0.0
    domain: float = float("inf")

    @property
    def leaves_domain(self):
        """Whether the candidate breaks condition (6) at this point (a record here rejects it
        on physics): its orbit reaches rates where it feeds energy into the impact, or it has
        no periodic orbit while the other candidates' orbits reach rates beyond its domain
        (``max_rate`` is then theirs: the energy its impacts would gain is what keeps it
        from settling)."""
        return self.status in ("ok", "nonperiodic") and self.max_rate > self.domain

    def to_dict(self):
        return {
            "status": self.status,
            "regime": self.regime,
            "impacts": int(self.impacts),
            "peak_force": _num(self.peak_force),
            "max_penetration": _num(self.max_penetration),
            "message": self.message,
            "max_rate": _num(self.max_rate),
            "domain": _num(self.domain),
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            status=d["status"],
            regime=d["regime"],
            impacts=int(d["impacts"]),
            peak_force=_float(d["peak_force"]),
            max_penetration=_float(d["max_penetration"]),
            message=d["message"],
            max_rate=_float(d.get("max_rate", 0.0)),
            domain=_float(d.get("domain", float("inf"))),
        )


@dataclass(frozen=True)
class PairSeparation:
    """How far two candidates' predicted records are apart at a point.

    Attributes
    ----------
    pair : (int, int)
        Candidate indices ``(i, j)``, ``i < j``.
    separation : float
        ``min`` over the two directions of ``max_k I_k / limit_k``: >= 1 means a record
        here rejects the false one of the two whichever is true.
    directions : (float, float)
        ``j`` judged with ``i`` true, ``i`` judged with ``j`` true.
    criteria : (dict, dict)
        The criteria of each direction.
    limits : (dict, dict)
        The verdict's limits of each direction (from the noise floor).
    regime_change : bool
        The two predict different regimes or contacts per orbit: separated outright.
    physics : bool
        One of the two predicts an orbit that leaves its dissipative domain (condition (6)
        broken on it): a record here rejects that one on physics, separated outright.
    """

    pair: tuple
    separation: float
    directions: tuple
    criteria: tuple
    limits: tuple
    regime_change: bool = False
    physics: bool = False

    @property
    def separated(self):
        return bool(self.regime_change or self.physics or self.separation >= 1.0)

    @property
    def score(self):
        """For ranking: a regime change or a break of physics counts as infinitely
        separated."""
        return float("inf") if self.regime_change or self.physics else self.separation

    def to_dict(self):
        return {
            "pair": [int(k) for k in self.pair],
            "separation": _num(self.separation),
            "directions": [_num(v) for v in self.directions],
            "criteria": [{k: _num(v) for k, v in c.items()} for c in self.criteria],
            "limits": [{k: _num(v) for k, v in c.items()} for c in self.limits],
            "regime_change": bool(self.regime_change),
            "physics": bool(self.physics),
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            pair=tuple(int(k) for k in d["pair"]),
            separation=_float(d["separation"]),
            directions=tuple(_float(v) for v in d["directions"]),
            criteria=tuple({k: _float(v) for k, v in c.items()} for c in d["criteria"]),
            limits=tuple({k: _float(v) for k, v in c.items()} for c in d["limits"]),
            regime_change=bool(d["regime_change"]),
            physics=bool(d.get("physics", False)),
        )


@dataclass(frozen=True)
class Point:
    """One operating point of the grid.

    Attributes
    ----------
    amplitude, frequency : float
        Drive amplitude [N] and frequency [Hz].
    m2 : float or None
        Moulding mass [kg] (``None``: the scenario's).
    predictions : tuple of Prediction
        One per candidate.
    pairs : tuple of PairSeparation
        Every pair (empty when the point is not usable).
    excluded : str
        Why the point is not advised (``""`` when usable): outside the safe region, or a
        candidate without a periodic steady state with contact.
    unsafe : bool
        Excluded by the safe region.
    stage : str
        ``"coarse"`` or ``"refine"``.
    """

    amplitude: float
    frequency: float
    m2: float | None
    predictions: tuple
    pairs: tuple = ()
    excluded: str = ""
    unsafe: bool = False
    stage: str = "coarse"

    @property
    def usable(self):
        return not self.excluded

    @property
    def smallest(self):
        """The smallest pair separation (``nan`` when not usable)."""
        return self.smallest_separation()

    def smallest_separation(self, ignore=frozenset()):
        """The smallest separation over the pairs not in ``ignore`` (all pairs when every
        pair is ignored; ``nan`` when not usable)."""
        qs = [q for q in self.pairs if q.pair not in ignore] or self.pairs
        return min((q.separation for q in qs), default=float("nan"))

    def to_dict(self):
        return {
            "amplitude": float(self.amplitude),
            "frequency": float(self.frequency),
            "m2": None if self.m2 is None else float(self.m2),
            "predictions": [p.to_dict() for p in self.predictions],
            "pairs": [p.to_dict() for p in self.pairs],
            "excluded": self.excluded,
            "unsafe": bool(self.unsafe),
            "stage": self.stage,
            "smallest_separation": _num(self.smallest),
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            amplitude=float(d["amplitude"]),
            frequency=float(d["frequency"]),
            m2=None if d["m2"] is None else float(d["m2"]),
            predictions=tuple(Prediction.from_dict(p) for p in d["predictions"]),
            pairs=tuple(PairSeparation.from_dict(p) for p in d["pairs"]),
            excluded=d["excluded"],
            unsafe=bool(d["unsafe"]),
            stage=d["stage"],
        )


def _num(v):
    """JSON-safe float: ``None`` for nan, ``"inf"`` for infinity."""
    v = float(v)
    if np.isnan(v):
        return None
    if np.isinf(v):
        return "inf" if v > 0 else "-inf"
    return v


def _float(v):
    return float("nan") if v is None else float(v)


@dataclass(frozen=True)
class _Orbit:
    """A candidate's steady state and exact impulse at a point (internal)."""

    prediction: Prediction
    impulse: object = None
    steady: object = None


def _orbit(scenario, law, tolerances):
    try:
        ss = steady_state(scenario, law, tolerances=tolerances)
        if not ss.periodic:
            return _Orbit(Prediction("nonperiodic", message="no stable periodic steady state"))
        imp = impulse_from_steady_state(scenario, law, ss, tolerances=tolerances)
        if imp is None:
            return _Orbit(Prediction("no-contact", regime=ss.regime, message="no contact"))
        W = ss.n_periods * scenario.period
        tr = simulate(
            scenario,
            law,
            (ss.t0, ss.t0 + W),
            y0=ss.y0,
            t_eval=np.linspace(ss.t0, ss.t0 + W, 400 * ss.n_periods + 1),
            tolerances=tolerances,
            zeta_max0=ss.zeta_max0,
        )
        z, zd = tr.y[0] - tr.y[2], tr.y[1] - tr.y[3]
        pen = float(np.max(z))
        rate = float(np.max(np.abs(zd[z > 0]))) if np.any(z > 0) else 0.0
        domain = law.dissipative_rate(scenario, up_to=max(4.0 * scenario.scales()[1], 2 * rate))
    except (IntegrationError, InputError) as exc:
        return _Orbit(Prediction("failed", message=str(exc)))
    pred = Prediction(
        "ok", ss.regime, int(ss.impacts), imp.peak, max(pen, 0.0), max_rate=rate, domain=domain
    )
    return _Orbit(pred, imp, ss)


def _synthetic(orbit, scenario, law, noise, noisy):
    """A synthetic record of ``law`` on its orbit, prepared like any record."""
    meas = synthesize(
        scenario,
        law,
        periods=max(2, int(round(noise.periods))),
        fs=1.0 / noise.dt,
        noise=noise.relative if noisy else 0.0,
        seed=noise.seed,
        ss=orbit.steady,
        position_noise=noise.position if noisy else 0.0,
    )
    return Reference.from_measurement(meas, scenario, n_boot=noise.n_boot, seed=noise.seed)


def _predicted_reference(orbit, scenario, law, noise):
    """The records a candidate predicts, ``(noisy, clean)``: the first sets the verdict's
    limits (its noise floor), the second the criteria.  Without positions both are its
    exact cycle with the next record's noise model; with positions, synthetic records on
    its orbit with and without the noise (a judged law's criteria against one noise
    realisation would make the grid's best point the luckiest realisation)."""
    if noise.position is not None:
        return (
            _synthetic(orbit, scenario, law, noise, True),
            _synthetic(orbit, scenario, law, noise, False),
        )
    imp = orbit.impulse
    sigma = noise.relative * imp.peak
    n_cycles = max(1, int(noise.periods // imp.n_periods) - 1)
    E = type(imp)(
        t=imp.t,
        F=imp.F,
        duration=imp.duration,
        support=imp.support,
        n_periods=imp.n_periods,
        onset=imp.onset,
        noise=sigma,
        n_cycles=n_cycles,
        onsets=imp.onsets,
    )
    nz = {"F": sigma, "zeta": None, "impact_velocity": None, "dt": noise.dt, "n_cycles": n_cycles}
    ref = Reference(impulse=E, noise=nz, n_boot=noise.n_boot, seed=noise.seed, source="prediction")
    return ref, ref


def _direction(scenario, judged, references, tolerances):
    """``(ratio, criteria, limits)`` of ``judged`` against a candidate's predicted records
    ``(noisy, clean)``, by the verdict's evaluation: the limits from the noisy one (its
    noise floor under ``judged``), the criteria from the clean one (a judged law without a
    periodic orbit with contact there is rejected: ``inf``)."""
    noisy, clean = references
    ev = evaluate(scenario, judged, noisy, tolerances=tolerances)
    if ev.status != "ok":
        return float("inf"), {}, {}
    lim = ev.limits
    crit = ev.criteria
    if clean is not noisy:
        ev_c = evaluate(scenario, judged, clean, tolerances=tolerances, floor=False)
        if ev_c.status != "ok":
            return float("inf"), {}, {}
        crit = ev_c.criteria
    ratio = max(crit[k] / lim[k] for k in lim)
    return float(ratio), {k: crit[k] for k in lim}, dict(lim)


def _physics_pair(i, j):
    """A pair one of whose candidates breaks condition (6) here (separated outright)."""
    inf = float("inf")
    return PairSeparation((i, j), inf, (inf, inf), ({}, {}), ({}, {}), physics=True)


def _beyond_domain(scenario, laws, preds):
    """The predictions with each nonperiodic candidate's dissipative domain set against
    the largest rate the other candidates' orbits reach (:attr:`Prediction.leaves_domain`)."""
    rates = [p.max_rate for p in preds if p.status == "ok"]
    if not rates or all(p.status == "ok" for p in preds):
        return preds
    top = max(rates)
    out = []
    for law, p in zip(laws, preds, strict=True):
        if p.status == "nonperiodic":
            domain = law.dissipative_rate(scenario, up_to=max(4.0 * scenario.scales()[1], 2 * top))
            p = replace(p, max_rate=top, domain=domain)
        out.append(p)
    return tuple(out)


def at_point(scenario, amplitude, frequency, m2=None):
    """``scenario`` driven at an operating point (its moulding's mass too, when given)."""
    changes = {"A": float(amplitude), "frequency": float(frequency)}
    if m2 is not None:
        changes["m2"] = float(m2)
    return scenario.replace(**changes)


def evaluate_point(context, amplitude, frequency, m2=None, stage="coarse"):
    """Evaluate one operating point (see the module docstring).

    Parameters
    ----------
    context : _Context
        The scenario, candidates, noise model, safe region and tolerances.
    amplitude, frequency : float
    m2 : float or None
    stage : str

    Returns
    -------
    Point
    """
    sc = at_point(context.scenario, amplitude, frequency, m2)
    orbits = [_orbit(sc, law, context.tolerances) for law in context.laws]
    preds = _beyond_domain(sc, context.laws, tuple(o.prediction for o in orbits))
    point = {"amplitude": amplitude, "frequency": frequency, "m2": m2, "stage": stage}
    bad = [(k, p) for k, p in enumerate(preds) if p.status != "ok" and not p.leaves_domain]
    if bad or all(p.status != "ok" for p in preds):
        why = "; ".join(f"candidate {k + 1}: {p.status}" for k, p in bad)
        return Point(predictions=preds, excluded=why, **point)
    unsafe = [
        (k, context.safe.violation(p.peak_force, p.max_penetration)) for k, p in enumerate(preds)
    ]
    unsafe = [(k, w) for k, w in unsafe if w]
    if unsafe:
        why = "; ".join(f"candidate {k + 1}: {w}" for k, w in unsafe)
        return Point(predictions=preds, excluded=f"unsafe ({why})", unsafe=True, **point)
    try:
        refs = [
            _predicted_reference(o, sc, law, context.noise) if p.status == "ok" else None
            for o, law, p in zip(orbits, context.laws, preds, strict=True)
        ]
    except VidiError as exc:
        why = f"a predicted record could not be prepared ({exc})"
        return Point(predictions=preds, excluded=why, **point)
    pairs = []
    n = len(orbits)
    for i in range(n):
        for j in range(i + 1, n):
            if refs[i] is None or refs[j] is None:
                # a candidate without an orbit here because it breaks condition (6) at the
                # rates the others reach: separated on physics
                inf = float("inf")
                pairs.append(
                    PairSeparation((i, j), inf, (inf, inf), ({}, {}), ({}, {}), physics=True)
                )
                continue
            r_ij, c_ij, l_ij = _direction(sc, context.laws[j], refs[i], context.tolerances)
            r_ji, c_ji, l_ji = _direction(sc, context.laws[i], refs[j], context.tolerances)
            regime = preds[i].regime != preds[j].regime or preds[i].impacts != preds[j].impacts
            pairs.append(
                PairSeparation(
                    pair=(i, j),
                    separation=min(r_ij, r_ji),
                    directions=(r_ij, r_ji),
                    criteria=(c_ij, c_ji),
                    limits=(l_ij, l_ji),
                    regime_change=bool(regime),
                    physics=preds[i].leaves_domain or preds[j].leaves_domain,
                )
            )
    return Point(predictions=preds, pairs=tuple(pairs), **point)


def inseparable(points):
    """The pairs no usable point separates (separation < 1 and the same regime at every
    point): within the noise they are one law over the whole bounds (e.g. a model and the
    same model with a tiny extra term), so no record in the bounds can settle them and the
    ranking leaves them out.  frozenset of ``(i, j)``."""
    usable = [p for p in points if p.usable]
    if not usable:
        return frozenset()
    pairs = {q.pair for q in usable[0].pairs}
    separated = {q.pair for p in usable for q in p.pairs if q.separated}
    return frozenset(pairs - separated)


def rank_key(point, ignore=frozenset()):
    """Sort key of a usable point, best first: more pairs separated, then the largest
    smallest separation (a regime change counting as infinite), then the largest smallest
    criteria ratio, over the pairs not in ``ignore`` (see :func:`inseparable`)."""
    qs = [q for q in point.pairs if q.pair not in ignore] or list(point.pairs)
    return (
        -sum(q.separated for q in qs),
        -min(q.score for q in qs),
        -min(q.separation for q in qs),
        point.amplitude,
        point.frequency,
    )


def point_job(context, job):
    """The executor's task: one point ``(amplitude, frequency, m2, stage)``."""
    return evaluate_point(context, *job)
