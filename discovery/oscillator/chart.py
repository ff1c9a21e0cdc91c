"""Regime charts over the forcing plane ``(nu, B)``, in parallel processes.

Each row of the chart (one ``B``) is swept in increasing ``nu``, every point starting
from the last state of the previous one (continuation, as an analog-computer sweep:
the chart follows one branch where attractors coexist; the first point of a row starts
from ``y0``).  Each point: ``transient`` periods, then ``periods`` periods with the
variational equations; the regime by :func:`~discovery.oscillator.classify_points`
(``P1`` synchronised, ``Pn`` subharmonic, ``beat`` quasi-periodic, ``chaotic``).
Rows are distributed over worker processes (they die with the parent; Ctrl-C stops
them); the result does not depend on the number of workers.
"""

import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from multiprocessing import get_context

import numpy as np

from .._workers import terminate_pool, worker_initializer
from ..dynamics import Tolerances
from ..errors import InputError, IntegrationError
from .attractor import _after, _setup, _variational, _y0, classify_points, lyapunov
from .system import UedaSystem

__all__ = ["Chart", "chart", "KINDS"]

KINDS = ("P1", "Pn", "beat", "chaotic")  # codes 0..3; -1 failed


@dataclass(frozen=True)
class Chart:
    """A regime chart.

    Attributes
    ----------
    system : UedaSystem
        The template (its ``nu`` and ``B`` are replaced by the axes).
    nu, B : ndarray
        The axes.
    kind : ndarray of int, shape (len(B), len(nu))
        Index into :data:`KINDS` (``-1``: the integration failed).
    period : ndarray of int
        ``n`` of periodic points, else 0.
    lyapunov : ndarray
        Largest exponent at each point (short run: ``periods`` periods).
    rotation : ndarray
        Rotation number of the strobe points (beat and chaos; NaN for periodic points).
    seconds : float
    workers : int
    settings : dict
    """

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

    def fractions(self):
        n = self.kind.size
        out = {k: float(np.sum(self.kind == i) / n) for i, k in enumerate(KINDS)}
        out["failed"] = float(np.sum(self.kind < 0) / n)
        return out

    def rows(self):
        """CSV rows ``nu, B, regime, period, lyapunov, rotation``."""
        for i, b in enumerate(self.B):
            for j, nu in enumerate(self.nu):
                k = int(self.kind[i, j])
                yield (float(nu), float(b), KINDS[k] if k >= 0 else "failed",
                       int(self.period[i, j]), float(self.lyapunov[i, j]),
                       float(self.rotation[i, j]))

    def as_dict(self):
        return {"system": self.system.as_dict(), "grid": [int(self.nu.size), int(self.B.size)],
                "nu_range": [float(self.nu[0]), float(self.nu[-1])],
                "B_range": [float(self.B[0]), float(self.B[-1])],
                "fractions": self.fractions(), "seconds": self.seconds,
                "workers": self.workers, "points": int(self.kind.size),
                "seconds_per_point_per_worker": self.seconds * self.workers / self.kind.size,
                "settings": self.settings}


_CTX = {}


def _init(system, settings):
    _CTX.update(system=system, settings=settings)


def _point(system, y, s, tol):
    T = system.period
    y = _after(system, y, s["transient"], tol)
    _, _, atol, hmax = _setup(system, tol)
    logs, trace, strobe, yf = _variational(system, y, 0.0, s["periods"], tol, T, atol, hmax)
    lyap = lyapunov(system, tolerances=tol, batches=4, _run=(logs, trace))
    reg = classify_points(strobe, system.scales(), lyap.value, 0.0,
                          max_period=s["max_period"], closure=s["closure"],
                          chaos_threshold=s["chaos_threshold"])
    return reg, lyap.value, yf


def _row(args):
    i, b, nus = args
    base, s = _CTX["system"], _CTX["settings"]
    tol = Tolerances(rtol=s["rtol"], hmax_fraction=s["hmax_fraction"])
    y = np.array(s["y0"], dtype=float)
    out = []
    for nu in nus:
        system = base.with_params(nu=float(nu), B=float(b))
        try:
            reg, lam, y = _point(system, y, s, tol)
        except IntegrationError:
            out.append((-1, 0, np.nan, np.nan))
            y = np.array(s["y0"], dtype=float)
            continue
        out.append((KINDS.index(reg.kind), reg.period, lam,
                    reg.evidence.get("rotation_number", np.nan)))
    return i, out


def _axis(values, name):
    a = np.asarray(values, dtype=float).reshape(-1)
    if a.size < 1 or not np.all(np.isfinite(a)) or np.any(np.diff(a) <= 0):
        raise InputError(f"the {name} axis must be finite and strictly increasing")
    return a


def chart(system, nu, B, *, y0=None, transient=60, periods=80, rtol=1e-6, hmax_fraction=0.1,
          max_period=8, closure=1e-4, chaos_threshold=0.015, workers=None, progress=None):
    """The regime at every ``(nu, B)`` of a grid (see the module docstring).

    Parameters
    ----------
    system : UedaSystem
        Template: model and the other parameters.
    nu, B : array_like
        Strictly increasing axes (``nu > 0``).
    y0 : (x, v), optional
        Start of every row.
    transient, periods : int
        Periods discarded, then observed, at each point.
    rtol, hmax_fraction : float
        Integrator tolerance and largest step (fraction of a period); charts favour
        speed (``attractor`` uses 1e-9 and 0.02).
    max_period, closure, chaos_threshold
        The classification rules (:func:`classify_points`).
    workers : int, optional
        Processes (default all cores, at most one per row).
    progress : callable, optional
        ``progress(done_rows, total_rows)`` after each row.

    Returns
    -------
    Chart
    """
    if not isinstance(system, UedaSystem):
        raise TypeError("system must be a discovery.oscillator.UedaSystem")
    nu, B = _axis(nu, "nu"), _axis(B, "B")
    if nu[0] <= 0:
        raise InputError("nu must be > 0")
    if workers is not None and int(workers) < 1:
        raise InputError(f"workers must be at least 1, got {workers!r}")
    settings = {"transient": int(transient), "periods": int(periods), "rtol": float(rtol),
                "hmax_fraction": float(hmax_fraction),
                "max_period": int(max_period), "closure": float(closure),
                "chaos_threshold": float(chaos_threshold),
                "y0": [float(v) for v in _y0(y0)], "continuation": "rows swept in increasing nu"}
    workers = min(int(workers or os.cpu_count() or 1), B.size)
    shape = (B.size, nu.size)
    kind = np.full(shape, -1, dtype=int)
    period = np.zeros(shape, dtype=int)
    lam = np.full(shape, np.nan)
    rot = np.full(shape, np.nan)
    jobs = [(i, b, nu) for i, b in enumerate(B)]
    t_start = time.perf_counter()
    if workers == 1:
        _init(system, settings)
        results, pool = map(_row, jobs), None
    else:
        pool = ProcessPoolExecutor(workers, mp_context=get_context("fork"),
                                   **worker_initializer(_init, (system, settings)))
        results = pool.map(_row, jobs)
    try:
        for done, (i, row) in enumerate(results, start=1):
            for j, (k, n, lv, r) in enumerate(row):
                kind[i, j], period[i, j], lam[i, j], rot[i, j] = k, n, lv, r
            if progress is not None:
                progress(done, len(jobs))
    except BaseException:
        if pool is not None:
            terminate_pool(pool)
            pool = None
        raise
    finally:
        if pool is not None:
            pool.shutdown()
    return Chart(system=system, nu=nu, B=B, kind=kind, period=period, lyapunov=lam,
                 rotation=rot, seconds=time.perf_counter() - t_start, workers=workers,
                 settings=settings)
