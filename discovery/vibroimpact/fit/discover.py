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
from dataclasses import dataclass, field, replace
from warnings import warn

import numpy as np

from constraints import Certificate
from constraints import require as require_certificate

from ..._printing import coefficient_lines, fmt, readable
from ..._progress import reports_progress, tick
from ..._result import Result, part
from ..._validate import Choice, Real, Text, params
from ...errors import InputError, IntegrationError, VidiError
from ...numerics.executor import map_on
from ..data.measurement import Measurement
from ..data.samples import contact_samples, join_samples
from ..dynamics import Tolerances
from ..model.law import ForceLaw, Term
from ..model.library import Library
from ..model.scenario import Scenario
from ..verify import Reference, evaluate
from ..verify.criteria import criteria_lines
from ..verify.criteria import criterion as _criterion
from ..verify.evaluate import Evaluation
from .identify import (
    INTERVAL_REFITS,
    Intervals,
    bootstrap_intervals,
    identify,
    pair_records,
    record_start,
)
from .regression import ConstrainedSparseRegressor

__all__ = ["RankedModel", "DiscoveryResult", "discover", "rank"]

_REFINE_BUDGET = 120  # simulations per shortlisted support (every record counts)
_FORWARD_STARTS = (0.01, 0.001)  # a new term's start force at the box corner / peak force
_RESTARTS = 2  # stalled smaller supports restarted from a consistent model, per step


def _loaded_evaluations(d):
    """A loaded ranked model's evaluations: every record's, or the one record's (its
    regime the simulated one's)."""
    if d.get("records"):
        return tuple(part(Evaluation, e) for e in d["records"])
    regime = {"measured": None, "simulated": d.get("regime")}
    return (part(Evaluation, {**d, "regime": regime, "impacts": {}}),)


def _loaded_intervals(d):
    if not d.get("intervals"):
        return None
    return Intervals(
        bounds={k: tuple(v) for k, v in d["intervals"].items()},
        sd={},
        level=d.get("interval_level"),
        n_boot=None,
        seed=None,
        method=d.get("interval_method"),
    )


@readable
@dataclass(frozen=True, eq=False)
class RankedModel(Result):
    """A candidate law with its simulation check against every record.

    Attributes
    ----------
    law : ForceLaw
        The law (refined by simulation when refinement ran and kept the certificate).
    candidate : Candidate
        Regression statistics of ``law`` on the contact samples (rss, bic, aic; for a
        refined law recomputed for the refined coefficients; the regression's own
        coefficients are in ``candidate.extra["regression_coefficients"]``).
    evaluations : tuple of Evaluation
        The law simulated and scored against each record
        (:func:`discovery.vibroimpact.verify.evaluate`): regime, criteria, noise floor, consistency.
    refinement : IdentificationResult or None
        The output-error refinement (standard errors, simulations used).
    note : str
        What happened to the refinement (kept, or why not).
    certificate : constraints.Certificate or None
        Of ``law`` on the box of the samples it was fitted to.
    intervals : Intervals or None
        Bootstrap intervals of the coefficients through the full processing
        (:func:`discovery.vibroimpact.fit.intervals.bootstrap_intervals`; the selected model only).
    """

    KIND = "ranked-model"
    _LOAD = {
        "law": lambda d: ForceLaw.from_dict(d["coefficients"]),
        "evaluations": _loaded_evaluations,
        "candidate": lambda d: None,
        "refinement": lambda d: None,
        "certificate": lambda d: None,
        "note": lambda d: d.get("refinement", ""),
        "intervals": _loaded_intervals,
    }

    law: object
    candidate: object
    evaluations: tuple
    refinement: object = None
    note: str = ""
    certificate: object = None
    intervals: object = None

    @property
    def evaluation(self):
        """The evaluation against the first record."""
        return self.evaluations[0]

    @property
    def regime(self):
        return ", ".join(ev.regime["simulated"] or ev.status for ev in self.evaluations)

    @property
    def criteria(self):
        """Criteria I0..I4, the mean over records (empty unless every record is ``ok``)."""
        if not all(ev.criteria for ev in self.evaluations):
            return {}
        return {
            k: float(np.mean([ev.criteria[k] for ev in self.evaluations]))
            for k in self.evaluations[0].criteria
        }

    @property
    def noise_floor(self):
        """Noise floor of every criterion, the mean over records."""
        if not all(ev.noise_floor for ev in self.evaluations):
            return {}
        return {
            k: float(np.mean([ev.noise_floor[k] for ev in self.evaluations]))
            for k in self.evaluations[0].noise_floor
        }

    @property
    def limits(self):
        """The consistency limits the law was judged by: the record's own (empty for
        several records: each has its own, in ``records``)."""
        return dict(self.evaluation.limits) if len(self.evaluations) == 1 else {}

    @property
    def consistent(self):
        """Consistent with every record."""
        return all(ev.consistent for ev in self.evaluations)

    @property
    def verdict(self):
        if len(self.evaluations) == 1:
            return self.evaluation.verdict
        bad = [(i, ev) for i, ev in enumerate(self.evaluations) if not ev.consistent]
        if not bad:
            return f"consistent with all {len(self.evaluations)} records"
        if len(bad) == 1:
            i, ev = bad[0]
            return f"inconsistent with record {i + 1}: {ev.verdict}"
        # every record's verdict in full: none is cut to "(and 1 more)"
        return f"inconsistent with {len(bad)} of {len(self.evaluations)} records: " + "; ".join(
            f"record {i + 1}: {ev.verdict}" for i, ev in bad
        )

    @property
    def defects(self):
        """Why the law is not a contact law (:meth:`ForceLaw.contact_defects`)."""
        return self.law.contact_defects()

    @property
    def standard_errors(self):
        """``{term: standard error}`` from the refinement (empty without it)."""
        return (
            dict(self.refinement.standard_errors)
            if self.refinement is not None and self.note.startswith("refined")
            else {}
        )

    def as_dict(self):
        ev = self.evaluation
        iv = self.intervals
        d = {
            "terms": list(self.law.names),
            "coefficients": self.law.as_dict(),
            "standard_errors": self.standard_errors,
            "intervals": {} if iv is None else {k: list(v) for k, v in iv.bounds.items()},
            "interval_method": None if iv is None else iv.method,
            "interval_level": None if iv is None else iv.level,
            "regression_coefficients": self.candidate.extra.get(
                "regression_coefficients", self.candidate.coefficients
            ),
            "latex": self.law.latex(),
            "regime": self.regime,
            "status": ev.status,
            "criteria": self.criteria,
            "noise_floor": self.noise_floor,
            "limits": self.limits,
            "consistent": self.consistent,
            "verdict": self.verdict,
            "bic": self.candidate.bic,
            "aic": self.candidate.aic,
            "cv_error": self.candidate.cv_error,
            "rss": self.candidate.rss,
            "constrained": self.candidate.constrained,
            "refinement": self.note,
            "contact_defects": self.defects,
        }
        if self.refinement is not None:
            d["n_simulations"] = self.refinement.n_simulations
        if len(self.evaluations) > 1:
            d["records"] = [e.as_dict() for e in self.evaluations]
        return d

    def _lines(self):
        head = (
            f"{self.law}  [{self.regime}]: "
            f"{'consistent' if self.consistent else 'NOT consistent'} with the record(s)"
        )
        out = [head, *coefficient_lines(self.law.as_dict(), self.standard_errors, self.intervals)]
        out += criteria_lines(self.criteria, self.noise_floor, self.limits)
        out.append(f"  verdict: {self.verdict}")
        if self.note:
            out.append(f"  refinement: {self.note}")
        return out


@readable
@dataclass(frozen=True, eq=False)
class DiscoveryResult(Result):
    """Outcome of :func:`discover`.

    Attributes
    ----------
    selected : RankedModel
        The chosen model.
    ranking : list of RankedModel
        Every shortlisted candidate, best first.
    certificate : constraints.Certificate
        Of the selected law on the data's box.
    estimator : ConstrainedSparseRegressor
        The fitted estimator.
    samples : ContactSamples
        The contact samples of all records, joined.
    measured : Impulse
        The first record's measured cycle.
    references : tuple of (Scenario, Reference)
        Every record with its scenario.
    stability : dict
        ``{term: selection frequency}`` over bootstrap resamples of impacts (empty if
        not requested).
    warnings : list of str
        Why the record(s) may not identify the law (see :func:`discover`).
    equivalent : list of dict
        Models the records cannot tell apart from the selected one, with the reason and
        what data would separate them.
    seconds : float
        Wall time of the whole discovery.
    settings : dict
    """

    KIND = "fit"
    _LOAD = {
        "selected": lambda d: part(RankedModel, d["selected"]),
        "ranking": lambda d: [part(RankedModel, m) for m in d["ranking"]],
        "certificate": lambda d: d.get("certificate") and Certificate(**d["certificate"]),
        "samples": lambda d: None,
        "measured": lambda d: None,
        "references": lambda d: (),
        "seconds": lambda d: d.get("discovery_seconds", 0.0),
        "settings": lambda d: d.get("fit_settings", {}),
    }

    selected: RankedModel
    ranking: list
    certificate: object
    estimator: object
    samples: object
    measured: object
    references: tuple = ()
    stability: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    equivalent: list = field(default_factory=list)
    seconds: float = 0.0
    settings: dict = field(default_factory=dict)

    @property
    def refinement(self):
        """The selected model's refinement (or None)."""
        return self.selected.refinement

    def as_dict(self, names=None):
        """The result as JSON-ready data (``summary.json`` of ``vidi fit``); ``names``
        labels the records (default: their sources)."""
        cert = self.certificate
        refs = [ref for _, ref in self.references]
        names = list(names) if names is not None else [getattr(r, "source", "") for r in refs]
        ref_out = self.refinement
        return {
            "records": [
                {
                    "data": n,
                    "scenario": s_k.name,
                    "regime": ref.regime,
                    "impacts": ref.impacts,
                    "noise": ref.noise,
                }
                for n, (s_k, ref) in zip(names, self.references, strict=True)
            ],
            "selected": self.selected.as_dict(),
            "warnings": self.warnings,
            "equivalent": self.equivalent,
            "ranking": [m.as_dict() for m in self.ranking],
            "certificate": None
            if cert is None
            else {
                "method": cert.method,
                "holds": cert.holds,
                "worst_violation": cert.worst_violation,
                "domain": cert.domain,
                "conditions": cert.conditions,
            },
            "stability": self.stability,
            "refinement": None
            if ref_out is None
            else {
                "coefficients": ref_out.coefficients,
                "criteria": ref_out.criteria,
                "standard_errors": ref_out.standard_errors,
                "n_simulations": ref_out.n_simulations,
                "message": ref_out.message,
                "failures": len(ref_out.failures),
            },
            "samples": {
                "n": len(self.samples),
                "impacts": self.samples.n_impacts,
                "derivative": self.samples.derivative,
                "noise": self.samples.noise,
            },
            "measured": {
                "n_cycles": self.measured.n_cycles,
                "n_periods": self.measured.n_periods,
                "noise": self.measured.noise,
                "threshold": self.measured.threshold,
            },
            "discovery_seconds": self.seconds,
            "fit_settings": self.settings,
        }

    def _lines(self):
        sel = self.selected
        crit = self.settings.get("criterion", "I2")
        head = (
            f"selected {sel.law}  [{sel.regime}]: "
            f"{'consistent' if sel.consistent else 'NOT consistent'} with the record(s)"
        )
        out = [head, *coefficient_lines(sel.law.as_dict(), sel.standard_errors, sel.intervals)]
        out += criteria_lines(sel.criteria, sel.noise_floor, sel.limits)
        out.append(f"  verdict: {sel.verdict}")
        out.append(f"ranking ({len(self.ranking)} candidates, criterion {crit}):")
        for i, m in enumerate(self.ranking[:8]):
            out.append(
                f"  {i + 1:>2}. {' + '.join(m.law.names):<28} {m.regime:<6} "
                f"{crit} {fmt((m.criteria or {}).get(crit), 3):>8}  "
                f"{'consistent' if m.consistent else ''}"
            )
        if len(self.ranking) > 8:
            out.append(f"  ... {len(self.ranking) - 8} more")
        for e in self.equivalent:
            out.append(f"equivalent: {e.get('law', e.get('terms'))}: {e.get('reason', '')}")
        cert = self.certificate
        if cert is not None:
            out.append(
                f"certificate: conditions {'hold' if cert.holds else 'DO NOT hold'} ({cert.method})"
            )
        out += [f"warning: {w}" for w in self.warnings]
        out.append(f"{self.seconds:.1f} s")
        return out


def _coefficients(law, library):
    """Coefficient vector of ``law`` over ``library`` (zeros for absent terms)."""
    d = law.as_dict()
    return np.array([d.get(t.name, 0.0) for t in library.terms])


def rank(models, criterion="I2", sim_rtol=0.1, sim_atol=0.005, physics=True):
    """Order checked models: the models consistent with the records first, the fewest terms
    first, then by the criterion (the records cannot tell them apart); then the others
    whose criterion is within ``sim_rtol`` (relative) or ``sim_atol`` of the best, by BIC;
    then the rest by the criterion; models without a periodic steady state with contact last.

    With ``physics`` (default) laws that are no contact laws
    (:meth:`ForceLaw.contact_defects`: no spring, a negative damper) come after every
    contact law, ranked among themselves by the same rule."""
    if physics:
        sound = [m for m in models if not m.defects]
        if len(sound) < len(models):
            unsound = [m for m in models if m.defects]
            head = rank(sound, criterion, sim_rtol, sim_atol, physics=False)
            tail = rank(unsound, criterion, sim_rtol, sim_atol, physics=False)
            # models without a periodic steady state stay last of all
            return (
                [m for m in head if m.criteria]
                + [m for m in tail if m.criteria]
                + [m for m in head if not m.criteria]
                + [m for m in tail if not m.criteria]
            )
    ok = [m for m in models if m.criteria]
    bad = sorted((m for m in models if not m.criteria), key=lambda m: m.candidate.bic)
    if not ok:
        return bad
    good = sorted(
        (m for m in ok if m.consistent), key=lambda m: (len(m.law.names), m.criteria[criterion])
    )
    rest = [m for m in ok if not m.consistent]
    if not rest:
        return good + bad
    best = min(m.criteria[criterion] for m in rest)
    limit = max(best * (1 + sim_rtol), best + sim_atol)
    tier = sorted(
        (m for m in rest if m.criteria[criterion] <= limit), key=lambda m: m.candidate.bic
    )
    tail = sorted(
        (m for m in rest if m.criteria[criterion] > limit), key=lambda m: m.criteria[criterion]
    )
    return good + tier + tail + bad


def _best_per_support(models, criterion):
    """One model per support: the consistent one, else the lowest criterion (a support
    refined again from another start keeps its better refinement)."""
    best = {}
    for m in models:
        key = frozenset(m.law.names)
        score = (not m.consistent, m.criteria.get(criterion, np.inf) if m.criteria else np.inf)
        if key not in best or score < best[key][0]:
            best[key] = (score, m)
    keep = {id(m) for _, m in best.values()}
    return [m for m in models if id(m) in keep]


def _sign_vector(signs, library):
    """``{term: +1 | -1 | 0}`` as the estimator's per-term sign vector."""
    lib = library if isinstance(library, Library) else Library.parse(library)
    names = [t.name for t in lib.terms]
    out = np.zeros(len(names))
    for key, sign in signs.items():
        try:
            name = Term.parse(str(key).strip()).name
        except VidiError:
            name = None
        if name not in names:
            raise InputError(f"signs: term {key!r} is not in the library ({', '.join(names)})")
        if sign not in (-1, 0, 1):
            raise InputError(f"signs: the sign of {key} must be +1, -1 or 0; got {sign!r}")
        out[names.index(name)] = sign
    return out


def _required_terms(require, library):
    """The set of required term names, each checked against the library."""
    if isinstance(require, str):
        require = [r for r in require.split(",") if r.strip()]
    names = [t.name for t in library.terms]
    out = set()
    for r in require:
        try:
            name = Term.parse(str(r).strip()).name
        except VidiError:
            name = None
        if name not in names:
            raise InputError(
                f"required term {r!r} is not in the library ({', '.join(names)})"
                "; give library terms to --require, e.g. --require z"
            )
        out.add(name)
    return frozenset(out)


def _trial(check, job):
    """One trial of the search (a task of the executor, the checker its forked context):
    ``job = (starts, origin)``, the first of the ``(law, candidate)`` starts whose
    refinement simulates (the last one's result when none does)."""
    starts, origin = job
    for law, cand in starts:
        trial = check.refined(law, cand, origin)
        if trial.criteria:
            break
    return trial


class _Checker:
    """Refines (optionally) and evaluates regression candidates against all records; the
    trials of one step (the shortlist, a forward or backward move) run on ``workers``
    processes (their results do not depend on it: each refinement is deterministic)."""

    def __init__(
        self,
        est,
        samples,
        refs,
        criterion,
        refine,
        tolerances,
        budget,
        required=frozenset(),
        workers=1,
    ):
        self.est, self.samples, self.refs = est, samples, refs
        self.required = frozenset(required)
        self.criterion, self.refine, self.tol, self.budget = criterion, refine, tolerances, budget
        self.workers = workers

    def evaluate(self, law):
        return tuple(evaluate(sc, law, ref, tolerances=self.tol) for sc, ref in self.refs)

    def run(self, jobs, stage=None, progress=None):
        """The trials of ``jobs`` (see :func:`_trial`) in their order, on up to ``workers``
        forked processes (never more than the jobs)."""
        return map_on(
            _trial, jobs, self, workers=self.workers, done=lambda k, n: tick(progress, stage, k, n)
        )

    def regression_law(self, cand):
        """A regression candidate's law."""
        lib = self.est.library_
        return lib.law([cand.coefficients.get(t.name, 0.0) for t in lib.terms])

    def refined(self, law, cand, origin):
        """Refine ``law`` (from ``origin``: "regression" or a forward step) and check it."""
        est = self.est
        extra = {"regression_coefficients": dict(cand.coefficients), "origin": origin}
        cand = replace(cand, extra={**cand.extra, **extra})
        cert0 = est.certify(_coefficients(law, est.library_))
        if not self.refine:
            return RankedModel(law, cand, self.evaluate(law), note="not refined", certificate=cert0)
        law = self._scaled_start(law)
        try:
            ref = identify(
                [sc for sc, _ in self.refs],
                [r for _, r in self.refs],
                law,
                criterion=self.criterion,
                method="least-squares",
                max_simulations=self.budget,
                tolerances=self.tol,
                check=False,
            )
        except IntegrationError as exc:
            return RankedModel(
                law,
                cand,
                self.evaluate(law),
                note=f"not refined: the {origin} law fails ({exc})",
                certificate=cert0,
            )
        coef = _coefficients(ref.law, est.library_)
        cert = est.certify(coef)
        if not cert.holds:
            return RankedModel(
                law,
                cand,
                self.evaluate(law),
                refinement=ref,
                note="not refined: the refined coefficients break a physical "
                f"condition (worst violation {cert.worst_violation:.2g})",
                certificate=cert0,
            )
        s = self.samples
        rescored = est.rescore(
            coef, s.X, s.F, s.weight, s.impact, constrained=cand.constrained, extra=cand.extra
        )
        if origin == "regression":  # the support's cross-validated error is the candidate's
            rescored = replace(rescored, cv_error=cand.cv_error)
        return RankedModel(
            ref.law,
            rescored,
            self.evaluate(ref.law),
            refinement=ref,
            note=f"refined by simulation from the {origin} "
            f"({ref.n_simulations} simulations, {self.criterion} "
            f"{ref.value:.3g})",
            certificate=cert,
        )

    def _scaled_start(self, law):
        """The refinement works in units of the start coefficients: a term whose start is
        negligible (its force at the box's far corner below 0.1 % of the peak force) could
        never grow, so it starts at 1 % of the peak instead (with its sign)."""
        lib, est = self.est.library_, self.est
        corner = lib.transform(np.array([[est.box_.zeta_max, est.box_.zd_max]]))[0]
        peak = float(np.max(np.abs(self.samples.F)))
        coef = _coefficients(law, lib)
        small = (coef != 0) & (np.abs(coef) * corner < 1e-3 * peak) & (corner > 0)
        if not small.any():
            return law
        coef[small] = np.sign(coef[small]) * _FORWARD_STARTS[0] * peak / corner[small]
        return lib.law(coef)

    def physical_start(self, scenario, ref):
        """A spring-dashpot start from the record alone, refined by simulation: stiffness from
        the measured contact time (``k = mu (pi / tau)^2``, ``mu`` the reduced mass), damping
        from the force jump at onset (``c = F(0+) / v``, ``v`` the impact velocity; 5 % of
        critical when there is no jump), put on the library's lowest elastic and damping
        terms at the typical penetration ``v tau / pi``.  ``None`` when the library has
        neither kind of term or the record gives no contact time."""
        est = self.est
        lib = est.library_
        if not len(ref.impulse.support):
            return None
        coef = np.zeros(len(lib))
        elastic = [i for i, t in enumerate(lib.terms) if t.b == 0]
        damping = [i for i, t in enumerate(lib.terms) if t.b == 1]
        chosen = [min(group, key=lambda j: lib.terms[j].a) for group in (elastic, damping) if group]
        if not chosen:
            return None
        coef[chosen] = record_start(scenario, ref, [lib.terms[i] for i in chosen])
        s = self.samples
        cand = est.rescore(coef, s.X, s.F, s.weight, s.impact)
        return self.refined(lib.law(coef), cand, "physical start (contact time, onset jump)")

    def backward(self, base, skip=frozenset()):
        """Output-error backward step: ``base`` without each of its terms in turn, refined
        by simulation from the other coefficients (the simplest consistent model wins)."""
        names = base.law.names
        if len(names) < 2:
            return []
        lib = self.est.library_
        jobs = []
        for term in names:
            if term in self.required or frozenset(names) - {term} in skip:
                continue
            coef = _coefficients(base.law, lib)
            coef[[t.name for t in lib.terms].index(term)] = 0.0
            cand = self.est.rescore(
                coef, self.samples.X, self.samples.F, self.samples.weight, self.samples.impact
            )
            jobs.append(([(lib.law(coef), cand)], f"backward step from {' + '.join(names)}"))
        return self.run(jobs)

    def restart(self, base, support):
        """``support`` refined again from ``base``'s coefficients (its other terms started
        like a forward step's new term): a smaller support whose refinement from the
        biased regression stalled, retried from a consistent model's start."""
        est = self.est
        lib = est.library_
        peak = float(np.max(np.abs(self.samples.F)))
        corner = lib.transform(np.array([[est.box_.zeta_max, est.box_.zd_max]]))[0]
        coef = np.zeros(len(lib))
        base_c = _coefficients(base.law, lib)
        for i, term in enumerate(lib.terms):
            if term.name in support:
                coef[i] = (
                    base_c[i] if base_c[i] else _FORWARD_STARTS[0] * peak / max(corner[i], 1e-300)
                )
        cand = est.rescore(
            coef, self.samples.X, self.samples.F, self.samples.weight, self.samples.impact
        )
        return self.refined(lib.law(coef), cand, f"restart from {' + '.join(base.law.names)}")

    def forward(self, base, max_terms, skip=frozenset()):
        """Output-error forward step: ``base`` plus each library term it lacks, every trial
        refined by simulation from ``base``'s coefficients and a small start value of the
        new term (its force at the far corner of the data's box 1 % of the peak force, or
        0.1 % when that start has no periodic orbit)."""
        est = self.est
        lib = est.library_
        peak = float(np.max(np.abs(self.samples.F)))
        corner = lib.transform(np.array([[est.box_.zeta_max, est.box_.zd_max]]))[0]
        have = set(base.law.names)
        if len(have) >= max_terms:
            return []
        jobs = []
        for i, term in enumerate(lib.terms):
            if term.name in have or corner[i] <= 0 or frozenset(have | {term.name}) in skip:
                continue
            starts = []
            for frac in _FORWARD_STARTS:
                coef = _coefficients(base.law, lib)
                coef[i] = frac * peak / corner[i]
                cand = est.rescore(
                    coef, self.samples.X, self.samples.F, self.samples.weight, self.samples.impact
                )
                starts.append((lib.law(coef), cand))
            jobs.append((starts, f"forward step from {' + '.join(base.law.names)}"))
        return self.run(jobs)


def _stability_warning(stab, selected):
    if not stab:
        return None
    names = set(selected.law.names)
    weak = [t for t in names if stab.get(t, 0.0) < 0.5]
    strong = [t for t, f in stab.items() if f >= 0.5 and t not in names]
    if not weak and not strong:
        return None
    parts = []
    if weak:
        parts.append(
            "selected but chosen in < 50 % of resamples: "
            + ", ".join(f"{t} ({stab.get(t, 0.0):.2f})" for t in sorted(weak))
        )
    if strong:
        parts.append(
            "chosen in >= 50 % of resamples but not selected: "
            + ", ".join(f"{t} ({stab[t]:.2f})" for t in sorted(strong))
        )
    return (
        "stability selection disagrees with the selected support ("
        + "; ".join(parts)
        + "): the record may not identify these terms"
    )


def _impact_warnings(pairs, parts, refs):
    out = []
    for k, ((sc, meas), s, (_, ref)) in enumerate(zip(pairs, parts, refs, strict=True)):
        E = ref.impulse
        span = float(meas.t[-1] - meas.t[0])
        expected = span / (E.n_periods * sc.period) * ref.impacts
        n = s.n_impacts
        if expected >= 2 and not (0.6 * expected - 1 <= n <= 1.15 * expected + 1):
            label = f"record {k + 1}" if len(pairs) > 1 else "the record"
            out.append(
                f"{label} gives {n} impacts for the contact samples, but its "
                f"{span / sc.period:.0f} periods of a {ref.regime} cycle with "
                f"{ref.impacts} contact(s) hold about {expected:.0f}: contacts are "
                "split or merged (noisy positions?); check the record, record the "
                "velocities, or lower the position noise"
            )
    return out


def _warnings(selected, by_bic, stab, pairs, parts, refs, samples, refine):
    out = []
    w = _stability_warning(stab, selected)
    if w:
        out.append(w)
    failing = [m for m in by_bic[:3] if not m.criteria]
    if failing:
        out.append(
            f"{len(failing)} of the 3 best candidates by the regression score have no "
            "periodic steady state with contact ("
            + "; ".join(f"{' + '.join(m.law.names)}: {m.evaluation.status}" for m in failing)
            + "): the regression alone would mislead here"
        )
    out.extend(_impact_warnings(pairs, parts, refs))
    if (
        not selected.consistent
        and selected.criteria
        and all(ev.consistent or ev.only_i4 for ev in selected.evaluations)
    ):
        out.append(
            "the selected model fails the consistency rule by I4 alone (the contact "
            "supports; I2 is within its noise floor): I4 is noise-sensitive on flat "
            "force tails and short contacts, so this may be the right law; compare the "
            "contact ends in fit_impulse before trying a larger library"
        )
    elif not selected.consistent:
        out.append(
            "no shortlisted model is consistent with the record(s) within the noise "
            "floor: try a larger library (e.g. poly:3+hc), a longer shortlist, or check "
            "the scenario (masses, supports, drive)"
        )
    if samples.derivative != "velocities" and not refine:
        out.append(
            f"dzeta was obtained by {samples.derivative} from noisy positions: the "
            "regression coefficients are biased (errors in variables); use the "
            "refinement by simulation"
        )
    ref = selected.refinement
    if ref is not None and selected.standard_errors:
        reg = selected.candidate.extra.get("regression_coefficients", {})
        moved = []
        for t, c in selected.law.as_dict().items():
            se = selected.standard_errors.get(t, 0.0)
            c0 = reg.get(t)
            if c0 is not None and se > 0 and abs(c - c0) > max(3 * se, 0.1 * abs(c)):
                moved.append(f"{t} {c0:.3g} -> {c:.3g} ({abs(c - c0) / se:.0f} standard errors)")
        if moved:
            out.append(
                "the refinement by simulation moved regression coefficients far beyond "
                "their uncertainty (" + "; ".join(moved) + "): the regression is biased "
                "by noisy penetration or velocity; the refined values are reported"
            )
    return out


def _collinearity(est, samples, terms, others):
    """R^2 of each of ``terms``' columns regressed on ``others``' along the samples."""
    lib = est.library_
    idx = {t.name: i for i, t in enumerate(lib.terms)}
    theta = lib.transform(samples.X) * np.sqrt(samples.weight)[:, None]
    B = theta[:, [idx[t] for t in others]] if others else np.zeros((theta.shape[0], 0))
    r2 = {}
    for t in terms:
        y = theta[:, idx[t]]
        if B.shape[1]:
            res = y - B @ np.linalg.lstsq(B, y, rcond=None)[0]
        else:
            res = y
        tot = float(y @ y)
        r2[t] = 1.0 - float(res @ res) / tot if tot > 0 else 0.0
    return r2


def _separation(est, a, b):
    """How much two checked models' simulated force histories differ on the recorded
    orbits, and where their laws differ most beyond the recorded range (up to 2x the
    recorded penetration and impact velocity); both relative to the peak force."""
    d_in, peak = 0.0, 1e-300
    for ea, eb in zip(a.evaluations, b.evaluations, strict=True):
        fa, fb = ea.simulated.F, eb.simulated.F
        peak = max(peak, float(np.max(np.abs(fa))))
        d_in = max(d_in, float(np.max(np.abs(fa - fb))))
    box = est.box_
    zz, vv = np.meshgrid(np.linspace(0, 2 * box.zeta_max, 41), np.linspace(0, 2 * box.zd_max, 41))
    d = np.abs(a.law(zz, vv) - b.law(zz, vv)) / peak
    i = np.unravel_index(int(np.argmax(d)), d.shape)
    return d_in / peak, float(d[i]), float(zz[i]), float(vv[i])


def _equivalent(ranking, selected, est, samples, criterion):
    """Consistent models whose criterion is within the noise floor of the selected one's."""
    if not selected.consistent or not selected.criteria:
        return []
    best = selected.criteria[criterion]
    tol = selected.noise_floor.get(criterion, 0.0)
    out = []
    for m in ranking:
        if m is selected or not m.consistent or m.criteria[criterion] > best + tol:
            continue
        sel_t, m_t = set(selected.law.names), set(m.law.names)
        extra = sorted(m_t - sel_t) or sorted(sel_t - m_t)
        base = sorted(sel_t & m_t)
        r2 = _collinearity(est, samples, extra, base) if extra else {}
        near = {t: v for t, v in r2.items() if v > 0.95}
        d_in, d_out, z, v = _separation(est, selected, m)
        differ = (
            " vs ".join(" + ".join(sorted(x)) for x in (sel_t - m_t, m_t - sel_t) if x)
            or "the coefficients"
        )
        if near:
            reason = "near-collinear along the recorded orbit(s): " + ", ".join(
                f"{t} is explained by {' + '.join(base) or 'nothing'} to R^2 = {v:.3f}"
                for t, v in near.items()
            )
        else:
            reason = (
                f"{differ}: their simulated force histories differ by at most "
                f"{100 * d_in:.2g} % of the peak on the recorded orbit(s), within the "
                "noise floor"
            )
        separate = (
            f"their forces differ by {100 * d_out:.0f} % of the recorded peak at "
            f"zeta = {z:.3g} m, zd = {v:.3g} m/s (recorded up to "
            f"{est.box_.zeta_max:.3g} m, {est.box_.zd_max:.3g} m/s): a record with "
            "faster or deeper impacts (larger drive amplitude, another frequency) "
            "would separate them"
            if d_out > 2 * d_in
            else "they differ little anywhere near the recorded range: the data cannot "
            "separate them; prefer the simpler one"
        )
        out.append(
            {
                "terms": list(m.law.names),
                "coefficients": m.law.as_dict(),
                "criteria": m.criteria,
                "consistent": True,
                "reason": reason,
                "separate": separate,
            }
        )
    return out


def _check_settings(
    random_state, seed, criterion, shortlist, stability, n_boot, max_simulations, stepwise
):
    """The settings :func:`discover` checks beyond their types; returns the seed
    (``random_state=`` is the deprecated name of ``seed=``)."""
    if random_state is not None:
        warn(
            "discover(random_state=...) is renamed seed=... (the CLI's --seed)",
            DeprecationWarning,
            stacklevel=4,
        )
        seed = random_state
    _criterion(criterion)
    if not (isinstance(shortlist, int | np.integer) and shortlist >= 1):
        raise InputError(
            f"shortlist must be a positive integer (candidates simulated); got {shortlist!r}"
        )
    for name, v, low in (
        ("stability", stability, 0),
        ("n_boot", n_boot, 1),
        ("max_simulations", max_simulations, 2),
        ("stepwise", stepwise, 0),
    ):
        if not (isinstance(v, int | np.integer) and not isinstance(v, bool) and v >= low):
            raise InputError(f"{name} must be an integer >= {low}; got {v!r}")
    return seed


def _regression(
    pairs, library, selection, scoring, max_terms, derivative, average_cycles, estimator_kwargs
):
    """Contact samples of every record, joined, and the certified sparse regression on
    them: ``(samples per record, joined samples, fitted estimator)``."""
    parts = [
        contact_samples(m, derivative=derivative, average_cycles=average_cycles, period=sc.period)
        for sc, m in pairs
    ]
    samples = join_samples(parts)
    if isinstance(estimator_kwargs.get("signs"), dict):
        estimator_kwargs["signs"] = _sign_vector(estimator_kwargs["signs"], library)
    est = ConstrainedSparseRegressor(
        library=library,
        selection=selection,
        scoring=scoring,
        max_terms=max_terms,
        **estimator_kwargs,
    )
    est.fit(samples.X, samples.F, groups=samples.impact, sample_weight=samples.weight)
    return parts, samples, est


def _stability(est, samples, resamples, seed):
    """Stability selection's term frequencies over ``resamples`` bootstrap resamples of
    impacts (``{}`` for none)."""
    if not resamples:
        return {}
    s = samples
    return est.stability(s.X, s.F, s.impact, resamples, seed, sample_weight=s.weight)


_SHORTLIST_STAGE = "fit: shortlisted supports checked by simulation"


def _shortlist(check, est, required, shortlist, progress):
    """The estimator's best supports (holding the required terms), each checked by
    simulation."""
    pool = [c for c in est.candidates_ if required <= set(c.coefficients)]
    if not pool:
        raise InputError(
            f"no candidate support of the library holds the required terms "
            f"{', '.join(sorted(required))}; raise --max-terms or drop --require"
        )
    jobs = [([(check.regression_law(c), c)], "regression") for c in pool[:shortlist]]
    tick(progress, _SHORTLIST_STAGE, 0, len(jobs))
    return check.run(jobs, _SHORTLIST_STAGE, progress)


class _Stepwise:
    """The output-error stepwise search around the best model: a consistent model loses a
    term (backward), an inconsistent one gains one (forward: the regression may have been
    misled, e.g. by noisy penetration), for up to ``stepwise`` moves."""

    def __init__(self, check, criterion, sim_rtol, sim_atol, physics, stepwise, max_terms):
        self.check, self.criterion, self.physics = check, criterion, physics
        self.sim_rtol, self.sim_atol = sim_rtol, sim_atol
        self.stepwise, self.max_terms = stepwise, max_terms
        self.retried = set()

    def rank(self, models):
        return rank(models, self.criterion, self.sim_rtol, self.sim_atol, physics=self.physics)

    def more(self, steps, ranking):
        """Up to ``stepwise`` moves, and one simplifying move more when the last move made
        the best model consistent (its backward step and restarts would be cut off
        otherwise)."""
        if len(steps) < self.stepwise:
            return True
        return (
            len(steps) == self.stepwise
            and self.stepwise > 0
            and ranking[0].consistent
            and steps[-1]["kind"] != "backward"
        )

    def trials(self, top, models):
        """The models of one move from ``top``, and the move's kind."""
        check, physics = self.check, self.physics
        # supports already simulated successfully are not tried again, except that a
        # consistent model's backward step retries a smaller support that was inconsistent
        # from its own (biased regression) start, once, from the consistent coefficients:
        # a refinement that stalled far from the truth must not hide the simplest model
        done = frozenset(frozenset(m.law.names) for m in models if m.criteria)
        if not (top.consistent and not (physics and top.defects)):
            # both directions: a wrong term may have to go while a missing one comes in
            trials = check.forward(top, self.max_terms, done) + check.backward(top, done)
            return trials, "forward+backward"
        good = frozenset(frozenset(m.law.names) for m in models if m.criteria and m.consistent)
        trials = check.backward(top, good | self.retried)
        self.retried |= {frozenset(m.law.names) for m in trials} & done
        # smaller supports that stalled and no backward step reaches: the two best,
        # restarted from the consistent model's coefficients
        stalled = sorted(
            (
                m
                for m in models
                if m.criteria
                and not m.consistent
                and len(m.law.names) <= len(top.law.names)
                and frozenset(m.law.names) not in self.retried
                and not (physics and m.defects)
            ),
            key=lambda m: m.criteria[self.criterion],
        )[:_RESTARTS]
        for m in stalled:
            self.retried.add(frozenset(m.law.names))
            trials.append(check.restart(top, set(m.law.names)))
        return trials, "backward"

    def run(self, models, refs, refine, progress):
        """``(ranking, steps)`` after the search."""
        ranking = self.rank(models)
        steps = []
        if refine and not ranking[0].criteria:
            # no regression law has a periodic orbit with contact: start from the record alone
            start = self.check.physical_start(*refs[0])
            if start is not None:
                steps.append({"kind": "physical start", "from": [], "trials": 1})
                models = models + [start]
                ranking = self.rank(models)
        while refine and ranking[0].criteria and self.more(steps, ranking):
            top = ranking[0]
            trials, kind = self.trials(top, models)
            if not trials:
                break
            steps.append({"kind": kind, "from": list(top.law.names), "trials": len(trials)})
            tick(
                progress, "fit: stepwise search around the best support", len(steps), self.stepwise
            )
            models = _best_per_support(models + trials, self.criterion)
            ranking = self.rank(models)
            if ranking[0] is top:
                break
        return ranking, steps


def _with_intervals(ranking, refs, refine, boot, criterion, tolerances, progress):
    """The selected (best ranked) model, with bootstrap intervals when asked for and it was
    refined, and the ranking holding it; ``boot``: ``(replicates, seed, workers, refit)``."""
    n_boot_intervals, seed, workers, refit = boot
    selected = ranking[0]
    if not (
        n_boot_intervals
        and refine
        and selected.refinement is not None
        and selected.note.startswith("refined")
    ):
        return selected, ranking
    tick(progress, "fit: bootstrap intervals", 0, n_boot_intervals)
    iv = bootstrap_intervals(
        [sc for sc, _ in refs],
        [r for _, r in refs],
        selected.law,
        n_boot=int(n_boot_intervals),
        seed=seed,
        criterion=criterion,
        tolerances=tolerances,
        workers=workers,
        refit=refit,
    )
    if iv is None:
        return selected, ranking
    chosen = replace(selected, intervals=iv)
    return chosen, [chosen if m is selected else m for m in ranking]


def _defects_warning(selected, physics):
    """The warning that the selected law is no contact law."""
    return (
        "the selected law is no contact law ("
        + "; ".join(selected.defects)
        + "): "
        + (
            "no candidate was one; widen the library or --require z"
            if physics
            else "ranked by the records alone (--allow-unphysical)"
        )
    )


def _contact_models(scenario, measurement, n_boot, seed, progress):
    """``library="contact-models"``: the named contact models fitted by name
    (:func:`~discovery.vibroimpact.fit.contact_fit.fit_contact_models`)."""
    from .contact_fit import fit_contact_models

    return fit_contact_models(
        scenario, measurement, n_boot=n_boot, seed=0 if seed is None else seed, progress=progress
    )


@params(
    scenario=(Scenario, list, tuple),
    measurement=(Measurement, list, tuple),
    library=(Text(), Library, list, tuple),
    selection=Text(),
    scoring=Text(),
    max_terms=Real(1, 64, integer=True),
    criterion=Text(),
    shortlist=Real(1, integer=True),
    stability=Real(0, integer=True),
    derivative=(None, Text()),
    sim_rtol=Real(0, open_low=True),
    sim_atol=Real(0),
    tolerances=(Tolerances, None),
    seed=Real(0, integer=True),
    random_state=(None, Real(0, integer=True)),
    n_boot=Real(0, integer=True),
    max_simulations=Real(0, integer=True),
    stepwise=Real(0, integer=True),
    require=(tuple, list),
    n_boot_intervals=Real(0, integer=True),
    interval_refit=Choice(*INTERVAL_REFITS),
    workers=(None, Real(1, integer=True)),
)
@reports_progress
def discover(
    scenario,
    measurement,
    *,
    library="poly:2",
    selection="best-subset",
    scoring="bic",
    max_terms=4,
    criterion="I2",
    shortlist=8,
    refine=True,
    stability=0,
    derivative=None,
    average_cycles=False,
    sim_rtol=0.1,
    sim_atol=0.005,
    tolerances=None,
    seed=0,
    n_boot=16,
    max_simulations=_REFINE_BUDGET,
    stepwise=3,
    physics=True,
    require=(),
    n_boot_intervals=30,
    interval_refit="two-step",
    workers=1,
    progress=None,
    random_state=None,
    **estimator_kwargs,
):
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
        Processes for the refinements of the shortlist and of each stepwise move, and for
        the bootstrap's refits (default 1; ``None``: every core); the result does not
        depend on it.
    progress : callable or bool, optional
        ``progress(stage, done, total)`` as the shortlist is simulated and the stepwise
        search and the bootstrap go on; None: a bar when the session is
        interactive, False: none (:mod:`discovery._progress`).
    random_state : int, optional
        Deprecated name of ``seed``.
    **estimator_kwargs
        Further estimator parameters (``margin``, ``monotone``, ``signs``, ...).

    Returns
    -------
    DiscoveryResult
        With ``warnings`` when the record(s) may not identify the law: stability selection
        disagreeing with the selected support, the best candidates by BIC without a
        periodic steady state, impact counts that do not fit the measured regime, no
        consistent model, a refinement that moved coefficients far beyond their
        uncertainty (regression bias).
    """
    if library == "contact-models":  # the named contact models, fitted by name
        return _contact_models(scenario, measurement, n_boot_intervals, seed, progress)
    t0 = time.perf_counter()
    seed = _check_settings(
        random_state, seed, criterion, shortlist, stability, n_boot, max_simulations, stepwise
    )
    pairs = pair_records(scenario, measurement)
    parts, samples, est = _regression(
        pairs, library, selection, scoring, max_terms, derivative, average_cycles, estimator_kwargs
    )
    refs = [(sc, Reference.from_measurement(m, sc, n_boot=n_boot, seed=seed)) for sc, m in pairs]
    required = _required_terms(require, est.library_)
    check = _Checker(
        est, samples, refs, criterion, refine, tolerances, max_simulations, required, workers
    )
    models = _shortlist(check, est, required, shortlist, progress)
    by_score = list(models)  # the estimator's order (its scoring)
    search = _Stepwise(check, criterion, sim_rtol, sim_atol, physics, stepwise, max_terms)
    ranking, steps = search.run(models, refs, refine, progress)
    boot = (n_boot_intervals, seed, workers, interval_refit)
    selected, ranking = _with_intervals(
        ranking, refs, refine, boot, criterion, tolerances, progress
    )
    # the certificate of the law actually selected (the ranking may prefer another
    # candidate than the estimator's best by BIC); a failure is an error
    cert = require_certificate(selected.certificate)
    stab = _stability(est, samples, stability, seed)
    warnings = _warnings(selected, by_score, stab, pairs, parts, refs, samples, refine)
    if selected.defects:
        warnings.insert(0, _defects_warning(selected, physics))
    settings = {
        "library": str(library),
        "selection": selection,
        "scoring": scoring,
        "max_terms": max_terms,
        "criterion": criterion,
        "shortlist": shortlist,
        "refine": refine,
        "max_simulations": max_simulations,
        "stability": stability,
        "derivative": samples.derivative,
        "average_cycles": average_cycles,
        "seed": seed,
        "n_boot": n_boot,
        "records": len(pairs),
        "stepwise": stepwise,
        "steps": steps,
        "physics": physics,
        "n_boot_intervals": n_boot_intervals,
        "interval_refit": interval_refit,
        "require": sorted(required),
        "ranking_rule": {"sim_rtol": sim_rtol, "sim_atol": sim_atol},
        "estimator": est.get_params(),
    }
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
        equivalent=_equivalent(ranking, selected, est, samples, criterion),
        seconds=time.perf_counter() - t0,
        settings=settings,
    )
