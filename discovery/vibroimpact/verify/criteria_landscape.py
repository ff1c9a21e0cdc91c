"""Criteria landscapes over a grid of two coefficients (the paper's Figs. 4-5).

Every grid point is the law with its first two coefficients replaced, scored against
the reference by :func:`discovery.vibroimpact.verify.evaluate` (the one evaluation also used by
``verify``, ``fit`` and ``identify``): steady state (from the record's measured state
when the reference carries one, else from the scenario's initial state), alignment,
criteria I0..I4.  Points are independent, so they are computed in parallel processes
and the result does not depend on the order of evaluation or the number of processes.

The reference's noise floor is computed **once**, under the template law, and every
point is judged by ``evaluate``'s consistency rule against that floor: a floor per point
(a parametric bootstrap, ~0.1 s) costs 10-20 times the point's simulation from a measured
state, and the floor varies little over the consistent points (I2's by about 5 % on the
paper's record with 1 % noise).  So ``consistent`` is exact for the template law and a
close approximation elsewhere: only points on the boundary of the consistent region can
be judged otherwise by a floor of their own.
"""

import os
import time
from dataclasses import dataclass, field, fields, replace

import numpy as np

from ..._api._printing import fmt, readable
from ..._api._progress import reports_progress, tick
from ..._api._result import Result
from ..._api._settings import Settings, option, takes
from ..._api._validate import Array, Instance, Real, params
from ...errors import InputError, VidiError, VidiTypeError
from ...numerics.executor import make_executor
from ..data.impulse import Impulse
from ..dynamics import Tolerances
from ..dynamics.law_response import response
from ..model.law import ForceLaw
from ..model.scenario import Scenario
from . import Reference, evaluate
from .criteria import CRITERIA
from .sensors import lag_observation

__all__ = ["Landscape", "landscape", "parse_grid", "default_range", "DEFAULT_SPREAD"]

DEFAULT_SPREAD = 0.5
"""Default ranges: ``(1 - s) c .. (1 + s) c`` around each template coefficient ``c``."""


def _array(key, dtype=float):
    def get(d):
        return None if d.get(key) is None else np.array(d[key], dtype=dtype)

    return get


@readable
@dataclass(frozen=True, eq=False)
class Landscape(Result):
    """Criteria over ``axes[0] x axes[1]`` coefficient values.

    Attributes
    ----------
    terms : tuple of str
        The two varied terms.
    axes : tuple of ndarray
        Values of the first and the second coefficient.
    values : dict
        ``name -> ndarray of shape (len(axes[0]), len(axes[1]))``; NaN where the
        point has no periodic steady state with contact.
    regime : ndarray of shape (len(axes[0]), len(axes[1])), dtype object
        ``"P1"``, ``"P2"``, ... (periodic with contact), ``"no-contact"`` (periodic
        without impact), ``"nonperiodic"`` (no stable periodic orbit: physical) or
        ``"failed"`` (the simulation failed: see ``messages``).
    seconds : float
        Wall time.
    workers : int
    consistent : ndarray of bool, optional
        The consistency rule of :func:`~discovery.vibroimpact.verify.evaluate` at every point,
        against :attr:`noise_floor`.
    impacts : ndarray of int, optional
        Contacts per simulated orbit (-1 where there is no periodic orbit).
    messages : ndarray of str, optional
        Why a point failed (empty elsewhere).
    noise_floor : dict, optional
        ``{I0..I4}``: the reference's noise floor (mean over bootstrap replicates;
        zeros for an exact reference).
    noise_floor_q95 : dict, optional
    noise_floor_under : str
        The law (its exact text) or the measured cycle the floor was computed under
        (:meth:`floor_under` is it to print).
    reference : dict
        What the points were compared with: ``source``, ``exact``, ``regime``,
        ``impacts``, ``start``.
    """

    terms: tuple
    axes: tuple
    values: dict
    regime: np.ndarray
    seconds: float
    workers: int
    consistent: np.ndarray | None = None
    impacts: np.ndarray | None = None
    messages: np.ndarray | None = None
    noise_floor: dict | None = None
    noise_floor_q95: dict | None = None
    noise_floor_under: str = ""
    reference: dict = field(default_factory=dict)
    continuation: bool = False

    KIND = "landscape"
    _LOAD = {
        "terms": lambda d: tuple(d["terms"]),
        "axes": lambda d: (np.array(d["alpha1"], float), np.array(d["alpha2"], float)),
        "values": lambda d: {k: np.array(d[k], float) for k in d["minima"]},
        "regime": _array("regime", object),
        "consistent": _array("consistent", bool),
        "impacts": _array("impacts", int),
        "messages": _array("messages", str),
    }

    def argmin(self, name):
        """Index ``(i, j)`` of the smallest value of criterion ``name``; ``None`` when no
        point has a value."""
        v = self.values[name]
        if not np.any(np.isfinite(v)):
            return None
        v = np.where(np.isfinite(v), v, np.inf)
        return tuple(int(k) for k in np.unravel_index(int(np.argmin(v)), v.shape))

    def regime_counts(self):
        """``{regime: number of points}``, most frequent first."""
        names, counts = np.unique(self.regime.astype(str), return_counts=True)
        order = np.argsort(-counts, kind="stable")
        return {str(names[k]): int(counts[k]) for k in order}

    @property
    def failures(self):
        """``(count, first message, (i, j) of the first)`` of the failed points
        (row-major order); ``(0, "", None)`` when none failed."""
        bad = np.argwhere(self.regime == "failed")
        if not bad.size:
            return 0, "", None
        i, j = (int(k) for k in bad[0])
        msg = "" if self.messages is None else str(self.messages[i, j])
        return int(len(bad)), msg, (i, j)

    def minima(self):
        """``{criterion: its smallest value's point}``: ``alpha1``, ``alpha2``, ``value``,
        ``regime``, ``consistent`` and the criterion's ``noise_floor`` there (``None`` for a
        criterion no point has a value of)."""
        a0, a1 = self.axes
        minima = {}
        for n in self.values:
            ij = self.argmin(n)
            minima[n] = (
                None
                if ij is None
                else {
                    "alpha1": a0[ij[0]],
                    "alpha2": a1[ij[1]],
                    "value": self.values[n][ij],
                    "regime": self.regime[ij],
                    "consistent": bool(self.consistent[ij]),
                    "noise_floor": (self.noise_floor or {}).get(n),
                }
            )
        return minima

    def as_dict(self):
        """The landscape as JSON-ready data (``summary.json`` of ``vidi landscape``)."""
        a0, a1 = self.axes
        count, first, at = self.failures
        return {
            "terms": self.terms,
            "alpha1": a0,
            "alpha2": a1,
            **self.values,
            "regime": self.regime.tolist(),
            "impacts": self.impacts,
            "consistent": self.consistent,
            "n_consistent": int(self.consistent.sum()),
            "regimes": self.regime_counts(),
            "failed": {
                "count": count,
                "first_message": first,
                "first_at": None if at is None else {"alpha1": a0[at[0]], "alpha2": a1[at[1]]},
            },
            "noise_floor": self.noise_floor,
            "noise_floor_q95": self.noise_floor_q95,
            "noise_floor_under": self.noise_floor_under,
            "minima": self.minima(),
            "seconds": self.seconds,
            "workers": self.workers,
            "continuation": self.continuation,
            "messages": self.messages,
        }

    @property
    def floor_under(self):
        """What the floor was computed under, to print: a law as every printout writes it
        (:meth:`ForceLaw.format`, ``2.06e+08*z``), not its exact text (``206000000*z``)."""
        try:
            return str(ForceLaw.parse(self.noise_floor_under))
        except (VidiError, TypeError, ValueError):
            return self.noise_floor_under

    def _lines(self):
        n0, n1 = (len(a) for a in self.axes)
        out = [
            f"landscape of {self.terms[0]}, {self.terms[1]} on {n0}x{n1} points "
            f"({self.seconds:.1f} s, {self.workers} worker(s))"
        ]
        for k, v in self.values.items():
            arr = np.asarray(v, dtype=float)
            if np.isfinite(arr).any():
                i, j = np.unravel_index(int(np.nanargmin(arr)), arr.shape)
                out.append(
                    f"  min {k} = {fmt(arr[i, j], 3)} at {self.terms[0]} = "
                    f"{fmt(self.axes[0][i])}, {self.terms[1]} = {fmt(self.axes[1][j])}"
                )
        if self.consistent is not None:
            out.append(f"  {int(np.sum(self.consistent))} point(s) consistent with the reference")
        return out


def parse_grid(text):
    """``'41x41'`` -> ``(41, 41)``."""
    try:
        a, b = (int(v) for v in str(text).lower().split("x"))
    except ValueError:
        raise InputError(f"grid {text!r} must look like 41x41") from None
    if a < 2 or b < 2 or a * b > 250_000:
        raise InputError(
            f"grid {text!r} needs at least 2 points per axis and at most 250000 points in all"
        )
    return a, b


def default_range(value, name, option, spread=DEFAULT_SPREAD):
    """``((1 - spread) value, (1 + spread) value)``, ordered; ``option`` names the CLI
    option that replaces it (in the error for a zero coefficient)."""
    value = float(value)
    if value == 0.0 or not np.isfinite(value):
        raise InputError(
            f"the coefficient of {name} in the template law is {value!r}, so no "
            f"range can be centred on it; give {option} LOW:HIGH"
        )
    lo, hi = sorted(((1.0 - spread) * value, (1.0 + spread) * value))
    return lo, hi


def _axis(values, what):
    a = np.asarray(values, dtype=float)
    if a.ndim != 1 or a.size < 1 or not np.all(np.isfinite(a)):
        raise InputError(f"{what} must be a 1-D array of finite coefficient values")
    if np.any(np.diff(a) <= 0):
        raise InputError(f"{what} must be strictly increasing")
    return a


@dataclass(frozen=True)
class _FixedFloor(Reference):
    """A reference whose noise floor was computed once: every point is judged by
    ``evaluate``'s consistency rule against the same floor, at no extra cost."""

    fixed_floor: dict | None = None

    def floor_for(self, stand_in, **kwargs):
        return self.fixed_floor


@dataclass(frozen=True)
class _Grid:
    """What every point of a landscape is evaluated with (a row's task carries it): the
    machine, the template law, the reference (its floor fixed), the integrator's
    tolerances, whether to start from the measured state, continuation along a row, and the
    observation model of the simulated force (a force sensor's lag; None: none)."""

    scenario: object
    law: object
    reference: object
    tolerances: object
    from_state: bool
    continuation: bool
    observe: object = None


def _point(ctx, law, guess=None):
    """``((regime, impacts, criteria or None, consistent, message), steady state or None)``
    of one law; ``ctx`` a :class:`_Grid`; ``guess`` the previous point's steady state
    (continuation)."""
    try:
        ev = evaluate(
            ctx.scenario,
            law,
            ctx.reference,
            tolerances=ctx.tolerances,
            from_state=ctx.from_state,
            floor=True,
            guess=guess,
            observe=ctx.observe,
        )
    except VidiError:
        raise  # bad input (e.g. a zero reference impulse) concerns every point: stop
    except (ValueError, ArithmeticError) as exc:  # numerics at this point only
        return ("failed", -1, None, False, f"{type(exc).__name__}: {exc}"), None
    ss = ev.steady
    if ev.status == "ok":
        return (ev.regime["simulated"], ev.impacts["simulated"], ev.criteria, ev.consistent, ""), ss
    if ev.status == "failed":
        return ("failed", -1, None, False, ev.message or ev.verdict), None
    if ev.status == "no-contact":
        return ("no-contact", 0, None, False, ""), ss
    return ("nonperiodic", -1, None, False, ""), None


def _row(ctx, job):
    """One row of the grid (a task of the executor: a row, not a point, lasts long enough
    to amortise a task's overhead).  With continuation each point's steady state starts
    from its neighbours' orbit (:func:`~discovery.vibroimpact.dynamics.steady_states.steady_state`'s
    ``guess``, see :func:`_predicted`), and from the cold search when that fails."""
    v0, axis1 = job
    law, continuation = ctx.law, ctx.continuation
    out, solved = [], []
    for v1 in axis1:
        coefs = list(law.coefficients)
        coefs[0], coefs[1] = v0, v1
        guess = _predicted(solved, v1) if continuation else None
        res, ss = _point(ctx, law.with_coefficients(coefs), guess)
        out.append(res)
        solved = [*solved[-1:], (v1, ss)] if ss is not None and ss.periodic else []
    return out


def _predicted(solved, v):
    """The guess at coefficient ``v`` from the last one or two solved points of the row,
    ``[(coefficient, SteadyState), ...]``: the last orbit, its state moved along the secant
    through the one before when both have the same period (a first-order predictor: it
    starts Newton about one iteration closer than the last orbit alone)."""
    if not solved:
        return None
    v_last, last = solved[-1]
    if len(solved) < 2 or solved[0][1].n_periods != last.n_periods:
        return last
    v_before, before = solved[0]
    r = (v - v_last) / (v_last - v_before)
    return replace(last, y0=last.y0 + r * (last.y0 - before.y0))


def _floor_once(ctx):
    """The reference's noise floor, ``(mean, q95, what it was computed under)``: under
    the template law; if that law has no periodic orbit with contact, under the
    scenario's law; else under the measured cycle itself (a noisy stand-in, which
    smooths force jumps and so gives a lower floor).  ``ctx``: a :class:`_Grid`."""
    scenario, law, reference = ctx.scenario, ctx.law, ctx.reference
    if not reference.noise:
        fl = reference.floor_for(reference.impulse)
        return fl["mean"], fl["q95"], "exact reference (no noise)"
    tried = []
    for cand in (law, scenario.law):
        if cand is None or cand.to_text() in (t for t, _ in tried):
            continue
        ev = evaluate(
            scenario,
            cand,
            reference,
            tolerances=ctx.tolerances,
            from_state=ctx.from_state,
            observe=ctx.observe,
        )
        if ev.status == "ok":
            return (
                dict(ev.noise_floor),
                dict(ev.noise_floor_q95 or {}),
                cand.to_text(),
            )
        tried.append((cand.to_text(), ev.status))
    fl = reference.floor_for(reference.impulse)
    why = "; ".join(f"'{ForceLaw.parse(t)}' gives {st}" for t, st in tried)
    return fl["mean"], fl["q95"], f"the measured cycle ({why})"


def _reference_of(scenario, reference, tolerances):
    """What a landscape compares with: ``reference`` (a :class:`Reference`), or by default
    the exact impulse of the scenario's law."""
    if reference is None:
        if scenario.law is None:
            raise InputError(
                f"scenario {scenario.name!r} has no reference law; add [law] text "
                "or compare with a measured record"
            )
        imp = response(scenario, scenario.law, tolerances=tolerances).impulse
        if imp is None:
            raise InputError(
                f"the reference law '{scenario.law}' has no periodic steady state with contact"
            )
        return Reference.exact(imp, source="law")
    if not isinstance(reference, Reference):
        raise VidiTypeError(
            "reference must be a discovery.vibroimpact.verify.Reference; wrap an exact impulse "
            "with Reference.exact(impulse) or prepare a record with "
            "Reference.from_measurement(measurement, scenario)"
        )
    return reference


@dataclass(frozen=True, repr=False)
class LandscapeSettings(Settings):
    """The options of :func:`landscape` (each is also a keyword of it; see its parameters)."""

    workers: object = option(None, (None, Real(1, integer=True)))
    tolerances: object = option(None, (Tolerances, None))
    from_state: bool = option(True)
    continuation: bool = option(True)
    sensor_lag: float = option(0.0, Real(0.0, 5e-3))


@takes(LandscapeSettings)
@params(
    scenario=Scenario,
    law=ForceLaw,
    axis0=Array(1),
    axis1=Array(1),
    reference=(None, Reference, Impulse),
    executor=(None, Instance("discovery.numerics.executor", "Executor")),
)
@reports_progress
def landscape(
    scenario,
    law,
    axis0,
    axis1,
    reference=None,
    *,
    settings=None,
    progress=None,
    executor=None,
    **options,
):
    """Compute all criteria over a grid of the first two coefficients of ``law``.

    Parameters
    ----------
    scenario : Scenario
    law : ForceLaw
        Template law; its first two coefficients are varied (others kept).  The noise
        floor is computed under it.
    axis0, axis1 : array_like
        Strictly increasing values of the first and second coefficient.
    reference : Reference, optional
        What every point is compared with: a measured record
        (:meth:`Reference.from_measurement`) or an exact impulse
        (:meth:`Reference.exact`); default the exact impulse of ``scenario.law``.
    settings : LandscapeSettings, optional
        The options below in one object; keywords override its fields.
    workers : int, optional
        Processes (default: all cores); the result does not depend on it.
    tolerances : Tolerances, optional
    from_state : bool
        Start each simulation from the reference's measured state when it has one
        (default), else from the scenario's initial state.
    progress : callable or bool, optional
        ``progress(stage, done, total)`` after each row of the grid; None: a bar when the session is
        interactive, False: none (:mod:`discovery._api._progress`).
    executor : Executor, optional
        Where the rows run (:mod:`discovery.numerics.executor`: serial, a process pool, a Dask
        cluster); overrides ``workers`` and is not closed here.  One task per row.
    continuation : bool
        Start each point's steady state from its neighbours' orbit along a row (default),
        falling back on the cold search; False: every point from the cold search.
    sensor_lag : float
        The force sensor's time constant [s] (a calibration's
        :attr:`~discovery.Calibration.sensor_lag`): every point's force is compared as the
        sensor sees it, as :func:`~discovery.verify` compares it (0: as simulated).

    Returns
    -------
    Landscape
    """
    s = LandscapeSettings.of("landscape", settings, options)
    if len(law.terms) < 2:
        raise InputError(
            f"a landscape varies two coefficients but the law '{law}' has "
            f"{len(law.terms)} term(s); give a law with at least two terms, e.g. "
            "'2.06e8*z + 1.28e7*zd'"
        )
    axis0 = _axis(axis0, "axis0")
    axis1 = _axis(axis1, "axis1")
    t_start = time.perf_counter()
    reference = _reference_of(scenario, reference, s.tolerances)
    grid = _Grid(
        scenario,
        law,
        reference,
        s.tolerances,
        s.from_state,
        bool(s.continuation),
        lag_observation(s.sensor_lag),
    )
    floor, q95, under = _floor_once(grid)
    ref = _FixedFloor(
        **{f.name: getattr(reference, f.name) for f in fields(Reference)},
        fixed_floor={"mean": floor, "q95": q95, "n_boot": reference.n_boot, "seed": reference.seed},
    )
    workers = min(int(s.workers or os.cpu_count() or 1), axis0.size)
    shape = (axis0.size, axis1.size)
    regime = np.empty(shape, dtype=object)
    impacts = np.full(shape, -1, dtype=int)
    consistent = np.zeros(shape, dtype=bool)
    messages = np.full(shape, "", dtype=object)
    values = {n: np.full(shape, np.nan) for n in CRITERIA}
    jobs = [(v0, axis1) for v0 in axis0]
    context = replace(grid, reference=ref)
    own = executor is None
    ex = make_executor(workers) if own else executor
    try:
        for done, (i, row) in enumerate(ex.run(_row, jobs, context), start=1):
            tick(progress, "landscape: rows of the grid", done, len(jobs))
            for j, (reg, k, crit, ok, msg) in enumerate(row):
                regime[i, j], impacts[i, j], consistent[i, j], messages[i, j] = reg, k, ok, msg
                if crit is not None:
                    for n, v in crit.items():  # I5 too where the record has positions
                        values.setdefault(n, np.full(shape, np.nan))[i, j] = v
    finally:
        if own:
            ex.close()
    workers = min(ex.workers, len(jobs))
    info = {
        "source": reference.source,
        "exact": not reference.noise,
        "regime": reference.regime,
        "impacts": reference.impacts,
        "start": "measured state"
        if s.from_state and reference.start is not None
        else "scenario initial state",
    }
    return Landscape(
        terms=tuple(law.names[:2]),
        axes=(axis0, axis1),
        values=values,
        regime=regime,
        seconds=time.perf_counter() - t_start,
        workers=workers,
        consistent=consistent,
        impacts=impacts,
        messages=messages,
        noise_floor=dict(floor),
        noise_floor_q95=dict(q95),
        noise_floor_under=under,
        reference=info,
        continuation=bool(s.continuation),
    )
