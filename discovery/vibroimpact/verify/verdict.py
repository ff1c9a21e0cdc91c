"""``verify``: is a law consistent with a record?"""

import time
from dataclasses import dataclass, field

import numpy as np

from ..._api._printing import readable
from ..._api._result import Result, part
from ..._api._settings import Settings, option, takes
from ..._api._validate import Real, params
from ..data.measurement import Measurement
from ..dynamics import Tolerances
from ..model.law import ForceLaw
from ..model.scenario import Scenario, scale_bounds
from .criteria import criteria_lines
from .evaluation import Evaluation, evaluate
from .reference import Reference
from .sensors import lag_note, lag_observation

__all__ = ["VerifyResult", "VerifySettings", "verify"]


def _contacts(n):
    return f"{n} contact(s)"


def _law(d):
    return None if d.get("law") is None else ForceLaw.parse(d["law"])


@readable
@dataclass(frozen=True, eq=False)
class VerifyResult(Result):
    """Outcome of :func:`verify`.

    Attributes
    ----------
    law : ForceLaw
    evaluation : Evaluation
        From the machine's measured state (or the scenario's start without positions).
    reference : Reference
        The record's steady cycle, noise floor and state.
    default_start : Evaluation or None
        The same law from the scenario's initial state, when it differs from the
        measured one; ``None`` when not checked.
    notes : tuple of str
        E.g. that the scenario's default start reaches another attractor.
    seconds : float
    settings : dict
    """

    law: object
    evaluation: object
    reference: object
    default_start: object = None
    notes: tuple = ()
    seconds: float = 0.0
    settings: dict = field(default_factory=dict)

    KIND = "verify"
    _LOAD = {
        "law": _law,
        "evaluation": lambda d: part(Evaluation, d),
        "default_start": lambda d: part(Evaluation, d.get("default_start")),
        "notes": lambda d: tuple(d.get("notes", ())),
        "settings": lambda d: d.get("verify_settings") or {},
    }

    @property
    def consistent(self):
        return self.evaluation.consistent

    @property
    def criteria(self):
        return self.evaluation.criteria

    @property
    def noise_floor(self):
        return self.evaluation.noise_floor

    @property
    def verdict(self):
        return self.evaluation.verdict

    def as_dict(self):
        ev = self.evaluation
        return {
            "law": self.law.to_text(),
            **ev.as_dict(),
            "noise_floor_q95": ev.noise_floor_q95,
            "measured": self.reference.measured(),
            "start": {
                "from": "measured state"
                if self.reference.start is not None
                else "scenario initial state",
                "state": self.reference.start,
                "time": self.reference.start_time,
                "time_offset": self.reference.time_offset,
            },
            "default_start": None if self.default_start is None else self.default_start.as_dict(),
            "notes": list(self.notes),
            "seconds": self.seconds,
            "verify_settings": self.settings,
        }

    def regime_line(self):
        """The measured and simulated regimes with their contacts per cycle, as one line
        (a failed simulation has neither)."""
        ev = self.evaluation
        out = (
            f"regime measured {ev.regime.get('measured')} "
            f"({_contacts(ev.impacts.get('measured'))}), simulated "
        )
        if ev.status == "failed":
            return out + "none (the simulation failed)"
        sim = ev.regime.get("simulated") or ev.status
        n = ev.impacts.get("simulated")
        return out + (sim if n is None else f"{sim} ({_contacts(n)})")

    def _lines(self):
        ev = self.evaluation
        out = [f"{self.law}: {ev.verdict or ev.message}"]
        out += criteria_lines(ev.criteria, ev.noise_floor, ev.limits)
        out.append(f"  {self.regime_line()}")
        out += [f"  note: {n}" for n in self.notes]
        return out


def _attractor(ev):
    """What an evaluation's simulation reached: its periodic regime (``"P1"``...),
    ``"nonperiodic"``, or ``None`` when that is not known (the simulation failed, or the
    steady orbit of a record-span comparison could not be found)."""
    if ev.status == "failed":
        return None
    reg = ev.regime.get("simulated")
    if ev.status == "nonperiodic" or reg == "nonperiodic":
        return "nonperiodic"
    if reg in (None, "unknown") or str(reg).startswith("failed"):
        return None
    return reg


def _reached(ev, attractor):
    """The attractor an evaluation reached, for a note (``"P1 without contact"``)."""
    if attractor is None:
        return str(ev.status)
    return f"{attractor} without contact" if ev.status == "no-contact" else attractor


def _default_start_note(ev, other):
    """The note on the law from the scenario's initial state (``other``) against the same
    law from the measured state (``ev``), or ``""``.

    Coexisting attractors are claimed only when both simulations reached an attractor and
    the two differ: another periodic regime, a periodic orbit against none, or (both on the
    same periodic regime, compared with the law's steady orbit) another orbit, by its I2.
    Two nonperiodic motions cannot be told apart this way, and a failed simulation reached
    no attractor: then only what is known is said."""
    a, b = _attractor(other), _attractor(ev)
    if a is None or b is None:
        if other.status == "failed" and ev.status == "failed":
            return ""  # the verdict already says the simulation failed
        if other.status == "failed":
            return (
                f"from the scenario's initial state the law's simulation failed ({other.message})"
            )
        if ev.status == "failed":
            return (
                "from the scenario's initial state the law's simulation does not fail: it "
                f"reaches {_reached(other, a)}"
            )
        return ""
    if a == b == "nonperiodic":
        return ""
    # (with a record span the two criteria come from different comparisons: only the
    # regimes are compared)
    span = ev.comparison == "record span"
    other_orbit = a == b and (
        (other.status == "no-contact") != (ev.status == "no-contact")
        or (
            not span
            and other.status == "ok"
            and ev.status == "ok"
            and abs(other.criteria["I2"] - ev.criteria["I2"]) > 0.01
        )
    )
    if a == b and not other_orbit:
        return ""
    i2 = other.value("I2")
    return (
        f"from the scenario's initial state the law reaches another attractor "
        f"({_reached(other, a)}"
        + (f", I2 {i2:.3g}" if np.isfinite(i2) else "")
        + f") than from the measured state ({_reached(ev, b)}): coexisting attractors"
    )


def _shedding(scenario, ref):
    """The machine a record is judged with when it sheds mass at every impact, and the notes
    that say how (as :meth:`~discovery.vibroimpact.explain.effects.Model.apply` does for
    explain): a record with positions is compared over its span, each block starting with
    the mass left after the record's impacts before it; a record without them only through
    its averaged cycle, against the scenario's mass (its drift is explain's drift channel);
    either way there is no steady orbit to start the law from the scenario's state."""
    if scenario.mass_loss == 0:
        return scenario, []
    if ref.span is not None:
        return scenario, [
            f"the machine sheds {scenario.mass_loss:g} of the moulding's mass per impact: "
            "each block of the record's span starts with the mass left after the record's "
            "impacts before it"
        ]
    return scenario.replace(mass_loss=0.0), [
        f"the machine sheds {scenario.mass_loss:g} of the moulding's mass per impact, and "
        "the record has no positions: its averaged cycle is compared with the scenario's "
        "mass (the drift across the impacts is explain's drift channel)"
    ]


#: the most simulations the search of the machine's scale makes
SCALE_EVALUATIONS = 8
#: how closely the search locates the best scale (0.01 %: 0.1 % moved the README's verdict
#: limits in their third digit)
SCALE_XTOL = 1e-4


def _scale_minimum(i2, lo, hi):
    """The factor in ``[lo, hi]`` with the lowest ``i2`` and that value: successive
    parabolic interpolation from the bounds and the calibration's own scale (1), each step
    through the best point found and its two neighbours, until a step would land within
    :data:`SCALE_XTOL` of a point already simulated or :data:`SCALE_EVALUATIONS` are spent.

    Over a calibration's scale range (about 1 %) I2 is smooth in the scale: a minimum at a
    bound (the commonest case) is found with the three starting simulations, one inside
    with two to four more.  Where the parabola through the three is not convex, the larger
    interval beside the best point is halved instead."""
    seen = {x: i2(x) for x in sorted({lo, min(max(1.0, lo), hi), hi})}
    while len(seen) < SCALE_EVALUATIONS:
        xs = sorted(seen)
        k = min(range(len(xs)), key=lambda j: seen[xs[j]])
        j = min(max(k - 1, 0), len(xs) - 3)
        (a, b, c), (fa, fb, fc) = xs[j : j + 3], [seen[x] for x in xs[j : j + 3]]
        num = (b - a) ** 2 * (fb - fc) - (b - c) ** 2 * (fb - fa)
        den = (b - a) * (fb - fc) - (b - c) * (fb - fa)
        if den < 0.0:  # convex: the parabola's vertex
            x = b - 0.5 * num / den
            if (k == 0 and x <= a) or (k == len(xs) - 1 and x >= c):
                break  # beyond the bound at which the best point is: the bound
            x = min(max(x, a), c)
        elif 0 < k < len(xs) - 1:  # not convex round an inner best: halve its larger side
            x = 0.5 * (xs[k] + (xs[k - 1] if xs[k] - xs[k - 1] > xs[k + 1] - xs[k] else xs[k + 1]))
        else:  # not convex, the best at a bound: the bound
            break
        if min(abs(x - y) for y in xs) < SCALE_XTOL:  # a tolerance from the best, towards x
            x = xs[k] + (SCALE_XTOL if x >= xs[k] else -SCALE_XTOL)
            if not lo <= x <= hi or min(abs(x - y) for y in xs) < 0.5 * SCALE_XTOL:
                break
        seen[x] = i2(x)
    best = min(seen, key=lambda x: (seen[x], abs(x - 1.0)))  # a tie: the calibration's
    return best, seen[best]


def _profiled_scale(scenario, law, ref, bounds, how):
    """The scenario scaled within ``bounds`` to fit ``law`` best (I2 of the record,
    :func:`_scale_minimum`; ``how``: :func:`evaluate`'s tolerances and observation model),
    and a note saying where."""
    lo, hi = scale_bounds(bounds, "verify: machine_scale")
    if hi - lo < 1e-9:
        return scenario, "the machine's scale is fixed"

    def i2(factor):
        ev = evaluate(scenario.scaled(factor), law, ref, floor=False, objective=("I2",), **how)
        v = ev.criteria.get("I2") if ev.status == "ok" and ev.criteria else None
        return float(v) if v is not None and np.isfinite(v) else 1e3

    best, value = _scale_minimum(i2, lo, hi)
    return scenario.scaled(best), (
        f"the machine's scale, known to [{lo:.4f}, {hi:.4f}] of the calibration's, fits "
        f"this law best at {best:.4f} (I2 {value:.3g} there)"
    )


@dataclass(frozen=True, repr=False)
class VerifySettings(Settings):
    """The options of :func:`verify` (each is also a keyword of it; see its parameters)."""

    time_offset: float = option(0.0, Real())
    n_boot: int = option(16, Real(0, integer=True))
    seed: int = option(0, Real(0, integer=True))
    check_default_start: bool = option(True, (bool, np.bool_))
    tolerances: object = option(None, (Tolerances, None))
    machine_scale: object = option(None, (tuple, list, None))
    sensor_lag: float = option(0.0, Real(0.0, 5e-3))


@takes(VerifySettings)
@params(scenario=Scenario, measurement=(Measurement, Reference), law=ForceLaw)
def verify(scenario, measurement, law, *, settings=None, **options):
    """Verify ``law`` against a record by full simulation.

    Parameters
    ----------
    scenario : Scenario
        The known part of the machine.
    measurement : Measurement or Reference
        The record (``t``, ``F``; ``w1, w2`` [``v1, v2``] for the measured state and the
        exact onsets), or an already prepared :class:`Reference`.
    law : ForceLaw
    settings : VerifySettings, optional
        The options below in one object; keywords override its fields.
    time_offset : float
        Drive-clock time [s] of the record's ``t = 0`` (0 when the record follows the
        convention that the drive ``A sin(2 pi f t)`` has phase 0 at ``t = 0``).
    n_boot : int
        Bootstrap replicates of the noise floor.
    seed : int
        Seed of the bootstrap.
    check_default_start : bool
        Also simulate from the scenario's initial state and note a different attractor.
    tolerances : Tolerances, optional
    machine_scale : (float, float), optional
        The factors ``(low, high)`` within which the machine's scale is uncertain (a
        calibration's :attr:`~discovery.Calibration.scale_range`).  The law is then judged
        with the scale in that range that fits it best (a one-dimensional search on I2,
        :data:`SCALE_EVALUATIONS` simulations at most): the record fixes the machine's
        ratios from its motions, its scale only through the force's quadrature, and a
        stiff machine's verdict can turn on a fraction of a percent of it.
    sensor_lag : float
        A force sensor's time constant [s] (a calibration's ``force_lag``): the simulated
        force is compared with the record as the sensor sees it (``tau F' + F = F_true``,
        :func:`~discovery.vibroimpact.verify.sensors.first_order_lag`); 0 (the default):
        the record's force is the contact force.

    Returns
    -------
    VerifyResult
    """
    s = VerifySettings.of("verify", settings, options)
    t0 = time.perf_counter()
    ref = (
        measurement
        if isinstance(measurement, Reference)
        else Reference.from_measurement(
            measurement, scenario, time_offset=s.time_offset, n_boot=s.n_boot, seed=s.seed
        )
    )
    scenario, notes = _shedding(scenario, ref)
    observe = lag_observation(s.sensor_lag)
    if observe is not None:
        notes.append(lag_note(s.sensor_lag))
    how = {"tolerances": s.tolerances, "observe": observe}
    if s.machine_scale is not None:
        scenario, note = _profiled_scale(scenario, law, ref, s.machine_scale, how)
        notes.append(note)
    ev = evaluate(scenario, law, ref, **how)
    other = None
    if s.check_default_start and ref.start is not None and scenario.mass_loss == 0:
        other = evaluate(scenario, law, ref, from_state=False, floor=False, **how)
        note = _default_start_note(ev, other)
        if note:
            notes.append(note)
    recorded = {
        "time_offset": s.time_offset,
        "n_boot": s.n_boot,
        "seed": s.seed,
        "check_default_start": s.check_default_start,
        "tolerances": None if s.tolerances is None else s.tolerances.as_dict(),
        "machine_scale": None if s.machine_scale is None else list(s.machine_scale),
        "sensor_lag": s.sensor_lag,
    }
    return VerifyResult(
        law=law,
        evaluation=ev,
        reference=ref,
        default_start=other,
        notes=tuple(notes),
        seconds=time.perf_counter() - t0,
        settings=recorded,
    )
