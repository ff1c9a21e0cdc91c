"""Discovery: sparse certified regression, then every shortlisted model checked by simulation.

Pipeline (:func:`discover`)::

    Measurement -> contact samples -> ConstrainedSparseRegressor (one candidate per
    proposed support) -> each candidate simulated to its periodic steady state ->
    criteria I0..I4 against the measured impulse -> ranking -> (optional) refinement
    of the chosen model's coefficients by identification through simulation.

Ranking rule (regression fit and simulation together): the candidates consistent
with the record (:mod:`discovery.verify`: same regime, I2 within its noise floor) come
first, the simplest by BIC; then those whose simulation criterion (default I2) is
within ``sim_rtol`` (relative) or ``sim_atol`` (absolute) of the best, by BIC; the
others follow in order of the criterion; models without a periodic steady state come
last.
"""

import time
from dataclasses import dataclass, field

import numpy as np

from constraints import require

from .criteria import criterion as _criterion
from .identify import identify
from .regression import ConstrainedSparseRegressor
from .samples import contact_samples
from .verify import Reference, evaluate

__all__ = ["RankedModel", "DiscoveryResult", "discover"]


@dataclass(frozen=True)
class RankedModel:
    """A candidate with its simulation check.

    Attributes
    ----------
    law : ForceLaw
    candidate : Candidate
        Regression statistics (rss, bic, aic, cv_error).
    evaluation : Evaluation
        The law simulated and scored against the record (:func:`discovery.verify.evaluate`):
        regime, criteria, noise floor, consistency.
    """

    law: object
    candidate: object
    evaluation: object

    @property
    def regime(self):
        ev = self.evaluation
        return ev.regime["simulated"] or ev.status

    @property
    def criteria(self):
        return self.evaluation.criteria

    @property
    def consistent(self):
        return self.evaluation.consistent

    def as_dict(self):
        ev = self.evaluation
        return {"terms": list(self.law.names), "coefficients": self.law.as_dict(),
                "latex": self.law.latex(), "regime": self.regime, "status": ev.status,
                "criteria": ev.criteria, "noise_floor": ev.noise_floor,
                "consistent": ev.consistent, "verdict": ev.verdict,
                "bic": self.candidate.bic, "aic": self.candidate.aic,
                "cv_error": self.candidate.cv_error, "rss": self.candidate.rss,
                "constrained": self.candidate.constrained}


@dataclass(frozen=True)
class DiscoveryResult:
    """Outcome of :func:`discover`.

    Attributes
    ----------
    selected : RankedModel
        The chosen model (after refinement when requested).
    ranking : list of RankedModel
        Every candidate, best first.
    certificate : constraints.Certificate
        Of the selected law on the data's box.
    estimator : ConstrainedSparseRegressor
        The fitted estimator.
    samples : ContactSamples
    measured : Impulse
    stability : dict
        ``{term: selection frequency}`` over bootstrap resamples of impacts (empty if
        not requested).
    refinement : IdentificationResult or None
    seconds : float
    settings : dict
    """

    selected: RankedModel
    ranking: list
    certificate: object
    estimator: object
    samples: object
    measured: object
    stability: dict = field(default_factory=dict)
    refinement: object = None
    seconds: float = 0.0
    settings: dict = field(default_factory=dict)


def _check(scenario, law, candidate, reference, tolerances):
    return RankedModel(law, candidate, evaluate(scenario, law, reference, tolerances=tolerances))


def _coefficients(law, library):
    """Coefficient vector of ``law`` over ``library`` (zeros for absent terms)."""
    d = law.as_dict()
    return np.array([d.get(t.name, 0.0) for t in library.terms])


def rank(models, criterion="I2", sim_rtol=0.1, sim_atol=0.005):
    """Order checked models: the models consistent with the record first, simplest by BIC
    (the record cannot tell them apart); then the others whose criterion is within
    ``sim_rtol`` (relative) or ``sim_atol`` of the best, by BIC; then the rest by the
    criterion; models without a periodic steady state with contact last."""
    ok = [m for m in models if m.criteria]
    bad = sorted((m for m in models if not m.criteria), key=lambda m: m.candidate.bic)
    if not ok:
        return bad
    good = sorted((m for m in ok if m.consistent), key=lambda m: m.candidate.bic)
    rest = [m for m in ok if not m.consistent]
    if not rest:
        return good + bad
    best = min(m.criteria[criterion] for m in rest)
    limit = max(best * (1 + sim_rtol), best + sim_atol)
    tier = sorted((m for m in rest if m.criteria[criterion] <= limit),
                  key=lambda m: m.candidate.bic)
    tail = sorted((m for m in rest if m.criteria[criterion] > limit),
                  key=lambda m: m.criteria[criterion])
    return good + tier + tail + bad


def discover(scenario, measurement, *, library="poly:2", selection="best-subset", scoring="bic",
             max_terms=4, criterion="I2", shortlist=8, refine=False, stability=0,
             derivative=None, average_cycles=False, sim_rtol=0.1, sim_atol=0.005,
             tolerances=None, random_state=0, n_boot=16, **estimator_kwargs):
    """Discover a contact law from a measurement and check the candidates by simulation.

    Parameters
    ----------
    scenario : Scenario
        The known part of the machine (masses, supports, drive).
    measurement : Measurement
        Needs ``t``, ``F``, ``w1``, ``w2`` (``v1``, ``v2`` optional).
    library, selection, scoring, max_terms
        Passed to :class:`~discovery.regression.ConstrainedSparseRegressor`.
    criterion : str
        Simulation criterion for the ranking (``I0``..``I4``).
    shortlist : int
        How many candidates (best by ``scoring``) are simulated.
    refine : bool
        Refine the chosen model's coefficients by identification through simulation
        (least squares on the impulse, starting from the regression); the refined law
        is kept only if it is better by simulation and still certified.
    stability : int
        Bootstrap resamples of impacts for stability selection (0 = skip).
    derivative : str, optional
        How ``dzeta`` is obtained (see :func:`~discovery.samples.contact_samples`).
    average_cycles : bool
        Average the steady cycles sample by sample before the regression.
    sim_rtol, sim_atol : float
        Tolerances of the ranking rule.
    tolerances : Tolerances, optional
        Integrator settings.
    random_state : int
        Seed of the stability selection and of the noise-floor bootstrap.
    n_boot : int
        Bootstrap replicates of each candidate's noise floor.
    **estimator_kwargs
        Further estimator parameters (``margin``, ``monotone``, ``signs``, ...).

    Returns
    -------
    DiscoveryResult
    """
    t0 = time.perf_counter()
    _criterion(criterion)
    samples = contact_samples(measurement, derivative=derivative,
                              average_cycles=average_cycles, period=scenario.period)
    reference = Reference.from_measurement(measurement, scenario, n_boot=n_boot,
                                           seed=random_state)
    measured = reference.impulse
    est = ConstrainedSparseRegressor(library=library, selection=selection, scoring=scoring,
                                     max_terms=max_terms, **estimator_kwargs)
    est.fit(samples.X, samples.F, groups=samples.impact, sample_weight=samples.weight)
    models = [_check(scenario, est.library_.law(
        [c.coefficients.get(t.name, 0.0) for t in est.library_.terms]), c, reference, tolerances)
        for c in est.candidates_[:shortlist]]
    ranking = rank(models, criterion, sim_rtol, sim_atol)
    selected = ranking[0]
    refinement = None
    # the certificate of the law actually selected (the ranking may prefer another
    # candidate than the estimator's best by BIC); a failure is an error
    cert = require(est.certify(_coefficients(selected.law, est.library_)))
    if refine and selected.criteria:
        refinement = identify(scenario, measured, selected.law, criterion=criterion,
                              method="least-squares")
        refined_cert = est.certify(_coefficients(refinement.law, est.library_))
        # the refined law replaces the fit only if it is better by simulation AND still
        # satisfies the physical conditions on the whole box
        if (refinement.criteria and refinement.value < selected.criteria[criterion]
                and refined_cert.holds):
            selected = RankedModel(refinement.law, selected.candidate,
                                   evaluate(scenario, refinement.law, reference,
                                            tolerances=tolerances))
            cert = refined_cert
    stab = est.stability(samples.X, samples.F, samples.impact, stability, random_state,
                         sample_weight=samples.weight) \
        if stability else {}
    settings = {"library": str(library), "selection": selection, "scoring": scoring,
                "max_terms": max_terms, "criterion": criterion, "shortlist": shortlist,
                "refine": refine, "stability": stability, "derivative": samples.derivative,
                "average_cycles": average_cycles,
                "random_state": random_state, "n_boot": n_boot,
                "ranking_rule": {"sim_rtol": sim_rtol, "sim_atol": sim_atol},
                "estimator": est.get_params()}
    return DiscoveryResult(selected=selected, ranking=ranking, certificate=cert, estimator=est,
                           samples=samples, measured=measured, stability=stab,
                           refinement=refinement, seconds=time.perf_counter() - t0,
                           settings=settings)
