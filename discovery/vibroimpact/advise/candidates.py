"""What ``advise`` separates and under what conditions: the candidate laws, the knobs'
bounds, the safe region and the noise of the next record.

The candidates come from a ``vidi fit`` run directory (its selected law and the
``equivalent`` models the record could not tell from it, read from ``summary.json``; with
``--library contact-models`` its selected named model and the named models it reports
equivalent), from a contact-models fit result, or from a list of laws or named models.
The noise is a *relative* force noise (a fraction of the peak force, as ``vidi simulate
--noise``) with a sampling step and a record length: a record made at another operating
point with the same sensor has another peak force, so its noise in newtons follows the
peak.
"""

import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..._files._jsonable import load_json, reads_document
from ...errors import InputError
from ..data.measurement import MAX_SAMPLES
from ..model.law import ForceLaw

__all__ = [
    "Knobs",
    "SafeRegion",
    "NoiseModel",
    "candidates_from_fit",
    "fit_scenario_changed",
    "contact_candidates",
    "unique_laws",
    "distinct_laws",
    "fitted_model",
]


def _pair(value, what, unit, low=0.0):
    """``(lo, hi)`` with ``low < lo <= hi`` finite, or an InputError naming ``what``."""
    try:
        lo, hi = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InputError(
            f"{what} must be two numbers LOW:HIGH in {unit}, got {value!r}; e.g. 3e5:6e5"
        ) from None
    if not (math.isfinite(lo) and math.isfinite(hi) and low < lo <= hi):
        raise InputError(
            f"{what} needs {low:g} < LOW <= HIGH (finite, in {unit}), got {lo:g}:{hi:g}"
        )
    return lo, hi


#: the most coarse grid points an advice evaluates
MAX_POINTS = 10_000
#: the most candidate laws (every pair is judged at every point)
MAX_CANDIDATES = 12
#: the most samples of one predicted record (as any record a run makes)
MAX_RECORD_SAMPLES = MAX_SAMPLES


@dataclass(frozen=True)
class Knobs:
    """The experimenter's knobs and their bounds.

    Attributes
    ----------
    amplitude : (float, float)
        Drive amplitude bounds ``A`` [N].
    frequency : (float, float)
        Drive frequency bounds [Hz].
    m2 : (float, float) or None
        Moulding mass bounds [kg]; ``None`` keeps the scenario's.
    grid : (int, int)
        Coarse grid points over amplitude x frequency (a bound with ``LOW == HIGH``
        takes one point).
    m2_points : int
        Coarse grid points over ``m2`` (when it varies).
    refine : int
        Best coarse points refined by a 3 x 3 grid at half the spacing around each.
    """

    amplitude: tuple
    frequency: tuple
    m2: tuple | None = None
    grid: tuple = (5, 5)
    m2_points: int = 3
    refine: int = 3

    def __post_init__(self):
        object.__setattr__(self, "amplitude", _pair(self.amplitude, "amplitude bounds", "N"))
        object.__setattr__(self, "frequency", _pair(self.frequency, "frequency bounds", "Hz"))
        if self.m2 is not None:
            object.__setattr__(self, "m2", _pair(self.m2, "moulding mass bounds", "kg"))
        try:
            grid = tuple(int(g) for g in self.grid)
        except (TypeError, ValueError):
            grid = ()
        if len(grid) != 2 or min(grid) < 1 or max(grid) > 200:
            raise InputError(f"grid must be two integers 1..200 (e.g. 5x5), got {self.grid!r}")
        object.__setattr__(self, "grid", grid)
        for name, top in (("m2_points", 50), ("refine", 100)):
            v = getattr(self, name)
            if not isinstance(v, int | np.integer) or not 0 <= int(v) <= top:
                raise InputError(f"{name} must be an integer 0..{top}, got {v!r}")
        points = grid[0] * grid[1] * (1 if self.m2 is None else int(self.m2_points))
        if points > MAX_POINTS:
            raise InputError(
                f"the grid has {points} points (each a steady state of every candidate and "
                f"their predicted records); at most {MAX_POINTS}: make the grid coarser "
                "(--grid; in the API Knobs(grid=..., m2_points=...)): the best points are "
                "refined anyway"
            )

    def axes(self):
        """Coarse axes ``(amplitudes, frequencies, masses or (None,))``."""

        def axis(b, n):
            return np.array([b[0]]) if b[0] == b[1] else np.linspace(b[0], b[1], n)

        a = axis(self.amplitude, self.grid[0])
        f = axis(self.frequency, self.grid[1])
        m = (None,) if self.m2 is None else tuple(axis(self.m2, self.m2_points))
        return a, f, m

    def contains(self, amplitude, frequency, m2=None):
        ok = (
            self.amplitude[0] <= amplitude <= self.amplitude[1]
            and self.frequency[0] <= frequency <= self.frequency[1]
        )
        return ok and (self.m2 is None or self.m2[0] <= m2 <= self.m2[1])

    def to_dict(self):
        return {
            "amplitude": list(self.amplitude),
            "frequency": list(self.frequency),
            "m2": None if self.m2 is None else list(self.m2),
            "grid": list(self.grid),
            "m2_points": int(self.m2_points),
            "refine": int(self.refine),
        }

    @classmethod
    @reads_document
    def from_dict(cls, d):
        return cls(
            amplitude=tuple(d["amplitude"]),
            frequency=tuple(d["frequency"]),
            m2=None if d.get("m2") is None else tuple(d["m2"]),
            grid=tuple(d["grid"]),
            m2_points=int(d["m2_points"]),
            refine=int(d["refine"]),
        )


@dataclass(frozen=True)
class SafeRegion:
    """What the machine may not exceed: a point where any candidate predicts more is
    excluded.

    Attributes
    ----------
    max_force : float or None
        Largest allowed peak contact force [N].
    max_penetration : float or None
        Largest allowed penetration ``w1 - w2`` [m].
    """

    max_force: float | None = None
    max_penetration: float | None = None

    def __post_init__(self):
        for name, unit in (("max_force", "N"), ("max_penetration", "m")):
            v = getattr(self, name)
            if v is None:
                continue
            try:
                v = float(v)
            except (TypeError, ValueError):
                v = float("nan")
            if not (math.isfinite(v) and v > 0):
                raise InputError(f"{name} must be a positive number in {unit}, got {v!r}")
            object.__setattr__(self, name, v)

    def violation(self, peak_force, max_penetration):
        """Why a prediction leaves the region (``""`` when it stays inside)."""
        out = []
        if self.max_force is not None and peak_force > self.max_force:
            out.append(f"peak force {peak_force:.3g} N > {self.max_force:.3g} N")
        if self.max_penetration is not None and max_penetration > self.max_penetration:
            out.append(f"penetration {max_penetration:.3g} m > {self.max_penetration:.3g} m")
        return ", ".join(out)

    def to_dict(self):
        return {"max_force": self.max_force, "max_penetration": self.max_penetration}

    @classmethod
    @reads_document
    def from_dict(cls, d):
        return cls(max_force=d.get("max_force"), max_penetration=d.get("max_penetration"))


@dataclass(frozen=True)
class NoiseModel:
    """The next record's noise and sampling (the verdict's noise floor is computed for it).

    Attributes
    ----------
    relative : float
        Force noise standard deviation as a fraction of the peak force (0 < r < 1).
    dt : float
        Sampling step [s].
    periods : float
        Drive periods recorded (cycles averaged = periods / orbit period).
    n_boot : int
        Bootstrap replicates of each noise floor.
    seed : int
        Seed of the bootstrap and of the predicted records' noise (the same at every point:
        the map is reproducible).
    source : str
        Where the noise level came from.
    position : float or None
        With positions recorded: noise on ``w1`` and on ``w2`` as a fraction of the largest
        penetration (as ``vidi simulate --position-noise``); the predicted records then
        carry positions and are judged by the verdict's record-span comparison, I5
        included.  ``None``: a force record (I2, I4).
    """

    relative: float
    dt: float = 5e-5
    periods: float = 12.0
    n_boot: int = 16
    seed: int = 0
    source: str = "given"
    position: float | None = None

    def __post_init__(self):
        checks = (
            ("relative", 0.0, 1.0, "a fraction of the peak force, e.g. 0.01"),
            ("dt", 0.0, 1.0, "the sampling step in s, e.g. 5e-5"),
            ("periods", 1.0, 1e5, "drive periods recorded, e.g. 12"),
        )
        for name, lo, hi, what in checks:
            v = getattr(self, name)
            try:
                v = float(v)
            except (TypeError, ValueError):
                v = float("nan")
            if not (math.isfinite(v) and lo < v < hi) and not (name == "periods" and v == lo):
                raise InputError(f"noise {name} must be {what} (in ({lo:g}, {hi:g})), got {v!r}")
            object.__setattr__(self, name, v)
        for name, lo, hi in (("n_boot", 1, 10_000), ("seed", 0, 2**63 - 1)):
            v = getattr(self, name)
            if isinstance(v, bool) or not isinstance(v, int | np.integer) or not lo <= v <= hi:
                raise InputError(f"noise {name} must be an integer {lo}..{hi}, got {v!r}")
        if not isinstance(self.source, str) or len(self.source) > 1000:
            raise InputError(
                "noise source must be a few words of text (where the level came from), got "
                f"{type(self.source).__name__}"
            )
        if self.position is not None:
            try:
                v = float(self.position)
            except (TypeError, ValueError):
                v = float("nan")
            if not (math.isfinite(v) and 0 < v < 1):
                raise InputError(
                    "noise position must be a fraction of the largest penetration in (0, 1), "
                    f"e.g. 0.01, or None; got {self.position!r}"
                )
            object.__setattr__(self, "position", v)

    @classmethod
    def from_measurement(cls, measurement, scenario, *, n_boot=16, seed=0):
        """The noise of a record: its force noise relative to its peak, its sampling step
        and its length in drive periods."""
        from ..data.noise import estimate_noise

        F = np.asarray(measurement.F, dtype=float)
        t = np.asarray(measurement.t, dtype=float)
        peak = float(np.max(np.abs(F)))
        if not peak > 0:
            raise InputError(f"the record {measurement.source!r} has no force; give --noise")
        rel = estimate_noise(F) / peak
        position = None
        zeta = measurement.zeta
        if zeta is not None and np.max(zeta) > 0:
            # noise on w1 and w2 each: the penetration's noise is sqrt(2) times it
            position = estimate_noise(zeta, order=3) / np.sqrt(2.0) / float(np.max(zeta))
            position = min(max(position, 1e-6), 0.5)
        return cls(
            relative=min(max(rel, 1e-6), 0.5),
            dt=float(np.median(np.diff(t))),
            periods=max(1.0, float(t[-1] - t[0]) / scenario.period),
            n_boot=n_boot,
            seed=seed,
            source=f"record {measurement.source}",
            position=position,
        )

    def to_dict(self):
        return {
            "relative": self.relative,
            "dt": self.dt,
            "periods": self.periods,
            "n_boot": int(self.n_boot),
            "seed": int(self.seed),
            "source": self.source,
            "position": self.position,
        }

    @classmethod
    @reads_document
    def from_dict(cls, d):
        keys = ("relative", "dt", "periods", "n_boot", "seed", "source", "position")
        return cls(**{k: d[k] for k in keys})


def _as_law(law):
    """A candidate as a :class:`ForceLaw`: a law, a named contact model
    (:class:`~discovery.vibroimpact.model.contact_models.ContactModel`, its law), or the
    text of either (``"2e8*z + 1e7*zd"``, ``"flores: k=1.4e9, n=1.3, e=0.45"``)."""
    from ..model.contact_models import ContactModel, parse_law

    if isinstance(law, ForceLaw):
        return law
    if isinstance(law, ContactModel):
        return law.law
    return parse_law(str(law))


def distinct_laws(laws):
    """The laws (or named models) without repeats of the same text, in order."""
    out, seen = [], set()
    for law in laws:
        if law.to_text() not in seen:
            seen.add(law.to_text())
            out.append(law)
    return out


def fitted_model(result, name):
    """The named model ``name`` of a contact-models fit with its fitted parameters."""
    from ..model.contact_models import ContactModel
    from ..model.contact_registry import CONTACT_MODELS

    p = result.fit(name).parameters
    return ContactModel(name, tuple(p[k] for k in CONTACT_MODELS[name].parameters))


def unique_laws(laws):
    """The laws without repeats (same text), in order; fewer than two is an error.  Each
    may be a :class:`ForceLaw`, a named contact model or the text of either; a
    :class:`~discovery.vibroimpact.fit.contact_fit.ContactModelsResult` stands for its
    selected model and the models it reports equivalent (:func:`contact_candidates`)."""
    from ..fit.contact_fit import ContactModelsResult

    if isinstance(laws, ContactModelsResult):
        laws = contact_candidates(laws)
    out = distinct_laws(_as_law(law) for law in laws)
    if len(out) < 2:
        raise InputError(
            f"advise separates two or more candidate laws, got {len(out)}; give --law "
            "twice or more, or a fit directory whose record left equivalent models"
        )
    return tuple(out)


def contact_candidates(result):
    """The selected named contact model of a contact-models fit
    (:class:`~discovery.vibroimpact.fit.contact_fit.ContactModelsResult`, or its
    ``to_dict()``) and the models it reports equivalent, each with its fitted parameters:
    a tuple of :class:`~discovery.vibroimpact.model.contact_models.ContactModel`.  The
    selected model's same-force twin
    (:attr:`~discovery.vibroimpact.fit.contact_fit.ContactModelsResult.same_force`) is left
    out, and a fit whose only equivalent model is that twin is refused (InputError)."""
    from ..fit.contact_fit import ContactModelsResult

    if isinstance(result, dict):
        result = ContactModelsResult.from_dict(result)
    if result.selected is None:
        raise InputError(
            "the contact-models fit selected no model (none is consistent with the record): "
            "there are no candidates to separate; try the polynomial library"
        )
    # the selected model's same-force twin is no candidate: no operating point separates it
    twin = result.same_force
    names = [m for m in result.equivalent if twin is None or m != twin[0]]
    if twin is not None and twin[0] in result.equivalent and not names:
        raise InputError(
            f"the only model the fit could not tell from {result.selected} is {twin[0]}, "
            "which makes the same force at every impact velocity: no operating point "
            "separates them, so there is nothing to advise"
        )
    return tuple(fitted_model(result, name) for name in (result.selected, *names))


def candidates_from_fit(run_dir):
    """The selected law and its ``equivalent`` models of a ``vidi fit`` run directory (a
    polynomial fit's, or a ``--library contact-models`` fit's: its selected named model
    and those it reports equivalent, :func:`contact_candidates`).

    Returns
    -------
    laws : tuple of ForceLaw
    scenario : str or None
        The fit's ``--scenario`` (a built-in name or a file), else its scenario's name (to
        load it when none is given).
    """
    p = Path(run_dir) / "summary.json"
    s, why = load_json(p)
    if s is None and why is None:
        raise InputError(f"{str(p)!r} does not exist; give the --out directory of a vidi fit run")
    if why is not None:
        raise InputError(f"{str(p)!r} {why}; run vidi fit again")
    if not isinstance(s, dict) or s.get("command") != "fit":
        raise InputError(f"{str(p)!r} is not a vidi fit summary; give a fit's --out directory")
    if s.get("library") == "contact-models":
        try:
            laws = contact_candidates(s)
        except InputError:
            raise
        except (KeyError, TypeError, ValueError, AttributeError, RecursionError) as exc:
            raise InputError(
                f"{str(p)!r} has no readable contact-models fit ({exc}); run vidi fit again"
            ) from None
    else:
        laws = _polynomial_candidates(s, p)
    if len(laws) < 2:
        raise InputError(
            f"the fit in {str(run_dir)!r} lists no equivalent model: its record already "
            "tells the laws apart; to compare other laws give --law twice or more"
        )
    settings = s.get("settings")
    given = settings.get("scenario") if isinstance(settings, dict) else None
    if isinstance(given, list):  # several records: the first one's
        given = given[0] if given else None
    sc = s.get("scenario") or {}
    name = sc.get("name") if isinstance(sc, dict) else None
    return unique_laws(laws), given if isinstance(given, str) and given else name


def fit_scenario_changed(run_dir, scenario):
    """Why the scenario ``scenario`` (a file or a built-in name, as the fit was given it)
    is not the one the ``vidi fit`` run in ``run_dir`` read (its sha256 in the fit's
    ``inputs``), or None when it is the same or the fit recorded no checksum: a scenario
    edited after the fit would give advice for another machine."""
    from ..._files._provenance import _input_record

    s, _ = load_json(Path(run_dir) / "summary.json")
    inputs = s.get("inputs") if isinstance(s, dict) else None
    then = inputs.get("scenario") if isinstance(inputs, dict) else None
    then = then.get("sha256") if isinstance(then, dict) else None
    if not isinstance(then, str):
        return None
    now = (_input_record(scenario) or {}).get("sha256")
    if now == then:
        return None
    return (
        f"the scenario {str(scenario)!r} is not the one the fit in {str(run_dir)!r} read "
        f"(sha256 {then[:12]}... then, {str(now)[:12]}... now): it changed after the fit; "
        "give --scenario to advise on the machine as it is now, or run vidi fit again"
    )


def _polynomial_candidates(s, p):
    """The selected law and the equivalent models of a polynomial fit's summary."""
    try:
        laws = [ForceLaw.from_dict(s["selected"]["coefficients"])]
        laws += [ForceLaw.from_dict(e["coefficients"]) for e in s.get("equivalent") or []]
    except (KeyError, TypeError, ValueError, AttributeError, RecursionError) as exc:
        raise InputError(
            f"{str(p)!r} has no readable selected law or equivalent models ({exc}); "
            "run vidi fit again"
        ) from None
    return laws
