"""Exact sensitivities against finite differences, in the same run (``make bench``).

The same computations with the exact Jacobians (variational equations and saltation in the
compiled kernel) and with the finite differences they replace, one after the other:

* a steady state's Newton shooting and Floquet multipliers (the period map's state and
  Jacobian: one run with the variational equations, or a plain run and four more);
* identify by least squares on a force-only record (the residuals' Jacobian from the
  orbit's derivatives) and on a record compared over its span (from one run per block);
* the cost of one run with the coefficients' sensitivities as a multiple of a plain run.
"""

import importlib
import time

import numpy as np


def _clear_memos():
    """Every timed run starts without the simulations an earlier one cached."""
    for name in (
        "discovery.vibroimpact.verify.evaluation",
        "discovery.vibroimpact.verify.trajectory",
    ):
        importlib.import_module(name).MEMO.clear()


def _time(f, repeat=3):
    best, out = np.inf, None
    for _ in range(repeat):
        _clear_memos()
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _differences(self, y, n=1):
    """The period map's state and its Jacobian by forward differences (four more runs)."""
    fy = self.advance(y, n)
    return fy, self.fd_jacobian(y, n, fy)


def bench_sensitivities():
    from discovery import ForceLaw, load_scenario
    from discovery.vibroimpact.dynamics.simulation import simulate
    from discovery.vibroimpact.dynamics.steady_states import StroboscopicMap, steady_state
    from discovery.vibroimpact.dynamics.synthetic import synthesize
    from discovery.vibroimpact.verify import Reference

    ident = importlib.import_module("discovery.vibroimpact.fit.identification")
    sc = load_scenario("paper")
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd + 2e10*z*zd")
    out = {}

    # the period map's Jacobian
    exact = StroboscopicMap.jacobian, StroboscopicMap.advance_jacobian
    t_ex, ss_ex = _time(lambda: steady_state(sc, law))
    StroboscopicMap.jacobian = StroboscopicMap.fd_jacobian
    StroboscopicMap.advance_jacobian = _differences
    try:
        t_fd, ss_fd = _time(lambda: steady_state(sc, law))
    finally:
        StroboscopicMap.jacobian, StroboscopicMap.advance_jacobian = exact
    out["steady_state"] = {
        "exact_seconds": t_ex,
        "differences_seconds": t_fd,
        "speedup": t_fd / t_ex,
        "exact_runs": ss_ex.n_simulations,
        "differences_runs": ss_fd.n_simulations,
        "multipliers_difference": float(
            np.max(np.abs(np.sort(np.abs(ss_ex.multipliers)) - np.sort(np.abs(ss_fd.multipliers))))
        ),
    }

    # identify on a force-only record and on a record compared over its span
    start = ForceLaw.parse("1.8e8*z + 1.1e7*zd + 1.5e10*z*zd")
    rec = synthesize(sc, law, periods=20, fs=20000, noise=0.01, seed=3)
    records = {
        "force_only": rec.impulse(sc.period),
        "span": Reference.from_measurement(rec, sc, n_boot=8, seed=0),
    }
    exact_cols = ident._Objective._exact_columns
    for name, ref in records.items():
        row = {}
        for mode in ("exact", "differences"):
            if mode == "differences":
                ident._Objective._exact_columns = lambda self: (
                    [None] * len(self.start.coefficients),
                    False,
                )
            try:
                t, r = _time(lambda ref=ref: ident.identify(sc, ref, start, check=False), 2)
            finally:
                ident._Objective._exact_columns = exact_cols
            row[mode] = {
                "seconds": t,
                "runs": r.n_simulations,
                "law": r.law.to_text(),
                "I2": r.criteria["I2"],
            }
        row["speedup"] = row["differences"]["seconds"] / row["exact"]["seconds"]
        out[f"identify_{name}"] = row

    # one run with the coefficients' sensitivities against a plain run
    T = sc.period
    y0 = simulate(sc, law, (0, 10 * T)).y_final
    te = np.linspace(10 * T, 14 * T, 3200)
    t_plain, _ = _time(lambda: simulate(sc, law, (10 * T, 14 * T), y0=y0, t_eval=te), 20)
    t_sens, _ = _time(
        lambda: simulate(
            sc,
            law,
            (10 * T, 14 * T),
            y0=y0,
            t_eval=te,
            sensitivities="coefficients",
            control_sensitivities=False,
        ),
        20,
    )
    out["run_with_3_coefficient_sensitivities_over_plain"] = t_sens / t_plain
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(bench_sensitivities(), indent=2, default=str))
