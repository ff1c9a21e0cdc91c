"""Discovery: sparse certified regression, then every shortlisted model refined and checked
by simulation.

Pipeline (:func:`discover`)::

    record(s) -> contact samples (joined over records) -> ConstrainedSparseRegressor
    (one candidate per proposed support) -> each shortlisted support refined by
    output-error identification through simulation (all records jointly, starting from
    its regression coefficients; the certificate is checked again) -> each law
    simulated from every record's measured state and scored against its noise floor
    (:func:`discovery.vibroimpact.verify.evaluate`) -> ranking -> warnings and equivalent models.

Why refine: the regression sees the penetration ``zeta = w1 - w2`` and its rate,
which are noisy (a small difference of two large motions); its coefficients are then
biased (errors in variables).  The output-error refinement fits the force history by
simulation, where the penetration is computed, not measured.

When no regression law has a periodic orbit with contact, a spring-dashpot start made
from the record alone (contact time, force jump at onset, reduced mass) is refined.  Then
up to ``stepwise`` output-error moves around the best model: when it is not consistent,
each library term it lacks is added and each of its terms dropped in turn (refined by
simulation from its coefficients), so a support the biased regression never proposed can
still be found; when it is consistent, a backward step drops each of its terms in turn and
refines the rest, so the simplest consistent model is found.

Ranking rule: the models consistent with every record (same regime; I2 and I4 within
their noise floors, see :mod:`discovery.verify`) come first, the fewest terms first, then
by the criterion; then
those whose simulation criterion (default I2) is within ``sim_rtol`` (relative) or
``sim_atol`` (absolute) of the best, by BIC; the others follow in order of the
criterion; models without a periodic steady state come last.
"""

import time
from dataclasses import dataclass, fields, replace

from constraints import require as require_certificate

from ..._api._progress import reports_progress, tick
from ..._api._settings import Settings, option, takes
from ..._api._validate import Choice, Real, Text, params
from ..data.measurement import Measurement
from ..dynamics import Tolerances
from ..model.library import Library
from ..model.scenario import Scenario
from ..verify import Reference
from ..verify.block_farm import block_workers, shared_blocks
from ..verify.criteria import CRITERIA
from .certified_fit import SCORES, SELECTIONS, RegressionSettings
from .discovery_result import DiscoveryResult, RankedModel
from .discovery_warnings import _defects_warning, _warnings
from .discovery_warnings import _impact_warnings as _impact_warnings
from .discovery_warnings import _stability_warning as _stability_warning
from .equivalence import _equivalent
from .evidence import _contact_samples, _Evidence, _regression, _required_terms, _stability
from .intervals import INTERVAL_REFITS, bootstrap_intervals
from .ranking import _RankingRule, rank
from .records import pair_records
from .shortlist import _Checker, _shortlist
from .stepwise import _Stepwise

__all__ = ["RankedModel", "DiscoveryResult", "discover", "rank"]

_REFINE_BUDGET = 120  # simulations per shortlisted support (every record counts)


@dataclass(frozen=True)
class _Bootstrap:
    """The selected model's bootstrap intervals as :func:`discover` asks for them: the
    settings of :func:`~discovery.vibroimpact.fit.intervals.bootstrap_intervals`
    (``replicates`` 0: none)."""

    replicates: int
    seed: int
    workers: int | None
    refit: str
    criterion: str
    tolerances: Tolerances | None
    machine_scale: tuple | None = None
    observe: object = None

    def selected(self, ranking, refs, refine, progress):
        """The selected (best ranked) model, with bootstrap intervals when asked for and it
        was refined, and the ranking holding it."""
        selected = ranking[0]
        if not (
            self.replicates
            and refine
            and selected.refinement is not None
            and selected.note.startswith("refined")
        ):
            return selected, ranking
        tick(progress, "fit: bootstrap intervals", 0, self.replicates)
        iv = bootstrap_intervals(
            [sc for sc, _ in refs],
            [r for _, r in refs],
            selected.law,
            n_boot=int(self.replicates),
            seed=self.seed,
            criterion=self.criterion,
            tolerances=self.tolerances,
            workers=self.workers,
            refit=self.refit,
            machine_scale=self.machine_scale,
            observe=self.observe,
        )
        if iv is None:
            return selected, ranking
        chosen = replace(selected, intervals=iv)
        return chosen, [chosen if m is selected else m for m in ranking]


def _settings(evidence, check, search, boot, *, shortlist, stability, n_boot, average_cycles):
    """The settings a discovery reports, read from the objects that ran it."""
    est = evidence.est.settings
    return {
        "library": str(est.library),
        "selection": est.selection,
        "scoring": est.scoring,
        "max_terms": est.max_terms,
        "criterion": check.criterion,
        "shortlist": shortlist,
        "refine": check.refine,
        "max_simulations": check.budget,
        "stability": stability,
        "derivative": evidence.samples.derivative,
        "average_cycles": average_cycles,
        "seed": boot.seed,
        "n_boot": n_boot,
        "records": len(evidence.pairs),
        "stepwise": search.stepwise,
        "steps": search.steps,
        "physics": search.rank.physics,
        "n_boot_intervals": boot.replicates,
        "interval_refit": boot.refit,
        "require": sorted(check.required),
        "ranking_rule": {"sim_rtol": search.rank.sim_rtol, "sim_atol": search.rank.sim_atol},
        "estimator": evidence.est.get_params(),
        "sensor_lag": check.sensor_lag,
    }


def _contact_models(scenario, measurement, s, progress):
    """``library="contact-models"``: the named contact models fitted by name
    (:func:`~discovery.vibroimpact.fit.contact_fit.fit_contact_models`) with the settings
    ``s`` (:class:`DiscoverSettings`: its intervals, seed and workers)."""
    from .contact_fit import fit_contact_models

    return fit_contact_models(
        scenario,
        measurement,
        n_boot=s.n_boot_intervals,
        seed=0 if s.seed is None else s.seed,
        workers=s.workers,
        progress=progress,
        sensor_lag=s.sensor_lag,
    )


#: the estimator's parameters a call of :func:`discover` may give as keywords
_ESTIMATOR_OPTIONS = tuple(f.name for f in fields(RegressionSettings))


@dataclass(frozen=True, repr=False)
class DiscoverSettings(Settings):
    """The options of :func:`discover` (each is also a keyword of it; see its parameters)."""

    library: object = option("poly:2", (Text(), Library, list, tuple))
    selection: str = option("best-subset", Choice(*SELECTIONS))
    scoring: str = option("bic", Choice(*SCORES))
    max_terms: int = option(4, Real(1, 64, integer=True))
    criterion: str = option("I2", Choice(*CRITERIA))
    shortlist: int = option(8, Real(1, integer=True))
    refine: bool = option(True)
    stability: int = option(0, Real(0, integer=True))
    derivative: object = option(None, (None, Text()))
    average_cycles: bool = option(False)
    sim_rtol: float = option(0.1, Real(0, open_low=True))
    sim_atol: float = option(0.005, Real(0))
    tolerances: object = option(None, (Tolerances, None))
    seed: int = option(0, Real(0, integer=True))
    n_boot: int = option(16, Real(1, integer=True))
    max_simulations: int = option(_REFINE_BUDGET, Real(2, integer=True))
    stepwise: int = option(3, Real(0, integer=True))
    physics: bool = option(True)
    require: tuple = option((), (tuple, list))
    n_boot_intervals: int = option(30, Real(5, integer=True, zero=True))
    interval_refit: str = option("two-step", Choice(*INTERVAL_REFITS))
    workers: object = option(1, (None, Real(1, integer=True)))
    estimator: object = option(None, (None, dict))
    machine_scale: object = option(None, (None, tuple, list))
    sensor_lag: float = option(0.0, Real(0.0, 5e-3))


@takes(DiscoverSettings)
@params(scenario=(Scenario, list, tuple), measurement=(Measurement, list, tuple))
@reports_progress
def discover(scenario, measurement, *, settings=None, progress=None, **options):
    """Discover a contact law from one or several records and check it by simulation.

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
        The known part of the machine (masses, supports, drive): one per record, or one
        for all (a machine tested at several drive frequencies or amplitudes has one
        scenario per operating point).
    measurement : Measurement or sequence of Measurement
        Each needs ``t``, ``F``, ``w1``, ``w2`` (``v1``, ``v2`` optional).  All records
        are fitted jointly: several operating points separate terms one orbit cannot.
    settings : DiscoverSettings, optional
        The options below in one object; keywords override its fields.
    library, selection, scoring, max_terms
        Passed to :class:`~discovery.vibroimpact.fit.regression.ConstrainedSparseRegressor`.
    criterion : str
        Simulation criterion of the refinement and of the ranking (``I0``..``I4``).
    shortlist : int
        How many candidates (best by ``scoring``) are refined and simulated (>= 1).
    refine : bool
        Refine every shortlisted support by output-error identification through
        simulation (least squares on the force histories of all records, from the
        regression coefficients); the certificate is checked again, and a refined law that
        breaks it is not used.  Gives the coefficients' standard errors.
    stability : int
        Bootstrap resamples of impacts for stability selection (0 = skip).
    derivative : str, optional
        How ``dzeta`` is obtained (see :func:`~discovery.vibroimpact.data.samples.contact_samples`).
    average_cycles : bool
        Average the steady cycles sample by sample before the regression.
    sim_rtol, sim_atol : float
        Tolerances of the ranking rule.
    tolerances : Tolerances, optional
        Integrator settings (the same for refinement and checks).
    seed : int
        Seed of the stability selection and of the noise-floor bootstrap (the CLI's
        ``--seed``).
    n_boot : int
        Bootstrap replicates of each candidate's noise floor.
    max_simulations : int
        Simulation budget of each support's refinement.
    stepwise : int
        Output-error stepwise moves around the best model (see the module docstring).
    physics : bool
        Rank laws that are no contact laws (no spring, a negative damper:
        :meth:`ForceLaw.contact_defects`) after every contact law (default); ``False``
        ranks them by the records alone.
    require : sequence of str
        Library terms every candidate must contain (e.g. ``("z",)``: a spring): supports
        without them are not simulated, and the backward step never drops them.
    n_boot_intervals : int
        Bootstrap replicates of the selected model's 95 % coefficient intervals through the
        full processing (:func:`discovery.vibroimpact.fit.intervals.bootstrap_intervals`; records
        with positions, refined models; 0 = none).  The Jacobian standard errors assume white
        residuals and miss the noise of the estimated machine states.
    interval_refit : str
        How a bootstrap replicate is refitted (``"two-step"`` or ``"full"``: see
        :func:`discovery.vibroimpact.fit.intervals.bootstrap_intervals`).
    workers : int or None
        Processes for the refinements of the shortlist and of each stepwise move (a lone
        refinement shares out its evaluations' blocks:
        :mod:`~discovery.vibroimpact.verify.block_farm`), and for the bootstrap's refits
        (default 1; ``None``: every core); the result does not depend on it.
    progress : callable or bool, optional
        ``progress(stage, done, total)`` as the shortlist is simulated and the stepwise
        search and the bootstrap go on; None: a bar when the session is
        interactive, False: none (:mod:`discovery._api._progress`).
    estimator : dict, optional
        Further estimator parameters (``margin``, ``monotone``, ``signs``, ...); they may
        also be given as keywords.
    machine_scale : (float, float), optional
        The factors within which the machine's scale is uncertain (a calibration's
        :attr:`~discovery.Calibration.scale_range`): the selected law's intervals of the
        forces are widened to it
        (:func:`~discovery.vibroimpact.fit.intervals.bootstrap_intervals`).
    sensor_lag : float
        The force sensor's time constant [s] (a calibration's ``force_lag``; 0: none):
        the regression sees the force before the lag
        (:meth:`~discovery.vibroimpact.data.measurement.Measurement.unlagged`), and every
        simulated force is compared as the sensor would have read it (its refinement,
        checks and bootstrap intervals, as :func:`discovery.verify`'s ``sensor_lag``).

    Returns
    -------
    DiscoveryResult
        With ``warnings`` when the record(s) may not identify the law: stability selection
        disagreeing with the selected support, the best candidates by BIC without a
        periodic steady state, impact counts that do not fit the measured regime, no
        consistent model, a refinement that moved coefficients far beyond their
        uncertainty (regression bias).
    """
    s, more = DiscoverSettings.of("discover", settings, options, rest=_ESTIMATOR_OPTIONS)
    if s.library == "contact-models":  # the named contact models, fitted by name
        return _contact_models(scenario, measurement, s, progress)
    t0 = time.perf_counter()
    seed = s.seed
    pairs = pair_records(scenario, measurement)
    # the regression sees the force before a known sensor lag; the records' references
    # keep the recorded force, and every simulated force is read through the lag
    parts, samples = _contact_samples(
        [(sc, m.unlagged(s.sensor_lag)) for sc, m in pairs], s.derivative, s.average_cycles
    )
    regressor = dict(
        library=s.library, selection=s.selection, scoring=s.scoring, max_terms=s.max_terms
    )
    est = _regression(samples, {**regressor, **(s.estimator or {}), **more})
    refs = [(sc, Reference.from_measurement(m, sc, n_boot=s.n_boot, seed=seed)) for sc, m in pairs]
    evidence = _Evidence(pairs, parts, samples, est, refs)
    required = _required_terms(s.require, est.library_)
    check = _Checker(
        est=est,
        samples=samples,
        refs=refs,
        criterion=s.criterion,
        refine=s.refine,
        tol=s.tolerances,
        budget=s.max_simulations,
        required=required,
        workers=s.workers,
        sensor_lag=s.sensor_lag,
    )
    # a refinement run here (a step with one trial, say) shares out its evaluations'
    # blocks over the workers (the steps' trials run in parallel processes)
    with shared_blocks([r for _, r in refs], block_workers(s.workers)):
        models = _shortlist(check, est, required, s.shortlist, progress)
        by_score = list(models)  # the estimator's order (its scoring)
        rule = _RankingRule(s.criterion, s.sim_rtol, s.sim_atol, s.physics)
        search = _Stepwise(check, rule, stepwise=s.stepwise, max_terms=s.max_terms)
        ranking = search.run(models, refs, s.refine, progress)
        boot = _Bootstrap(
            s.n_boot_intervals,
            seed,
            s.workers,
            s.interval_refit,
            s.criterion,
            s.tolerances,
            None if s.machine_scale is None else tuple(s.machine_scale),
            check.observe,
        )
        selected, ranking = boot.selected(ranking, refs, s.refine, progress)
    # the certificate of the law actually selected (the ranking may prefer another
    # candidate than the estimator's best by BIC); a failure is an error
    cert = require_certificate(selected.certificate)
    stab = _stability(est, samples, s.stability, seed)
    warnings = _warnings(selected, by_score, stab, evidence, s.refine)
    if selected.defects:
        warnings.insert(0, _defects_warning(selected, s.physics))
    recorded = _settings(
        evidence,
        check,
        search,
        boot,
        shortlist=s.shortlist,
        stability=s.stability,
        n_boot=s.n_boot,
        average_cycles=s.average_cycles,
    )
    return DiscoveryResult(
        selected=selected,
        ranking=ranking,
        certificate=cert,
        estimator=est,
        samples=samples,
        measured=refs[0][1].impulse,
        references=tuple(refs),
        stability=stab,
        warnings=warnings,
        equivalent=_equivalent(ranking, selected, est, samples, s.criterion),
        seconds=time.perf_counter() - t0,
        settings=recorded,
    )
