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
    scipy's Nelder–Mead simplex (derivative-free); it stops once its best criterion has
    fallen by less than 0.01 % of itself in 10 iterations (:class:`.optimise._Plateau`).
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
from dataclasses import dataclass, field

import numpy as np

from ..._api._printing import coefficient_lines, fmt, readable
from ..._api._progress import reports_progress
from ..._api._result import Result, part
from ..._api._settings import Settings, option, takes
from ..._api._validate import Choice, Real, params
from ...errors import IntegrationError
from ..data.impulse import Impulse
from ..data.measurement import Measurement
from ..dynamics import Tolerances
from ..model.law import ForceLaw
from ..model.scenario import Scenario
from ..verify import Reference, evaluate
from ..verify.block_farm import block_workers, shared_blocks
from ..verify.criteria import CRITERIA, criteria_lines
from ..verify.evaluation import Evaluation

# the fit's parts (records, problem, optimise, intervals)
from .intervals import (
    INTERVAL_NOISE,
    INTERVAL_REFITS,
    Intervals,
    bootstrap_intervals,
)
from .optimise import METHODS, Screens, _checked, _fitted
from .problem import _Objective, _uncertainty
from .records import (
    _named,
    as_records,
    contact_scales,
    cycle_pairs,
    model_parts,
    pair_records,
    record_start,
    records_verdict,
)

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
        All criteria ``I0..I4`` at the identified law, and ``I5`` where records have
        positions (each the mean over the records that have it).
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
    given_up : bool
        The fit stopped after its cycle-by-cycle first fit (``give_up_above``).
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
    given_up: bool = False

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
        return records_verdict(self.checks, lambda ev: ev.verdict or ev.message)

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
            "given_up": self.given_up,
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


_NO_PROGRESS = 0.9
"""``give_up_above`` stops a fit only when its cycle-by-cycle first fit left the criterion on
the blocks above this fraction of the start's: on the bench record the laws without a
stiffness term went from 1.64 to 1.66 there, while a right support started from a
consistent model's other coefficients went from 1.22 to 0.67 (and was consistent after
the fit on the blocks)."""


def _hopeless(short_value, give_up_above):
    """Why a fit is given up after its cycle-by-cycle first fit (``short_value``: the
    start's and that fit's criterion on the blocks), or ``""`` (see ``give_up_above``)."""
    if give_up_above is None or short_value is None:
        return ""
    v0, v1 = short_value
    if min(v0, v1) <= give_up_above or v1 <= _NO_PROGRESS * v0:
        return ""
    return (
        f"{min(v0, v1):.3g} on the blocks is above {give_up_above:.3g}, and the fit lowered "
        f"it by less than {1 - _NO_PROGRESS:.0%}"
    )


@dataclass(frozen=True)
class _Fit:
    """The settings of one :func:`identify` call that the cycle-by-cycle first fit repeats."""

    criterion: str
    method: str
    xtol: float
    max_simulations: int
    tolerances: object = None
    observe: object = None
    progress: object = None


def _short_first(records, start, fit):
    """With record spans compared in blocks, the start fitted cycle by cycle first (up to
    half the budget; continuation in block length): ``(start, simulations spent, (the
    caller's start's criterion on the blocks, the first fit's) or None)``.  The caller's
    start is kept when it already matches the blocks better.  This first fit is not
    restarted (:func:`~.optimise._fitted`): it only seeds the fit on the blocks, which
    is."""
    short = [r.shortened() if isinstance(r, Reference) else None for _, r in records]
    if not (all(r is not None for r in short) and fit.max_simulations >= 8 * len(records)):
        return start, 0, None
    progress = (
        None
        if fit.progress is None
        else (lambda s, d, t: fit.progress("identify: cycle by cycle", d, t))
    )
    first = _Objective(
        [(sc, r) for (sc, _), r in zip(records, short, strict=True)],
        start,
        fit.criterion,
        fit.tolerances,
        fit.max_simulations // 2,
        observe=fit.observe,
        progress=progress,
    )
    try:
        x, _ = _fitted(first, fit.method, fit.xtol, fit.max_simulations // 2, restarts=False)
    except IntegrationError:
        return start, first.n, None
    spent, law = first.n, first.law(x)
    if any(c == 0 for c in law.coefficients):
        return start, spent, None
    # keep the caller's start when it already matches the blocks better
    probe = _Objective(records, start, fit.criterion, fit.tolerances, 10**9, observe=fit.observe)
    alt = _Objective(records, law, fit.criterion, fit.tolerances, 10**9, observe=fit.observe)
    x1 = np.ones(len(law.coefficients))
    v0, v1 = probe(x1), alt(x1)
    return (law if v1 <= v0 else start), spent + probe.n + alt.n, (v0, v1)


def _checks(records, law, observe, tolerances):
    """The identified law against every record with its noise floor."""
    plain, machine, observed = model_parts(law, observe)
    return tuple(
        evaluate(machine(sc, ref), plain, ref, tolerances=tolerances, observe=observed)
        for sc, ref in records
    )


def _mean_criteria(evs):
    """Each criterion's mean over the records that have it (a record without positions,
    or whose evaluation has no penetration to compare, has no I5)."""
    keys = dict.fromkeys(k for e in evs for k in e.criteria)
    return {k: float(np.mean([e.criteria[k] for e in evs if k in e.criteria])) for k in keys}


@dataclass(frozen=True, repr=False)
class IdentifySettings(Settings):
    """The options of :func:`identify` (each is also a keyword of it; see its parameters)."""

    criterion: str = option("I2", Choice(*CRITERIA))
    method: str = option("least-squares", Choice(*METHODS))
    xtol: float = option(1e-5, Real(0, open_low=True))
    max_simulations: int = option(600, Real(2, integer=True))
    tolerances: object = option(None, (Tolerances, None))
    uncertainty: bool = option(True)
    observe: object = option(None)
    short_first: bool = option(True)
    n_boot_intervals: int = option(0, Real(5, integer=True, zero=True))
    seed: int = option(0, Real(0, integer=True))
    check: bool = option(True, bool)
    workers: object = option(1, (None, Real(1, integer=True)))
    interval_refit: str = option("two-step", Choice(*INTERVAL_REFITS))
    interval_noise: str = option("cycles", Choice(*INTERVAL_NOISE))
    give_up_above: object = option(None, (None, Real(0, open_low=True)))
    restart_above: object = option(None, (None, Real(0)))
    machine_scale: object = option(None, (None, tuple, list))


@takes(IdentifySettings)
@params(
    scenario=(Scenario, list, tuple),
    reference=(Measurement, Reference, Impulse, list, tuple),
)
@reports_progress
def identify(scenario, reference, start, *, settings=None, progress=None, **options):
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
    settings : IdentifySettings, optional
        The options below in one object; keywords override its fields.
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
        Processes for the fit's evaluations (a record compared over its span is shared out
        block by block: :mod:`~discovery.vibroimpact.verify.block_farm`) and the bootstrap's
        refits (default 1; ``None``: every core; the result does not depend on it).
    interval_refit : str
        How a bootstrap replicate is refitted (:func:`bootstrap_intervals`: ``"two-step"``).
    interval_noise : str
        The replicates' noise (:func:`bootstrap_intervals`: ``"cycles"``).
    machine_scale : (float, float), optional
        The factors within which the machine's scale is uncertain (a calibration's
        :attr:`~discovery.Calibration.scale_range`): the bootstrap intervals are widened to
        it (:func:`bootstrap_intervals`), as ``verify``, ``discover`` and ``explain`` widen
        theirs; a law fitted on a calibrated machine carries the scale's error.
    progress : callable or bool, optional
        ``progress(stage, done, total)`` after each simulation; None: a bar when the session is
        interactive, False: none (:mod:`discovery._api._progress`).
    short_first : bool
        With record spans compared in blocks of several cycles: first fit the records
        cycle by cycle (:meth:`~discovery.vibroimpact.verify.Reference.shortened`, up to half the
        budget), where a law's timing error cannot accumulate and the basin is wider, then
        go on from there on the blocks (continuation in block length).
    check : bool
        Verify the identified law against every record with its noise floor (one more
        evaluation per record): the result's :attr:`~IdentificationResult.verdict`.
    give_up_above : float, optional
        Stop after the cycle-by-cycle first fit (``short_first``) when the criterion on the
        blocks is above this value and that fit lowered it by less than 10 % (a support
        that cannot explain the record; a right one from a poor start moves): the better
        of the start and that fit's law is returned, without the fit on the blocks and
        without standard errors (the result's :attr:`~IdentificationResult.given_up`).  A
        fit on the blocks above it stops after two iterations that lower its sum of squares
        by less than 10 % each, and is not restarted (a restart leaves a wrong basin of a
        law that can match the record).  ``discover`` sets it at ten times the record's
        consistency limit of the criterion, at least 0.5
        (:data:`~discovery.vibroimpact.fit.shortlist.GIVE_UP_FACTOR`).
    restart_above : float, optional
        A fit on the blocks whose criterion is at or below this value is not started again
        from its best point scaled (:data:`~discovery.vibroimpact.fit.optimise.RESTART_FACTORS`):
        it already matches the records as well as the true law would.  ``discover`` sets it
        at the smallest noise floor of the criterion over the records; None (the default)
        restarts every fit below ``give_up_above``.

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
    s = IdentifySettings.of("identify", settings, options)
    records = _checked(scenario, reference, start, max_simulations=s.max_simulations)
    # every evaluation's blocks shared out over ``workers`` processes (none with one)
    with shared_blocks([r for _, r in records], block_workers(s.workers)):
        return _identified(records, start, s, progress)


def _identified(records, start, s, progress):
    """:func:`identify` on checked ``records`` with its settings ``s``."""
    t0 = time.perf_counter()
    spent, short_value = 0, None
    if s.short_first:
        fit = _Fit(
            criterion=s.criterion,
            method=s.method,
            xtol=s.xtol,
            max_simulations=s.max_simulations,
            tolerances=s.tolerances,
            observe=s.observe,
            progress=progress,
        )
        start, spent, short_value = _short_first(records, start, fit)
    given_up = _hopeless(short_value, s.give_up_above)
    obj = _Objective(
        records,
        start,
        s.criterion,
        s.tolerances,
        max(int(s.max_simulations) - spent, 2 * len(records)),
        observe=s.observe,
        progress=progress,
    )
    obj.n = 0
    if given_up:
        x_best = np.ones(len(start.coefficients))
        message = f"given up after the cycle-by-cycle fit: {s.criterion} {given_up}"
    else:
        # before the error probes
        screens = Screens(s.give_up_above, s.restart_above)
        x_best, message = _fitted(obj, s.method, s.xtol, s.max_simulations, screens=screens)
    law = obj.law(x_best)
    evs = obj.full_evaluations(x_best)
    if evs is None:  # a given-up start compared on the blocks before: never, short of a bug
        raise IntegrationError(f"the law {law} cannot be compared with the record")
    se, corr = {}, None
    if s.uncertainty and not given_up:
        obj.max_sim += len(x_best) * len(records)  # the error estimate has its own budget
        se, corr = _uncertainty(obj, x_best, law.names)
    crit = _mean_criteria(evs)
    if obj.failures:
        message += (
            f"; {len(obj.failures)} trial law(s) had no periodic steady state with "
            "contact (see failures)"
        )
    intervals = None
    if s.n_boot_intervals:
        intervals = bootstrap_intervals(
            *zip(*records, strict=True),
            law,
            n_boot=int(s.n_boot_intervals),
            seed=s.seed,
            criterion=s.criterion,
            tolerances=s.tolerances,
            workers=s.workers,
            refit=s.interval_refit,
            noise=s.interval_noise,
            machine_scale=None if s.machine_scale is None else tuple(s.machine_scale),
            observe=s.observe,
        )
    return IdentificationResult(
        checks=_checks(records, law, s.observe, s.tolerances) if s.check else (),
        intervals=intervals,
        law=law,
        criterion=s.criterion,
        value=crit[s.criterion],
        criteria=crit,
        method=s.method,
        n_simulations=obj.n + spent,
        evaluations=tuple(evs),
        iterations=obj.path,
        standard_errors=se,
        correlation=corr,
        failures=obj.failures,
        seconds=time.perf_counter() - t0,
        message=message,
        given_up=bool(given_up),
    )
