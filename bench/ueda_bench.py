"""Benchmarks of Ueda's oscillators (issue 9): ratios against a scipy baseline measured
in the same run.

``bench_ueda(grid=60)`` returns a dict (JSON-ready):

* ``chart_point``: one full chart point (60 transient + 80 observed periods with the
  variational equations, rtol 1e-6: the work of a chaotic or quasi-periodic point, and of
  every point without the early exit) with the compiled kernels vs scipy ``solve_ivp``
  (RK45, same rtol, same step cap, restarted every period for the Gram-Schmidt step);
  ``speedup`` for the same work (goal >= 100x per point).  Also the chart's mean CPU
  time per point (early exit on) against the same scipy point: ``chart_speedup``;
* ``chart``: a ``grid x grid`` chart (negres, nu 0.8..1.2, B 0..0.6) on all cores: wall
  and CPU seconds, per point, the 200x200 time extrapolated from the wall time and from
  the CPU time (``/ cores``: the idle-machine estimate), the load average before and
  after (other work on the machine slows the wall time, not the CPU time);
* ``chart_without_early_exit``: the same chart by the old procedure (every point the full
  transient + variational run, periods <= 8), measured in the same run: the early exit's
  gain, and the share of points whose class changed;
* ``lyapunov_duffing``: 20000 periods at rtol 1e-9 (value, stderr, seconds) and the
  scipy time of 200 periods of the same computation, as a ratio per period.

``python bench/ueda_bench.py [GRID]`` prints the dict (``GRID 200``: the full chart).
"""

import os
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

from discovery.ueda import UedaSystem, lyapunov
from discovery.ueda.regime_chart import chart
from discovery.ueda.sweep import point
from discovery.vibroimpact.dynamics import Tolerances


def _best(f, repeat):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t0)
    return min(ts), out


def _scipy_point(system, y0, transient, periods, rtol, hmax_fraction):
    """The same work as one full chart point, by scipy (RK45)."""
    T = system.period
    atol = rtol * 1e-3 * system.scales()
    hmax = hmax_fraction * T
    y = (
        solve_ivp(
            system.rhs, (0, transient * T), y0, method="RK45", rtol=rtol, atol=atol, max_step=hmax
        ).y[:, -1]
        if transient
        else np.asarray(y0, dtype=float)
    )

    def f(t, z):
        J = system.jacobian(t, z[:2])
        return np.concatenate([system.rhs(t, z[:2]), J @ z[2:4], J @ z[4:6]])

    z = np.array([*y, 1.0, 0.0, 0.0, 1.0])
    at = np.concatenate([atol, np.full(4, rtol * 1e-3)])
    logs = np.zeros(2)
    for k in range(periods):
        z = solve_ivp(
            f, (k * T, (k + 1) * T), z, method="RK45", rtol=rtol, atol=at, max_step=hmax
        ).y[:, -1]
        q, r = np.linalg.qr(np.column_stack([z[2:4], z[4:6]]))
        logs += np.log(np.abs(np.diag(r)))
        q = q * np.sign(np.diag(r))
        z[2:4], z[4:6] = q[:, 0], q[:, 1]
    return logs / (periods * T)


def _load():
    return os.getloadavg()[0] if hasattr(os, "getloadavg") else None


def bench_ueda(grid=60):
    system = UedaSystem.from_model("negres")  # the broken egg: a chaotic (full) point
    s = {
        "transient": 60,
        "periods": 80,
        "max_period": 16,
        "closure": 1e-4,
        "chaos_threshold": 0.015,
        "early_exit": True,
        "min_pairs": 12,
    }
    tol = Tolerances(rtol=1e-6, hmax_fraction=0.1)
    y0 = np.array([0.1, 0.0])
    point(system, y0, s, tol)  # compile / load the cache
    t_fast, r = _best(lambda: point(system, y0, s, tol), 20)
    assert r.cost == 140, "the reference point must take the full path"
    t_scipy, _ = _best(lambda: _scipy_point(system, y0, 60, 80, 1e-6, 0.1), 2)
    nu, B = np.linspace(0.8, 1.2, grid), np.linspace(0.0, 0.6, grid)
    cores = os.cpu_count() or 1
    chart(system, nu[:2], B[:2], workers=1)
    runs = {}
    for name, kw in (("new", {}), ("old", {"early_exit": False, "max_period": 8})):
        before = _load()
        ch = chart(system, nu, B, **kw)
        runs[name] = (ch, before, _load())
    ch, before, after = runs["new"]
    old, ob, oa = runs["old"]
    n = grid * grid
    per_point, cpu_point = ch.seconds / n, ch.cpu_seconds / n
    same = np.mean(
        (np.where(ch.period > 8, 2, ch.kind) == old.kind)
        & (np.where(ch.period > 8, 0, ch.period) == old.period)
    )
    duff = UedaSystem.from_model("duffing")
    lyapunov(duff, periods=10)
    t_lyap, L = _best(lambda: lyapunov(duff, periods=20000, batches=40), 1)
    t_lyap_scipy, _ = _best(lambda: _scipy_point(duff, np.array([0.1, 0.0]), 0, 200, 1e-9, 0.02), 1)
    return {
        "chart_point": {
            "kernel_seconds": t_fast,
            "scipy_seconds": t_scipy,
            "speedup": t_scipy / t_fast,
            "goal": ">= 100x per point",
            "work": "60 transient + 80 variational periods, rtol 1e-6 (a chaotic "
            "point: the full path)",
            "chart_cpu_seconds_per_point": cpu_point,
            "chart_speedup": t_scipy / cpu_point,
            "chart_speedup_note": "the chart's mean CPU time per point (early "
            "exit at periodic points) vs scipy's full "
            "point",
        },
        "chart": {
            "grid": [grid, grid],
            "seconds": ch.seconds,
            "cpu_seconds": ch.cpu_seconds,
            "workers": ch.workers,
            "seconds_per_point": per_point,
            "cpu_seconds_per_point": cpu_point,
            "mean_periods_integrated": float(ch.periods_integrated.mean()),
            "extrapolated_200x200_seconds": per_point * 40000,
            "extrapolated_200x200_seconds_idle_cores": cpu_point * 40000 / min(cores, 200),
            "cores": cores,
            "load_average_before": before,
            "load_average_after": after,
            "max_period": ch.settings["max_period"],
            "goal": "200x200 <= 60 s on 2 cores",
        },
        "chart_without_early_exit": {
            "seconds": old.seconds,
            "cpu_seconds": old.cpu_seconds,
            "cpu_seconds_per_point": old.cpu_seconds / n,
            "mean_periods_integrated": float(old.periods_integrated.mean()),
            "load_average_before": ob,
            "load_average_after": oa,
            "cpu_ratio_old_over_new": old.cpu_seconds / ch.cpu_seconds,
            "same_class_fraction": float(same),
            "note": "max_period 8, no early exit (the earlier charts); classes compared "
            "with periods > 8 of the new chart counted as beat",
        },
        "lyapunov_duffing": {
            "value": L.value,
            "stderr": L.stderr,
            "periods": 20000,
            "seconds": t_lyap,
            "scipy_seconds_200_periods": t_lyap_scipy,
            "speedup_per_period": (t_lyap_scipy / 200) / (t_lyap / 20000),
        },
    }


if __name__ == "__main__":
    import json

    print(json.dumps(bench_ueda(int(sys.argv[1]) if len(sys.argv) > 1 else 60), indent=2))
