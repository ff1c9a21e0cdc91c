"""Candidate laws refined by simulation and checked against every record: the shortlist of
the regression's best supports and the trials of each stepwise move."""

from dataclasses import dataclass, replace
from functools import cached_property

import numpy as np

from ..._api._progress import tick
from ...errors import InputError, IntegrationError
from ...numerics.executor import map_on
from ..data.samples import ContactSamples
from ..dynamics import Tolerances
from ..verify import evaluate
from ..verify.sensors import lag_observation
from .certified_fit import CertifiedSparseFit
from .discovery_result import RankedModel
from .identification import identify
from .optimise import SCREEN_PROGRESS, SCREEN_STOP
from .problem import ModelProblem
from .records import record_start
from .rescan import WIDE_SPRING_SCAN, lower_basin

_FORWARD_STARTS = (0.01, 0.001)  # a new term's start force at the box corner / peak force

GIVE_UP_FACTOR = 10.0
GIVE_UP_FLOOR = 0.5
"""A refinement stops after its cycle-by-cycle first fit when the law's criterion on the
record's blocks is still above :data:`GIVE_UP_FACTOR` times the record's consistency limit
and above :data:`GIVE_UP_FLOOR`, and that fit did not lower it (:func:`identify`'s
``give_up_above``): the force histories then differ by more than half the force, and the
fit on the blocks would only polish that (on the bench record, a law without a stiffness
term went from I2 1.25 to 1.22 in 80 more simulations).  The floor keeps a low-noise
record's small limit (0.15 at 0.5 % force noise) from stopping right supports whose poor
starts the cycle-by-cycle fit has not yet brought close: with ten times the limit alone,
the shipped study selected a false-positive term more often (in its cells at 0.5 % force
noise)."""


def _coefficients(law, library):
    """Coefficient vector of ``law`` over ``library`` (zeros for absent terms)."""
    d = law.as_dict()
    return np.array([d.get(t.name, 0.0) for t in library.terms])


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


#: the ranking note of a support none of whose terms is the penetration's alone (every term
#: carries the rate ``zd``): its law has no force at rest in contact, cannot carry the
#: moulding, and is ranked on its regression law without a refinement by simulation.  In the
#: fit-sheet survey such supports took 21 % of the simulations (88 of 466 refinements) and
#: none ended consistent; without them the survey's selections and verdicts are the same on
#: 48 records in 56 % of the time (CHANGELOG)
NO_ELASTIC = "not refined: no elastic term (no force at rest in contact)"


@dataclass(eq=False)
class _Checker:
    """Refines (optionally) and evaluates regression candidates against all records; the
    trials of one step (the shortlist, a forward or backward move) run on ``workers``
    processes (their results do not depend on it: each refinement is deterministic).

    ``est`` is the fitted regression, ``samples`` the records' joined contact samples,
    ``refs`` every record's ``(Scenario, Reference)``, ``budget`` the simulations of one
    refinement, ``required`` the terms no backward step drops, ``give_up_above`` the
    criterion above which a refinement stops after its cycle-by-cycle first fit
    (:meth:`screen_from`), ``restart_above`` the criterion at or below which a refinement
    is not restarted (the same), ``sensor_lag`` the force sensor's time constant every simulated
    force is read through (:attr:`observe`)."""

    est: CertifiedSparseFit
    samples: ContactSamples
    refs: list
    criterion: str
    refine: bool
    tol: Tolerances | None
    budget: int
    required: frozenset = frozenset()
    workers: int | None = 1
    give_up_above: float | None = None
    restart_above: float | None = None
    sensor_lag: float = 0.0

    @cached_property
    def observe(self):
        """The force sensor's observation model (None without a lag:
        :func:`~discovery.vibroimpact.verify.sensors.lag_observation`), made once."""
        return lag_observation(self.sensor_lag)

    def evaluate(self, law):
        observe = self.observe
        return tuple(
            evaluate(sc, law, ref, tolerances=self.tol, observe=observe) for sc, ref in self.refs
        )

    def screen_from(self, laws):
        """Set :attr:`give_up_above` to :data:`GIVE_UP_FACTOR` times the records' largest
        consistency limit of the criterion, or :data:`GIVE_UP_FLOOR` when larger, and
        :attr:`restart_above` to their smallest noise floor of it (a refinement that ends
        there matches every record as the true law would and is not restarted:
        :func:`identify`), read from the first of ``laws`` that every record can be compared
        with (the limits and floors follow the record's noise, not the law).  None (no
        screen) when the criterion has no limit or no law simulates, and when a record's
        limit (or, for :attr:`restart_above`, its floor) is not finite."""
        for law in laws:
            try:
                evs = self.evaluate(law)
            except IntegrationError:
                continue
            if any(e.status != "ok" for e in evs):
                continue
            lims = [e.limits.get(self.criterion) for e in evs]
            # a limit that is not finite (a record whose floor the law cannot set) is none
            if None not in lims and np.all(np.isfinite(lims)):
                self.give_up_above = max(GIVE_UP_FACTOR * max(lims), GIVE_UP_FLOOR)
                floors = [(e.noise_floor or {}).get(self.criterion, np.nan) for e in evs]
                if np.all(np.isfinite(floors)):
                    self.restart_above = float(min(floors))
            return

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
        if not law.has_elastic_term:
            return RankedModel(law, cand, self.evaluate(law), note=NO_ELASTIC, certificate=cert0)
        law = self._scaled_start(law)
        try:
            ref = self._identified(law)
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
        if ref.given_up:
            note = (
                f"refinement from the {origin} given up after its cycle-by-cycle fit "
                f"({ref.n_simulations} simulations): {self.criterion} {ref.value:.3g}, above "
                f"{self.give_up_above:.3g} (the larger of {GIVE_UP_FACTOR:g} x the "
                f"consistency limit and {GIVE_UP_FLOOR:g}), and that fit did not lower it"
            )
        else:
            note = (
                f"refined by simulation from the {origin} "
                f"({ref.n_simulations} simulations, {self.criterion} {ref.value:.3g})"
            )
            if ref.message.startswith(SCREEN_STOP):
                note += (
                    f"; stopped above {self.give_up_above:.3g} (the screen of hopeless laws), "
                    f"its steps lowering the squares by less than {SCREEN_PROGRESS:.0%}, and "
                    "not restarted"
                )
        return RankedModel(
            ref.law, rescored, self.evaluate(ref.law), refinement=ref, note=note, certificate=cert
        )

    def rescanned(self, model):
        """A refined ``model`` that is not consistent with a record (and below the screen of
        hopeless laws) refined again from its springs scanned wide
        (:data:`~.rescan.WIDE_SPRING_SCAN`) where one has a sum of squares
        :data:`~.rescan.RESCAN_DROP` below its own; None when none has."""
        ref = model.refinement
        if ref is None or ref.given_up or ref.message.startswith(SCREEN_STOP):
            return None
        if model.consistent or model.note.startswith("not refined"):
            return None
        problem = ModelProblem(self.refs, self.tol, observe=self.observe)
        lower = lower_basin(model.law, WIDE_SPRING_SCAN, problem.squares)
        if lower is None:
            return None
        factor, start, squares, base = lower
        origin = (
            f"springs of {' + '.join(model.law.names)} scaled x {factor:g}, where the squares "
            f"were {1 - squares / base:.0%} lower"
        )
        # the coefficients its refinement started from stay those the model's came from
        cand = model.candidate
        before = cand.extra.get("regression_coefficients")
        return self.refined(
            start, replace(cand, coefficients=dict(before or cand.coefficients)), origin
        )

    def _identified(self, law):
        """``law`` refined by simulation on every record (least squares, :attr:`budget`
        simulations, not checked: the shortlist evaluates its result)."""
        return identify(
            [sc for sc, _ in self.refs],
            [r for _, r in self.refs],
            law,
            criterion=self.criterion,
            method="least-squares",
            max_simulations=self.budget,
            tolerances=self.tol,
            check=False,
            give_up_above=self.give_up_above,
            restart_above=self.restart_above,
            observe=self.observe,
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
    laws = [check.regression_law(c) for c in pool[:shortlist]]
    jobs = [([(law, c)], "regression") for law, c in zip(laws, pool, strict=False)]
    if check.refine:
        check.screen_from(laws)
    tick(progress, _SHORTLIST_STAGE, 0, len(jobs))
    return check.run(jobs, _SHORTLIST_STAGE, progress)
