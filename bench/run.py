"""Benchmarks (``make bench``): ratios against baselines measured in the same run.

Writes ``bench/results.json``.  Figures:

0. start-up: ``vidi --help`` and ``import discovery`` against a bare Python start
   (goal: help <= 0.3 s); the first command after ``make install`` and the same with an
   empty numba cache (the compile ``make install`` does once);
1. one steady-state force history: compiled kernel vs the scipy reference path at
   equal accuracy (goal >= 1000x faster);
2. the 41x41 landscape wall time with continuation and with the cold search at every
   point (goal <= 4 s on 2 cores, <= 0.3 steady-state equivalents per point);
3. simulations each identification method needs from the same start to reach
   0.1 % of the true alphas (goal: a method needing >= 10x fewer than coordinate
   descent);
4. discovery (``bench/discovery_bench.py``): certified fit of a 10-term library on
   10^4 samples (goal <= 1 s), and pysindy's ConstrainedSR3 side by side;
5. the public pipeline (``bench/discovery_bench.py``): ``verify`` on a 20-period record
   and ``discover(..., library="poly:2" / "poly:3", refine=True)`` on a run-up record,
   as ratios to one steady state measured in the same run;
6. ``explain`` on a 20-period record with the full catalogue (``bench/explain_bench.py``);
7. exact sensitivities against the finite differences they replace, same run
   (``bench/sensitivity_bench.py``): a steady state, identify on a force-only record and
   on a record compared over its span, a run with sensitivities over a plain one;
8. Ueda's oscillator (``bench/ueda_bench.py``): one chart point against scipy, a chart's
   wall time (and the 200x200 extrapolation), the duffing exponent per period against scipy.
9. how parallel work scales (``bench/scaling_bench.py``): a 24-run study and ``explain`` on
   1, 2 and every core, with the study's parallel efficiency.
10. old against new (``bench/paired_bench.py``): ``verify``, ``fit``, ``explain``, the
    five named contact models, the README quickstart's and the demo's ``fit`` and
    ``explain`` on the corpus records c02, c06 and c12 run with a checkout of the baseline
    commit and with this one,
    alternately, the median of the pairs' ratios, beside the work each command counted
    (``summary.json``'s ``counts``).  The shipped paper study (120 runs, 8 minutes a pair
    on two cores) is paired on its own: ``python run.py paper-study`` (``make
    bench-study``), with its tables compared cell by cell; so is the corpus (every record
    verified with its true law, fitted and explained, 12 minutes): ``python run.py corpus``
    (``make bench-corpus``), what each side found compared with the other's and the truth.

Each run is also saved for the documentation's tables (``make tables``): appended as a row to
``docs/_measured/bench-history.jsonl`` (``tests/bench_history.py``; ``python run.py kernel``
appends its kernel-only run too) and its scaling section written to
``docs/_measured/scaling-bench.jsonl`` (``tests/bench_scaling.py``).
"""

import json
import os
import sys
import time
from pathlib import Path

import numpy as np

from discovery._files._io import provenance, to_jsonable
from discovery.vibroimpact.dynamics import Tolerances, simulate
from discovery.vibroimpact.dynamics.reference import reference_simulate
from discovery.vibroimpact.dynamics.steady_states import steady_state
from discovery.vibroimpact.dynamics.synthetic import synthesize
from discovery.vibroimpact.fit.identification import METHODS, identify
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import load_scenario
from discovery.vibroimpact.verify.criteria_landscape import landscape

ROOT = Path(__file__).resolve().parent.parent
MEASURED = ROOT / "docs" / "_measured"
_PROVENANCE = ("versions", "git", "platform", "created", "settings")


def _saved_runs():
    """``tests.bench_history`` and ``tests.bench_scaling``: they keep the runs the
    documentation's tables are rendered from."""
    if str(ROOT) not in sys.path:
        sys.path.insert(0, str(ROOT))
    from tests import bench_history, bench_scaling

    return bench_history, bench_scaling


def save_history(results):
    """Append the runs of ``results`` (a results file's dict) to the bench history."""
    history, _ = _saved_runs()
    for run in history.append(json.loads(json.dumps(to_jsonable(results)))):
        print(f"added the run at {history.label(run)} to {history.PATH.relative_to(ROOT)}")


def save_scaling(scaling, prov, path, command, append=False):
    """Write the scaling section ``scaling`` with the run's provenance ``prov`` as a row of
    the run file ``path`` (``docs/_measured/scaling*.jsonl``: the scaling table's rows)."""
    _, bench_scaling = _saved_runs()
    row = json.loads(json.dumps(to_jsonable({**scaling, **prov})))
    bench_scaling.write_run(path, row, command, append=append)
    print(f"wrote {path}")


def _best(f, repeat=5):
    ts = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        ts.append(time.perf_counter() - t0)
    return min(ts), out


def _periods_integrated(sc, law, tol):
    """One cold steady state and the drive periods its period map integrated (each run's
    span: the transient, the strobe points, Newton's runs and the orbit's onset count)."""
    from discovery.vibroimpact.dynamics import steady_states as S

    maps = []
    init = S.StroboscopicMap.__init__

    def keeping(self, *a, **k):
        init(self, *a, **k)
        maps.append(self)

    S.StroboscopicMap.__init__ = keeping
    try:
        ss = steady_state(sc, sc.law, tolerances=tol)
    finally:
        S.StroboscopicMap.__init__ = init
    return ss, sum(m.n_periods for m in maps)


def bench_kernel(sc):
    """One steady-state cycle with a dense force history, fast vs scipy, equal accuracy; the
    kernel with its free flights in closed form (the default) and stepped (the cross-check
    path), and one cold steady state on each path against the scipy path's time for the
    periods it integrates, all in the same run."""
    ss = steady_state(sc, sc.law)
    T = sc.period
    te = np.linspace(ss.t0, ss.t0 + T, 2001)
    # accuracy of each path against a very tight reference
    truth = reference_simulate(sc, sc.law, (ss.t0, ss.t0 + T), y0=ss.y0, t_eval=te, rtol=1e-13)
    # same method (Dormand-Prince 5(4)) and tolerance on both paths
    ref_rtol, fast_rtol = 1e-9, 1e-9
    t_ref, ref = _best(
        lambda: reference_simulate(
            sc, sc.law, (ss.t0, ss.t0 + T), y0=ss.y0, t_eval=te, rtol=ref_rtol, method="RK45"
        ),
        repeat=10,
    )
    x = sc.scales()[0]
    err_ref = float(np.max(np.abs(ref["y"][[0, 2]] - truth["y"][[0, 2]])) / x)
    # a long run (40 periods, the size of a steady-state search): per-step cost dominates
    t40_ref, _ = _best(
        lambda: reference_simulate(
            sc, sc.law, (ss.t0, ss.t0 + 40 * T), y0=ss.y0, rtol=ref_rtol, method="RK45"
        ),
        repeat=4,
    )
    # the two free-flight paths timed in turns (best of each), so that a change of the
    # shared machine's load falls on both
    tols = {ff: Tolerances(rtol=fast_rtol, free_flight=ff) for ff in ("closed", "integrate")}
    best = {ff: {"one": np.inf, "forty": np.inf, "steady": np.inf} for ff in tols}
    out = {}
    for _ in range(15):
        for ff, tol in tols.items():
            t_one, fast = _best(
                lambda tol=tol: simulate(
                    sc, sc.law, (ss.t0, ss.t0 + T), y0=ss.y0, t_eval=te, tolerances=tol
                ),
                repeat=4,
            )
            t_forty, _ = _best(
                lambda tol=tol: simulate(
                    sc, sc.law, (ss.t0, ss.t0 + 40 * T), y0=ss.y0, tolerances=tol
                ),
                repeat=2,
            )
            t_ss, steady = _best(lambda tol=tol: _periods_integrated(sc, sc.law, tol), repeat=1)
            b = best[ff]
            b["one"], b["forty"], b["steady"] = (
                min(b["one"], t_one),
                min(b["forty"], t_forty),
                min(b["steady"], t_ss),
            )
            out[ff] = (fast, steady)
    paths = {}
    for ff, b in best.items():
        fast, (ss_ff, n_periods) = out[ff]
        paths[ff] = {
            "kernel_seconds": b["one"],
            "steps_one_period": int(fast.n_steps),
            "speedup": t_ref / b["one"],
            "long_run_40_periods_speedup": t40_ref / b["forty"],
            "kernel_max_error_rel": float(np.max(np.abs(fast.y[[0, 2]] - truth["y"][[0, 2]])) / x),
            "steady_state_seconds": b["steady"],
            "steady_state_periods_integrated": n_periods,
            # the scipy path's time for the periods the steady state integrated (40 periods'
            # time per period): what the steady state would cost on it
            "steady_state_speedup_over_scipy": n_periods * t40_ref / 40 / b["steady"],
            "steady_state_regime": ss_ff.regime,
        }
    c, i = paths["closed"], paths["integrate"]
    return {
        "long_run_40_periods_speedup": c["long_run_40_periods_speedup"],
        "scipy_seconds": t_ref,
        "scipy_40_periods_seconds": t40_ref,
        "kernel_seconds": c["kernel_seconds"],
        "speedup": c["speedup"],
        "linear_law_period_speedup": c["speedup"],
        "steady_state_speedup_over_scipy": c["steady_state_speedup_over_scipy"],
        "closed_form_flight_over_integrated_flight": {
            "one_period": i["kernel_seconds"] / c["kernel_seconds"],
            "40_periods": c["long_run_40_periods_speedup"] / i["long_run_40_periods_speedup"],
            "steady_state": i["steady_state_seconds"] / c["steady_state_seconds"],
        },
        "free_flight_paths": paths,
        "scipy_rtol": ref_rtol,
        "kernel_rtol": fast_rtol,
        "scipy_max_error_rel": err_ref,
        "kernel_max_error_rel": c["kernel_max_error_rel"],
        "scipy_method": "RK45 restarted at events",
        "equal_or_better_accuracy": c["kernel_max_error_rel"] <= 2 * err_ref,
        "goal": ">= 1000x (a steady state), >= 3000x (a linear-law period)",
    }


def _print_kernel(k):
    print(
        f"kernel vs scipy: {k['speedup']:.0f}x faster on one period (the paper's linear "
        f"law), {k['long_run_40_periods_speedup']:.0f}x on 40 periods (errors "
        f"{k['kernel_max_error_rel']:.1e} vs {k['scipy_max_error_rel']:.1e}); one cold "
        f"steady state {k['steady_state_speedup_over_scipy']:.0f}x"
    )
    for ff, d in k["free_flight_paths"].items():
        print(
            f"  free flight {ff}: one period {d['kernel_seconds'] * 1e6:.0f} us "
            f"({d['steps_one_period']} steps, {d['speedup']:.0f}x), 40 periods "
            f"{d['long_run_40_periods_speedup']:.0f}x, steady state "
            f"{d['steady_state_seconds'] * 1e3:.2f} ms over {d['steady_state_periods_integrated']}"
            f" periods ({d['steady_state_speedup_over_scipy']:.0f}x)"
        )


def bench_landscape(sc):
    """The 41x41 landscape with continuation (the default) and with the cold search at every
    point, in the same run, against one cold steady state."""
    a0, a1 = np.linspace(1.03e8, 3.09e8, 41), np.linspace(0.64e7, 1.92e7, 41)
    t_one, _ = _best(lambda: steady_state(sc, sc.law), repeat=5)
    land = landscape(sc, sc.law, a0, a1)
    cold = landscape(sc, sc.law, a0, a1, continuation=False)
    pts = 41 * 41
    return {
        "seconds": land.seconds,
        "workers": land.workers,
        "points": pts,
        "one_steady_state_seconds": t_one,
        "ratio_to_one_point": land.seconds / t_one,
        "steady_state_equivalents_per_point": land.seconds * land.workers / (pts * t_one),
        "cold_seconds": cold.seconds,
        "cold_steady_state_equivalents_per_point": cold.seconds * cold.workers / (pts * t_one),
        "continuation_speedup": cold.seconds / land.seconds,
        "same_regimes": bool(np.array_equal(land.regime, cold.regime)),
        "max_criterion_difference": float(
            max(np.nanmax(np.abs(land.values[n] - cold.values[n])) for n in land.values)
        ),
        "parallel_efficiency": pts * t_one / (cold.seconds * cold.workers),
        "goal": "<= 4 s on 2 cores; <= 0.3 steady-state equivalents per point",
    }


def bench_study():
    """A small study (the paper's law, 2 noise levels x 2 methods x 4 seeds, regression only:
    16 runs) serially, on the local process pool and on a Dask LocalCluster, each from
    scratch, in the same run: the executors' speed-ups and whether their tables agree."""
    import tempfile

    from discovery.vibroimpact.studies import study

    cfg = {
        "name": "bench",
        "seeds": 4,
        "factors": {
            "force_noise": [0.01, 0.05],
            "periods": [6],
            "library": ["z, zd, z^2, z*zd"],
            "selection": ["best-subset", "stlsq"],
            "refine": [False],
        },
    }
    out, tables = {}, {}
    runs = [("serial", {"workers": 1}), ("pool_2", {"workers": 2})]
    try:
        import distributed  # noqa: F401

        runs.append(("dask_local_2", {"scheduler": "local", "workers": 2}))
    except ImportError:
        pass
    with tempfile.TemporaryDirectory() as d:
        for name, kw in runs:
            t0 = time.perf_counter()
            res = study(cfg, Path(d) / name, figures=False, **kw)
            out[name + "_seconds"] = time.perf_counter() - t0
            tables[name] = [
                {k: v for k, v in row.items() if "seconds" not in k} for row in res.cells
            ]
    for name, _ in runs[1:]:
        out[name + "_speedup"] = out["serial_seconds"] / out[name + "_seconds"]
        out[name + "_same_table"] = tables[name] == tables["serial"]
    out["runs"] = 16
    out["note"] = "each executor's time includes its start-up (a LocalCluster takes seconds)"
    return out


def bench_start_up(repeat=5):
    """``vidi --help`` and ``import discovery`` against a bare interpreter start, measured
    in the same run (best of ``repeat``), as ratios and extra seconds."""
    import subprocess

    def best(argv):
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            subprocess.run(argv, capture_output=True, check=True)
            times.append(time.perf_counter() - t0)
        return min(times)

    py = sys.executable
    vidi = str(Path(py).with_name("vidi"))
    base = best([py, "-c", "pass"])
    help_ = best([vidi, "--help"])
    imp = best([py, "-c", "import discovery"])
    return {
        "python_start_seconds": base,
        "vidi_help_seconds": help_,
        "import_discovery_seconds": imp,
        "vidi_help_over_python_start": help_ / base,
        "vidi_help_extra_seconds": help_ - base,
        "goal": "vidi --help <= 0.3 s",
    }


def bench_cold_start():
    """The first command after ``make install`` (``vidi steady``, the kernels loaded from
    numba's cache) and the same command with an empty cache (it compiles the vibro-impact
    kernel first: what ``make install`` does once), as seconds and their ratio."""
    import subprocess
    import tempfile

    vidi = str(Path(sys.executable).with_name("vidi"))

    def run(env_extra):
        with tempfile.TemporaryDirectory() as d:
            env = {**os.environ, **env_extra(d)}
            t0 = time.perf_counter()
            subprocess.run(
                [vidi, "steady", "--scenario", "paper", "--out", str(Path(d) / "out")],
                capture_output=True,
                check=True,
                env=env,
            )
            return time.perf_counter() - t0

    warm = min(run(lambda d: {}) for _ in range(2))
    cold = run(lambda d: {"NUMBA_CACHE_DIR": str(Path(d) / "numba-cache")})
    return {
        "first_command_after_install_seconds": warm,
        "first_command_empty_cache_seconds": cold,
        "compile_seconds": cold - warm,
        "cold_over_warm": cold / warm,
        "goal": "first command after make install <= 30 s",
    }


def bench_identify(sc):
    meas = synthesize(sc, sc.law, periods=20, fs=20000)
    E = meas.impulse(sc.period)
    start = ForceLaw.parse("1.5e8*z + 0.9e7*zd")
    true = np.array(sc.law.coefficients)
    out = {}
    for m in METHODS:
        r = identify(sc, E, start, criterion="I2", method=m)
        hit = next(
            (
                it["n_simulations"]
                for it in r.iterations
                if np.all(np.abs(np.array(list(it["coefficients"].values())) / true - 1) < 1e-3)
            ),
            None,
        )
        out[m] = {
            "simulations_to_0.1%": hit,
            "total_simulations": r.n_simulations,
            "seconds": r.seconds,
            "final": r.coefficients,
        }
    cd = out["coordinate-descent"]["simulations_to_0.1%"]
    for m in METHODS:
        h = out[m]["simulations_to_0.1%"]
        out[m]["fewer_than_coordinate_descent"] = (cd / h) if (cd and h) else None
    out["goal"] = "a method needing >= 10x fewer simulations than coordinate descent"
    return out


def main_kernel():
    """``python run.py kernel``: the kernel's figures only, merged into the results file
    (its other figures and their provenance are left as they were)."""
    sc = load_scenario("paper")
    steady_state(sc, sc.law)  # compile / load the cached kernels first
    k = bench_kernel(sc)
    path = Path(__file__).with_name("results.json")
    results = json.loads(path.read_text()) if path.exists() else {}
    results["kernel_vs_scipy"] = k
    results["kernel_vs_scipy_provenance"] = provenance({"scenario": "paper"})
    path.write_text(json.dumps(to_jsonable(results), indent=2) + "\n")
    _print_kernel(k)
    save_history(results)
    return 0


def main_paper_study(argv):
    """``python run.py paper-study [--pairs N]``: the shipped paper study old against new
    (:func:`paired_bench.bench_paper_study`, about 8 minutes a pair on two cores), merged
    into the results file as a section of its own with its own provenance (a run of its own
    in the bench history, as ``kernel``'s)."""
    import argparse

    from paired_bench import bench_paper_study, print_study

    ap = argparse.ArgumentParser(prog="run.py paper-study")
    ap.add_argument("--pairs", type=int, default=3, help="pairs (default %(default)s)")
    a = ap.parse_args(argv)
    if a.pairs < 1:
        ap.error("--pairs must be at least 1")
    res = bench_paper_study(a.pairs)
    _save_section("paired_study", res, {"config": "examples/study_paper.toml"})
    print_study(res)
    return 0


def main_corpus(argv):
    """``python run.py corpus [--records c02 ...] [--commands explain ...]``: the corpus's
    records verified, fitted and explained old against new (:mod:`corpus_bench`, about 12
    minutes on two cores), what each side found compared with the other's and with the
    truth; a section of its own in the results file and a run of its own in the history."""
    from corpus_bench import bench_corpus, print_corpus
    from corpus_bench import main as parse

    a = parse(argv, parse_only=True)
    res = bench_corpus(a.records, a.commands)
    _save_section("paired_corpus", res, {"records": a.records, "commands": a.commands})
    print_corpus(res)
    return 0


def _save_section(name, section, settings):
    """``section`` merged into the results file as ``name`` with its own provenance (a
    partial run of the bench history), and the history appended."""
    path = Path(__file__).with_name("results.json")
    results = json.loads(path.read_text()) if path.exists() else {}
    results[name] = section
    results[f"{name}_provenance"] = provenance(settings)
    path.write_text(json.dumps(to_jsonable(results), indent=2) + "\n")
    save_history(results)


def main():
    from discovery_bench import bench_discovery, bench_pipeline
    from explain_bench import bench_explain
    from paired_bench import bench_paired, print_paired
    from scaling_bench import bench_scaling, print_scaling
    from sensitivity_bench import bench_sensitivities
    from ueda_bench import bench_ueda

    sc = load_scenario("paper")
    steady_state(sc, sc.law)  # compile / load the cached kernels first
    results = {
        "start_up": bench_start_up(),
        "cold_start": bench_cold_start(),
        "kernel_vs_scipy": bench_kernel(sc),
        "landscape_41x41": bench_landscape(sc),
        "identification": bench_identify(sc),
        "sensitivities": bench_sensitivities(),
        "study": bench_study(),
        "discovery": bench_discovery(),
        "pipeline": bench_pipeline(),
        "explain": bench_explain(),
        "ueda": bench_ueda(),
        "scaling": bench_scaling(),
        "paired": bench_paired(),
        "cores": os.cpu_count(),
        **provenance({"scenario": "paper"}),
    }
    text = json.dumps(to_jsonable(results), indent=2) + "\n"
    Path(__file__).with_name("results.json").write_text(text)
    c = results["cold_start"]
    print(
        f"first command after make install: {c['first_command_after_install_seconds']:.1f} s; "
        f"with an empty numba cache {c['first_command_empty_cache_seconds']:.1f} s (compiling "
        f"{c['compile_seconds']:.0f} s)"
    )
    k, L, idf = results["kernel_vs_scipy"], results["landscape_41x41"], results["identification"]
    s = results["start_up"]
    print(
        f"vidi --help: {s['vidi_help_seconds']:.2f} s ({s['vidi_help_over_python_start']:.1f}"
        f" x a bare python start of {s['python_start_seconds']:.3f} s); import discovery "
        f"{s['import_discovery_seconds']:.2f} s"
    )
    _print_kernel(k)
    print(
        f"landscape 41x41: {L['seconds']:.1f} s on {L['workers']} processes with "
        f"continuation ({L['steady_state_equivalents_per_point']:.2f} steady-state "
        f"equivalents per point), {L['cold_seconds']:.1f} s cold "
        f"({L['cold_steady_state_equivalents_per_point']:.2f}): "
        f"{L['continuation_speedup']:.1f}x; same regimes {L['same_regimes']}, criteria "
        f"within {L['max_criterion_difference']:.1e}"
    )
    st = results["study"]
    print(
        "study (16 runs): serial {:.1f} s; ".format(st["serial_seconds"])
        + "; ".join(
            f"{k[:-8]} {st[k]:.1f}x (same table {st[k[:-8] + '_same_table']})"
            for k in st
            if k.endswith("_speedup")
        )
    )
    for m in METHODS:
        fewer = idf[m]["fewer_than_coordinate_descent"]
        print(
            f"identify {m}: {idf[m]['simulations_to_0.1%']} simulations to 0.1 % "
            + (f"({fewer:.2g} x fewer than coordinate descent)" if fewer else "(not reached)")
        )
    se = results["sensitivities"]
    print(
        "exact sensitivities over finite differences: steady state {:.2f}x ({} vs {} runs), "
        "identify force-only {:.2f}x, over the span {:.2f}x; a run with 3 coefficients' "
        "sensitivities {:.1f}x a plain run".format(
            se["steady_state"]["speedup"],
            se["steady_state"]["exact_runs"],
            se["steady_state"]["differences_runs"],
            se["identify_force_only"]["speedup"],
            se["identify_span"]["speedup"],
            se["run_with_3_coefficient_sensitivities_over_plain"],
        )
    )
    d = results["discovery"]
    ours, ps_ = d["ours_max_terms_4"], d["pysindy_constrained_sr3_grid30"]
    print(
        f"discovery fit, {d['library']} on {d['samples']} samples: {ours['seconds']:.3f} s "
        f"certified (all sizes: {d['ours_max_terms_10']['seconds']:.3f} s); pysindy "
        f"ConstrainedSR3 {d['time_ratio_pysindy_over_ours']:.0f}x slower, exact zeros "
        f"{ps_['exact_zeros']} vs {ours['exact_zeros']}, support recovered "
        f"{ps_['support_recovered_1e-3_cutoff']} vs {ours['support_recovered']}"
    )
    p = results["pipeline"]
    v = p["verify_20_periods"]
    print(
        f"verify, 20-period record: {v['seconds']:.2f} s ({v['ratio_to_one_steady_state']:.0f}"
        f" x one steady state of {p['one_steady_state_seconds'] * 1e3:.1f} ms)"
    )
    c_, vc = p["calibrate_20_periods"], p["verify_calibrated_20_periods"]
    print(
        f"calibrate, the same record: {c_['seconds']:.3f} s ({c_['ratio_to_verify']:.2f} x "
        f"verify; m1 {c_['m1_error']:+.2%}); verify with the calibrated machine and its scale "
        f"searched: {vc['seconds']:.2f} s ({vc['ratio_to_verify']:.2f} x, consistent "
        f"{vc['consistent']})"
    )
    for lib in ("poly:2", "poly:3"):
        d_ = p[f"discover_{lib}"]
        if "error" in d_:
            print(f"discover {lib}: failed: {d_['error']}")
        else:
            par = (
                f"; {d_['parallel_speedup']:.2f}x faster on {d_['cores']} cores "
                f"(same ranking {d_['same_ranking_all_cores']})"
                if "parallel_speedup" in d_
                else ""
            )
            print(
                f"discover {lib}, refine: {d_['seconds']:.1f} s "
                f"({d_['ratio_to_one_steady_state']:.0f} x one steady state){par}"
            )
    e = results["explain"]
    print(
        f"explain, 20-period record, full catalogue: {e['seconds']:.1f} s "
        f"({e['ratio_to_one_steady_state']:.0f} x one steady state), named {e['named']}; "
        f"{e['parallel_speedup']:.2f}x faster than one process on {e['cores']} cores"
    )
    u = results["ueda"]
    print(
        f"ueda chart point: {u['chart_point']['speedup']:.0f}x faster than scipy; chart "
        f"{u['chart']['grid'][0]}x{u['chart']['grid'][1]} in {u['chart']['seconds']:.1f} s "
        f"(200x200 extrapolated {u['chart']['extrapolated_200x200_seconds']:.0f} s); duffing "
        f"exponent {u['lyapunov_duffing']['value']:.4f} +- {u['lyapunov_duffing']['stderr']:.4f}"
    )
    print_scaling(results["scaling"])
    print_paired(results["paired"])
    print("wrote bench/results.json")
    save_history(results)
    prov = {k: results[k] for k in _PROVENANCE}
    path = MEASURED / "scaling-bench.jsonl"
    save_scaling(results["scaling"], prov, path, "make bench (cd bench && python run.py)")
    return 0


def main_scaling(argv):
    """``python run.py scaling [--workers 1,2,16] [--paper-study] [--out FILE [--append]]``:
    the scaling section alone, written to FILE (default bench/scaling.json); a FILE ending
    in ``.jsonl`` is a run file of the scaling table's rows (``--out
    ../docs/_measured/scaling-NAME.jsonl``, then ``make tables``; ``--append`` adds the row
    to it instead of replacing it)."""
    import argparse

    from scaling_bench import bench_scaling, print_scaling, worker_counts

    ap = argparse.ArgumentParser(prog="run.py scaling")
    ap.add_argument("--workers", help="comma-separated worker counts (default 1, 2, all)")
    ap.add_argument("--study-workers", help="the study's worker counts (default: --workers)")
    ap.add_argument("--paper-study", action="store_true", help="also the 120-run paper study")
    ap.add_argument("--out", default=str(Path(__file__).with_name("scaling.json")))
    ap.add_argument("--append", action="store_true", help="add the row to a .jsonl --out")
    a = ap.parse_args(argv)
    if a.append and not a.out.endswith(".jsonl"):
        ap.error("--append needs a .jsonl --out (a run file of the scaling table's rows)")
    sc = load_scenario("paper")
    steady_state(sc, sc.law)  # compile / load the cached kernels first
    scaling = bench_scaling(
        worker_counts(a.workers),
        paper_study=a.paper_study,
        study_counts=worker_counts(a.study_workers) if a.study_workers else None,
    )
    prov = provenance({"scenario": "paper"})
    print_scaling(scaling)
    if a.out.endswith(".jsonl"):
        command = " ".join(["cd bench && python run.py scaling", *argv])
        save_scaling(scaling, prov, a.out, command, append=a.append)
        return 0
    Path(a.out).write_text(json.dumps(to_jsonable({**scaling, **prov}), indent=2) + "\n")
    print(f"wrote {a.out}")
    return 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["scaling"]:
        sys.exit(main_scaling(sys.argv[2:]))
    if sys.argv[1:2] == ["paper-study"]:
        sys.exit(main_paper_study(sys.argv[2:]))
    if sys.argv[1:2] == ["corpus"]:
        sys.exit(main_corpus(sys.argv[2:]))
    sys.exit(main_kernel() if sys.argv[1:] == ["kernel"] else main())
