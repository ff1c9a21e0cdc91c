"""Fit the named contact models (:mod:`~discovery.vibroimpact.model.contact_models`) to
records and say which one they support.

Each model is fitted by output error (:func:`discovery.identify`: every evaluation a full
simulation from the record's measured state, least squares on the force and penetration
residuals) over its physical parameters themselves (``k, c``; ``k, n, lambda``;
``k, n, e``), the Jacobian by differences of full simulations: ``n`` and ``e`` enter
the force non-linearly, and ``e`` through each impact's approach velocity, a contact state
the kernel does not differentiate.  The start is the record's spring-dashpot estimate
(:func:`~discovery.vibroimpact.fit.identification.record_start`) at ``n = 1.25`` for the models
that fit ``n``.  Every fitted model is then checked against every record with its noise
floor (the verdict of :mod:`discovery.vibroimpact.verify`), and the 95 % intervals are
``+-1.96`` standard errors from that Jacobian (or the bootstrap through the record-span
processing with ``n_boot > 0``).

Selection: the model with the lowest mean criterion (I2) among those consistent with every
record (among all when none is); every other consistent model is one the record cannot
tell from it (``equivalent``).  Lankarani-Nikravesh and Flores make the same force for
``e`` related by ``r = 3 (1 - e_LN^2) / 4 = 8 (1 - e_F) / (5 e_F)``; on a record whose
impacts all arrive at one velocity (a periodic orbit), Hunt-Crossley with
``lambda = k r / v0`` makes it too.  Those are reported as equivalent, never guessed
between.
"""

import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..._api._printing import interval_text, readable
from ..._api._progress import reports_progress
from ..._api._result import SCHEMA_VERSION, Result
from ..._api._settings import Settings, option, takes
from ..._api._validate import Real, params
from ...errors import InputError, IntegrationError
from ...wording import records as the_records
from ...wording import verb
from ..data.measurement import Measurement
from ..dynamics import Tolerances
from ..model.contact_models import same_force
from ..model.contact_registry import CONTACT_MODELS, DOMAINS, domain_edges
from ..model.scenario import Scenario
from ..verify import Reference
from ..verify.block_farm import block_workers, shared_blocks
from ..verify.sensors import lag_note, lag_observation
from .contact_starts import from_seed, record_samples, regression_start, start_model
from .identification import _checks, as_records, identify

__all__ = ["ContactFit", "ContactModelsResult", "ContactModelsSettings", "fit_contact_models"]

_Z95 = 1.959963984540054


@dataclass(frozen=True)
class ContactFit:
    """One named model fitted to the record(s).

    Attributes
    ----------
    model : str
    parameters : dict
        ``{name: value}`` of the fitted model (``k``, ``n``, ``c`` / ``lambda`` / ``e``).
    intervals : dict
        ``{name: [low, high]}``, 95 %.
    criteria : dict
        Mean criteria I0..I5 over the records.
    value : float
        The mean I2.
    consistent : bool or None
        Consistent with every record (None: the fit failed).
    law : str
        The fitted law's text (``ForceLaw.to_text``).
    message : str
    n_simulations : int
    interval_method : str
        How the intervals were made (the bootstrap, or the Jacobian's standard errors).
    conditions : dict
        The paper's conditions (3)-(6) for the fitted model
        (:meth:`~discovery.vibroimpact.model.contact_models.ContactModel.conditions`).
    """

    model: str
    parameters: dict
    intervals: dict
    criteria: dict
    value: float
    consistent: object
    law: str
    message: str = ""
    n_simulations: int = 0
    interval_method: str = ""
    conditions: dict = field(default_factory=dict)

    def to_dict(self):
        return {
            "schema_version": SCHEMA_VERSION,
            "model": self.model,
            "parameters": {k: float(v) for k, v in self.parameters.items()},
            "intervals": {k: [float(a), float(b)] for k, (a, b) in self.intervals.items()},
            "criteria": {k: float(v) for k, v in self.criteria.items()},
            "value": float(self.value),
            "consistent": self.consistent,
            "law": self.law,
            "message": self.message,
            "n_simulations": int(self.n_simulations),
            "interval_method": self.interval_method,
            "conditions": {k: dict(v) for k, v in self.conditions.items()},
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            model=d["model"],
            parameters=dict(d["parameters"]),
            intervals={k: tuple(v) for k, v in d["intervals"].items()},
            criteria=dict(d["criteria"]),
            value=float("inf") if d["value"] is None else float(d["value"]),  # JSON: null
            consistent=d["consistent"],
            law=d["law"],
            message=d.get("message", ""),
            n_simulations=int(d.get("n_simulations", 0)),
            interval_method=d.get("interval_method", ""),
            conditions={k: dict(v) for k, v in d.get("conditions", {}).items()},
        )

    def __post_init__(self):
        object.__setattr__(
            self, "intervals", {k: tuple(float(x) for x in v) for k, v in self.intervals.items()}
        )


@readable
@dataclass(frozen=True, eq=False)
class ContactModelsResult(Result):
    """Which named contact model the record(s) support.

    Attributes
    ----------
    fits : tuple of ContactFit
        Every model fitted, best (lowest I2) first.
    selected : str or None
        The model the record supports: the consistent model with the lowest I2 (None when
        none is consistent).
    equivalent : tuple of str
        The other models consistent with every record: the record cannot tell them from
        the selected one.
    settings : dict
    seconds : float
    n_records : int
        How many records were fitted together (the conclusion follows their number).
    """

    KIND = "contact-models"
    _LOAD = {
        "fits": lambda d: tuple(ContactFit.from_dict(f) for f in d["fits"]),
        "equivalent": lambda d: tuple(d["equivalent"]),
        "settings": lambda d: dict(d["fit_settings"]),
        "seconds": lambda d: float(d["seconds"]),
        # a summary written before it kept n_records: the records it names
        "n_records": lambda d: int(d.get("n_records") or _count(d.get("data")) or 1),
    }

    fits: tuple
    selected: object
    equivalent: tuple = ()
    settings: dict = field(default_factory=dict)
    seconds: float = 0.0
    n_records: int = 1

    def fit(self, name):
        """The :class:`ContactFit` of a model."""
        for f in self.fits:
            if f.model == name:
                return f
        raise KeyError(name)

    def as_dict(self):
        """The result's keys of its document (:meth:`~discovery.Result.to_dict` adds the
        schema version and kind)."""
        return {
            "library": "contact-models",
            "selected": self.selected,
            "equivalent": list(self.equivalent),
            "fits": [f.to_dict() for f in self.fits],
            "fit_settings": dict(self.settings),
            "seconds": float(self.seconds),
            "n_records": int(self.n_records),
            "conclusion": self.conclusion,
        }

    @property
    def conclusion(self):
        """One sentence: the model the record(s) support and those they cannot tell from it."""
        n = self.n_records
        if self.selected is None:
            best = self.fits[0].model if self.fits else "none"
            return (
                f"No named contact model is consistent with {the_records(n, every=n > 1)} "
                f"(closest: {best}); the contact is none of them, try the polynomial library "
                "or vidi explain."
            )
        text = f"{the_records(n).capitalize()} {verb(n, 'supports', 'support')} {self.selected}"
        twin = self.same_force
        if twin is not None:
            other, p = twin
            text += (
                f"; {other} with e = {p['e']:.3g} makes the same force at every impact "
                "velocity (one family: no record can separate them)"
            )
        rest = [m for m in self.equivalent if twin is None or m != twin[0]]
        if rest:
            text += (
                f"; {verb(n, 'it', 'they')} cannot tell it from {', '.join(rest)} (consistent "
                "too: a record with impacts at other velocities, e.g. another drive amplitude, "
                "would separate them)"
            )
        return text + "."

    @property
    def same_force(self):
        """``(model, parameters)``: the model that makes exactly the selected model's
        force at every impact velocity (Lankarani-Nikravesh and Flores,
        :func:`~discovery.vibroimpact.model.contact_models.same_force`), or ``None``."""
        if self.selected is None:
            return None
        return same_force(self.selected, self.fit(self.selected).parameters)

    def _lines(self):
        out = [self.conclusion]
        if self.settings.get("sensor_lag"):
            out.append(f"note: {lag_note(self.settings['sensor_lag'])}")
        for f in self.fits:
            mark = "*" if f.model == self.selected else " "
            ok = {True: "consistent", False: "inconsistent", None: "failed"}[f.consistent]
            if f.consistent is None:
                out.append(f" {mark} {f.model:<20s} failed: {f.message}")
                continue
            out.append(f" {mark} {f.model:<20s} I2 {f.value:.4g}  {ok}")
            for k, v in f.parameters.items():
                lo, hi = f.intervals.get(k, (np.nan, np.nan))
                out.append(f"      {k:<7s} {v:.5g}  95 % {interval_text(lo, hi, least=5)}")
            if f.model == self.selected and f.conditions:
                out.append(
                    "      conditions: "
                    + ", ".join(
                        f"{k} {'holds' if c['holds'] else 'does not hold'}"
                        for k, c in f.conditions.items()
                    )
                )
        return out


def _count(data):
    """The number of records a summary's ``data`` names (one name or a list of them)."""
    if data is None:
        return 0
    return len(data) if isinstance(data, list) else 1


def _intervals(res, records, settings, progress=None):
    """95 % intervals of the fitted ``res.law``: the bootstrap's when asked for
    (``settings["n_boot"]``, with the settings' ``seed`` and ``tolerances``) and available,
    else +-1.96 standard errors."""
    model = res.law
    if settings["n_boot"]:
        from .identification import bootstrap_intervals

        iv = bootstrap_intervals(
            *zip(*records, strict=True),
            model,
            n_boot=settings["n_boot"],
            seed=settings["seed"],
            tolerances=settings["tolerances"],
            workers=settings["workers"],
            progress=progress,
            observe=settings["observe"],
            domains=_BOUNDED,
        )
        if iv is not None:
            return {k: tuple(v) for k, v in iv.bounds.items()}, "bootstrap"
    se = res.standard_errors or {}
    return {  # a parameter whose standard error is not estimable has no interval
        k: (v - _Z95 * se[k], v + _Z95 * se[k])
        for k, v in zip(model.names, model.values, strict=True)
        if k in se and np.isfinite(se[k])
    }, "1.96 standard errors (Jacobian)"


#: the named models' parameters bounded on both sides: a bootstrap whose first third spans
#: one of them ends there (the fit is degenerate, :func:`_degenerate`; 1.5 s of a model)
_BOUNDED = {k: DOMAINS[k][:2] for k in ("n", "e")}


def _in_domain(name, bounds):
    """An interval clipped to its parameter's domain (a restitution below 0 or a stiffness
    below 0 is no value the model has)."""
    lo, hi, _ = DOMAINS.get(name, (-np.inf, np.inf, False))
    a, b = (float(x) for x in bounds)
    return (min(max(a, lo), hi), max(min(b, hi), lo))


def _degenerate(params, intervals):
    """Why a fit is no result (``""`` when it is one): a parameter at the edge of what a fit
    may reach (a stiffness at its floor, an exponent or a restitution at its range's end), or
    a parameter without a finite interval, or one that spans its whole range."""
    why = domain_edges(params)
    for k in params:
        lo, hi, _ = DOMAINS.get(k, (-np.inf, np.inf, False))
        b = intervals.get(k)
        if b is not None and not all(np.isfinite(b)):
            why.append(f"{k} has no finite interval")
        elif b is not None and k in ("n", "e") and b[0] <= lo and b[1] >= hi:
            why.append(f"{k}'s interval spans its whole range")
    return "; ".join(why)


def _too_damped(name, params):
    """Why an impact-scaled model's restitution at the low end of its range means: the
    record's impacts are damped more than the model can (Lankarani-Nikravesh's ratio stays
    below 3/4 whatever ``e``), or ``""``."""
    spec = CONTACT_MODELS[name]
    if not spec.impact_scaled or params.get("e", 1.0) > DOMAINS["e"][0] * (1 + 1e-9):
        return ""
    r = spec.ratio(DOMAINS["e"][0])
    return (
        f" (the record's impacts are damped more than {name} can damp them: its ratio "
        f"r = lambda v0 / k is at most {r:.3g})"
    )


def _within(progress, name, i, names):
    """The progress of one model's fit and intervals, named in the models' count (the bar
    moves within a model: each fit takes tens of seconds)."""
    if progress is None:
        return None
    head = f"contact models {i + 1}/{len(names)}: {name}"
    return lambda stage, done, total: progress(f"{head} ({stage})", done, total)


def _fit_one(name, records, settings, progress, seeding=None):
    """The fit of model ``name``; ``seeding``: the fit of the model its spec is seeded by
    (None: not fitted)."""
    sc0, ref0 = records[0]
    extra = (regression_start(name, settings["samples"]),)
    if CONTACT_MODELS[name].seeded_by is not None:
        extra += (from_seed(name, seeding, sc0, ref0),)
    start = start_model(name, records, settings["tolerances"], extra, settings["observe"])
    try:
        res = identify(
            [sc for sc, _ in records],
            [ref for _, ref in records],
            start,
            max_simulations=settings["max_simulations"],
            tolerances=settings["tolerances"],
            progress=progress,
            check=False,
            observe=settings["observe"],
        )
    except (IntegrationError, InputError) as exc:
        return ContactFit(
            model=name,
            parameters=start.params,
            intervals={},
            criteria={},
            value=float("inf"),
            consistent=None,
            law=start.law.to_text(),
            message=f"fit failed: {exc}",
        )
    model = res.law
    params = dict(zip(model.names, model.values, strict=True))
    # a fit at the edge of its domain is listed as failed whatever its intervals: neither
    # its check nor its bootstrap is made (30 refits of a degenerate model took 32 s of the
    # named models' fit)
    edge = _degenerate(params, {})
    if not edge:  # the check against the noise floors (31 s of a degenerate fit's 63 s)
        res = replace(
            res, checks=_checks(records, model, settings["observe"], settings["tolerances"])
        )
    iv, method = _intervals(res, records, {**settings, "n_boot": 0} if edge else settings, progress)
    iv = {k: _in_domain(k, b) for k, b in iv.items()}
    degenerate = _degenerate(params, iv) + _too_damped(name, params)
    return ContactFit(
        model=name,
        parameters=params,
        intervals=iv,
        criteria={k: float(v) for k, v in res.criteria.items()},
        value=float(res.criteria.get("I2", res.value)) if not degenerate else float("inf"),
        consistent=None if degenerate else bool(res.consistent),
        law=model.law.to_text(),
        message=f"fit degenerate: {degenerate}" if degenerate else res.message,
        n_simulations=res.n_simulations,
        interval_method=method,
        conditions=model.conditions(),
    )


@dataclass(frozen=True, repr=False)
class ContactModelsSettings(Settings):
    """The options of :func:`fit_contact_models` (each is also a keyword of it)."""

    models: object = option(None, (None, list, tuple))
    max_simulations: int = option(200, Real(2, integer=True))
    n_boot: int = option(30, Real(5, integer=True, zero=True))
    seed: int = option(0, Real(0, integer=True))
    tolerances: object = option(None, (Tolerances, None))
    workers: object = option(1, (None, Real(1, integer=True)))
    sensor_lag: float = option(0.0, Real(0.0, 5e-3))


@takes(ContactModelsSettings)
@params(
    scenario=(Scenario, list, tuple),
    reference=(Measurement, Reference, list, tuple),
)
@reports_progress
def fit_contact_models(scenario, reference, *, settings=None, progress=None, **options):
    """Fit every named contact model to the record(s) and select the one they support.

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
        One per record (or one for all).
    reference : Measurement or Reference, or a sequence of them
    settings : ContactModelsSettings, optional
        The options below in one object; keywords override its fields.
    models : sequence of str, optional
        Models to fit (default all of
        :data:`~discovery.vibroimpact.model.contact_registry.CONTACT_MODELS`).
    max_simulations : int
        Budget of each model's fit.
    n_boot : int
        Bootstrap replicates of the intervals through the record-span processing (default
        30, as ``vidi fit``; 0 or a record without positions: +-1.96 standard errors of
        the fit's Jacobian).
    seed : int
    tolerances : Tolerances, optional
    workers : int or None
        Processes for each fit's record blocks (:mod:`~discovery.vibroimpact.verify.block_farm`)
        and the bootstrap's refits (default 1; ``None``: every core; the result does not
        depend on it).
    sensor_lag : float
        The force sensor's time constant [s] (0: none): each model's start regression sees
        the force before the lag, and every simulated force is read through it (as
        :func:`discovery.discover`'s ``sensor_lag``).
    progress : callable or bool, optional
        ``progress(stage, done, total)`` as each model is fitted; None: a bar when the session is
        interactive, False: none (:mod:`discovery._api._progress`).

    Returns
    -------
    ContactModelsResult
    """
    o = ContactModelsSettings.of("fit_contact_models", settings, options)
    models, max_simulations, n_boot, seed = o.models, o.max_simulations, o.n_boot, o.seed
    t0 = time.perf_counter()
    names = list(CONTACT_MODELS) if models is None else [str(m) for m in models]
    bad = [m for m in names if m not in CONTACT_MODELS]
    if bad or not names:
        raise InputError(
            f"unknown contact model {bad[0] if bad else ''!r}; the models: "
            f"{', '.join(CONTACT_MODELS)}"
        )
    records = as_records(scenario, reference)
    # what every model's fit is given (``settings`` is the caller's options object)
    fitting = {
        "samples": record_samples(scenario, reference, o.sensor_lag),
        "max_simulations": int(max_simulations),
        "n_boot": int(n_boot),
        "seed": int(seed),
        "tolerances": o.tolerances,
        "workers": o.workers,
        "observe": lag_observation(o.sensor_lag),
    }
    fits = []
    # the seeds first: Hunt-Crossley's fit starts Lankarani-Nikravesh and Flores (the same
    # force at one impact velocity), each model's spec naming its seed
    order = sorted(names, key=lambda m: CONTACT_MODELS[m].seeded_by is not None)
    with shared_blocks([ref for _, ref in records], block_workers(o.workers)):
        for i, name in enumerate(order):
            if progress is not None:
                progress("contact models", i, len(names))
            by = CONTACT_MODELS[name].seeded_by
            seeding = next((f for f in fits if f.model == by), None)
            at = _within(progress, name, i, names)
            fits.append(_fit_one(name, records, fitting, at, seeding))
    if progress is not None:
        progress("contact models", len(names), len(names))
    fits.sort(key=lambda f: f.value)
    ok = [f.model for f in fits if f.consistent]
    selected = ok[0] if ok else None
    return ContactModelsResult(
        n_records=len(records),
        fits=tuple(fits),
        selected=selected,
        equivalent=tuple(ok[1:]),
        settings={
            "models": names,
            "max_simulations": int(max_simulations),
            "n_boot": int(n_boot),
            "seed": int(seed),
            "sensor_lag": float(o.sensor_lag),
            "interval_method": (
                f"bootstrap ({int(n_boot)} replicates) where the record allows, else "
                "1.96 standard errors (Jacobian)"
                if n_boot
                else "1.96 standard errors (Jacobian)"
            ),
        },
        seconds=time.perf_counter() - t0,
    )
