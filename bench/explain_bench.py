"""Benchmark of the missing-effect workflow: ``explain`` on a 20-period record with the full
catalogue, as a ratio to one steady state measured in the same run, and the speed-up of the
parallel screening refits over one process (same run)."""

import importlib.util
import os
import sys
import time
from pathlib import Path

import numpy as np


def _realistic():
    """tests/realistic.py, loaded by path (tests/ on sys.path would shadow the constraints
    package with tests/constraints)."""
    path = Path(__file__).resolve().parent.parent / "tests" / "realistic.py"
    spec = importlib.util.spec_from_file_location("realistic", path)
    mod = importlib.util.module_from_spec(spec)
    sys.modules["realistic"] = mod
    spec.loader.exec_module(mod)
    return mod


def bench_record():
    """``(scenario, record)``: the paper's machine and a 20-period scipy-path record of a law
    with a hidden coupling (what explain is timed on)."""
    from discovery import ForceLaw, load_scenario

    sc = load_scenario("paper")
    law = ForceLaw.parse("2.06e8*z + 0.9e7*zd + 2e10*z*zd")  # a hidden coupling
    rec = _realistic().reference_record((sc.with_law(law), law), periods=20, seed=0, check=False)
    return sc, rec


def bench_explain(repeat=2):
    from discovery.vibroimpact.dynamics.steady_states import steady_state
    from discovery.vibroimpact.explain import EFFECTS, explain

    sc, rec = bench_record()
    steady_state(sc, sc.law)  # compiled kernels loaded
    t_ss = min(_time(lambda: steady_state(sc, sc.law)) for _ in range(5))
    times, serial, res = [], [], None
    for _ in range(repeat):
        t0 = time.perf_counter()
        res = explain(sc, rec, "linear")
        times.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        explain(sc, rec, "linear", workers=1)
        serial.append(time.perf_counter() - t0)
    t, t1 = float(np.min(times)), float(np.min(serial))
    return {
        "seconds": t,
        "one_steady_state_seconds": t_ss,
        "ratio_to_one_steady_state": t / t_ss,
        "seconds_one_worker": t1,
        "parallel_speedup": t1 / t,
        "cores": os.cpu_count(),
        "catalogue": [e.id for e in EFFECTS],
        "named": [it.effect for it in res.iterations if it.effect],
        "simulations": res.settings["simulations"],
    }


def _time(f):
    t0 = time.perf_counter()
    f()
    return time.perf_counter() - t0


if __name__ == "__main__":
    print(bench_explain())
