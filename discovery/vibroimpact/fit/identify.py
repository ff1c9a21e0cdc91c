"""Identification by simulation (output error): minimise a criterion over a law's coefficients.

Every objective evaluation is :func:`discovery.vibroimpact.verify.evaluate` (the one evaluation
function: simulate to the periodic steady state from the record's measured state,
align the impacts, sample like the record, score I0..I4).  Several records, each with
its own scenario (operating point), are fitted jointly.  Coefficients are optimised in
units of the start values (``x_i = c_i / c_i^start``) so all methods see a
well-scaled problem.  Methods:

``coordinate-descent``
    The paper's accelerated coordinate descent: along each coefficient in turn
    try a step, double it while it keeps improving, else try the other direction,
    else halve it; stop when every step is below ``xtol``.
``nelder-mead``
    scipy's Nelder–Mead simplex (derivative-free).
``least-squares``
    scipy's trust-region least squares on the residual vector ``(F_N - F_E)`` of every
    record, weighted so that each record's squared norm is its ``I3^2`` (a smooth
    surrogate, Gauss–Newton fast); the chosen criterion is reported.

The simulation budget counts every simulation, the Jacobians' included (one run per record
with the variational equations for the law's coefficients: :meth:`_Objective.jacobian`;
forward differences for other parameters).  A simulation that fails or has no periodic
orbit with contact is recorded in ``failures`` (the optimiser sees a penalty); a start law
that fails is an error.

Coefficient uncertainty: the Jacobian ``J`` of the weighted residuals at the optimum
(as the least squares' own, exact where it can be) gives the
covariance ``s^2 (J^T J)^-1`` with ``s^2 = RSS / (m - p)`` (as lmfit scales it: the
residual variance estimated from the fit), hence a standard error per coefficient.
"""

import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.optimize import least_squares, minimize

from ..._printing import coefficient_lines, fmt, readable
from ..._progress import tick
from ..._result import Result, part
from ..._validate import Choice, Real, Text, params
from ...errors import InputError, IntegrationError, VidiTypeError
from ...numerics.executor import map_on
from ..data.impulse import Impulse
from ..data.measurement import Measurement
from ..dynamics import Tolerances
from ..model.law import ForceLaw, Term
from ..model.scenario import Scenario
from ..verify import Reference, evaluate
from ..verify.criteria import criteria_lines
from ..verify.criteria import criterion as _criterion
from ..verify.evaluate import Evaluation
from ..verify.motion import penetration_jacobian, penetration_residuals, penetration_size

__all__ = [
    "IdentificationResult",
    "identify",
    "METHODS",
    "as_records",
    "pair_records",
    "contact_scales",
    "record_start",
    "cycle_pairs",
    "Intervals",
    "bootstrap_intervals",
]

METHODS = ("coordinate-descent", "nelder-mead", "least-squares")
# how a bootstrap replicate of the intervals is refitted (see bootstrap_intervals)
INTERVAL_REFITS = ("two-step", "full")
#: the bootstrap replicates' noise: the record's own residuals, each cycle's multiplied by
#: one weight (``"cycles"``, the default), or white noise of the record's level (``"white"``)
INTERVAL_NOISE = ("cycles", "white")
_PENALTY = 10.0  # criterion value of a failed simulation (criteria are O(1))
_JAC_STEP = 1e-5  # relative step of the standard-error Jacobian


@readable
@dataclass(frozen=True, eq=False)
class IdentificationResult(Result):
    """Outcome of :func:`identify`.

    Attributes
    ----------
    law : ForceLaw or Model
        Identified law (of the kind ``start`` was: a model when more than a law was
        fitted).
    criterion : str
        The criterion minimised (reported for every method; the mean over records).
    value : float
        Its final value.
    criteria : dict
        All criteria ``I0..I4`` at the identified law (the mean over records).
    evaluations : tuple of Evaluation
        The identified law against each record (without noise floor).
    method : str
    n_simulations : int
        Steady-state simulations used (every record counts, Jacobians included; the final
        check adds one per record).
    iterations : list of dict
        Every improving iterate: ``coefficients`` {term: value}, ``value``,
        ``n_simulations``.
    standard_errors : dict
        ``{term: standard error}`` (empty when not computed or not estimable).
    correlation : ndarray or None
        Correlation matrix of the coefficients (order of ``law.names``).
    failures : list of dict
        Simulations that failed: ``coefficients``, ``status``, ``message``.
    seconds : float
    message : str
    intervals : Intervals or None
        Bootstrap intervals (``n_boot_intervals``).
    checks : tuple of Evaluation
        The identified law against every record with its noise floor (``check=True``):
        :attr:`consistent` and :attr:`verdict` come from them.
    """

    KIND = "identify"
    _LOAD = {
        "law": lambda d: ForceLaw.parse(d["law"]),
        "criteria": lambda d: d.get("criteria_found", {}),
        "correlation": lambda d: (
            None if d.get("correlation") is None else np.array(d["correlation"], float)
        ),
        "intervals": lambda d: part(Intervals, d.get("intervals")),
        "checks": lambda d: tuple(part(Evaluation, e) for e in d.get("checks", ())),
    }

    law: object
    criterion: str
    value: float
    criteria: dict
    method: str
    n_simulations: int
    evaluations: tuple = ()
    iterations: list = field(default_factory=list)
    standard_errors: dict = field(default_factory=dict)
    correlation: object = None
    failures: list = field(default_factory=list)
    seconds: float = 0.0
    message: str = ""
    intervals: object = None
    checks: tuple = ()

    @property
    def coefficients(self):
        return _named(self.law)

    @property
    def consistent(self):
        """Consistent with every record (``None`` when not checked)."""
        return all(ev.consistent for ev in self.checks) if self.checks else None

    @property
    def verdict(self):
        """One sentence on the identified law against the record(s)."""
        if not self.checks:
            return "not checked against the records' noise floors (check=False)"
        if len(self.checks) == 1:
            return self.checks[0].verdict or self.checks[0].message
        bad = [(i, ev) for i, ev in enumerate(self.checks) if not ev.consistent]
        if not bad:
            return f"consistent with all {len(self.checks)} records"
        if len(bad) == 1:
            i, ev = bad[0]
            return f"inconsistent with record {i + 1}: {ev.verdict or ev.message}"
        # every record's verdict in full: none is cut to "(and 1 more)"
        return f"inconsistent with {len(bad)} of {len(self.checks)} records: " + "; ".join(
            f"record {i + 1}: {ev.verdict or ev.message}" for i, ev in bad
        )

    def as_dict(self):
        """The result as JSON-ready data (the identification part of ``summary.json``)."""
        return {
            "criterion": self.criterion,
            "method": self.method,
            "coefficients": self.coefficients,
            "law": self.law.to_text(),
            "latex": self.law.latex(),
            "standard_errors": self.standard_errors,
            "intervals": None if self.intervals is None else self.intervals.as_dict(),
            "correlation": self.correlation,
            "value": self.value,
            "criteria_found": self.criteria,
            "n_simulations": self.n_simulations,
            "failures": self.failures,
            "iterations": self.iterations,
            "message": self.message,
            "seconds": self.seconds,
            "consistent": self.consistent,
            "verdict": self.verdict,
            # the consistency limits the law was judged by (one record; with several,
            # each record has its own)
            "limits": dict(self.checks[0].limits) if len(self.checks) == 1 else {},
            "checks": [ev.as_dict() for ev in self.checks],
        }

    def _lines(self):
        out = [
            f"identified {self.law}: {self.criterion} = {fmt(self.value, 3)} "
            f"({self.method}, {self.n_simulations} simulations, {self.seconds:.1f} s)"
        ]
        out.append(f"  verdict: {self.verdict}")
        out += coefficient_lines(self.coefficients, self.standard_errors, self.intervals)
        one = self.checks[0] if len(self.checks) == 1 else None
        out += criteria_lines(
            self.criteria,
            one.noise_floor if one is not None else None,
            one.limits if one is not None else None,
        )
        if self.message:
            out.append(f"  optimiser: {self.message}")
        if self.failures:
            out.append(f"  {len(self.failures)} simulation(s) failed on the way")
        return out


class _Budget(Exception):
    """The simulation budget is used up."""


def pair_records(scenario, records):
    """``[(scenario, record), ...]``: one scenario per record, or one for all; a single
    scenario or record may be given bare."""
    scs = list(scenario) if isinstance(scenario, list | tuple) else [scenario]
    recs = list(records) if isinstance(records, list | tuple) else [records]
    if len(scs) == 1 and len(recs) > 1:
        scs = scs * len(recs)
    if not recs or len(scs) != len(recs):
        raise InputError(
            f"{len(recs)} record(s) but {len(scs)} scenario(s): give one scenario "
            "per record (or one for all)"
        )
    return list(zip(scs, recs, strict=True))


def as_records(scenario, reference):
    """``[(scenario, Reference), ...]`` from one pair or from two equal-length sequences.

    ``reference`` may be a :class:`~discovery.vibroimpact.verify.Reference`, a
    :class:`~discovery.vibroimpact.data.measurement.Measurement` (prepared with
    :meth:`Reference.from_measurement`) or an exact
    :class:`~discovery.vibroimpact.data.impulse.Impulse`.
    """
    out = []
    for sc, ref in pair_records(scenario, reference):
        if isinstance(ref, Impulse):
            ref = Reference.exact(ref, source="impulse")
        elif not isinstance(ref, Reference):
            ref = Reference.from_measurement(ref, sc)
        out.append((sc, ref))
    return out


def contact_scales(scenario, reference):
    """Typical contact time [s], impact velocity [m/s] and penetration ``v tau / pi`` [m] of
    a record (the scenario's period and motion scale when the record lacks them)."""
    E = reference.impulse
    tau = float(np.median(E.support[:, 1] - E.support[:, 0])) if len(E.support) else scenario.period
    v = (reference.noise.get("impact_velocity") if reference.noise else None) or scenario.scales()[
        1
    ]
    return tau, v, v * tau / np.pi


def record_start(scenario, reference, terms):
    """Start coefficients for ``terms`` from the record alone (a spring-dashpot estimate, to
    be refined by simulation): stiffness ``k = mu (pi / tau)^2`` from the contact time and
    the reduced mass, damping ``c = F(0+) / v`` from the force jump at onset (5 % of
    critical without a jump), each term scaled to give that force at the typical
    penetration ``z0``: elastic terms (``b = 0``) ``k z0 / z0^a``, the others ``c / z0^a``.

    Returns
    -------
    ndarray
        One coefficient per term.
    """
    E = reference.impulse
    tau, v, z0 = contact_scales(scenario, reference)
    mu = scenario.m1 * scenario.m2 / (scenario.m1 + scenario.m2)
    k = mu * (np.pi / tau) ** 2
    jump = float(E.evaluate(0.0, "right"))
    c = jump / v if jump > 0.05 * E.peak else 0.1 * np.sqrt(k * mu)
    return np.array([(k * z0 if t.b == 0 else c) / z0**t.a for t in terms])


def _named(model):
    return dict(zip(model.names, model.coefficients, strict=True))


def model_parts(model, observe=None):
    """``(law, scenario -> scenario, observation)`` of what :func:`identify` fits: a
    :class:`ForceLaw`, or a model with more parameters than a law's coefficients (the
    missing-effect workflow's :class:`~discovery.vibroimpact.explain.Model`: ``coefficients``,
    ``names``, ``with_coefficients``, ``law``, ``apply(scenario)``, ``observe()``)."""
    if isinstance(model, ForceLaw):
        return model, (lambda sc: sc), observe
    return model.law, model.apply, model.observe()


def _measured_cycles(ref):
    """The measured cycles a record is compared on: every block of a record span, else
    the one aligned cycle."""
    return list(ref.blocks) if getattr(ref, "blocks", ()) else [ref.impulse]


def cycle_pairs(ev, ref):
    """``[(measured, simulated), ...]`` of an evaluation, one per compared cycle."""
    return ev.extra.get("blocks") or [(ref.impulse, ev.simulated)]


def _residual_weights(ref):
    """Per measured cycle: trapezoid-like sample spacing, normalised so that the sum of
    squared residuals of a cycle is its I3^2, times the square root of its share of the
    record's cycles."""
    cycles = _measured_cycles(ref)
    n = np.array([max(E.n_cycles, 1) for E in cycles], dtype=float)
    share = np.sqrt(n / n.sum())
    return [
        s * np.sqrt(np.gradient(E.t) / max(np.trapezoid(E.F**2, E.t), 1e-300))
        for E, s in zip(cycles, share, strict=True)
    ]


class _Objective:
    """Counts and caches simulations, enforces the budget, records the best-so-far path."""

    def __init__(self, records, start, name, tolerances, max_sim, observe=None, progress=None):
        self.progress = progress
        self.records, self.start, self.name = records, start, name
        self.observe = observe
        self.tol, self.max_sim = tolerances, max_sim
        _criterion(name)
        self.c0 = np.array(start.coefficients)
        self.n = 0
        self.cache = {}
        self.best = (np.inf, None)
        # least squares: the point of smallest sum of squared residuals (the estimate whose
        # spread the standard errors and the bootstrap describe), apart from the criterion's
        self.best_squares = (np.inf, None)
        self.path, self.failures = [], []
        # continuation: per record compared with its steady orbit, the solved orbits
        # ``[(x, SteadyState), ...]``; the next one starts from the nearest (Newton from
        # it, the cold search only when that fails: steady_state's ``guess``)
        self.orbits = [[] for _ in records]
        # residual weights: trapezoid-like sample spacing, normalised so that the sum
        # of squared residuals of a record is its I3^2
        self.w = [_residual_weights(ref) for _, ref in records]
        # which residual columns the variational equations give (fixed by the start)
        self.exact_columns = self._exact_columns()
        # the penetration's residual rows (records with positions), after the force's
        self.n_motion = sum(penetration_size(ref) for _, ref in self.records)

    def law(self, x):
        return self.start.with_coefficients(self.c0 * np.asarray(x))

    def evaluations(self, x):
        key = tuple(np.round(np.asarray(x, dtype=float), 14))
        if key not in self.cache:
            if self.n + len(self.records) > self.max_sim:
                raise _Budget
            law, machine, observe = model_parts(self.law(x), self.observe)
            evs = []
            for i, (sc, ref) in enumerate(self.records):
                self.n += 1
                tick(self.progress, "identify: simulations", self.n, self.max_sim)
                ev = evaluate(
                    machine(sc),
                    law,
                    ref,
                    tolerances=self.tol,
                    floor=False,
                    observe=observe,
                    smooth_onset=True,
                    **self._continued(i, x),
                )
                if ev.status == "ok" and getattr(ref, "span", None) is None:
                    self.orbits[i].append((np.asarray(x, dtype=float), ev.steady))
                evs.append(ev)
                if ev.status != "ok":
                    self.failures.append(
                        {
                            "coefficients": _named(self.law(x)),
                            "status": ev.status,
                            "message": ev.message or ev.verdict,
                        }
                    )
                    break
            self.cache[key] = evs if all(e.status == "ok" for e in evs) else None
        return self.cache[key]

    def _continued(self, i, x):
        """``{"guess": orbit}``: the solved steady orbit of record ``i`` nearest to ``x``
        (none for a record compared over its span, or before the first)."""
        if not self.orbits[i]:
            return {}
        d = [np.max(np.abs(xs - x) / np.maximum(np.abs(xs), 1e-12)) for xs, _ in self.orbits[i]]
        return {"guess": self.orbits[i][int(np.argmin(d))][1]}

    def __call__(self, x):
        evs = self.evaluations(x)
        if evs is None:
            return _PENALTY
        v = float(np.mean([e.criteria[self.name] for e in evs]))
        if v < self.best[0]:
            self.best = (v, np.array(x, dtype=float))
            self.path.append(
                {"coefficients": _named(self.law(x)), "value": v, "n_simulations": self.n}
            )
        return v

    def residuals(self, x):
        evs = self.evaluations(x)
        if evs is None:
            # a failed point: residuals as large as an all-wrong force history
            return np.concatenate(
                [
                    _PENALTY * w[1:] * np.max(np.abs(E.F))
                    for (_, ref), ws in zip(self.records, self.w, strict=True)
                    for E, w in zip(_measured_cycles(ref), ws, strict=True)
                ]
                + [np.zeros(self.n_motion)]
            )
        self(x)  # records the path with the requested criterion
        # the first point (F_E(0+), extrapolated from samples for an aligned cycle) is left
        # out so the fit is not biased by the extrapolation error at the jump; the recorded
        # penetration's residual (records with positions) follows the force's
        r = np.concatenate(
            [
                ((S.F - E.F) * w)[1:]
                for ev, (_, ref), ws in zip(evs, self.records, self.w, strict=True)
                for (E, S), w in zip(cycle_pairs(ev, ref), ws, strict=True)
            ]
            + [
                penetration_residuals(ref, ev, ws)
                for ev, (_, ref), ws in zip(evs, self.records, self.w, strict=True)
            ]
        )
        cost = float(r @ r)
        if cost < self.best_squares[0]:
            self.best_squares = (cost, np.array(x, dtype=float))
        return r

    def estimate(self, method):
        """The fitted point: for least squares the smallest sum of squares met (the
        estimator the standard errors and the bootstrap describe; the point of smallest
        criterion along the path is a noisier one, whose spread on the coverage survey's
        records was 1.4 times theirs), else the smallest criterion."""
        if method == "least-squares" and self.best_squares[1] is not None:
            return self.best_squares[1]
        return self.best[1]

    # ------------------------------------------------ the residuals' Jacobian
    def _exact_columns(self):
        """For each parameter, its index among the kernel's coefficients (loading, then
        unloading terms) when its residual column can be had from the variational
        equations, else ``None`` (a machine parameter, a permanent set: differences); and
        whether any column can (every record compared over its span, an observation
        model linear in the force or none, no permanent set)."""
        model = self.start
        law, _, observe = model_parts(model, self.observe)
        n = len(law.coefficients)
        cols = list(range(n))
        if not isinstance(model, ForceLaw):
            for e in model.free_effects():
                t = Term.parse(e.key) if e.target == "unloading" else None
                cols.append(n + law.unloading.index(t) if t in law.unloading else None)
        # a record compared over its span takes an observation linear in the force; one
        # compared with its steady orbit (a force-only record) takes none
        linear = observe is None or getattr(observe, "linear", False)
        if getattr(model, "exact_jacobian", True) is False:
            # a named contact model: its parameters are not the kernel's coefficients
            return [None] * len(model.coefficients), False
        ok = not law.has_memory and all(
            linear if getattr(ref, "span", None) is not None else observe is None
            for _, ref in self.records
        )
        return cols, ok

    def jacobian(self, x):
        """``d residuals / d x``: the law's coefficients' columns from one run per record
        with the variational equations (:func:`~discovery.vibroimpact.verify.trajectory.
        history_sensitivities`), the other parameters' by forward differences (scipy's
        2-point step); all by differences when no column can be exact."""
        x = np.asarray(x, dtype=float)
        r0 = self.residuals(x)
        cols, ok = self.exact_columns
        J = np.empty((r0.size, x.size))
        exact = np.zeros(x.size, dtype=bool)
        if ok and self.evaluations(x) is not None:
            try:
                J[:, :] = 0.0
                exact = self._exact_jacobian(x, cols, J)
            except (IntegrationError, InputError):
                exact[:] = False
            # a column that is not finite (a graze at an onset, an infinite slope of a
            # fractional power at zero penetration) is taken by differences
            exact &= np.all(np.isfinite(J), axis=0)
        # the variational equations give the force's and the penetration's rows of the
        # exact columns; the other columns by forward differences
        for i in np.flatnonzero(~exact):
            xi = x.copy()
            h = 1e-6 * max(1.0, abs(x[i]))
            xi[i] += h
            J[:, i] = (self.residuals(xi) - r0) / h
        return J

    def _exact_jacobian(self, x, cols, J):
        """Fill the exact columns of ``J`` (in units of ``x``); returns which are."""
        from ..verify.trajectory import history_sensitivities, penetration_sensitivities

        law, machine, observe = model_parts(self.law(x), self.observe)
        exact = np.array([c is not None for c in cols])
        if self.n + len(self.records) > self.max_sim:
            raise _Budget
        row = 0
        evs = self.evaluations(x)
        motion = []  # the penetration's rows, after every force row
        for (sc, ref), ws, ev in zip(self.records, self.w, evs, strict=True):
            self.n += 1
            tick(self.progress, "identify: simulations", self.n, self.max_sim)
            if getattr(ref, "span", None) is not None:
                dH = history_sensitivities(
                    machine(sc), law, ref.span, tolerances=self.tol, observe=observe
                )
                if penetration_size(ref):
                    dZ = penetration_sensitivities(machine(sc), law, ref.span, tolerances=self.tol)
                    motion.append(penetration_jacobian(ref, dZ, ws))
                dS = []
                for blk, d in zip(ref.span.blocks, dH, strict=True):
                    dm = np.array([blk.fold.average(r) for r in d]).reshape(len(d), -1)
                    dS.append(np.concatenate([dm[:, :1], dm, dm[:, -1:]], axis=1))
            else:
                dS = [_aligned_sensitivity(machine(sc), law, ref, ev, self.tol)]
            for d, w in zip(dS, ws, strict=True):
                for i, c in enumerate(cols):
                    if c is not None:
                        J[row : row + w.size - 1, i] = (d[c] * w)[1:] * self.c0[i]
                row += w.size - 1
        for dz in motion:
            for i, c in enumerate(cols):
                if c is not None:
                    J[row : row + dz.shape[0], i] = dz[:, c] * self.c0[i]
            row += dz.shape[0]
        return exact


def _aligned_sensitivity(scenario, law, ref, ev, tolerances):
    """The derivatives along the law's coefficients of a steady orbit's force sampled like
    the measured cycle, seen from the onset the alignment chose (which moves with the
    coefficients): :meth:`~discovery.vibroimpact.dynamics.orbit_sensitivity.
    OrbitSensitivity.from_onset` at the measured sample times, shape (m, samples)."""
    from ..dynamics import _kernel as K
    from ..dynamics.orbit_sensitivity import orbit_sensitivity

    os_ = orbit_sensitivity(scenario, law, ev.steady, impacts=False, tolerances=tolerances)
    W = scenario.period * ev.steady.n_periods
    on = np.flatnonzero(os_.event_kind == K.EV_ONSET)
    if not on.size:
        raise IntegrationError("the orbit has no contact onset")
    # the onset the alignment put at t* = 0 (the rotated impulse's own onset, on the orbit)
    gap = np.abs(np.mod(os_.event_t[on] - ev.extra["aligned"].onset + 0.5 * W, W) - 0.5 * W)
    _, dF = os_.from_onset(on[int(np.argmin(gap))], ref.impulse.t)
    return dF


def _coordinate_descent(obj, x0, xtol, step0=0.1):
    x = np.array(x0, dtype=float)
    fx = obj(x)
    steps = np.full(x.size, step0)
    while np.any(steps > xtol):
        for i in range(x.size):
            if steps[i] <= xtol:
                continue
            improved = False
            for direction in (1.0, -1.0):
                trial = x.copy()
                trial[i] += direction * steps[i]
                ft = obj(trial)
                if ft < fx:
                    x, fx, improved = trial, ft, True
                    # accelerate: keep going and double the step while it pays
                    while True:
                        steps[i] *= 2.0
                        trial = x.copy()
                        trial[i] += direction * steps[i]
                        ft = obj(trial)
                        if ft >= fx:
                            steps[i] *= 0.5
                            break
                        x, fx = trial, ft
                    break
            if not improved:
                steps[i] *= 0.5
    return x


def _uncertainty(obj, x, names):
    """Standard errors and correlations from the residual Jacobian at ``x`` (exact where
    :meth:`_Objective.jacobian` can be, else forward differences); none when the
    simulations they need are beyond the budget."""
    try:
        return _standard_errors(obj, x, names)
    except _Budget:
        return {}, None


def _standard_errors(obj, x, names):
    r0 = obj.residuals(x)
    if obj.exact_columns[1]:
        J = obj.jacobian(x)
    else:
        J = np.empty((r0.size, x.size))
        for i in range(x.size):
            xi = x.copy()
            h = _JAC_STEP * max(abs(x[i]), 1e-3)
            xi[i] += h
            if obj.evaluations(xi) is None:
                return {}, None
            J[:, i] = (obj.residuals(xi) - r0) / h
    m, p = J.shape
    if m <= p:
        return {}, None
    s2 = float(r0 @ r0) / (m - p)
    try:
        cov = s2 * np.linalg.inv(J.T @ J)
    except np.linalg.LinAlgError:
        return {}, None
    d = np.sqrt(np.clip(np.diag(cov), 0.0, None))
    se = {n: float(abs(c) * s) for n, c, s in zip(names, obj.c0, d, strict=True)}
    with np.errstate(invalid="ignore", divide="ignore"):
        corr = cov / np.outer(d, d)
    return se, corr


def _checked(scenario, reference, start, method, xtol, max_simulations):
    """The settings :func:`identify` checks beyond their types; returns the records."""
    if isinstance(start, str):
        raise VidiTypeError(
            f"identify: start must be a ForceLaw or a Model (parse text with "
            f"ForceLaw.parse({start[:30]!r})); got str"
        )
    if method not in METHODS:
        raise InputError(f"unknown method {method!r}; valid methods: {', '.join(METHODS)}")
    if any(c == 0 for c in start.coefficients):
        raise InputError("every start coefficient must be non-zero (they set the scale)")
    if not (np.isfinite(xtol) and xtol > 0):
        raise InputError(f"xtol must be a positive number, got {xtol!r}")
    records = as_records(scenario, reference)
    if not (isinstance(max_simulations, int | np.integer) and max_simulations >= 2 * len(records)):
        raise InputError(
            f"the simulation budget must be an integer of at least "
            f"{2 * len(records)} (two per record); got {max_simulations!r}"
        )
    return records


def _short_first(
    records,
    start,
    short_first,
    criterion,
    method,
    xtol,
    max_simulations,
    tolerances,
    observe,
    progress,
):
    """With record spans compared in blocks, the start fitted cycle by cycle first (up to
    half the budget; continuation in block length): ``(start, simulations spent)``.  The
    caller's start is kept when it already matches the blocks better."""
    short = [r.shortened() if isinstance(r, Reference) else None for _, r in records]
    if not (
        short_first and all(r is not None for r in short) and max_simulations >= 8 * len(records)
    ):
        return start, 0
    spent = 0
    try:
        first = identify(
            [sc for sc, _ in records],
            short,
            start,
            criterion=criterion,
            method=method,
            xtol=xtol,
            max_simulations=max_simulations // 2,
            tolerances=tolerances,
            uncertainty=False,
            observe=observe,
            short_first=False,
            progress=None
            if progress is None
            else (lambda s, d, t: progress("identify: cycle by cycle", d, t)),
            check=False,
        )
        spent = first.n_simulations
        if not any(c == 0 for c in first.law.coefficients):
            start0, start = start, first.law
            # keep the caller's start when it already matches the blocks better
            probe = _Objective(records, start0, criterion, tolerances, 10**9, observe)
            alt = _Objective(records, start, criterion, tolerances, 10**9, observe)
            x1 = np.ones(len(start.coefficients))
            v0, v1 = probe(x1), alt(x1)
            spent += probe.n + alt.n
            if not v1 <= v0:
                start = start0
    except IntegrationError:
        pass
    return start, spent


def _x_bounds(model):
    """Bounds of the least-squares variables ``x = c / c_start``: an observation model's
    parameter (a sensor's time constant) within its physical bounds, so the trust region
    does not step beyond a bound the model clips to (a step to ``tau < 0`` is clipped to no
    filter, where the fit stalls).  Everything else is unbounded, the model clipping those
    parameters itself: scipy's trust region scales every bounded variable by its distance
    to the bound, which stops a fit near a bound short of the optimum."""
    c0 = np.asarray(model.coefficients, dtype=float)
    lo, hi = np.full(c0.size, -np.inf), np.full(c0.size, np.inf)
    if isinstance(model, ForceLaw):
        return lo, hi
    n = len(model.law.coefficients)
    for i, e in enumerate(model.free_effects(), start=n):
        if e.target == "observation":
            a, b = (v / c0[i] for v in e.parameters[0].bounds)
            lo[i], hi[i] = min(a, b), max(a, b)
    return lo, hi


def _optimise(obj, x0, method, xtol, max_simulations):
    """Run ``method`` on the objective from ``x0``; returns the optimiser's message."""
    try:
        if method == "coordinate-descent":
            _coordinate_descent(obj, x0, xtol)
            return "steps below xtol"
        if method == "nelder-mead":
            simplex = np.vstack([x0] + [x0 + 0.1 * np.eye(x0.size)[i] for i in range(x0.size)])
            res = minimize(
                obj,
                x0,
                method="Nelder-Mead",
                options={
                    "xatol": xtol,
                    "fatol": 1e-12,
                    "maxfev": max_simulations,
                    "initial_simplex": simplex,
                },
            )
            return str(res.message)
        # the law's coefficients' columns exact when they can be (one run per record
        # with the variational equations), else scipy's forward differences
        res = least_squares(
            obj.residuals,
            x0,
            jac=obj.jacobian if obj.exact_columns[1] else "2-point",
            bounds=_x_bounds(obj.start),
            method="trf",
            x_scale=1.0,
            diff_step=1e-6,
            xtol=xtol * 1e-2,
            ftol=1e-12,
            gtol=1e-12,
        )
        return str(res.message)
    except _Budget:
        return f"simulation budget of {max_simulations} used"


RESTART_FACTORS = (1.25, 0.8)
"""After the first optimisation, it is started again from its best point with every
parameter scaled by each factor, while the budget allows, and the best point is kept (by the
sum of squares for least squares, else by the criterion).  A law refitted from a start 20 %
off can stop in a basin whose spring is too soft (another contact sequence along the
record's transient); a restart from a stiffer and a softer point often leaves such a basin
(the rates: CHANGELOG)."""


def _restarted(obj, method, xtol, max_simulations, message):
    """:data:`RESTART_FACTORS` restarts from the best point (see there); the message says
    which improved it."""
    lo, hi = _x_bounds(obj.start)
    squares = method == "least-squares"
    for f in RESTART_FACTORS:
        x_best = obj.estimate(method)
        if x_best is None or obj.n + 4 * len(obj.records) > obj.max_sim:
            break
        before = obj.best_squares[0] if squares else obj.best[0]
        x = np.clip(x_best * f, np.nextafter(lo, np.inf), np.nextafter(hi, -np.inf))
        _optimise(obj, x, method, xtol, max_simulations)
        after = obj.best_squares[0] if squares else obj.best[0]
        if after < before:
            what = "sum of squares" if squares else obj.name
            message += (
                f"; restarted from the best point x {f:g}: {what} {before:.3g} -> {after:.3g}"
            )
    return message


def _checks(records, law, observe, tolerances):
    """The identified law against every record with its noise floor."""
    plain, machine, observed = model_parts(law, observe)
    return tuple(
        evaluate(machine(sc), plain, ref, tolerances=tolerances, observe=observed)
        for sc, ref in records
    )


@params(
    scenario=(Scenario, list, tuple),
    reference=(Measurement, Reference, Impulse, list, tuple),
    criterion=Text(),
    method=Text(),
    xtol=Real(0, open_low=True),
    max_simulations=Real(1, integer=True),
    tolerances=(Tolerances, None),
    n_boot_intervals=Real(0, integer=True),
    seed=Real(0, integer=True),
    check=bool,
    workers=(None, Real(1, integer=True)),
    interval_refit=Choice(*INTERVAL_REFITS),
    interval_noise=Choice(*INTERVAL_NOISE),
)
def identify(
    scenario,
    reference,
    start,
    *,
    criterion="I2",
    method="least-squares",
    xtol=1e-5,
    max_simulations=600,
    tolerances=None,
    uncertainty=True,
    observe=None,
    short_first=True,
    n_boot_intervals=0,
    seed=0,
    progress=None,
    check=True,
    workers=1,
    interval_refit="two-step",
    interval_noise="cycles",
):
    """Identify the coefficients of ``start`` from one or several records by simulation.

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
        The known part of the machine; one per record (or one for all).
    reference : Reference, Measurement or Impulse, or a sequence of them
        The record(s) (see :func:`as_records`).  A :class:`Reference` built with
        :meth:`~discovery.vibroimpact.verify.Reference.from_measurement` starts every simulation
        from the machine's measured state.
    start : ForceLaw or Model
        Terms to identify and their start values (all non-zero); or a model whose
        parameters go beyond a law's coefficients (:func:`model_parts`: an unloading
        branch, a machine parameter, an observation model, fitted jointly).
    criterion : str
        Criterion to minimise (``I0``..``I4``; the mean over records).
    method : str
        One of :data:`METHODS` (default ``"least-squares"``, as ``vidi identify``: it needs
        5-10x fewer simulations than the paper's coordinate descent, ``bench/``).
    xtol : float
        Relative coefficient tolerance (> 0).
    max_simulations : int
        Simulation budget (every record and every Jacobian evaluation counts).
    tolerances : Tolerances, optional
        Integrator settings (the same for every evaluation).
    uncertainty : bool
        Estimate standard errors (one more simulation per coefficient and record).
    observe : callable, optional
        Observation model of the simulated force (see
        :func:`discovery.vibroimpact.verify.evaluate`).
    n_boot_intervals : int
        Bootstrap replicates of 95 % coefficient intervals through the full processing
        (:func:`bootstrap_intervals`; records with positions; 0 = none).
    seed : int
        Seed of that bootstrap.
    workers : int or None
        Processes for the bootstrap's refits (default 1; ``None``: every core; the
        intervals do not depend on it).
    interval_refit : str
        How a bootstrap replicate is refitted (:func:`bootstrap_intervals`: ``"two-step"``).
    interval_noise : str
        The replicates' noise (:func:`bootstrap_intervals`: ``"cycles"``).
    progress : callable, optional
        ``progress(stage, done, total)`` after each simulation (:mod:`discovery._progress`).
    short_first : bool
        With record spans compared in blocks of several cycles: first fit the records
        cycle by cycle (:meth:`~discovery.vibroimpact.verify.Reference.shortened`, up to half the
        budget), where a law's timing error cannot accumulate and the basin is wider, then
        go on from there on the blocks (continuation in block length).
    check : bool
        Verify the identified law against every record with its noise floor (one more
        evaluation per record): the result's :attr:`~IdentificationResult.verdict`.

    Returns
    -------
    IdentificationResult

    Raises
    ------
    InputError
        Bad settings.
    IntegrationError
        The start law has no periodic steady state with contact.
    """
    records = _checked(scenario, reference, start, method, xtol, max_simulations)
    t0 = time.perf_counter()
    start, spent = _short_first(
        records,
        start,
        short_first,
        criterion,
        method,
        xtol,
        max_simulations,
        tolerances,
        observe,
        progress,
    )
    obj = _Objective(
        records,
        start,
        criterion,
        tolerances,
        max(int(max_simulations) - spent, 2 * len(records)),
        observe,
        progress,
    )
    obj.n = 0
    x0 = np.ones(len(start.coefficients))
    if obj.evaluations(x0) is None:
        f = obj.failures[-1]
        raise IntegrationError(
            f"the start law {start} cannot be compared with the record: "
            f"{f['status']} ({f['message']}); give start values closer to "
            "the record (e.g. from vidi fit)"
        )
    message = _optimise(obj, x0, method, xtol, max_simulations)
    if obj.best[1] is None:  # least squares evaluates residuals, which record the path
        obj(x0)
    message = _restarted(obj, method, xtol, max_simulations, message)
    x_best = obj.estimate(method)  # before the error probes run
    law = obj.law(x_best)
    evs = obj.evaluations(x_best)
    se, corr = {}, None
    if uncertainty:
        obj.max_sim += len(x_best) * len(records)  # the error estimate has its own budget
        se, corr = _uncertainty(obj, x_best, law.names)
    crit = {k: float(np.mean([e.criteria[k] for e in evs])) for k in evs[0].criteria}
    if obj.failures:
        message += (
            f"; {len(obj.failures)} trial law(s) had no periodic steady state with "
            "contact (see failures)"
        )
    intervals = None
    if n_boot_intervals:
        intervals = bootstrap_intervals(
            *zip(*records, strict=True),
            law,
            n_boot=int(n_boot_intervals),
            seed=seed,
            criterion=criterion,
            tolerances=tolerances,
            workers=workers,
            refit=interval_refit,
            noise=interval_noise,
        )
    return IdentificationResult(
        checks=_checks(records, law, observe, tolerances) if check else (),
        intervals=intervals,
        law=law,
        criterion=criterion,
        value=crit[criterion],
        criteria=crit,
        method=method,
        n_simulations=obj.n + spent,
        evaluations=tuple(evs),
        iterations=obj.path,
        standard_errors=se,
        correlation=corr,
        failures=obj.failures,
        seconds=time.perf_counter() - t0,
        message=message,
    )


# ------------------------------------------------------------------ bootstrap intervals
# Coefficient intervals by a bootstrap through the full processing (a refit per replicate:
# it lives beside the fit it repeats).
#
# The Jacobian standard errors of an output-error fit assume white residuals.  A record
# compared over its span has two more sources of error that they miss: the machine's state
# at the start of each block is itself estimated from noisy positions (its error moves
# every later impact of the block), and the record's own sampling.  The bootstrap repeats
# the whole experiment under the fitted model: for each replicate, every block is simulated
# from a state drawn from that block's state-fit covariance, sampled at the record's own
# sample times with noise, folded like the record, and refitted from the fitted model; the
# spread of the refitted coefficients gives the intervals.  Seeds are explicit.
#
# The noise is the record's own residual against the fitted model, force and penetration,
# each cycle's multiplied by one weight drawn from Webb's six-point distribution (a wild
# bootstrap with the cycles as clusters: Cameron, Gelbach & Miller 2008; Webb 2023).  White
# noise of the record's level (``noise="white"``) misses what repeats within a cycle: an
# onset's timing, a force sensor's own structure, a misfit the model leaves; the cycles'
# residuals carry it.
#
# The refit is two Gauss-Newton steps from the fitted model by default (the k-step
# bootstrap of Davidson & MacKinnon 1999 and Andrews 2002, k = 2: the replicate's estimate
# lies within a standard error of the fit, where Newton's steps converge fast): each step is
# the replicate's residuals and their exact Jacobian, one plain and one sensitivity run per
# block, where a least-squares refit takes about five of each; two steps keep the
# bootstrap's standard deviations close to the full refits' (one step does not; the
# numbers: CHANGELOG).  ``refit="full"`` keeps the full refit.
#
# A record has few cycles (a dozen, six for a period-two orbit) against two to four
# parameters, and a cluster bootstrap's spread, like the cluster-robust variance it mimics,
# is then too small by about ``(G - p) / G`` and itself uncertain.  The spread is scaled by
# ``sqrt(G / (G - p))`` and the interval takes Student's t with ``G - p`` degrees of freedom
# (Cameron & Miller 2015, section VI), as a regression's does with ``N - p``.


@dataclass(frozen=True, eq=False)
class Intervals(Result):
    """Bootstrap intervals of a fitted law's coefficients.

    Attributes
    ----------
    bounds : dict
        ``{name: (low, high)}`` at ``level``: the estimate +- q * sd, ``q`` the quantile of
        Student's t with ``dof`` degrees of freedom (the normal's when ``dof`` is 0).
    sd : dict
        ``{name: standard error}``: the bootstrap's standard deviation, scaled by
        ``sqrt(G / (G - p))`` for ``G`` resampled cycles and ``p`` parameters.
    level : float
    n_boot : int
        Replicates whose refit succeeded.
    seed : int
    method : str
    dof : int
        ``G - p`` (0: white noise, the normal quantile).
    """

    KIND = "intervals"
    _LOAD = {"bounds": lambda d: {k: tuple(v) for k, v in d["bounds"].items()}}

    bounds: dict
    sd: dict
    level: float
    n_boot: int
    seed: int
    method: str = "parametric bootstrap through the record-span processing"
    dof: int = 0

    def as_dict(self):
        return {
            "bounds": {k: list(v) for k, v in self.bounds.items()},
            "sd": dict(self.sd),
            "level": self.level,
            "n_boot": self.n_boot,
            "seed": self.seed,
            "method": self.method,
            "dof": self.dof,
        }


# Webb's six-point weights: mean 0, variance 1, and more distinct replicates than signs when
# a record has a dozen cycles
_WEBB = np.array([-np.sqrt(1.5), -1.0, -np.sqrt(0.5), np.sqrt(0.5), 1.0, np.sqrt(1.5)])


def _cycle_weights(fold, rng):
    """One Webb weight per cycle of ``fold``, at each folded sample, ndarray of shape (m,)."""
    c = np.clip(((fold.td - fold.origin) // fold.duration).astype(int), 0, fold.n_cycles - 1)
    return rng.choice(_WEBB, fold.n_cycles)[c]


def _replicate(scenario, law, observe, ref, rng, tolerances, noise="cycles"):
    """A synthetic copy of ``ref`` made by ``law`` (the same span, states and sample times).

    Every block is simulated from a state drawn from its state fit's covariance; its noise
    is, with ``noise="cycles"``, the record's own residual against ``law`` (force and
    penetration) with each cycle's multiplied by one random weight (a wild bootstrap by
    cycles: what repeats within a cycle, correlated noise, an onset's timing, a misfit the
    model leaves, is kept, and only its sign and size vary between cycles), or white noise
    of the record's level (``"white"``)."""
    from ..verify.trajectory import simulated_motion

    span = ref.span
    starts = [b.state.draw(rng) for b in span.blocks]
    hist, zs = simulated_motion(
        scenario, law, span, tolerances=tolerances, starts=starts, observe=observe
    )
    if noise == "cycles":
        fit_F, fit_Z = simulated_motion(scenario, law, span, tolerances=tolerances, observe=observe)
        blocks = []
        for b, h, z, f0, z0 in zip(span.blocks, hist, zs, fit_F, fit_Z, strict=True):
            v = _cycle_weights(b.fold, rng)
            blocks.append(replace(b, F=h + v * (b.F - f0), Z=z + v * (b.Z - z0)))
        blocks = tuple(blocks)
    else:
        blocks = tuple(
            replace(
                b,
                F=h + rng.normal(0.0, span.sigma_f, h.size),
                Z=z + rng.normal(0.0, span.sigma_z, z.size),
            )
            for b, h, z in zip(span.blocks, hist, zs, strict=True)
        )
    span2 = replace(span, blocks=blocks)
    imps = tuple(span2.measured(onset_record_time=ref.impulse.onset))
    return replace(ref, span=span2, blocks=imps, impulse=imps[-1], _source=None)


def _refit_replicate(context, k):
    """The coefficients of one bootstrap replicate's refit (a task of the executor; the
    replicates are in the forked context, so no record is copied), None when it fails."""
    scenarios, replicates, model, settings = context
    try:
        res = identify(
            scenarios,
            replicates[k],
            model,
            method="least-squares",
            uncertainty=False,
            short_first=False,
            check=False,
            criterion=settings["criterion"],
            max_simulations=settings["max_simulations"],
            tolerances=settings["tolerances"],
        )
    except IntegrationError:
        return None
    return np.array(res.law.coefficients, dtype=float)


_GN_STEPS = 2  # the Gauss-Newton steps of a "two-step" replicate


def _step_replicate(context, k):
    """The coefficients after two Gauss-Newton steps from the fitted model on one bootstrap
    replicate (a task of the executor, as :func:`_refit_replicate`), None when it fails."""
    scenarios, replicates, model, settings = context
    records = list(zip(scenarios, replicates[k], strict=True))
    obj = _Objective(records, model, settings["criterion"], settings["tolerances"], 10**9)
    x = np.ones(len(model.coefficients))
    for _ in range(_GN_STEPS):
        try:
            if obj.evaluations(x) is None:
                return None
            r, J = obj.residuals(x), obj.jacobian(x)
        except IntegrationError:
            return None
        if not (np.all(np.isfinite(r)) and np.all(np.isfinite(J))):
            return None
        x = x + np.linalg.lstsq(J, -r, rcond=None)[0]
    return np.array(model.coefficients, dtype=float) * x


REFITS = {"two-step": _step_replicate, "full": _refit_replicate}

MIN_CYCLE_DOF = 3
"""The fewest resampled cycles beyond the parameters (``G - p``) for the bootstrap by
cycles; below it (a period-four orbit over 12 periods: three cycles) the replicates take
white noise of the record's level."""


def bootstrap_intervals(
    scenario,
    reference,
    model,
    *,
    n_boot=30,
    seed=0,
    level=0.95,
    max_simulations=60,
    criterion="I2",
    tolerances=None,
    workers=1,
    executor=None,
    refit="two-step",
    noise="cycles",
):
    """Intervals of ``model``'s coefficients by a bootstrap through the record-span
    processing (the comment above).

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
    reference : Reference or sequence of Reference
        Records prepared with positions (a record span); others have no bootstrap.
    model : ForceLaw or Model
        The fitted law (or a model with effect parameters, :func:`identify.model_parts`).
    n_boot : int
        Replicates (>= 5).
    seed : int
        Seed of ``numpy.random.default_rng``.
    level : float
        Two-sided level in (0, 1).
    max_simulations : int
        Budget of each replicate's full refit.
    criterion : str
    tolerances : Tolerances, optional
    workers : int or None
        Processes for the replicates' refits (default 1; ``None``: every core).  The
        replicates are drawn in this process, in order, and only their refits run in
        parallel, so the intervals do not depend on it.
    executor : Executor, optional
        Where the refits run (:mod:`discovery.numerics.executor`); overrides ``workers``
        and is not closed here.
    refit : str
        ``"two-step"`` (default): two Gauss-Newton steps from the fitted model with the
        exact Jacobian (the comment above); ``"full"``: a least-squares refit.
    noise : str
        The replicates' noise (:data:`INTERVAL_NOISE`): ``"cycles"`` (default), the
        record's own residuals with one random weight per cycle (white noise when the
        cycles are too few: :data:`MIN_CYCLE_DOF`); ``"white"``, white noise of the
        record's level (a parametric bootstrap).

    Returns
    -------
    Intervals or None
        ``None`` when a record has no span (no state to draw), a parameter is 0, or fewer
        than 5 refits succeeded.
    """
    if not (isinstance(n_boot, int) and n_boot >= 5):
        raise InputError(f"n_boot must be an integer >= 5; got {n_boot!r}")
    if not 0 < level < 1:
        raise InputError(f"level must be in (0, 1); got {level!r}")
    if refit not in INTERVAL_REFITS:
        raise InputError(f"unknown refit {refit!r}; valid: {', '.join(INTERVAL_REFITS)}")
    if noise not in INTERVAL_NOISE:
        raise InputError(f"unknown noise {noise!r}; valid: {', '.join(INTERVAL_NOISE)}")
    records = as_records(scenario, reference)
    if any(getattr(ref, "span", None) is None for _, ref in records):
        return None
    if any(c == 0 for c in model.coefficients):
        return None  # a parameter at 0 sets no scale for the refits
    law, machine, observe = model_parts(model)
    # the resampled cycles against the parameters (see the comment above): too few, and the
    # replicates take white noise of the record's level instead
    G = sum(b.fold.n_cycles for _, ref in records for b in ref.span.blocks)
    few = noise == "cycles" and G - len(model.names) < MIN_CYCLE_DOF
    if few:
        noise = "white"
    rng = np.random.default_rng(seed)
    replicates = []  # drawn here, in order: the rng's sequence does not depend on workers
    for _ in range(n_boot):
        try:
            replicates.append(
                [
                    _replicate(machine(sc), law, observe, ref, rng, tolerances, noise)
                    for sc, ref in records
                ]
            )
        except IntegrationError:
            continue
    context = (
        [sc for sc, _ in records],
        replicates,
        model,
        {
            "criterion": criterion,
            "max_simulations": max_simulations,
            "tolerances": tolerances,
        },
    )
    refits = map_on(
        REFITS[refit], range(len(replicates)), context, workers=workers, executor=executor
    )
    draws = [d for d in refits if d is not None]
    if len(draws) < 5:
        return None
    return _intervals(np.array(draws), model, _Resampling(G, noise, few, refit, level, seed))


@dataclass(frozen=True)
class _Resampling:
    """How the replicates were made: ``G`` cycles, their noise, whether the cycles were too
    few (white noise instead), the refit, the level and the seed."""

    cycles: int
    noise: str
    few: bool
    refit: str
    level: float
    seed: int


def _intervals(D, model, how):
    """The :class:`Intervals` of the refitted coefficients ``D`` (replicates x parameters)
    around ``model``'s: normal quantiles on the spread for white noise; for the cycles, the
    spread scaled by ``sqrt(G / (G - p))`` and Student's t with ``G - p`` degrees of freedom
    (the comment above)."""
    from scipy.stats import norm
    from scipy.stats import t as student_t

    names = list(model.names)
    est = np.array(model.coefficients, dtype=float)
    sd = D.std(axis=0, ddof=1)
    dof, G = 0, how.cycles
    z = float(norm.ppf(0.5 + how.level / 2))
    if how.noise == "cycles":
        dof = G - len(names)
        sd = sd * np.sqrt(G / dof)
        z = float(student_t.ppf(0.5 + how.level / 2, dof))
    method = (
        f"wild bootstrap by cycles (the record's residuals, one weight per cycle; Student t "
        f"with {dof} degrees of freedom)"
        if how.noise == "cycles"
        else "parametric bootstrap"
        + (
            f" (white noise of the record's level: {G} cycles for {len(names)} parameters "
            "are too few to resample)"
            if how.few
            else ""
        )
    )
    step = "two Gauss-Newton steps" if how.refit == "two-step" else "a least-squares refit"
    return Intervals(
        bounds={
            n: (float(e - z * s), float(e + z * s)) for n, e, s in zip(names, est, sd, strict=True)
        },
        sd={n: float(s) for n, s in zip(names, sd, strict=True)},
        level=float(how.level),
        n_boot=len(D),
        seed=int(how.seed),
        method=f"{method} through the record-span processing ({step} per replicate)",
        dof=int(dof),
    )
