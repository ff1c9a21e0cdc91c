"""Where the missing-effect loop starts and how it refits: the records, start laws from the
certified regression and from the record alone, the start fitted cycle by cycle, and the
output-error refits (:func:`~discovery.vibroimpact.fit.identification.identify`).
"""

import itertools
import re
from dataclasses import dataclass, replace

import numpy as np

from ..._api._progress import tick
from ...errors import InputError, IntegrationError
from ..fit.identification import identify
from ..fit.intervals import cycle_widening
from ..fit.records import as_records, pair_records, record_start
from ..model.law import ForceLaw, Term
from ..verify import Reference, evaluate
from .effects import Model

# a number multiplying a factor: the start is a law with coefficients, not a term list
_HAS_COEFFICIENT = re.compile(r"(^|[+\-])\s*[0-9.]+([eE][+\-]?[0-9]+)?\s*\*")


def _records_of(scenario, measurement, n_boot, seed):
    """``(pairs, records)``: the records paired with their scenarios, and as references
    (each with its noise floor from ``n_boot`` replicates)."""
    pairs = pair_records(scenario, measurement)
    records = as_records(
        [sc for sc, _ in pairs],
        [
            m
            if isinstance(m, Reference)
            else Reference.from_measurement(m, sc, n_boot=n_boot, seed=seed)
            for sc, m in pairs
        ],
    )
    return pairs, records


#: the effect a machine's frame reads before the loop (:func:`supports_read`)
SUPPORTS = "support_nonlinearity"


@dataclass(frozen=True)
class SupportsReading:
    """Stiffening supports the machine's own equations read (:func:`supports_read`): ``k3``
    [N/m^3] and its 95 % interval."""

    k3: float
    low: float
    high: float

    def machine(self, scenario, measurement):
        """The records' scenarios (one per record, in order) with these supports, and their
        measurements."""
        pairs = pair_records(scenario, measurement)
        return [sc.replace(k3=self.k3) for sc, _ in pairs], [m for _, m in pairs]

    def entry(self):
        """The reading as the result's settings keep it."""
        return {"k3": self.k3, "low": self.low, "high": self.high}

    def beside(self, intervals):
        """``intervals`` with the supports' read interval beside the bootstrap's (None stays
        None)."""
        if intervals is None:
            return None
        return replace(intervals, bounds={**intervals.bounds, "k3": (self.low, self.high)})


def supports_read(scenario, measurement, catalogue, seed=0):
    """A :class:`SupportsReading`: the stiffening supports the machine's own equations read from the
    records, the rest of the machine held as given (:func:`~discovery.calibrate` with every
    other parameter kept: it reads ``k3`` where it is pinned and moves the supports' force
    by 1 %, with its 95 % interval over resamples of the records' cycles, and weighs a
    moulding that sheds mass before it), where the machine is given with linear supports,
    the catalogue has the effect and the calibration of the whole machine reads a stiffening
    too; None elsewhere (a record without positions or given as a reference, records of
    several machines, no stiffening read).  Held at the given machine alone, a sheet whose
    linear supports are 8 % too soft (corpus c15's) reads a stiffening that is not there;
    the whole machine's calibration reads the 8 % in ``k1``.

    On the effect survey's 160 records the calibration read every stiffening within 0.7 %
    of its truth and no linear support as one; a reading of the frame's equation without
    the calibration's mass-loss weighing read ``k3`` 8e9 on a 40-period record whose moulding
    shed 17 % of its mass.  The contact force's refits trade the supports against the
    contact law: survey draw 59's quieter record (an unloading damper under stiffening
    supports) ended with ``k3`` 70 % high, the damper never named and the model
    inconsistent; read first and held there, the damper is named to 0.2 %, consistent.

    The reading's interval stands beside explain's bootstrap intervals and follows their
    rule for few resampled cycles (:func:`~discovery.vibroimpact.fit.intervals.
    cycle_widening`, one parameter: 1.13 times the calibration's percentile interval on a
    15-period record).  Unwidened, it missed the truth on 5 of the survey's 30 stiffening
    records, by 1.04-1.33 of its half width."""
    if SUPPORTS not in {e.id for e in catalogue}:
        return None
    pairs = pair_records(scenario, measurement)
    machines = {(sc.m1, sc.c1, sc.k1, sc.m2) for sc, _ in pairs}
    if len(machines) != 1 or any(isinstance(m, Reference) or sc.k3 != 0 for sc, m in pairs):
        return None
    from ..calibration.machine import calibrate

    scs, ms = [sc for sc, _ in pairs], [m for _, m in pairs]
    try:
        # the whole machine free first: supports only a few percent stiffer than the given
        # machine's linear ones are its k1, not a stiffening (corpus c15's sheet)
        if not calibrate(scs, ms, seed=seed).parameters.get("k3"):
            return None
        cal = calibrate(scs, ms, seed=seed, keep=("m1", "c1", "k1", "m2", "A"))
    except (InputError, np.linalg.LinAlgError):
        return None  # a record the machine's equations cannot read: the loop's refits decide
    k3 = cal.parameters.get("k3")
    if not k3:
        return None
    # the calibration's percentile interval over the records' cycles, widened by the rule
    # of the bootstrap intervals it stands beside (one parameter on the resampled cycles)
    cycles = sum(int((m.t[-1] - m.t[0]) // sc.period) for sc, m in pairs)
    f, v = cycle_widening(cycles, 1), k3["record"]
    return SupportsReading(v, v - f * (v - k3["low"]), v + f * (k3["high"] - v))


def _output_error(records, start, criterion, budget, tol, *, polish=False, floor=None):
    """Output-error identification of a law or model on every record: least squares, and
    with ``polish`` Nelder-Mead on the budget least squares left.  Least squares can stop
    early, its step rejected, where the residual is not smooth in the coefficients (a force
    jump at the onset moving across the samples); the simplex, which only compares
    criterion values, goes on from there.

    ``floor``: the records' noise floor of the criterion (what the true model itself reaches
    on records this noisy).  A least-squares fit that ends at or below it is neither started
    again from its best point scaled (:func:`identify`'s ``restart_above``) nor polished by
    the simplex: a lower criterion there would be fitted noise, and the simplex, which
    minimises the force's criterion alone, trades the penetration's fit for it (the bench
    record's winner: polished from I2 0.0416 to 0.0415, floor 0.046, in 113 of explain's
    1274 simulations, its penetration's I5 0.0015 -> 0.0025, its spring and unloading damper
    from 0.5 % and 0.9 % of the truth to 2.0 % and 3.4 %)."""
    scs, refs = [s for s, _ in records], [r for _, r in records]
    res = identify(
        scs,
        refs,
        start,
        criterion=criterion,
        method="least-squares",
        max_simulations=budget,
        tolerances=tol,
        check=False,
        restart_above=floor,
    )
    left = budget - res.n_simulations
    if not polish or left < 4 * (len(res.law.coefficients) + 1) * len(records):
        return res
    if floor is not None and res.value <= floor:
        return res
    try:
        res2 = identify(
            scs,
            refs,
            res.law,
            criterion=criterion,
            method="nelder-mead",
            max_simulations=left,
            tolerances=tol,
            check=False,
        )
    except IntegrationError:
        return res
    return res2 if res2.value < res.value else res


def _polish_start(records, fit, criterion, budget, tol):
    """The cycle-by-cycle start refined on the records' blocks, kept when it keeps the
    measured number of contacts in every record and lowers the criterion, and either stays
    local (every coefficient within 3 standard errors of the cycle-by-cycle fit) or is
    consistent with every record (a far refit that trades the spring for the restitution
    has left the start's basin without explaining the record)."""
    scs, refs = [s for s, _ in records], [r for _, r in records]
    try:
        res = identify(
            scs,
            refs,
            fit.law,
            criterion=criterion,
            method="least-squares",
            max_simulations=budget,
            tolerances=tol,
            short_first=False,
            check=False,
        )
    except (IntegrationError, InputError):
        return fit
    same = all(e.impacts["simulated"] == e.impacts["measured"] for e in res.evaluations)
    base = [evaluate(sc, fit.law, ref, tolerances=tol, floor=False) for sc, ref in records]
    v0 = float(np.mean([e.criteria.get(criterion, np.inf) for e in base]))
    if not (same and res.value <= v0):
        return fit
    se = fit.standard_errors
    near = all(
        abs(b - a) <= 3.0 * se.get(n, 0.0)
        for n, a, b in zip(fit.law.names, fit.law.coefficients, res.law.coefficients, strict=True)
    )
    # a far move is kept only when it reaches a law consistent with every record
    return (
        res
        if near or all(evaluate(sc, res.law, ref, tolerances=tol).consistent for sc, ref in records)
        else fit
    )


def _physical(names, records):
    """Start values from the record alone
    (:func:`discovery.vibroimpact.fit.identification.record_start`)."""
    terms = [ForceLaw.parse(f"1*{n}").terms[0] for n in names]
    return ForceLaw(tuple(terms), tuple(record_start(*records[0], terms)))


def _joined_samples(scenarios, measurements, by_force=False, contacts=None):
    """The contact samples of every record joined (None without positions in every
    record): built once per run, for every regression of the force on a term list.  Contact
    is where the penetration stands above its noise, or with ``by_force`` (where too few
    samples do: a stiff contact's penetration a few noise deviations deep) where the force
    does.  Such a regression sees a penetration mostly noise, so its spring is biased low
    (errors in the variables): a start to try, not a law to restart the loop's refits from.
    ``contacts``: the ways of telling contact tried in turn (overrides ``by_force``)."""
    from ..data.samples import contact_samples, join_samples

    if contacts is None:
        contacts = ("penetration", "force") if by_force else ("penetration",)
    for contact in contacts:
        try:
            return join_samples(
                [
                    contact_samples(m, period=sc.period, contact=contact)
                    for sc, m in zip(scenarios, measurements, strict=True)
                ]
            )
        except (InputError, ValueError):
            continue
    return None


def _regression(names, samples, loading=False, shift=0.0):
    """The certified regression of the force on exactly these terms over ``samples``
    (:func:`_joined_samples`; None without them, or when the regression fails); with
    ``loading``, on the loading samples (``dzeta > 0``) alone, which an unloading branch
    or a set leaves as they are; with a ``shift`` (a contact offset), on the penetration
    beyond it (the force's argument is the recorded penetration less the offset)."""
    from ..fit.certified_fit import CertifiedSparseFit, RegressionSettings

    if samples is None:
        return None
    try:
        zeta = samples.zeta - shift
        keep = samples.dzeta > 0 if loading else np.ones(len(samples), dtype=bool)
        if shift:
            keep &= zeta > 0
        if np.count_nonzero(keep) < 10 * len(names):
            return None
        est = CertifiedSparseFit(RegressionSettings(library=",".join(names), max_terms=len(names)))
        est.fit(
            np.column_stack([zeta, samples.dzeta])[keep],
            samples.F[keep],
            groups=samples.impact[keep],
            sample_weight=samples.weight[keep],
        )
    except (InputError, ValueError):
        return None
    full = [c for c in est.candidates_ if len(c.terms) == len(names)]
    if not full:
        return None
    coef = full[0].coefficients
    terms = [Term.parse(n) for n in names]
    if not all(coef.get(t.name, 0.0) for t in terms):
        return None
    return ForceLaw(tuple(terms), tuple(float(coef[t.name]) for t in terms))


class Regressions:
    """The certified regressions of one run's records (:func:`_regression`), called as
    ``regress(names, loading=False, shift=0.0, lag=0.0)``: over the samples whose
    penetration stands above its noise, or with a ``shift`` (a contact offset) over those
    the force says are in contact, since an offset moves the recorded penetration's zero (a
    record whose contacts start 0.88 mm below it has no samples by penetration; survey draw
    6); with a ``lag`` (a sensor's time constant), of the force before the lag
    (:meth:`unlagged`).
    A call returns None where the records have no such samples."""

    def __init__(self, scenarios, measurements):
        self.scenarios, self.measurements = scenarios, measurements
        self.samples = _joined_samples(scenarios, measurements)
        self._by_force = self._supports = self._offset = None

    def __call__(self, names, loading=False, shift=0.0, lag=0.0):
        if lag:
            return _regression(names, self.unlagged(lag), loading)
        if not shift:
            fit = _regression(names, self.samples, loading)
            if fit is not None:
                return fit
        return _regression(names, self.by_force(), loading, shift)

    def unlagged(self, tau):
        """The contact samples of the force a first-order sensor lag of time constant
        ``tau`` would have recorded as the measured one
        (:meth:`~discovery.vibroimpact.data.measurement.Measurement.unlagged`)."""
        return _joined_samples(self.scenarios, [m.unlagged(tau) for m in self.measurements])

    def supports(self):
        """The supports' ``k3`` the frame's own equation reads from the records, the rest of
        the machine as given (:func:`~discovery.vibroimpact.calibration.machine.supports_reading`;
        None where it reads none), computed once."""
        if self._supports is None:
            from ..calibration.machine import supports_reading

            read = supports_reading(self.scenarios, self.measurements)
            self._supports = (read,)
        return self._supports[0]

    def offset(self):
        """The contact offset the records read: the median over every contact of the
        recorded penetration at the force's onset
        (:func:`~discovery.vibroimpact.data.contact_edges.onset_penetrations`); None where no
        record has positions or contacts with a free flight before them, computed once."""
        if self._offset is None:
            from ..data.contact_edges import onset_penetrations

            reads = [
                onset_penetrations(m.t, m.F, m.zeta, s.period)
                for s, m in zip(self.scenarios, self.measurements, strict=True)
                if m.zeta is not None
            ]
            reads = np.concatenate(reads) if reads else np.zeros(0)
            self._offset = (float(np.median(reads)) if reads.size >= 3 else None,)
        return self._offset[0]

    def by_force(self):
        """The contact samples the force says are in contact (None without them)."""
        if self._by_force is None:
            self._by_force = (
                _joined_samples(self.scenarios, self.measurements, contacts=("force",)) or False
            )
        return self._by_force or None


def _regressed(model, names, regress, *, loading=False, shift=0.0, lag=0.0):
    """``model`` with every loading coefficient from the certified regression of the
    measured force on the terms ``names`` (its unloading branch and added effects kept);
    None when the records have no positions or the regression fails.  The regression sees
    the force against the measured penetration alone, so a start law that has compensated
    for a missing effect with its coefficients (a stiffer spring for a Hertz term or for
    stiffening supports) does not hold the refit in its basin.  ``shift``: the penetration
    the force starts from (a contact offset's, :func:`_regression`); ``lag``: the time
    constant of a sensor lag the force is read through (:meth:`Regressions.unlagged`)."""
    if regress is None:
        return None
    fit = regress(list(names), loading, shift, lag)
    if fit is None:
        return None
    law = model.law
    return model.with_law(
        ForceLaw(
            fit.terms,
            fit.coefficients,
            law.unloading,
            law.unloading_coefficients,
            law.permanent_set,
        )
    )


def start_law(text, records, measurements=None):
    """Candidate start laws: ``linear`` (z, zd) or a term list (``z,zd``) gets its
    coefficients from the certified regression on the contact samples (when the records
    have positions: first), then from the record alone (contact time, reduced mass, force
    jump), term-wise mixtures of the two and softer springs; a law with coefficients
    (``2e8*z + 1e7*zd``) is used as given."""
    preferred, others = _start_candidates(text, records, measurements)
    return preferred + others


def _start_candidates(text, records, measurements):
    """``(preferred, others)`` of :func:`start_law`: the given law or the regression (a
    fit to the force itself), and the fallbacks :func:`explain` ranks by one simulation
    each."""
    text = str(text).strip()
    if not text:
        raise InputError(
            "--start is empty; give 'linear', a term list such as 'z,zd' or a "
            "law such as '2e8*z + 1e7*zd'"
        )
    if text != "linear" and "," not in text and _HAS_COEFFICIENT.search(text):
        return [ForceLaw.parse(text)], []
    names = ["z", "zd"] if text == "linear" else [n.strip() for n in text.split(",") if n.strip()]
    for n in names:
        ForceLaw.parse(f"1*{n}")  # a clear error for a bad term name
    E = records[0][1].impulse
    if not len(E.support):
        raise InputError("the record has no contact to start from")
    reg = None
    if measurements is not None:
        samples = _joined_samples([sc for sc, _ in records], measurements, by_force=True)
        reg = _regression(names, samples)
    phys = _physical(names, records)
    others = [phys]
    if reg is not None and len(names) <= 4 and reg.terms == phys.terms:
        # term-wise mixtures: the regression's damping with the contact time's stiffness
        # (a short contact's few noisy penetration samples can bias one coefficient only)
        for mask in itertools.product((0, 1), repeat=len(names)):
            if 0 < sum(mask) < len(names):
                others.append(
                    reg.with_coefficients(
                        [(phys if m else reg).coefficients[i] for i, m in enumerate(mask)]
                    )
                )
    # softer springs: a contact that damping ends early (the paper's law unloads
    # elastically, so the contact lasts at least a quarter of the spring's period) is far
    # shorter than the half period the contact-time stiffness assumes; stiffer ones: a
    # noisy force's threshold (2 % of the peak) reads a short contact longer than it is
    others += [phys.with_springs_scaled(f) for f in (0.25, 0.25**2, 0.25**3, 4.0, 16.0)]
    return ([reg] if reg is not None else []), others


def _fallbacks(preferred, others, problem, criterion):
    """The start laws in the order they are tried: the preferred ones, then (only when
    those fail) the three closest fallbacks, ranked by one simulation each (a start can
    land in another regime's basin)."""
    yield from preferred
    yield from sorted(others, key=lambda law: problem.value(Model(law), criterion))[:3]


def _without_force(evaluations, records):
    """Whether the simulated contacts of a law's ``evaluations`` carry little force (a peak
    under :data:`WEAK_FORCE` of the measured one) in some record.  Where no start reproduces the
    contacts' timing (a short contact whose onset moves with a missing effect), a law
    without force is the least squares' nearest point (the relative L1 distance 1, where a
    force at the wrong time gives up to 2), and no effect's refit leaves it."""
    for ev, (_, ref) in zip(evaluations, records, strict=False):
        sim = ev.simulated
        if sim is None or not len(sim.F):
            continue
        if float(np.max(sim.F)) < WEAK_FORCE * float(np.max(ref.impulse.F)):
            return True
    return False


#: a fitted start whose simulated peak force is under this share of the measured one in some
#: record has collapsed to a law without force (the least squares' nearest point where no
#: candidate matches the contacts' timing) and is passed over
WEAK_FORCE = 0.05


def _fit_start(run, start, plain, progress):
    """The start law fitted to ``run``'s records (``plain``: their measurements, for the
    regression; None when not every record has one): the first of the start candidates
    (and their fallbacks) whose fit simulates, with positive coefficients and force in its
    contacts (:func:`_without_force`).  Which of several poor starts (I2 near or above 1, a
    short contact's timing not matched) leads the loop to the missing effect is not told
    by their criterion: on the effects survey, taking the best of them instead named the
    effect as often and lost other draws.  A fit that ends with most of its force in the
    wrong place is rescued from a grid around its start (:func:`_rescued`).  Where no fit
    stays physical, the best of the candidates as drawn (:func:`_unfitted`).  Returns
    ``(fit, note)``: the note says why the start is not fitted ("" when it is)."""
    preferred, others = (
        ([start], [])
        if isinstance(start, ForceLaw)
        else _start_candidates(start, run.records, plain)
    )
    fit, why, tried = None, "", []
    for law in _fallbacks(preferred, others, run.problem, run.criterion):
        tried.append(law)
        fit, why = _fit_one(run, law, progress)
        if fit is not None:
            return _rescued(run, fit, law, progress), ""
    law = _unfitted(run, tried)
    if law is None:
        raise IntegrationError(
            f"no start law for {start!r} has a periodic steady state with "
            f"contact for the record ({why}); give --start as a law with "
            "coefficients closer to the record"
        )
    return LawOnly(law, {}), (
        f"no fit of a start law stayed physical ({why}); the loop began from {law}, "
        "drawn from the record and not fitted"
    )


def _fit_one(run, law, progress):
    """``(fit, "")`` of the start ``law``, or ``(None, why)`` when its fit fails or leaves
    physics (a negative coefficient, contacts without force).  The start is fitted cycle
    by cycle (each cycle from the machine's state before it): over several cycles a law
    can trade its spring against the missing effect through the restitution (a soft
    spring mimics damping while unloading), and the effect would then look absent."""
    records, criterion, budget, tolerances = run.records, run.criterion, run.budget, run.tolerances
    try:
        short = [(sc, ref.shortened() or ref) for sc, ref in records]
        tick(progress, "explain: fitting the start cycle by cycle", 0, None)
        got = _output_error(short, law, criterion, budget, tolerances, polish=True)
        got = _polish_start(records, got, criterion, max(budget // 3, 8), tolerances)
    except IntegrationError as exc:
        return None, str(exc)
    if min(got.law.coefficients) < 0:
        return None, f"the fit from {law} reached {got.law}, with a negative coefficient"
    if _without_force(got.evaluations, records):
        return None, f"the fit from {law} reached {got.law}, whose contacts carry no force"
    return got, ""


#: a fitted start whose criterion stays above this has most of its force in the wrong place
#: (a law without force scores 1; force at the wrong time up to 2): its start's
#: neighbourhood is scanned (:func:`_rescued`)
POOR_START = 0.5


def _grid(law):
    """Laws around ``law``: every coefficient scaled by ``2**-2 .. 2**2`` in half-octave
    steps (octaves for three coefficients; no grid beyond three)."""
    n = len(law.coefficients)
    if n > 3:
        return []
    f = 2.0 ** np.arange(-2.0, 2.0 + 1e-9, 0.5 if n <= 2 else 1.0)
    return [
        law.with_coefficients([c * g for c, g in zip(law.coefficients, gs, strict=True)])
        for gs in itertools.product(f, repeat=n)
        if any(g != 1.0 for g in gs)
    ]


def _value(run, law):
    """The run's criterion of ``law`` on every record (inf where it does not simulate)."""
    try:
        return run.problem.value(Model(law), run.criterion)
    except (IntegrationError, InputError):
        return np.inf


def _rescued(run, fit, start, progress, tries=2):
    """``fit`` (from ``start``), or where it ends poor (criterion above
    :data:`POOR_START`) the lowest of it and the fits from the ``tries`` best laws of the
    grid around ``start`` (:func:`_grid`, one simulation each) that beat it with force in
    their contacts.  A short contact's timing makes the criterion rugged in the
    coefficients: on survey draw 30 (a 0.6 ms contact at 2 % force noise) the
    regression's start (I2 1.8) ran to a law a hundred times too soft (0.93), while one
    grid point (0.67) fitted to the truth (0.076, consistent).  A grid fit whose contacts
    carry no force (:func:`_without_force`) is not taken: on draw 9 (stiffening supports)
    one stopped at I2 1.0, its peak 4.7 % of the record's, from where no effect's refit
    leaves, while the supports' refit from the fit itself (1.2) reached 0.13."""
    v = _value(run, fit.law)
    if v <= POOR_START:
        return fit
    tick(progress, "explain: the start fit is poor; scanning around it", 0, None)
    ranked = sorted((_value(run, law), i, law) for i, law in enumerate(_grid(start)))
    best = (v, fit)
    for value, _, law in ranked[:tries]:
        if value >= v:
            break
        got, _ = _fit_one(run, law, progress)
        if got is None or (w := _value(run, got.law)) >= best[0]:
            continue
        try:
            evs = run.problem.evaluations(Model(got.law), floor=True)
        except (IntegrationError, InputError):
            continue
        if not _without_force(evs, run.records) and _testable(evs, run.criterion):
            best = (w, got)
    return best[1]


def _testable(evaluations, criterion):
    """Whether a law's ``evaluations`` have a finite noise floor of ``criterion`` on every
    record: a law whose own noisy records show no contact (its floor infinite) is a start
    from which no effect can be named, since every refit must beat the law's by that floor.
    On survey draw 33 (a 0.3 ms contact, stiffening supports) a grid fit reached I2 1.0 with
    no simulated contact and an infinite floor; the supports' refit from it reached the
    truth's 0.081 and went unnamed."""
    return all(
        ev.noise_floor and np.isfinite(ev.noise_floor.get(criterion, np.inf)) for ev in evaluations
    )


@dataclass(frozen=True)
class LawOnly:
    """A law (or model) with its standard errors, where no identification stands behind it:
    a start taken as drawn from the record (none), a trial's refit with its collapsed
    effect taken out (the refit's, less the effect's)."""

    law: object
    standard_errors: dict


def _unfitted(run, laws):
    """The law of ``laws`` (the start candidates tried) with the lowest criterion whose
    simulation has force in its contacts in every record, unfitted; None when none has.
    Where every fit of a start left physics, the start is not the model to explain but
    where the loop's refits begin: on survey draw 6 (a contact offset of -0.88 mm, the
    recorded positions shifted by it) every fit from a law without the offset ran to a
    negative spring, and the loop named the offset from the true law's start (I2 1.04 ->
    0.025, consistent)."""
    best, value = None, np.inf
    for law in laws:
        model = Model(law)
        try:
            evs = run.problem.evaluations(model)
            v = run.problem.value(model, run.criterion)
        except (IntegrationError, InputError):
            continue
        if v < value and not _without_force(evs, run.records):
            best, value = law, v
    return best
