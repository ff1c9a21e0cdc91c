"""The results of :func:`~discovery.vibroimpact.fit.discovery.discover`: each checked model
(:class:`RankedModel`), each record as the discovery describes it (:class:`FitRecord`) and the
discovery (:class:`DiscoveryResult`), with their loaders.

A loaded result holds, typed, the laws, each record's evaluation, the candidates' regression
statistics (a :class:`Candidate` whose coefficients are the law's), the selected model's
standard errors and intervals, the certificate (the selected model's too), the records, the
warnings, the equivalent models and the settings.  What the document does not hold is
``None`` or empty: the refinements themselves, the other ranked models' certificates, the
estimator, the samples, the measured cycle and the references.
"""

import dataclasses
import math
import re
from dataclasses import dataclass, field

import numpy as np

from constraints import Certificate

from ..._api._printing import coefficient_lines, fmt, readable
from ..._api._result import Result, part
from ..model.law import ForceLaw
from ..verify.criteria import criteria_lines
from ..verify.evaluation import Evaluation
from ..verify.sensors import lag_note
from .intervals import Intervals
from .records import records_verdict

__all__ = ["RankedModel", "FitRecord", "DiscoveryResult"]


def _real(value):
    """A document's number as a float (``null``, written for one not finite: ``nan``)."""
    return math.nan if value is None else float(value)


def _mean_over(dicts):
    """The key-wise mean of ``dicts`` over the keys every one has (empty unless every one has
    entries): a record judged on its steady orbit has no I5 where another, judged over its
    span, has one, and a mean over the records has none.  A value a document holds as null
    (a number that was not finite) is NaN."""
    if not all(dicts):
        return {}
    return {
        k: float(np.mean([np.nan if d[k] is None else d[k] for d in dicts]))
        for k in dicts[0]
        if all(k in d for d in dicts)
    }


def _loaded_evaluations(d):
    """A loaded ranked model's evaluations: every record's, or the one record's (its
    regime the simulated one's)."""
    if d.get("records"):
        return tuple(part(Evaluation, e) for e in d["records"])
    regime = {"measured": None, "simulated": d.get("regime")}
    return (part(Evaluation, {**d, "regime": regime, "impacts": {}}),)


def _loaded_candidate(d):
    """A loaded ranked model's regression statistics: the law's terms and coefficients, the
    regression's own coefficients in ``extra`` (as a refined candidate keeps them)."""
    from .certified_fit import Candidate

    return Candidate(
        terms=tuple(d["terms"]),
        coefficients=dict(d["coefficients"]),
        rss=_real(d.get("rss")),
        bic=_real(d.get("bic")),
        aic=_real(d.get("aic")),
        cv_error=_real(d.get("cv_error")),
        constrained=bool(d.get("constrained", False)),
        extra={"regression_coefficients": dict(d.get("regression_coefficients") or {})},
    )


def _loaded_intervals(d):
    if not d.get("intervals") and d.get("interval_method") is None:
        return None
    return Intervals(
        bounds={k: tuple(v) for k, v in (d.get("intervals") or {}).items()},
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
        coefficients are in ``candidate.extra["regression_coefficients"]``).  A loaded
        model's holds what its document does, its coefficients the law's.
    evaluations : tuple of Evaluation
        The law simulated and scored against each record
        (:func:`discovery.vibroimpact.verify.evaluate`): regime, criteria, noise floor, consistency.
    refinement : IdentificationResult or None
        The output-error refinement (standard errors, simulations used).
    note : str
        What happened to the refinement (kept, or why not).
    certificate : constraints.Certificate or None
        Of ``law`` on the box of the samples it was fitted to (a loaded result keeps the
        selected model's only).
    intervals : Intervals or None
        Bootstrap intervals of the coefficients through the full processing
        (:func:`discovery.vibroimpact.fit.intervals.bootstrap_intervals`; the selected model only).
    """

    KIND = "ranked-model"
    _LOAD = {
        "law": lambda d: ForceLaw.from_dict(d["coefficients"]),
        "evaluations": _loaded_evaluations,
        "candidate": _loaded_candidate,
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
        return _mean_over([ev.criteria for ev in self.evaluations])

    @property
    def noise_floor(self):
        """Noise floor of every criterion, the mean over records."""
        return _mean_over([ev.noise_floor for ev in self.evaluations])

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
        return records_verdict(self.evaluations, lambda ev: ev.verdict)

    @property
    def defects(self):
        """Why the law is not a contact law (:meth:`ForceLaw.contact_defects`)."""
        return self.law.contact_defects()

    @property
    def standard_errors(self):
        """``{term: standard error}`` from the refinement when its law was kept (empty
        without it); a loaded model's are its document's (its refinement is not kept)."""
        if self.refinement is None and self.loaded:
            kept = self.__dict__["_document"].get("standard_errors") or {}
            return {k: _real(v) for k, v in kept.items()}
        return (
            dict(self.refinement.standard_errors)
            if self.refinement is not None and self.note.startswith("refined")
            else {}
        )

    @property
    def bic(self):
        """The BIC of the law on the contact samples (the candidate's)."""
        return self.candidate.bic

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


@dataclass(frozen=True)
class FitRecord:
    """A record of a discovery as its document describes it.

    Attributes
    ----------
    data : str
        The record's name (the file as given to ``vidi fit``, else its source).
    scenario : str
        The name of its scenario.
    regime : str
        Its measured regime (``"P1"``, ...).
    impacts : int
        Contacts per orbit.
    noise : dict
        Its noise model (``F`` [N], ``zeta`` [m], ``n_cycles``, ...).
    """

    data: str
    scenario: str
    regime: str
    impacts: int
    noise: dict

    def as_dict(self):
        return dataclasses.asdict(self)


def _regime_head(regime):
    """``regime`` without its parenthesised reasons (``failed (I2 is undefined: ...)`` ->
    ``failed``)."""
    out, depth = [], 0
    for ch in regime:
        depth += ch == "("
        if depth == 0:
            out.append(ch)
        depth -= ch == ")" and depth > 0
    return re.sub(r" +", " ", "".join(out)).strip().replace(" ,", ",")


def ranking_lines(ranking, criterion, shown=8):
    """The first ``shown`` ranked models, one row each in aligned columns (terms, regime,
    criterion, consistency); a regime's reason (a failed simulation's), and why a law is no
    contact law (it ranks after every contact law, consistent or not), on their own
    indented lines below the row."""
    rows = ranking[:shown]
    names = [" + ".join(m.law.names) for m in rows]
    regimes = [str(m.regime) for m in rows]
    heads = [_regime_head(r) for r in regimes]
    wn = max((len(n) for n in names), default=0)
    wr = max((len(h) for h in heads), default=0)
    out = []
    for i, (m, name, regime, head) in enumerate(zip(rows, names, regimes, heads, strict=True)):
        value = fmt((m.criteria or {}).get(criterion), 3)
        row = (
            f"  {i + 1:>2}. {name:<{wn}}  {head:<{wr}}  {criterion} {value:>8}  "
            f"{'consistent' if m.consistent else ''}"
        )
        out.append(row.rstrip())
        if head != regime:
            out.append(f"      {regime}")
        defects = m.law.contact_defects()
        if defects:  # ranked after every contact law (the ranking rule's physics)
            out.append(f"      no contact law: {'; '.join(defects)}")
    if len(ranking) > shown:
        out.append(f"  ... {len(ranking) - shown} more")
    return out


def equivalent_text(e):
    """An equivalent model (an entry of ``DiscoveryResult.equivalent``) as text: its terms
    and why the records cannot tell it from the selected one."""
    terms = e.get("terms") or e.get("law") or ()
    terms = terms if isinstance(terms, str) else " + ".join(terms)
    reason = e.get("reason")
    return f"{terms} ({reason})" if reason else terms


def _loaded_certificate(d):
    return Certificate.from_dict(d["certificate"]) if d.get("certificate") else None


def _loaded_selected(d):
    """The loaded selected model, with the result's certificate (the selected law's)."""
    selected = part(RankedModel, d["selected"])
    object.__setattr__(selected, "certificate", _loaded_certificate(d))
    return selected


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
    estimator : CertifiedSparseFit
        The fitted certified regression (the fitted attributes of
        :class:`~discovery.vibroimpact.fit.regression.ConstrainedSparseRegressor`:
        ``candidates_``, ``library_``, ``box_``, ``coef_``...; without scikit-learn).
    samples : ContactSamples
        The contact samples of all records, joined.
    measured : Impulse
        The first record's measured cycle.
    references : tuple of (Scenario, Reference)
        Every record with its scenario (empty on a loaded result: :attr:`records` has what
        its document holds of them).
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
        "selected": _loaded_selected,
        "ranking": lambda d: [part(RankedModel, m) for m in d["ranking"]],
        "certificate": _loaded_certificate,
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

    @property
    def records(self):
        """Every record as a :class:`FitRecord`, named as the run named it (the files as
        given to ``vidi fit``; without a run, their sources); a loaded result's are its
        document's."""
        if self.loaded:
            return tuple(
                FitRecord(r["data"], r["scenario"], r["regime"], r["impacts"], r["noise"])
                for r in self.__dict__["_document"].get("records") or ()
            )
        return self._records(self.run_record["options"].get("names"))

    def _records(self, names):
        refs = [ref for _, ref in self.references]
        names = list(names) if names is not None else [getattr(r, "source", "") for r in refs]
        return tuple(
            FitRecord(n, s_k.name, ref.regime, ref.impacts, ref.noise)
            for n, (s_k, ref) in zip(names, self.references, strict=True)
        )

    def as_dict(self, names=None):
        """The result as JSON-ready data (``summary.json`` of ``vidi fit``); ``names``
        labels the records (default: their sources)."""
        cert = self.certificate
        ref_out = self.refinement
        return {
            "records": [r.as_dict() for r in self._records(names)],
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
        if self.settings.get("sensor_lag"):
            out.append(f"  note: {lag_note(self.settings['sensor_lag'])}")
        out.append(
            f"ranking ({len(self.ranking)} candidates: the consistent ones first, the fewest "
            f"terms first, then by {crit}):"
        )
        out += ranking_lines(self.ranking, crit)
        out += [f"equivalent: {equivalent_text(e)}" for e in self.equivalent]
        cert = self.certificate
        if cert is not None:
            out.append(
                f"certificate: conditions {'hold' if cert.holds else 'DO NOT hold'} ({cert.method})"
            )
        out += [f"warning: {w}" for w in self.warnings]
        out.append(f"fitted in {self.seconds:.1f} s")
        return out
