"""The experiment loop as one call: fit -> advise -> a record at the advised point -> the
joint fit, until one law remains or no point in the bounds separates the rest.

records (the first one, then one per step) + their sheets at their drive settings ->
the machine each record shows (:func:`~discovery.vibroimpact.calibration.calibrate`, or the
sheets as given) -> the joint fit (:func:`~discovery.discover`): the selected law and the
models it reports equivalent are the candidates -> :func:`~discovery.advise` over them ->
``acquire(NextRecord)`` returns the record at the advised point -> again.

The loop stops when

* ``"settled"``: the joint fit lists no equivalent model (one law remains);
* ``"twins"``: no point in the bounds separates the remaining candidates (they are twins
  within the bounds: wider bounds, another knob or another sensor might);
* ``"no usable point"``: every point of the bounds is unsafe, or a candidate has no
  periodic orbit with contact there;
* ``"budget"``: the records reached ``max_records``;
* ``"none consistent"``: the joint fit's best law is not consistent with every record (no
  law of the library explains them: a missing effect, :func:`~discovery.explain`).

``acquire`` is where the records come from: a simulator stand-in in tests and dry runs, a
rig in the field (the CLI runs a command, ``vidi advise --until-settled --acquire CMD``).
"""

import time
from dataclasses import dataclass, field

import numpy as np

from ..._api._printing import readable
from ..._api._progress import reports_progress, tick
from ..._api._result import Result
from ..._api._settings import Settings, option, takes
from ..._api._validate import Choice, Real, params
from ...errors import InputError, VidiTypeError
from ..data.measurement import Measurement
from ..dynamics import Tolerances
from ..fit.discovery import DiscoverSettings, discover
from ..model.law import ForceLaw
from ..model.scenario import Scenario
from .candidates import (
    Knobs,
    NoiseModel,
    SafeRegion,
    contact_candidates,
    distinct_laws,
    fitted_model,
)
from .search import advise
from .separation import at_point

__all__ = ["CampaignSettings", "CampaignResult", "CampaignStep", "NextRecord", "campaign"]

#: why a campaign stopped -> what that means, for the printed result
STOPS = {
    "settled": "one law remains: the joint fit lists no equivalent model",
    "twins": "no point in the bounds separates the remaining candidates",
    "no usable point": "no point in the bounds is safe with an orbit of every candidate",
    "budget": "the records reached max_records",
    "none consistent": "no law the fit can form is consistent with every record",
}


@dataclass(frozen=True, repr=False)
class CampaignSettings(Settings):
    """The options of :func:`campaign` (each is also a keyword of it)."""

    max_records: int = option(4, Real(2, 20, integer=True))
    machine: str = option("record", Choice("record", "sheet"))
    fit: object = option(None, (DiscoverSettings, None))
    safe: object = option(None, (SafeRegion, None))
    noise: object = option(None, (NoiseModel, None))
    refit_simulations: int = option(40, Real(0, 10_000, integer=True))
    workers: object = option(None, (None, Real(1, integer=True)))
    tolerances: object = option(None, (Tolerances, None))
    seed: int = option(0, Real(0, 2**63 - 1, integer=True))


@dataclass(frozen=True)
class NextRecord:
    """What ``acquire`` is asked for: a record of the machine at one drive setting.

    Attributes
    ----------
    step : int
        The record's number (2 for the first record taken by the campaign).
    amplitude, frequency : float
        The drive's amplitude [N] and frequency [Hz] to set.
    m2 : float or None
        The moulding's mass [kg] to load (``None``: as in the first record).
    scenario : Scenario
        The designer's sheet at this setting (what the record's machine is said to be).
    separation : float
        The predicted smallest separation of the candidates there (> 1: separated; ``inf``:
        by a regime change or physics).
    """

    step: int
    amplitude: float
    frequency: float
    m2: float | None
    scenario: Scenario
    separation: float

    def __str__(self):
        m2 = "" if self.m2 is None else f", m2 = {self.m2:.4g} kg"
        return (
            f"record {self.step} at A = {self.amplitude:.4g} N, f = {self.frequency:.4g} Hz"
            f"{m2} (predicted separation {self.separation:.3g}; sheet {self.scenario.name!r})"
        )


@dataclass(frozen=True)
class CampaignStep:
    """One step: the joint fit of the records so far, and the point advised after it.

    Attributes
    ----------
    records : int
        How many records the fit used.
    selected : str
        The selected law (exact text).
    consistent : bool
        Whether it is consistent with every record.
    candidates : tuple of str
        The selected law and the models the fit reports equivalent.
    point : dict or None
        The advised point: ``amplitude``, ``frequency``, ``m2``, ``separation`` (predicted,
        smallest over the pairs some point separates; ``None``: infinite, a regime change or
        physics), ``refitted`` (the smallest with each rival refitted, ``None`` when not
        computed), ``regime_change``, ``pairs`` (each pair's ``separation``, ``refitted``
        and what separates it, ``by``: criteria, regime or physics); ``None`` when the
        loop stopped at this step.
    seconds : float
    """

    records: int
    selected: str
    consistent: bool
    candidates: tuple
    point: dict | None = None
    seconds: float = 0.0

    def to_dict(self):
        return {
            "records": self.records,
            "selected": self.selected,
            "consistent": self.consistent,
            "candidates": list(self.candidates),
            "point": self.point,
            "seconds": self.seconds,
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            int(d["records"]),
            str(d["selected"]),
            bool(d["consistent"]),
            tuple(str(c) for c in d["candidates"]),
            None if d.get("point") is None else dict(d["point"]),
            float(d.get("seconds") or 0.0),
        )

    def line(self):
        head = (
            f"{_n_records(self.records)}: selected {short(self.selected)} "
            f"({'consistent' if self.consistent else 'NOT consistent'})"
        )
        if len(self.candidates) > 1:
            head += f", {len(self.candidates) - 1} equivalent"
        p = self.point
        if p is None:
            return head
        m2 = "" if p.get("m2") is None else f", m2 = {p['m2']:.4g} kg"
        r = p.get("refitted")
        refit = "" if r is None else f"; with each rival refitted {r:.3g}"
        if r is not None and r <= 1:
            refit += ": a pair may stay open"
        sep = p.get("separation")
        sep = "infinite: a regime change" if sep is None else f"{sep:.3g}"
        return (
            f"{head}; next record at A = {p['amplitude']:.4g} N, f = {p['frequency']:.4g} Hz"
            f"{m2} (separation {sep}{refit})"
        )


@readable
@dataclass(frozen=True, eq=False)
class CampaignResult(Result):
    """The experiment loop's course and outcome.

    Attributes
    ----------
    steps : tuple of CampaignStep
        One per joint fit, in order.
    stopped : str
        Why the loop stopped (a key of :data:`STOPS`).
    reason : str
        The same in words, with the laws it concerns.
    law : str
        The last fit's selected law.
    remaining : tuple of str
        The candidates left (one when settled).
    records : tuple of dict
        Each record's drive setting (``amplitude``, ``frequency``, ``m2``) and source.
    machine_from : str
        ``"record"`` (each record's machine calibrated from the records) or ``"sheet"``.
    settings : dict
    seconds : float
    fit : DiscoveryResult or None
        The last joint fit (``None`` on a loaded result).
    """

    steps: tuple
    stopped: str
    reason: str
    law: str
    remaining: tuple
    records: tuple
    machine_from: str = "record"
    settings: dict = field(default_factory=dict)
    seconds: float = 0.0
    fit: object = field(default=None, repr=False)

    KIND = "campaign"
    _LOAD = {
        "steps": lambda d: tuple(CampaignStep.from_dict(s) for s in d["steps"]),
        "remaining": lambda d: tuple(str(x) for x in d["remaining"]),
        "records": lambda d: tuple(dict(r) for r in d["records"]),
        "fit": lambda d: None,
    }

    @property
    def settled(self):
        """Whether one law remains."""
        return self.stopped == "settled"

    def as_dict(self):
        return {
            "stopped": self.stopped,
            "reason": self.reason,
            "law": self.law,
            "remaining": list(self.remaining),
            "steps": [s.to_dict() for s in self.steps],
            "records": [dict(r) for r in self.records],
            "machine_from": self.machine_from,
            "settings": self.settings,
            "seconds": self.seconds,
        }

    def _lines(self):
        out = [f"campaign: {self.stopped} after {_n_records(len(self.records))}: {self.reason}"]
        out += [f"  step {k}: {s.line()}" for k, s in enumerate(self.steps, start=1)]
        if not self.settled and len(self.remaining) > 1:
            out.append("  remaining candidates:")
            out += [f"    {short(t)}" for t in self.remaining]
        used = "calibrated from the records" if self.machine_from == "record" else "the sheets"
        out.append(f"  machine: {used}")
        return out


# ---------------------------------------------------------------------------- the loop
@dataclass
class _State:
    """What the loop carries from step to step."""

    sheets: list
    records: list
    settings: CampaignSettings
    t0: float
    steps: list = field(default_factory=list)


def _machines(state, s):
    """``(scenarios, fit options)``: the scenario each record is fitted with (calibrated
    from the records, or the sheets) and what the calibration adds to the joint fit, as
    ``vidi fit`` takes it: the machine's scale uncertainty (the records pin its ratios far
    better than its scale; each law is judged at the scale that suits it within that range)
    and the force sensor's lag the records show (``{}`` for the sheets)."""
    if s.machine == "sheet":
        return list(state.sheets), {}
    from ..calibration import calibrate

    cal = calibrate(list(state.sheets), list(state.records), seed=s.seed)
    if not cal.calibrated:
        return list(state.sheets), {}
    found = {"machine_scale": cal.scale_range, "sensor_lag": cal.sensor_lag}
    return list(cal.scenarios), {k: v for k, v in found.items() if v}


def _outcome(fit):
    """``(selected text or None, consistent, candidates)`` of a joint fit: a polynomial
    fit's selected law and equivalent models, or a contact-models fit's selected model and
    the models it reports equivalent (its same-force twin left out)."""
    from ..fit.contact_fit import ContactModelsResult

    if not isinstance(fit, ContactModelsResult):
        laws = [fit.selected.law]
        laws += [ForceLaw.from_dict(e["coefficients"]) for e in fit.equivalent]
        return fit.selected.law.to_text(), bool(fit.selected.consistent), distinct_laws(laws)
    if fit.selected is None:
        return None, False, []
    try:
        laws = list(contact_candidates(fit))
    except InputError:  # only the selected model's same-force twin is left: one law
        laws = [fitted_model(fit, fit.selected)]
    return laws[0].to_text(), True, distinct_laws(laws)


def _nested(laws):
    """Whether every rival holds the selected law's terms and more (polynomial laws)."""
    if not all(isinstance(law, ForceLaw) for law in laws):
        return False
    own = set(laws[0].names)
    return all(own < set(law.names) for law in laws[1:])


def short(text):
    """A law's text with four significant digits, for the printed result."""
    from ..model.contact_models import parse_law

    try:
        law = parse_law(text)
    except InputError:
        return text
    return law.format(4) if isinstance(law, ForceLaw) else str(law)


def _finite(x):
    return float(x) if np.isfinite(x) else None


def _point_entry(adv):
    b = adv.best
    refit = {tuple(r.pair): r.separation for r in adv.refit}
    refitted = min(refit.values(), default=None)
    return {
        "amplitude": float(b.amplitude),
        "frequency": float(b.frequency),
        "m2": None if b.m2 is None else float(b.m2),
        "separation": _finite(b.smallest_separation(frozenset(adv.inseparable))),
        "refitted": None if refitted is None else _finite(refitted),
        "regime_change": any(q.regime_change for q in b.pairs),
        # each pair's predicted separation (inf: by regime or physics: None in JSON) and
        # with the rival refitted, to measure how often a predicted separation comes true
        "pairs": [
            {
                "pair": list(q.pair),
                "separation": _finite(q.separation),
                "refitted": _finite(refit[tuple(q.pair)]) if tuple(q.pair) in refit else None,
                "by": "regime" if q.regime_change else "physics" if q.physics else "criteria",
            }
            for q in b.pairs
        ],
    }


def _acquired(acquire, request):
    rec = acquire(request)
    if not isinstance(rec, Measurement):
        raise VidiTypeError(
            f"campaign: acquire must return a Measurement (the record at the drive setting "
            f"it is given); got {type(rec).__name__} at step {request.step}"
        )
    return rec


def _stop_after_advice(adv, laws):
    """``(stop, reason)`` when the advice ends the loop, else ``None``."""
    if adv.best is None:
        return "no usable point", STOPS["no usable point"]
    twins = adv.inseparable
    if not twins or len(twins) < len(adv.best.pairs):
        return None
    if _nested(laws):
        extra = sorted({n for law in laws[1:] for n in law.names} - set(laws[0].names))
        return "settled", (
            f"one law remains ({short(laws[0].to_text())}): the rivals left add "
            f"{', '.join(extra)} to it, which no point in the bounds tells from zero"
        )
    names = "; ".join(f"{short(laws[i].to_text())} / {short(laws[j].to_text())}" for i, j in twins)
    return "twins", f"{STOPS['twins']} ({names})"


@takes(CampaignSettings)
@params(scenario=(Scenario, list, tuple), measurement=(Measurement, list, tuple), knobs=Knobs)
@reports_progress
def campaign(scenario, measurement, acquire, knobs, *, settings=None, progress=None, **options):
    """Run the experiment loop until one law remains (see the module docstring).

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
        The designer's sheet of the machine at the first record's drive setting; to go on
        from an earlier loop, the sheet at each of its records' settings.
    measurement : Measurement or sequence of Measurement
        The first record (or the records so far, one per sheet).
    acquire : callable
        ``acquire(NextRecord) -> Measurement``: the record of the machine at the drive
        setting asked for (:class:`NextRecord`).
    knobs : Knobs
        The bounds the drive setting may take (see :func:`~discovery.advise`).
    settings : CampaignSettings, optional
        The options below in one object; keywords override its fields.
    max_records : int
        Records in all, the first included (2..20).
    machine : {"record", "sheet"}
        Fit each record with the machine calibrated from the records (default) or with its
        sheet as given.
    fit : DiscoverSettings, optional
        The joint fit's options (default: :func:`~discovery.discover`'s).
    safe : SafeRegion, optional
        Peak force and penetration the machine may not exceed.
    noise : NoiseModel, optional
        The next records' noise (default: the first record's).
    refit_simulations, workers, tolerances
        As in :func:`~discovery.advise`.
    seed : int
        Seed of the calibration's and the noise model's bootstrap.
    progress : callable or bool, optional
        As in :func:`~discovery.advise`.

    Returns
    -------
    CampaignResult
    """
    s = CampaignSettings.of("campaign", settings, options)
    if not callable(acquire):
        raise VidiTypeError(
            f"campaign: acquire must be a callable acquire(NextRecord) -> Measurement; got "
            f"{type(acquire).__name__}"
        )
    t0 = time.perf_counter()
    fit_settings = s.fit if s.fit is not None else DiscoverSettings()
    state = _State(*_so_far(scenario, measurement), s, t0)
    scenario, measurement = state.sheets[0], state.records[0]
    noise = s.noise
    while True:
        k = len(state.records)
        tick(progress, f"campaign: joint fit of {_n_records(k)}", 0, None)
        t_step = time.perf_counter()
        machines, found = _machines(state, s)
        # what the calibration found, where the fit's settings do not say it themselves
        given = {"machine_scale": fit_settings.machine_scale, "sensor_lag": fit_settings.sensor_lag}
        extra = {k: v for k, v in found.items() if not given[k]}
        settings = DiscoverSettings.of("campaign", fit_settings, extra) if extra else fit_settings
        fit = discover(
            machines,
            list(state.records),
            settings=settings,
            progress=_prefixed(progress, f"campaign, {_n_records(k)}"),
        )
        selected, consistent, laws = _outcome(fit)
        step = CampaignStep(k, selected or "", consistent, tuple(law.to_text() for law in laws))
        stop = None
        if selected is None:
            stop = ("none consistent", f"{STOPS['none consistent']} (no named contact model)")
        elif not consistent:
            stop = (
                "none consistent",
                f"{STOPS['none consistent']}: the best, {short(selected)}, is not; a missing "
                "effect (vidi explain) or a machine the records do not pin",
            )
        elif len(laws) < 2:
            stop = ("settled", f"{STOPS['settled']} ({short(selected)})")
        elif k >= s.max_records:
            stop = ("budget", f"{STOPS['budget']} ({s.max_records}); {len(laws)} candidates remain")
        adv = None
        if stop is None:
            if noise is None:
                noise = NoiseModel.from_measurement(measurement, machines[0], seed=s.seed)
            tick(progress, f"campaign: advising record {k + 1}", 0, None)
            adv = advise(
                machines[0],
                laws,
                knobs,
                noise,
                s.safe,
                workers=s.workers,
                tolerances=s.tolerances,
                refit_simulations=s.refit_simulations,
                progress=_prefixed(progress, f"campaign, record {k + 1}"),
            )
            stop = _stop_after_advice(adv, laws)
        if stop is not None:
            state.steps.append(_timed(step, t_step))
            return _result(state, stop, fit, laws)
        entry = _point_entry(adv)
        b = adv.best
        request = NextRecord(
            k + 1,
            b.amplitude,
            b.frequency,
            b.m2,
            at_point(scenario, b.amplitude, b.frequency, b.m2),
            float("inf") if entry["separation"] is None else entry["separation"],
        )
        tick(progress, f"campaign: acquiring record {k + 1}", 0, None)
        rec = _acquired(acquire, request)
        state.steps.append(_timed(CampaignStep(**{**step.__dict__, "point": entry}), t_step))
        state.sheets.append(request.scenario)
        state.records.append(rec)


def _so_far(scenario, measurement):
    """``(sheets, records)``: the first record with its sheet, or the records so far."""
    sheets = [scenario] if isinstance(scenario, Scenario) else list(scenario)
    records = [measurement] if isinstance(measurement, Measurement) else list(measurement)
    if not records or len(sheets) != len(records):
        raise InputError(
            f"campaign: give one sheet per record ({len(sheets)} sheet(s), "
            f"{len(records)} record(s))"
        )
    for k, (sc, rec) in enumerate(zip(sheets, records, strict=True)):
        if not isinstance(sc, Scenario) or not isinstance(rec, Measurement):
            raise VidiTypeError(
                f"campaign: record {k + 1} must be a Measurement with a Scenario as its "
                f"sheet; got {type(rec).__name__} and {type(sc).__name__}"
            )
    return sheets, records


def _n_records(k):
    return f"{k} record" + ("" if k == 1 else "s")


def _prefixed(progress, head):
    """The progress of a stage of the loop, under the loop's own name."""
    if progress is None:
        return False
    return lambda stage, done, total: progress(f"{head}: {stage}", done, total)


def _timed(step, t0):
    return CampaignStep(**{**step.__dict__, "seconds": time.perf_counter() - t0})


def _result(state, stop, fit, laws):
    records = tuple(
        {
            "amplitude": float(sc.A),
            "frequency": float(sc.frequency),
            "m2": float(sc.m2),
            "source": str(getattr(r, "source", "") or ""),
        }
        for sc, r in zip(state.sheets, state.records, strict=True)
    )
    return CampaignResult(
        steps=tuple(state.steps),
        stopped=stop[0],
        reason=stop[1],
        law=state.steps[-1].selected,
        remaining=tuple(law.to_text() for law in laws),
        records=records,
        machine_from=state.settings.machine,
        settings=state.settings.to_dict(),
        seconds=time.perf_counter() - state.t0,
        fit=fit,
    )
