"""Fit the named contact models (:mod:`~discovery.vibroimpact.model.contact_models`) to
records and say which one they support.

Each model is fitted by output error (:func:`discovery.identify`: every evaluation a full
simulation from the record's measured state, least squares on the force and penetration
residuals) over its physical parameters themselves (``k, c``; ``k, n, lambda``;
``k, n, e``), the Jacobian by differences of full simulations: ``n`` and ``e`` enter
the force non-linearly, and ``e`` through each impact's approach velocity, a contact state
the kernel does not differentiate.  The start is the record's spring-dashpot estimate
(:func:`~discovery.vibroimpact.fit.identify.record_start`) at ``n = 1.25`` for the models
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
from dataclasses import dataclass, field

import numpy as np

from ..._printing import readable
from ..._validate import Real, params
from ...errors import InputError, IntegrationError, VidiError
from ..data.measurement import Measurement
from ..model.contact_models import MODELS, ContactModel, restitution_from_ratio
from ..model.law import Term
from ..model.scenario import Scenario
from ..verify import Reference
from .identify import as_records, contact_scales, identify, record_start

__all__ = ["ContactFit", "ContactModelsResult", "fit_contact_models"]

SCHEMA_VERSION = 1
_Z95 = 1.959963984540054
_N_START = 1.25


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
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            model=d["model"],
            parameters=dict(d["parameters"]),
            intervals={k: tuple(v) for k, v in d["intervals"].items()},
            criteria=dict(d["criteria"]),
            value=float(d["value"]),
            consistent=d["consistent"],
            law=d["law"],
            message=d.get("message", ""),
            n_simulations=int(d.get("n_simulations", 0)),
            interval_method=d.get("interval_method", ""),
        )

    def __post_init__(self):
        object.__setattr__(
            self, "intervals", {k: tuple(float(x) for x in v) for k, v in self.intervals.items()}
        )


@readable
@dataclass(frozen=True)
class ContactModelsResult:
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
    """

    fits: tuple
    selected: object
    equivalent: tuple = ()
    settings: dict = field(default_factory=dict)
    seconds: float = 0.0

    def fit(self, name):
        """The :class:`ContactFit` of a model."""
        for f in self.fits:
            if f.model == name:
                return f
        raise KeyError(name)

    def to_dict(self):
        return {
            "schema_version": SCHEMA_VERSION,
            "library": "contact-models",
            "selected": self.selected,
            "equivalent": list(self.equivalent),
            "fits": [f.to_dict() for f in self.fits],
            "fit_settings": dict(self.settings),
            "seconds": float(self.seconds),
            "conclusion": self.conclusion,
        }

    @classmethod
    def from_dict(cls, d):
        return cls(
            fits=tuple(ContactFit.from_dict(f) for f in d["fits"]),
            selected=d["selected"],
            equivalent=tuple(d["equivalent"]),
            settings=dict(d["fit_settings"]),
            seconds=float(d["seconds"]),
        )

    def save(self, directory):
        """Write ``summary.json`` (:meth:`to_dict`) into ``directory``."""
        import json
        from pathlib import Path

        path = Path(directory)
        path.mkdir(parents=True, exist_ok=True)
        (path / "summary.json").write_text(json.dumps(self.to_dict(), indent=2, default=str))
        return path / "summary.json"

    @property
    def conclusion(self):
        """One sentence: the model the record supports and those it cannot tell from it."""
        if self.selected is None:
            best = self.fits[0].model if self.fits else "none"
            return (
                f"No named contact model is consistent with the record (closest: {best}); "
                "the contact is none of them, try the polynomial library or vidi explain"
            )
        text = f"The record supports {self.selected}"
        if self.equivalent:
            text += (
                f"; it cannot tell it from {', '.join(self.equivalent)} (consistent too: a "
                "record with impacts at other velocities, e.g. another drive amplitude, "
                "would separate them)"
            )
        return text

    def _lines(self):
        out = [self.conclusion]
        for f in self.fits:
            mark = "*" if f.model == self.selected else " "
            ok = {True: "consistent", False: "inconsistent", None: "failed"}[f.consistent]
            out.append(f" {mark} {f.model:<20s} I2 {f.value:.4g}  {ok}")
            for k, v in f.parameters.items():
                lo, hi = f.intervals.get(k, (np.nan, np.nan))
                out.append(f"      {k:<7s} {v:.5g}  95 % [{lo:.5g}, {hi:.5g}]")
        return out


_START_N = (1.0, 1.25, 1.5)
_START_XI = (0.05, 0.2, 0.6)  # damping ratios of the start grid
# stiffness factors of the start grid: the contact time's spring is too stiff when the
# force rises slowly from zero (a Hertzian onset, Hunt-Crossley damping), where the
# record's threshold cuts the contact short
_START_K = (1.0, 0.3, 0.1)


def _candidate(name, k, n, c, v0, z0):
    """A start model of stiffness ``k`` and a dashpot ``c`` at the typical penetration."""
    if name in ("kelvin-voigt", "hertz-damper"):
        return ContactModel(name, (k, c))
    if name == "hunt-crossley":
        return ContactModel(name, (k, n, c / z0**n))
    e = restitution_from_ratio(name, c / z0**n * v0 / k)
    e = e if np.isfinite(e) else 0.3
    return ContactModel(name, (k, n, min(max(e, 0.1), 0.95)))


def _start_candidates(name, scenario, ref):
    """The start grid of a model: ``n`` in :data:`_START_N` (the model's own when fixed),
    the record's spring-dashpot stiffness times :data:`_START_K`, damping ratios
    :data:`_START_XI`."""
    mu = scenario.m1 * scenario.m2 / (scenario.m1 + scenario.m2)
    _, v0, z0 = contact_scales(scenario, ref)
    fixed = {"kelvin-voigt": 1.0, "hertz-damper": 1.5}.get(name)
    out = []
    for n in (fixed,) if fixed else _START_N:
        (k,) = record_start(scenario, ref, [Term(n, 0.0)])
        for kf in _START_K:
            k_lin = kf * k * z0 ** (n - 1.0)  # the secant stiffness at the typical penetration
            for xi in _START_XI:
                c = 2.0 * xi * np.sqrt(k_lin * mu)
                out.append(_candidate(name, kf * k, n, c, v0, z0))
    return out


_LS_N = np.linspace(1.0, 1.6, 13)  # exponents the regression start tries


def _impact_velocities(samples):
    """Each sample's impact approach velocity: the penetration rate of its impact's first
    sample in contact."""
    imp = samples.impact
    first = {}
    for i, j in enumerate(imp):
        first.setdefault(int(j), max(float(samples.dzeta[i]), 1e-9))
    return np.array([first[int(j)] for j in imp])


def _regression_start(name, samples):
    """The model fitted to the record's contact samples by linear least squares (each ``n``
    of :data:`_LS_N` for the models that fit it, the best kept), or None: a start near the
    answer when the positions are recorded (the samples are noisy, the fit by simulation
    then removes the bias).  Samples with a clipped force (under 5 % of the peak) are left
    out."""
    if samples is None or len(samples) < 10:
        return None
    keep = samples.F > 0.05 * np.max(samples.F)
    z = np.maximum(samples.zeta[keep], 0.0)
    dz, F = samples.dzeta[keep], samples.F[keep]
    v0 = _impact_velocities(samples)[keep]
    fixed = {"kelvin-voigt": 1.0, "hertz-damper": 1.5}.get(name)
    best, best_r = None, np.inf
    for n in (fixed,) if fixed else _LS_N:
        zn = z**n
        if fixed:
            damp = dz  # a linear dashpot
        elif name == "hunt-crossley":
            damp = zn * dz
        else:
            damp = zn * dz / v0  # lambda = k r / v0: the second coefficient is k r
        A = np.column_stack([zn, damp])
        coef, *_ = np.linalg.lstsq(A, F, rcond=None)
        r = float(np.sum((A @ coef - F) ** 2))
        k, c = float(coef[0]), max(float(coef[1]), 0.0)
        if not (k > 0 and r < best_r):
            continue
        if fixed:
            cand = (k, c)
        elif name == "hunt-crossley":
            cand = (k, n, c)
        else:
            e = restitution_from_ratio(name, c / k)
            cand = (k, n, min(max(e if np.isfinite(e) else 0.05, 0.05), 0.98))
        best, best_r = ContactModel(name, cand), r
    return best


def _from_hunt_crossley(name, fit, scenario, ref):
    """A Lankarani-Nikravesh or Flores start from a fitted Hunt-Crossley model: the same
    force at the record's typical impact velocity (``r = lambda v0 / k``), or None."""
    if fit is None or fit.consistent is None:
        return None
    p = fit.parameters
    v0 = contact_scales(scenario, ref)[1]
    e = restitution_from_ratio(name, p["lambda"] * v0 / p["k"])
    if not np.isfinite(e):
        return None
    return ContactModel(name, (p["k"], p["n"], min(max(e, 0.05), 0.98)))


def _start(name, records, tolerances, extra=()):
    """The start of a model's fit: the best of its start grid (and ``extra`` starts) by
    the mean I2 (one simulation per record and candidate)."""
    from ..verify import evaluate

    sc0, ref0 = records[0]
    best, best_v = None, np.inf
    for cand in [*_start_candidates(name, sc0, ref0), *(m for m in extra if m is not None)]:
        vals = []
        for sc, ref in records:
            ev = evaluate(sc, cand.law, ref, tolerances=tolerances, floor=False)
            vals.append(ev.criteria["I2"] if ev.status == "ok" else np.inf)
        v = float(np.mean(vals))
        if v < best_v or best is None:
            best, best_v = cand, v
    return best


def _intervals(model, res, n_boot, records, seed, tolerances):
    """95 % intervals: the bootstrap's when asked for and available, else +-1.96 standard
    errors."""
    if n_boot:
        from .identify import bootstrap_intervals

        iv = bootstrap_intervals(
            *zip(*records, strict=True), model, n_boot=n_boot, seed=seed, tolerances=tolerances
        )
        if iv is not None:
            return {k: tuple(v) for k, v in iv.bounds.items()}, "bootstrap"
    se = res.standard_errors or {}
    return {  # a parameter whose standard error is not estimable has no interval
        k: (v - _Z95 * se[k], v + _Z95 * se[k])
        for k, v in zip(model.names, model.values, strict=True)
        if k in se and np.isfinite(se[k])
    }, "1.96 standard errors (Jacobian)"


def _fit_one(name, records, settings, progress, hunt_crossley=None):
    sc0, ref0 = records[0]
    extra = (_regression_start(name, settings["samples"]),)
    if name in ("lankarani-nikravesh", "flores"):
        extra += (_from_hunt_crossley(name, hunt_crossley, sc0, ref0),)
    start = _start(name, records, settings["tolerances"], extra)
    try:
        res = identify(
            [sc for sc, _ in records],
            [ref for _, ref in records],
            start,
            max_simulations=settings["max_simulations"],
            tolerances=settings["tolerances"],
            progress=progress,
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
    iv, method = _intervals(
        model, res, settings["n_boot"], records, settings["seed"], settings["tolerances"]
    )
    params = dict(zip(model.names, model.values, strict=True))
    return ContactFit(
        model=name,
        parameters=params,
        intervals=iv,
        criteria={k: float(v) for k, v in res.criteria.items()},
        value=float(res.criteria.get("I2", res.value)),
        consistent=bool(res.consistent),
        law=model.law.to_text(),
        message=res.message,
        n_simulations=res.n_simulations,
        interval_method=method,
    )


def _samples(scenario, reference):
    """The first record's contact samples (None without positions or for a prepared
    :class:`~discovery.vibroimpact.verify.Reference`)."""
    from ..data.samples import contact_samples

    meas = reference[0] if isinstance(reference, list | tuple) else reference
    sc = scenario[0] if isinstance(scenario, list | tuple) else scenario
    if not isinstance(meas, Measurement):
        return None
    try:
        return contact_samples(meas, period=sc.period)
    except (VidiError, ValueError):
        return None


@params(
    scenario=(Scenario, list, tuple),
    reference=(Measurement, Reference, list, tuple),
    models=(None, list, tuple),
    max_simulations=Real(2, integer=True),
    n_boot=Real(0, integer=True),
    seed=Real(0, integer=True),
)
def fit_contact_models(
    scenario,
    reference,
    *,
    models=None,
    max_simulations=200,
    n_boot=30,
    seed=0,
    tolerances=None,
    progress=None,
):
    """Fit every named contact model to the record(s) and select the one they support.

    Parameters
    ----------
    scenario : Scenario or sequence of Scenario
        One per record (or one for all).
    reference : Measurement or Reference, or a sequence of them
    models : sequence of str, optional
        Models to fit (default all of :data:`~discovery.vibroimpact.model.contact_models.MODELS`).
    max_simulations : int
        Budget of each model's fit.
    n_boot : int
        Bootstrap replicates of the intervals through the record-span processing (default
        30, as ``vidi fit``; 0 or a record without positions: +-1.96 standard errors of
        the fit's Jacobian).
    seed : int
    tolerances : Tolerances, optional
    progress : callable, optional
        ``progress(stage, done, total)``.

    Returns
    -------
    ContactModelsResult
    """
    t0 = time.perf_counter()
    names = list(MODELS) if models is None else [str(m) for m in models]
    bad = [m for m in names if m not in MODELS]
    if bad or not names:
        raise InputError(
            f"unknown contact model {bad[0] if bad else ''!r}; the models: {', '.join(MODELS)}"
        )
    records = as_records(scenario, reference)
    settings = {
        "samples": _samples(scenario, reference),
        "max_simulations": int(max_simulations),
        "n_boot": int(n_boot),
        "seed": int(seed),
        "tolerances": tolerances,
    }
    fits = []
    # Hunt-Crossley first: its fit starts Lankarani-Nikravesh and Flores (the same force
    # at one impact velocity)
    order = sorted(names, key=lambda m: m in ("lankarani-nikravesh", "flores"))
    for i, name in enumerate(order):
        if progress is not None:
            progress("contact models", i, len(names))
        hc = next((f for f in fits if f.model == "hunt-crossley"), None)
        fits.append(_fit_one(name, records, settings, None, hc))
    if progress is not None:
        progress("contact models", len(names), len(names))
    fits.sort(key=lambda f: f.value)
    ok = [f.model for f in fits if f.consistent]
    selected = ok[0] if ok else None
    return ContactModelsResult(
        fits=tuple(fits),
        selected=selected,
        equivalent=tuple(ok[1:]),
        settings={
            "models": names,
            "max_simulations": int(max_simulations),
            "n_boot": int(n_boot),
            "seed": int(seed),
            "interval_method": (
                f"bootstrap ({int(n_boot)} replicates) where the record allows, else "
                "1.96 standard errors (Jacobian)"
                if n_boot
                else "1.96 standard errors (Jacobian)"
            ),
        },
        seconds=time.perf_counter() - t0,
    )
