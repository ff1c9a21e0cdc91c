"""The residual problem of an output-error fit, for identify and for the missing-effect loop.

:func:`output_residuals` is the residual rule: ``(F_N - F_E)`` of every compared cycle, then
each record's recorded penetration residual in the force's units (records with positions).
:class:`ModelProblem` is a model (a :class:`ForceLaw` or a model with more parameters,
:func:`~.records.model_parts`) against every record, with a memo of its evaluations.
:class:`_Objective` is identify's: a model's coefficients in units of the start values ->
every record's evaluation, the criterion and the weighted residuals (each record's squared
norm its ``I3^2``), with a cache of the simulations, the simulation budget and the best point
met; the residuals' Jacobian (exact from the variational equations where it can be) and the
standard errors it gives.

Every evaluation is :func:`discovery.vibroimpact.verify.evaluate`.
"""

import numpy as np

from ..._api._progress import tick
from ...errors import InputError, IntegrationError
from ...numerics.memo import Memo, value_key
from ..model.law import ForceLaw, Term
from ..verify import evaluate
from ..verify.criteria import CRITERIA
from ..verify.criteria import criterion as _criterion
from ..verify.motion import (
    MOTION_CRITERION,
    penetration_jacobian,
    penetration_residuals,
    penetration_size,
)
from .records import _measured_cycles, _named, _residual_weights, cycle_pairs, model_parts

_PENALTY = 10.0  # criterion value of a failed simulation (criteria are O(1))
_JAC_STEP = 1e-5  # relative step of the standard-error Jacobian


class _Budget(Exception):
    """The simulation budget is used up."""


class _NotFinite(Exception):
    """The optimiser proposed a point that is not finite (its step solved a system that
    overflowed): the fit ends there, with the best point it met."""


#: An exact Jacobian column steeper than this (residual units per unit of the scaled
#: parameter, which starts at 1) is taken by differences instead.  A slope of 1e8 moves
#: the residuals (whose squares sum to I3^2, about 1) by one unit within a relative step
#: of 1e-8, finer than any fit resolves; such columns come from variational equations
#: integrated through a contact they cannot follow.  On a short-contact record of a
#: random machine (``tests.realistic``, draw 7 at 0.5 % noise) a hopeless law
#: ``zd + z*zd`` got a column of 2.6e97: the least-squares step overflowed to NaN and
#: ended the whole discovery.
JACOBIAN_LIMIT = 1e8


def output_residuals(evaluations, records, weights=None):
    """The output-error residual of a model's ``evaluations`` on ``records``: the simulated
    minus the measured force of every compared cycle (:func:`~.records.cycle_pairs`), record
    by record, then every record's penetration residual in the force's units
    (:func:`~discovery.vibroimpact.verify.motion.penetration_residuals`).

    With ``weights`` (per record, one array per compared cycle: the sample spacing normalised
    so that a record's squared norm is its ``I3^2``) each cycle's residual is weighted and its
    first point (``F_E(0+)``, extrapolated from samples for an aligned cycle) left out, so a
    fit is not biased by the extrapolation error at the jump; without, the plain differences.

    Returns
    -------
    ndarray of shape (n,)
    """
    ws_all = [None] * len(records) if weights is None else weights
    force, motion = [], []
    for ev, (_, ref), ws in zip(evaluations, records, ws_all, strict=True):
        pairs = cycle_pairs(ev, ref)
        if ws is None:
            force += [S.F - E.F for E, S in pairs]
        else:
            force += [((S.F - E.F) * w)[1:] for (E, S), w in zip(pairs, ws, strict=True)]
        motion.append(penetration_residuals(ref, ev, ws))
    return np.concatenate(force + motion)


def _evaluated(parts, sc, ref, tolerances, **how):
    """One record's :func:`~discovery.vibroimpact.verify.evaluate` of a model split by
    :func:`~.records.model_parts` (``parts``: its law, machine and observation model);
    ``how``: evaluate's other keywords."""
    law, machine, observe = parts
    return evaluate(machine(sc, ref), law, ref, tolerances=tolerances, observe=observe, **how)


class ModelProblem:
    """A model against every record: its evaluations (with a memo), residuals, mean criteria
    and the noise of the averaged cycles.

    Parameters
    ----------
    records : list of (Scenario, Reference)
        The records (:func:`~.records.as_records`).
    tolerances : Tolerances or None
        Integrator settings of every evaluation.
    observe : callable or None
        A known sensor's observation model, where the model has none of its own
        (:func:`~.records.model_parts`).

    Attributes
    ----------
    n_sim : int
        Evaluations run (one per record; answers from the memo do not count).
    """

    def __init__(self, records, tolerances, observe=None):
        self.records, self.tol, self.observe = records, tolerances, observe
        self.n_sim = 0
        # a model asked for again (in the missing-effect loop: verified at the start of an
        # iteration and named in the one before; its residual follows its verification) is
        # answered from here (and the block simulations a floor and a residual share, from
        # the verify layer's)
        self._memo = Memo(16)

    def evaluations(self, model, floor=False, smooth_onset=False):
        """The model's evaluation on every record (:func:`~discovery.vibroimpact.verify.evaluate`,
        asked again: answered from the memo)."""
        law = model if isinstance(model, ForceLaw) else model.law
        key = value_key(
            law,
            getattr(model, "observation", None),
            getattr(model, "scenario", None),
            floor,
            smooth_onset,
        )
        return self._memo.get(key, lambda: self._evaluate(model, floor, smooth_onset))

    def _evaluate(self, model, floor, smooth_onset):
        """The evaluations of :meth:`evaluations`; those with the onset smoothed are the
        residual's (:meth:`residual`), which reads the histories and no criterion."""
        parts = model_parts(model, self.observe)
        evs = []
        for sc, ref in self.records:
            self.n_sim += 1
            how = {"floor": floor, "objective": () if smooth_onset else None}
            evs.append(_evaluated(parts, sc, ref, self.tol, **how))
        return evs

    def residual(self, model):
        """The force residual of every compared cycle (the optimisers' continuous form),
        then the recorded penetration's in the force's units (:func:`output_residuals`,
        unweighted); None when a record has no steady cycle."""
        evs = self.evaluations(model, smooth_onset=True)
        if not all(e.status == "ok" for e in evs):
            return None
        return output_residuals(evs, self.records)

    def squares(self, model):
        """The sum of squared residuals (force and penetration, :meth:`residual`): what the
        output-error refits minimise (inf when a record has no steady cycle)."""
        r = self.residual(model)
        return np.inf if r is None else float(r @ r)

    def value(self, model, criterion):
        """The mean ``criterion`` over records (inf when a record has no steady cycle)."""
        evs = self.evaluations(model)
        if not all(e.status == "ok" and criterion in (e.criteria or {}) for e in evs):
            return np.inf
        return float(np.mean([e.criteria[criterion] for e in evs]))

    def sigma(self):
        """The force noise of the averaged cycles (rms over records; 0 without noise)."""
        s = [
            ref.noise["F"] / np.sqrt(max(ref.noise["n_cycles"], 1))
            for _, ref in self.records
            if ref.noise
        ]
        return float(np.sqrt(np.mean(np.square(s)))) if s else 0.0


class _Objective:
    """Counts and caches simulations, enforces the budget, records the best-so-far path."""

    def __init__(self, records, start, name, tolerances, max_sim, *, observe=None, progress=None):
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

    @property
    def dof(self):
        """The residuals' degrees of freedom: their count (every compared cycle's weighted
        force but its first point, then the penetration's rows) less the parameters."""
        m = sum(w.size - 1 for ws in self.w for w in ws) + self.n_motion
        return max(m - len(self.c0), 1)

    def evaluations(self, x):
        """Every record's evaluation at ``x`` with the objective's criterion alone (what the
        optimisers read; :meth:`full_evaluations` for every criterion), None where one
        fails; cached, and counted against the budget."""
        if not np.all(np.isfinite(x)):
            raise _NotFinite
        key = tuple(np.round(np.asarray(x, dtype=float), 14))
        if key not in self.cache:
            if self.n + len(self.records) > self.max_sim:
                raise _Budget
            parts = model_parts(self.law(x), self.observe)
            evs = []
            for i, (sc, ref) in enumerate(self.records):
                self.n += 1
                tick(self.progress, "identify: simulations", self.n, self.max_sim)
                how = {"floor": False, "objective": (self.name,), **self._continued(i, x)}
                ev = _evaluated(parts, sc, ref, self.tol, **how)
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

    def full_evaluations(self, x):
        """Every record's evaluation at ``x`` (met before: :meth:`evaluations`) with every
        criterion: its block runs are the memo's, so only the criteria are computed."""
        if self.evaluations(x) is None:
            return None
        parts = model_parts(self.law(x), self.observe)
        every = (*CRITERIA, MOTION_CRITERION)
        return [
            _evaluated(
                parts, sc, ref, self.tol, floor=False, objective=every, **self._continued(i, x)
            )
            for i, (sc, ref) in enumerate(self.records)
        ]

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
        r = output_residuals(evs, self.records, self.w)
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
            cols += [None] * len(getattr(model, "free_machine", tuple)())
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
            # fractional power at zero penetration) or beyond any resolvable slope
            # (JACOBIAN_LIMIT) is taken by differences
            exact &= np.all(np.abs(J) <= JACOBIAN_LIMIT, axis=0)  # False for inf and NaN
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
                    machine(sc, ref), law, ref.span, tolerances=self.tol, observe=observe
                )
                if penetration_size(ref):
                    dZ = penetration_sensitivities(
                        machine(sc, ref), law, ref.span, tolerances=self.tol
                    )
                    motion.append(penetration_jacobian(ref, dZ, ws))
                dS = []
                for blk, d in zip(ref.span.blocks, dH, strict=True):
                    dm = np.array([blk.fold.average(r) for r in d]).reshape(len(d), -1)
                    dS.append(np.concatenate([dm[:, :1], dm, dm[:, -1:]], axis=1))
            else:
                dS = [_aligned_sensitivity(machine(sc, ref), law, ref, ev, self.tol)]
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
    from ..dynamics.kernel import codes as K
    from ..dynamics.orbit_sensitivity import orbit_sensitivity

    os_ = orbit_sensitivity(scenario, law, ev.steady, impacts=False, tolerances=tolerances)
    W = scenario.period * ev.steady.n_periods
    on = np.flatnonzero(os_.event_kind == K.EV_ONSET)
    if not on.size:
        raise IntegrationError("the orbit has no contact onset")
    # the onset the alignment put at t* = 0 (the rotated impulse's own onset, on the orbit)
    gap = np.abs(np.mod(os_.event_t[on] - ev.aligned.onset + 0.5 * W, W) - 0.5 * W)
    _, dF = os_.from_onset(on[int(np.argmin(gap))], ref.impulse.t)
    return dF


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
