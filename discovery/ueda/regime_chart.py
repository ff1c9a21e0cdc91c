"""Regime charts over the forcing plane ``(nu, B)``, in parallel processes.

Each row of the chart (one ``B``) is a continuation sweep in ``nu`` (and back, with
``sweeps=2``), each point classified by the stroboscopic map, its early exit and the
variational equations: :mod:`.sweep` says how.

Rows are distributed over worker processes (they die with the parent; Ctrl-C stops
them); the result does not depend on the number of workers.
"""

import copy
import os
import time
from dataclasses import dataclass, field

import numpy as np

from .._api._printing import readable
from .._api._progress import reports_progress, tick
from .._api._result import Result
from .._api._settings import Settings, option, takes
from .._api._validate import Array, Instance, Real, params
from ..errors import InputError, VidiTypeError
from ..numerics.executor import make_executor
from ._runs import initial_state as _y0
from .sweep import KINDS, sweep_row
from .system import UedaSystem

__all__ = ["Chart", "chart", "KINDS"]


@readable
@dataclass(frozen=True, eq=False)
class Chart(Result):
    """A regime chart.

    Attributes
    ----------
    system : UedaSystem
        The template (its ``nu`` and ``B`` are replaced by the axes).
    nu, B : ndarray
        The axes.
    kind : ndarray of int, shape (len(B), len(nu))
        Index into :data:`KINDS` (``-1``: the integration failed); the sweep in
        increasing ``nu``.
    period : ndarray of int
        ``n`` of periodic points, else 0.
    lyapunov : ndarray
        Largest exponent at each point: ``log|m_1| / (n T)`` of the largest Floquet
        multiplier for an orbit found by the early exit, else the Benettin estimate over
        ``periods`` periods.
    rotation : ndarray
        Rotation number of the strobe points (beat and chaos; NaN for periodic points).
    periods_integrated : ndarray of int
        Forcing periods integrated at each point, both sweeps (the cost; the early exit
        shortens it; the rechecks of ``sweeps=2`` are not counted).
    seconds : float
        Wall time.
    cpu_seconds : float
        CPU time of the rows summed over the processes (the work, whatever the load).
    workers : int
    settings : dict
    kind_down, period_down, lyapunov_down, rotation_down : ndarray or None
        The same for the sweep in decreasing ``nu`` (``sweeps=2``).
    coexisting : ndarray of bool or None
        ``sweeps=2``: the two sweeps ended on different attractors - at least one on a
        stable periodic orbit, the other on another orbit or a non-periodic regime, also
        after ``recheck`` times the transient more from both (two non-periodic results
        are not compared).
    """

    KIND = "ueda-chart"
    _LOAD = {
        "system": lambda d: UedaSystem.from_dict(d["system"]),
        "nu": lambda d: np.array(d["nu"], float),
        "B": lambda d: np.array(d["B"], float),
        "kind": lambda d: None,
        "period": lambda d: None,
        "lyapunov": lambda d: None,
        "rotation": lambda d: None,
        "periods_integrated": lambda d: None,
        "kind_down": lambda d: None,
        "period_down": lambda d: None,
        "lyapunov_down": lambda d: None,
        "rotation_down": lambda d: None,
        "coexisting": lambda d: None,
    }

    system: UedaSystem
    nu: np.ndarray
    B: np.ndarray
    kind: np.ndarray = field(repr=False)
    period: np.ndarray = field(repr=False)
    lyapunov: np.ndarray = field(repr=False)
    rotation: np.ndarray = field(repr=False)
    seconds: float
    workers: int
    settings: dict
    periods_integrated: np.ndarray | None = field(default=None, repr=False)
    cpu_seconds: float = float("nan")
    kind_down: np.ndarray | None = field(default=None, repr=False)
    period_down: np.ndarray | None = field(default=None, repr=False)
    lyapunov_down: np.ndarray | None = field(default=None, repr=False)
    rotation_down: np.ndarray | None = field(default=None, repr=False)
    coexisting: np.ndarray | None = field(default=None, repr=False)

    @property
    def sweeps(self):
        return 1 if self.kind_down is None else 2

    def fractions(self):
        """Fraction of the points in each class (the sweep in increasing ``nu``; on a
        loaded chart, whose grids are not in its summary, the summary's)."""
        if self.loaded:
            return copy.deepcopy(self.__dict__["_document"].get("fractions") or {})
        n = self.kind.size
        out = {k: float(np.sum(self.kind == i) / n) for i, k in enumerate(KINDS)}
        out["failed"] = float(np.sum(self.kind < 0) / n)
        return out

    def period_counts(self):
        """``{n: number of points}`` of the periodic points (increasing ``nu``; on a loaded
        chart the summary's ``periods_found``, ``{"P<n>": number of points}``)."""
        if self.loaded:
            found = self.__dict__["_document"].get("periods_found") or {}
            return {int(k.removeprefix("P")): v for k, v in found.items()}
        n, c = np.unique(self.period[self.period > 0], return_counts=True)
        return {int(a): int(b) for a, b in zip(n, c, strict=True)}

    @property
    def columns(self):
        """The CSV header (:meth:`rows`)."""
        cols = ["nu", "B", "regime", "period", "lyapunov", "rotation_number"]
        if self.sweeps == 2:
            cols += [
                "regime_down",
                "period_down",
                "lyapunov_down",
                "rotation_number_down",
                "coexisting",
            ]
        return cols

    def rows(self):
        """CSV rows (:attr:`columns`): ``nu, B, regime, period, lyapunov, rotation``
        and, with two sweeps, the same for the sweep in decreasing ``nu`` and
        ``coexisting`` (0/1)."""

        def name(k):
            return KINDS[k] if k >= 0 else "failed"

        for i, b in enumerate(self.B):
            for j, nu in enumerate(self.nu):
                row = (
                    float(nu),
                    float(b),
                    name(int(self.kind[i, j])),
                    int(self.period[i, j]),
                    float(self.lyapunov[i, j]),
                    float(self.rotation[i, j]),
                )
                if self.sweeps == 2:
                    row += (
                        name(int(self.kind_down[i, j])),
                        int(self.period_down[i, j]),
                        float(self.lyapunov_down[i, j]),
                        float(self.rotation_down[i, j]),
                        int(self.coexisting[i, j]),
                    )
                yield row

    def as_dict(self):
        n = int(self.kind.size)
        out = {
            "system": self.system.as_dict(),
            "grid": [int(self.nu.size), int(self.B.size)],
            "nu_range": [float(self.nu[0]), float(self.nu[-1])],
            "B_range": [float(self.B[0]), float(self.B[-1])],
            "nu": self.nu,
            "B": self.B,
            "fractions": self.fractions(),
            "periods_found": {f"P{k}": v for k, v in self.period_counts().items()},
            "seconds": self.seconds,
            "cpu_seconds": self.cpu_seconds,
            "workers": self.workers,
            "points": n,
            "sweeps": self.sweeps,
            "seconds_per_point_per_worker": self.seconds * self.workers / n,
            "cpu_seconds_per_point": self.cpu_seconds / (n * self.sweeps),
            "settings": self.settings,
        }
        if self.periods_integrated is not None:
            out["mean_periods_integrated"] = float(np.mean(self.periods_integrated))
        if self.sweeps == 2:
            down = {k: float(np.sum(self.kind_down == i) / n) for i, k in enumerate(KINDS)}
            down["failed"] = float(np.sum(self.kind_down < 0) / n)
            out["fractions_down"] = down
            out["coexisting_fraction"] = float(np.mean(self.coexisting))
            out["coexisting_points"] = int(np.sum(self.coexisting))
        return out

    def _lines(self):
        kinds, counts = np.unique(np.asarray(self.kind).astype(str), return_counts=True)
        share = ", ".join(f"{k} {c}" for k, c in zip(kinds, counts, strict=True))
        return [
            f"regime chart of {self.system.model} on {np.size(self.nu)} x "
            f"{np.size(self.B)} points ({self.seconds:.1f} s, {self.workers} worker(s))",
            f"  regimes: {share}",
        ]


def _axis(values, name):
    a = np.asarray(values, dtype=float).reshape(-1)
    if a.size < 1 or not np.all(np.isfinite(a)) or np.any(np.diff(a) <= 0):
        raise InputError(f"the {name} axis must be finite and strictly increasing")
    return a


def _check_grid(system, nu, B):
    """The system and the axes of :func:`chart`, checked; returns the axes."""
    if not isinstance(system, UedaSystem):
        raise VidiTypeError("system must be a discovery.ueda.UedaSystem")
    nu, B = _axis(nu, "nu"), _axis(B, "B")
    if nu[0] <= 0:
        raise InputError("nu must be > 0")
    return nu, B


def _run_rows(system, settings, nu, B, *, workers, executor, progress):
    """Every row of ``B`` on the executor (one task per row): the chart's grids (regime,
    period, exponent, rotation, cost, and the second sweep's), the CPU seconds and the
    workers used (``workers``, ``executor`` and ``progress`` as :func:`chart` takes
    them)."""
    workers = min(int(workers or os.cpu_count() or 1), B.size)
    shape = (B.size, nu.size)
    kind = np.full(shape, -1, dtype=int)
    period = np.zeros(shape, dtype=int)
    lam = np.full(shape, np.nan)
    rot = np.full(shape, np.nan)
    cost = np.zeros(shape, dtype=int)
    two = settings["sweeps"] == 2
    if two:
        kind2, period2 = kind.copy(), period.copy()
        lam2, rot2 = lam.copy(), rot.copy()
        coex = np.zeros(shape, dtype=bool)
    jobs = [(b, nu) for b in B]
    cpu = 0.0
    own = executor is None
    ex = make_executor(workers) if own else executor
    try:
        for done, (i, (up, down, cx, sec)) in enumerate(
            ex.run(sweep_row, jobs, (system, settings)), start=1
        ):
            cpu += sec
            for j, (k, n, lv, r, c) in enumerate(up):
                kind[i, j], period[i, j], lam[i, j], rot[i, j], cost[i, j] = k, n, lv, r, c
            if two:
                for j, (k, n, lv, r, c) in enumerate(down):
                    kind2[i, j], period2[i, j], lam2[i, j], rot2[i, j] = k, n, lv, r
                    cost[i, j] += c
                coex[i] = cx
            tick(progress, "chart: rows", done, len(jobs))
    finally:
        if own:
            ex.close()
    workers = min(ex.workers, len(jobs))
    extra = {}
    if two:
        extra = {
            "kind_down": kind2,
            "period_down": period2,
            "lyapunov_down": lam2,
            "rotation_down": rot2,
            "coexisting": coex,
        }
    grids = {
        "kind": kind,
        "period": period,
        "lyapunov": lam,
        "rotation": rot,
        "periods_integrated": cost,
        **extra,
    }
    return grids, cpu, workers


@dataclass(frozen=True, repr=False)
class UedaChartSettings(Settings):
    """The options of :func:`chart` (each is also a keyword of it; see its parameters)."""

    y0: object = option(None, (None, Array(1)))
    transient: int = option(60, Real(0, integer=True))
    periods: int = option(80, Real(1, integer=True))
    rtol: float = option(1e-6, Real(0, 1, open_low=True))
    hmax_fraction: float = option(0.1, Real(0, 1, open_low=True))
    max_period: int = option(16, Real(1, integer=True))
    closure: float = option(1e-4, Real(0, open_low=True))
    chaos_threshold: float = option(0.015, Real(0))
    sweeps: int = option(1, Real(1, 2, integer=True))
    early_exit: bool = option(True)
    min_pairs: int = option(12, Real(1, integer=True))
    recheck: int = option(5, Real(0, integer=True))
    workers: object = option(None, (None, Real(1, integer=True)))

    def _check_together(self, where):
        if self.periods < 4 * self.max_period:
            raise InputError(
                f"{where}: periods ({self.periods}) must be at least 4 x max_period = "
                f"{4 * self.max_period}: the recurrence test of period n compares "
                "three cycles of strobe points with the cycle before"
            )


@takes(UedaChartSettings)
@params(
    system=UedaSystem,
    nu=Array(1),
    B=Array(1),
    executor=(None, Instance("discovery.numerics.executor", "Executor")),
)
@reports_progress
def chart(system, nu, B, *, settings=None, progress=None, executor=None, **options):
    """The regime at every ``(nu, B)`` of a grid (see :mod:`discovery.ueda.sweep`).

    Parameters
    ----------
    system : UedaSystem
        Template: model and the other parameters.
    nu, B : array_like
        Strictly increasing axes (``nu > 0``).
    settings : UedaChartSettings, optional
        The options below in one object; keywords override its fields.
    y0 : (x, v), optional
        Start of every row.
    transient : int
        Periods discarded at most (the early exit stops sooner at periodic points).
    periods : int
        Periods observed with the variational equations where no stable orbit was found
        in the transient; at least ``4 max_period`` (the recurrence test of period ``n``
        compares three cycles of strobe points with the cycle before).
    rtol, hmax_fraction : float
        Integrator tolerance and largest step (fraction of a period); charts favour
        speed (``attractor`` uses 1e-9 and 0.02).
    max_period : int
        The longest period recognised (longer locked orbits appear as beat).
    closure, chaos_threshold
        The classification rules (:func:`classify_points`).
    sweeps : {1, 2}
        2: each row swept in increasing ``nu`` and back; both regimes and
        ``coexisting`` recorded (twice the work, and the rechecks).
    recheck : int
        ``sweeps=2``: where the two sweeps' attractors differ, both are run again from
        their final states with ``recheck`` times the transient; ``coexisting`` only if
        they still differ (0: no recheck).
    early_exit : bool
        Stop the transient once a period-``n`` orbit repeats (see :mod:`discovery.ueda.sweep`).
    min_pairs : int
        Consecutive repeating pairs the early exit needs at least (and ``3 n``).
    workers : int, optional
        Processes (default all cores, at most one per row).
    progress : callable or bool, optional
        ``progress(stage, done, total)`` after each row (stage ``"chart: rows"``); None:
        a bar when the session is interactive, False: none (:mod:`discovery._api._progress`).
    executor : Executor, optional
        Where the rows run (:mod:`discovery.numerics.executor`); overrides ``workers`` and is not
        closed here.  One task per row of ``B``.

    Returns
    -------
    Chart
    """
    s = UedaChartSettings.of("chart", settings, options)
    nu, B = _check_grid(system, nu, B)
    recorded = {
        "transient": int(s.transient),
        "periods": int(s.periods),
        "rtol": float(s.rtol),
        "hmax_fraction": float(s.hmax_fraction),
        "max_period": int(s.max_period),
        "closure": float(s.closure),
        "chaos_threshold": float(s.chaos_threshold),
        "sweeps": int(s.sweeps),
        "early_exit": bool(s.early_exit),
        "min_pairs": int(s.min_pairs),
        "recheck": int(s.recheck),
        "y0": [float(v) for v in _y0(s.y0)],
        "continuation": "rows swept in increasing nu"
        + (
            ", then back in decreasing nu from the state the first sweep ended in"
            if int(s.sweeps) == 2
            else ""
        ),
    }
    t_start = time.perf_counter()
    grids, cpu, workers = _run_rows(
        system, recorded, nu, B, workers=s.workers, executor=executor, progress=progress
    )
    return Chart(
        system=system,
        nu=nu,
        B=B,
        seconds=time.perf_counter() - t_start,
        workers=workers,
        settings=recorded,
        cpu_seconds=cpu,
        **grids,
    )
