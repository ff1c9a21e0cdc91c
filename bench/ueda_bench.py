"""Benchmarks of Ueda's oscillators (issue 9): ratios against a scipy baseline measured
in the same run.

``bench_ueda()`` returns a dict (JSON-ready):

* ``chart_point``: one chart point (60 transient + 80 observed periods with the
  variational equations, rtol 1e-6, as ``vidi ueda chart``) with the compiled kernels
  vs scipy ``solve_ivp`` (RK45, same rtol, same step cap, restarted every period for
  the Gram-Schmidt step); ``speedup`` per point (goal >= 100x);
* ``chart``: a ``grid x grid`` chart's wall time on all cores, with the per-point time
  and the 200x200 time extrapolated from it (goal <= 60 s on 2 cores), and the load
  average (other work on the machine slows it);
* ``lyapunov_duffing``: 20000 periods at rtol 1e-9 (value, stderr, seconds) and the
  scipy time of 200 periods of the same computation, as a ratio per period.
"""

import os
import time

import numpy as np
from scipy.integrate import solve_ivp

from discovery.dynamics import Tolerances
from discovery.oscillator import UedaSystem, lyapunov
from discovery.oscillator.chart import _point, chart


def _best(f, repeat):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t0)
    return min(ts), out


def _scipy_point(system, y0, transient, periods, rtol, hmax_fraction):
    """The same work as one chart point, by scipy (RK45)."""
    T = system.period
    atol = rtol * 1e-3 * system.scales()
    hmax = hmax_fraction * T
    y = solve_ivp(system.rhs, (0, transient * T), y0, method="RK45", rtol=rtol, atol=atol,
                  max_step=hmax).y[:, -1]

    def f(t, z):
        J = system.jacobian(t, z[:2])
        return np.concatenate([system.rhs(t, z[:2]), J @ z[2:4], J @ z[4:6]])

    z = np.array([*y, 1.0, 0.0, 0.0, 1.0])
    at = np.concatenate([atol, np.full(4, rtol * 1e-3)])
    logs = np.zeros(2)
    for k in range(periods):
        z = solve_ivp(f, (k * T, (k + 1) * T), z, method="RK45", rtol=rtol, atol=at,
                      max_step=hmax).y[:, -1]
        q, r = np.linalg.qr(np.column_stack([z[2:4], z[4:6]]))
        logs += np.log(np.abs(np.diag(r)))
        q = q * np.sign(np.diag(r))
        z[2:4], z[4:6] = q[:, 0], q[:, 1]
    return logs / (periods * T)


def bench_ueda(grid=60):
    system = UedaSystem.from_model("negres")
    s = {"transient": 60, "periods": 80, "max_period": 8, "closure": 1e-4,
         "chaos_threshold": 0.015}
    tol = Tolerances(rtol=1e-6, hmax_fraction=0.1)
    y0 = np.array([0.1, 0.0])
    _point(system, y0, s, tol)  # compile / load the cache
    t_fast, _ = _best(lambda: _point(system, y0, s, tol), 20)
    t_scipy, _ = _best(lambda: _scipy_point(system, y0, 60, 80, 1e-6, 0.1), 2)
    nu, B = np.linspace(0.8, 1.2, grid), np.linspace(0.0, 0.6, grid)
    load = os.getloadavg()[0] if hasattr(os, "getloadavg") else None
    ch = chart(system, nu, B)
    per_point = ch.seconds / (grid * grid)
    duff = UedaSystem.from_model("duffing")
    lyapunov(duff, periods=10)
    t_lyap, L = _best(lambda: lyapunov(duff, periods=20000, batches=40), 1)
    t_lyap_scipy, _ = _best(lambda: _scipy_point(duff, np.array([0.1, 0.0]), 0, 200, 1e-9,
                                                 0.02), 1)
    return {
        "chart_point": {"kernel_seconds": t_fast, "scipy_seconds": t_scipy,
                        "speedup": t_scipy / t_fast, "goal": ">= 100x per point",
                        "work": "60 transient + 80 variational periods, rtol 1e-6"},
        "chart": {"grid": [grid, grid], "seconds": ch.seconds, "workers": ch.workers,
                  "seconds_per_point": per_point,
                  "extrapolated_200x200_seconds": per_point * 40000,
                  "load_average_before": load, "goal": "200x200 <= 60 s on 2 cores"},
        "lyapunov_duffing": {"value": L.value, "stderr": L.stderr, "periods": 20000,
                             "seconds": t_lyap, "scipy_seconds_200_periods": t_lyap_scipy,
                             "speedup_per_period": (t_lyap_scipy / 200) / (t_lyap / 20000)},
    }


if __name__ == "__main__":
    import json

    print(json.dumps(bench_ueda(), indent=2))
