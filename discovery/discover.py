"""Discovery: sparse certified regression, then every shortlisted model checked by simulation.

Pipeline (:func:`discover`)::

    Measurement -> contact samples -> ConstrainedSparseRegressor (one candidate per
    proposed support) -> each candidate simulated to its periodic steady state ->
    criteria I0..I4 against the measured impulse -> ranking -> (optional) refinement
    of the chosen model's coefficients by identification through simulation.

Ranking rule (regression fit and simulation together): the candidates whose
simulation criterion (default I2) is within ``sim_rtol`` (relative) or ``sim_atol``
(absolute) of the best are equivalent by simulation and ordered by BIC; the others
follow in order of the criterion; models without a periodic steady state come last.
"""

import time
from dataclasses import dataclass, field

import numpy as np

from constraints import require

from .criteria import criterion as _criterion
from .criteria import evaluate_criteria
from .errors import IntegrationError
from .identify import identify
from .regression import ConstrainedSparseRegressor
from .response import response
from .samples import contact_samples

__all__ = ["RankedModel", "DiscoveryResult", "discover"]


@dataclass(frozen=True)
class RankedModel:
    """A candidate with its simulation check.

    Attributes
    ----------
    law : ForceLaw
    candidate : Candidate
        Regression statistics (rss, bic, aic, cv_error).
    regime : str
        Steady-state regime of the simulation (``"P1"``, ... or ``"nonperiodic"``).
    criteria : dict
        ``I0..I4`` against the measured impulse (empty when not periodic with contact).
    """

    law: object
    candidate: object
    regime: str
    criteria: dict

    def as_dict(self):
        return {"terms": list(self.law.names), "coefficients": self.law.as_dict(),
                "latex": self.law.latex(), "regime": self.regime, "criteria": self.criteria,
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


def _check(scenario, law, candidate, measured, tolerances):
    try:
        r = response(scenario, law, tolerances=tolerances)
    except IntegrationError:
        return RankedModel(law, candidate, "nonperiodic", {})
    if r.impulse is None:
        regime = r.regime if not r.steady.periodic else "no-contact"
        return RankedModel(law, candidate, regime, {})
    return RankedModel(law, candidate, r.regime, evaluate_criteria(measured, r.like(measured)))


def _coefficients(law, library):
    """Coefficient vector of ``law`` over ``library`` (zeros for absent terms)."""
    d = law.as_dict()
    return np.array([d.get(t.name, 0.0) for t in library.terms])


def rank(models, criterion="I2", sim_rtol=0.1, sim_atol=0.005):
    """Order checked models by the ranking rule of the module docstring."""
    ok = [m for m in models if m.criteria]
    bad = sorted((m for m in models if not m.criteria), key=lambda m: m.candidate.bic)
    if not ok:
        return bad
    best = min(m.criteria[criterion] for m in ok)
    limit = max(best * (1 + sim_rtol), best + sim_atol)
    tier = sorted((m for m in ok if m.criteria[criterion] <= limit), key=lambda m: m.candidate.bic)
    rest = sorted((m for m in ok if m.criteria[criterion] > limit),
                  key=lambda m: m.criteria[criterion])
    return tier + rest + bad


def discover(scenario, measurement, *, library="poly:2", selection="best-subset", scoring="bic",
             max_terms=4, criterion="I2", shortlist=8, refine=False, stability=0,
             derivative=None, average_cycles=False, sim_rtol=0.1, sim_atol=0.005,
             tolerances=None, random_state=0, **estimator_kwargs):
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
        Seed of the stability selection.
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
    measured = measurement.impulse(scenario.period)
    est = ConstrainedSparseRegressor(library=library, selection=selection, scoring=scoring,
                                     max_terms=max_terms, **estimator_kwargs)
    est.fit(samples.X, samples.F, groups=samples.impact, sample_weight=samples.weight)
    models = [_check(scenario, est.library_.law(
        [c.coefficients.get(t.name, 0.0) for t in est.library_.terms]), c, measured, tolerances)
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
            selected = RankedModel(refinement.law, selected.candidate, selected.regime,
                                   refinement.criteria)
            cert = refined_cert
    stab = est.stability(samples.X, samples.F, samples.impact, stability, random_state,
                         sample_weight=samples.weight) \
        if stability else {}
    settings = {"library": str(library), "selection": selection, "scoring": scoring,
                "max_terms": max_terms, "criterion": criterion, "shortlist": shortlist,
                "refine": refine, "stability": stability, "derivative": samples.derivative,
                "average_cycles": average_cycles,
                "random_state": random_state, "ranking_rule": {"sim_rtol": sim_rtol,
                                                               "sim_atol": sim_atol},
                "estimator": est.get_params()}
    return DiscoveryResult(selected=selected, ranking=ranking, certificate=cert, estimator=est,
                           samples=samples, measured=measured, stability=stab,
                           refinement=refinement, seconds=time.perf_counter() - t0,
                           settings=settings)
