"""Discovery benchmarks: certified fit time, pysindy's ConstrainedSR3 side by side, and
the wall time of ``verify`` and ``discover`` (:func:`bench_pipeline`).

Same data for both: 10^4 contact samples of a run-up record (paper scenario, law
(11) + 2e10 z zd, 1 % noise), a 10-term library (poly:3 + z^1.5).  ConstrainedSR3
gets the paper's conditions as inequalities at the points of a 30 x 30 grid of the
same box (its documented way); our estimator certifies them on the whole box.
Each fitted law is then checked on the dense 1001 x 1001 grid.
"""

import os
import time
import warnings

import numpy as np

from constraints import certify
from discovery import ForceLaw, load_scenario, synthesize
from discovery.vibroimpact.data.samples import contact_samples
from discovery.vibroimpact.fit.constrained_lsq import _Constraints, _Problem
from discovery.vibroimpact.fit.regression import ConstrainedSparseRegressor

TRUE = "2.06e8*z + 1.28e7*zd + 2e10*z*zd"
LIBRARY = "poly:3+z^1.5"


def _data(n=10_000, seed=1):
    sc = load_scenario("paper")
    m = synthesize(sc, ForceLaw.parse(TRUE), periods=300, noise=0.01, seed=seed, from_rest=True)
    cs = contact_samples(m)
    rows = np.sort(np.random.default_rng(seed).choice(len(cs), size=min(n, len(cs)), replace=False))
    return cs.X[rows], cs.F[rows], cs.impact[rows]


def _best(f, repeat=3):
    best, out = np.inf, None
    for _ in range(repeat):
        t0 = time.perf_counter()
        out = f()
        best = min(best, time.perf_counter() - t0)
    return best, out


def _pysindy_grid(est_template, X, y, grid=30, thr=0.05):
    import pysindy as ps

    est = est_template
    prob = _Problem(
        est.library_,
        _Constraints(box=est.box_, margin=0.0, monotone=False, signs=None, elevation=2),
        X,
        y,
        np.ones(y.size),
        solver="CLARABEL",
    )
    lib = est.library_
    Z, V = est.box_.zeta_max, est.box_.zd_max
    zz, vv = np.meshgrid(np.linspace(0, Z, grid), np.linspace(0, V, grid))
    pts = np.column_stack([zz.ravel(), vv.ravel()])
    P = lib.transform(pts) / prob.scale
    P0 = lib.transform(np.column_stack([pts[:, 0], np.zeros(len(pts))])) / prob.scale
    lhs = -np.vstack([P, P - P0])  # pysindy: lhs @ x <= rhs  <=>  P x >= 0, (P - P0) x >= 0
    rhs = np.zeros(lhs.shape[0])
    opt = ps.ConstrainedSR3(
        reg_weight_lam=thr,
        regularizer="L1",
        constraint_lhs=lhs,
        constraint_rhs=rhs,
        constraint_order="feature",
        inequality_constraints=True,
    )
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        opt.fit(prob.A, prob.b)
    x = np.asarray(opt.coef_).ravel()
    return x * prob.fscale / prob.scale


def bench_discovery():
    X, y, g = _data()
    true = ForceLaw.parse(TRUE).as_dict()
    out = {"samples": int(y.size), "library": LIBRARY}
    for max_terms in (4, 10):
        t, est = _best(
            lambda mt=max_terms: ConstrainedSparseRegressor(library=LIBRARY, max_terms=mt).fit(
                X, y, groups=g
            )
        )
        out[f"ours_max_terms_{max_terms}"] = {
            "seconds": t,
            "law": est.law_.to_text(),
            "holds": est.certificate_.holds,
            "worst_violation": est.certificate_.worst_violation,
            "exact_zeros": int(np.sum(est.coef_ == 0)),
            "n_terms": len(est.library_),
            "support_recovered": set(est.law_.names) == set(true),
            "cvxpy_solves": est.n_solves_,
        }
    est = ConstrainedSparseRegressor(library=LIBRARY).fit(X, y, groups=g)
    t_ps, c_ps = _best(lambda: _pysindy_grid(est, X, y), repeat=1)
    lib = est.library_
    cert = certify(c_ps, lib.exponents, est.box_)
    big = np.abs(c_ps) > 1e-3 * np.max(np.abs(c_ps * 1.0))
    names = {t.name for t, b in zip(lib.terms, big, strict=True) if b}
    out["pysindy_constrained_sr3_grid30"] = {
        "seconds": t_ps,
        "holds": cert.holds,
        "worst_violation": cert.worst_violation,
        "exact_zeros": int(np.sum(c_ps == 0)),
        "n_terms": len(lib),
        "support_recovered_exact_zeros": {
            t.name for t, c in zip(lib.terms, c_ps, strict=True) if c != 0
        }
        == set(true),
        "support_recovered_1e-3_cutoff": names == set(true),
        "coefficients": {t.name: float(c) for t, c in zip(lib.terms, c_ps, strict=True)},
    }
    out["time_ratio_pysindy_over_ours"] = t_ps / out["ours_max_terms_4"]["seconds"]
    out["goal"] = "certified fit of a 10-term library on 1e4 samples in <= 1 s"
    return out


def bench_pipeline(repeat=3):
    """Wall time of the public entry points, as ratios to one steady state of the same
    scenario and law measured in the same run (the unit of every simulation they make):

    * ``discovery.calibrate`` of that record, and ``verify`` with its machine and the
      search of the machine's scale (``machine_scale``), as ratios to the plain ``verify``;
    * ``discovery.vibroimpact.verify.verify`` on a 20-period steady record (paper scenario, law
      (11), 1 % force noise, positions and velocities; best of ``repeat``): one
      steady state from the measured state, the alignment, a 16-replicate noise floor
      and the check from the scenario's default start;
    * ``discovery.discover(scenario, record, library=..., refine=True)`` with
      ``poly:2`` and ``poly:3`` on a 100-period run-up from rest (law (11) + 2e10 z zd,
      1 % noise; one run each: regression, shortlist, refinement by simulation,
      verification of every shortlisted model); ``poly:2`` once more on every core (the
      refinements of each search step in parallel) for the speed-up and the same ranking.
    """
    from discovery import discover
    from discovery.vibroimpact.dynamics.steady_states import steady_state
    from discovery.vibroimpact.verify import verify

    sc = load_scenario("paper")
    steady_state(sc, sc.law)  # compiled kernels loaded
    t_one, _ = _best(lambda: steady_state(sc, sc.law), repeat=5)
    rec = synthesize(sc, sc.law, periods=20, fs=20000, noise=0.01, seed=1)
    t_ver, res = _best(lambda: verify(sc, rec, sc.law), repeat=repeat)
    from discovery import calibrate

    t_cal, cal = _best(lambda: calibrate(sc, rec), repeat=repeat)
    t_vcal, res_cal = _best(
        lambda: verify(cal.scenario, rec, sc.law, machine_scale=cal.scale_range), repeat=repeat
    )
    out = {
        "one_steady_state_seconds": t_one,
        "verify_20_periods": {
            "seconds": t_ver,
            "ratio_to_one_steady_state": t_ver / t_one,
            "consistent": res.consistent,
        },
        "calibrate_20_periods": {
            "seconds": t_cal,
            "ratio_to_verify": t_cal / t_ver,
            "m1_error": cal.scenario.m1 / sc.m1 - 1,
        },
        "verify_calibrated_20_periods": {
            "seconds": t_vcal,
            "ratio_to_verify": t_vcal / t_ver,
            "consistent": res_cal.consistent,
        },
    }
    law = ForceLaw.parse(TRUE)
    t_ss, _ = _best(lambda: steady_state(sc, law), repeat=5)
    run_up = synthesize(sc, law, periods=100, noise=0.01, seed=1, from_rest=True)
    out["discover_one_steady_state_seconds"] = t_ss
    for lib in ("poly:2", "poly:3"):
        t0 = time.perf_counter()
        try:
            r = discover(sc, run_up, library=lib, refine=True)
        except Exception as exc:  # noqa: BLE001 - a benchmark reports, it does not stop
            out[f"discover_{lib}"] = {"error": f"{type(exc).__name__}: {exc}"}
            continue
        t = time.perf_counter() - t0
        out[f"discover_{lib}"] = {
            "seconds": t,
            "ratio_to_one_steady_state": t / t_ss,
            "law": r.selected.law.to_text(),
            "consistent": getattr(r.selected, "consistent", None),
        }
        if lib == "poly:2" and "error" not in out[f"discover_{lib}"]:
            # the refinements of each search step on every core (the CLI's default)
            t0 = time.perf_counter()
            rp = discover(sc, run_up, library=lib, refine=True, workers=None)
            tp = time.perf_counter() - t0
            out[f"discover_{lib}"].update(
                seconds_all_cores=tp,
                parallel_speedup=t / tp,
                cores=os.cpu_count(),
                same_ranking_all_cores=[str(m.law) for m in rp.ranking]
                == [str(m.law) for m in r.ranking],
            )
    return out


if __name__ == "__main__":
    import json

    print(
        json.dumps(
            {"discovery": bench_discovery(), "pipeline": bench_pipeline()}, indent=2, default=str
        )
    )
