"""One study run: make the records (scipy path, from rest), discover, score against the truth.

:func:`run_one` is a pure function of the run's description (seeds included), so a run
executed twice (a worker lost mid-task) gives the same numbers.  What it measures:

* ``exact``: the selected support is the true one; ``tp``/``fp``/``fn``: true terms
  selected, false terms selected, true terms missed; ``truth_in_library``;
* ``truth_equivalent``: the true support is the selected one or among the models the
  records cannot tell from it (``DiscoveryResult.equivalent``);
* ``coef_error``: the normalised coefficient error in force units,
  ``||(c - c*) s|| / ||c* s||`` over the union of the true and selected terms, where ``s``
  is each term's RMS over the record's contact samples (so a coefficient of ``z*zd`` and
  one of ``z`` weigh by the force they make, not by their units);
* ``coverage``: for an exact support, whether each true coefficient lies in its 95 %
  interval (the bootstrap interval when the fit made one, else ``c +- 1.96 SE`` of the
  output-error Jacobian; none without refinement);
* the selected model's verified criteria, noise floors, consistency and verdict (every
  selected model is checked by full simulation), simulations spent and wall time.

With ``library = "contact-models"`` the fit is
:func:`~discovery.vibroimpact.fit.contact_fit.fit_contact_models` and the same measures are
the named model's (:func:`score_contact`): ``exact`` the true model's name selected,
``truth_equivalent`` selected or among the models the record cannot tell from it,
``coef_error`` the RMS relative error of the true model's parameters, ``coverage`` whether
each lies in its 95 % interval; a polynomial truth is never in that library.

A run whose record or fit fails is recorded with ``status = "failed"`` and its one-line
reason; it counts as not recovered.
"""

from __future__ import annotations

import time

import numpy as np

from ...errors import VidiError
from ..model.contact_models import is_model_text, parse_law, parse_model
from ..model.contact_registry import CONTACT_MODELS
from ..model.scenario import Scenario
from .records import auto_transient, field_record

__all__ = ["run_one", "score", "score_contact"]

Z95 = 1.959963984540054


def _scenario(d):
    d = dict(d)
    if d.get("initial") is not None:
        d["initial"] = tuple(d["initial"])
    return Scenario(**d)


def _records(spec, law):
    scenarios = [_scenario(d) for d in spec["scenarios"]]
    rec = spec["record"]
    out = []
    for k, sc in enumerate(scenarios):
        tr = rec.get("transient", "auto")
        transient = auto_transient(sc, law) if tr == "auto" else int(tr)
        seed = int(np.random.SeedSequence([spec["seed"], k]).generate_state(1)[0])
        out.append(
            field_record(
                sc,
                law,
                periods=spec["periods"],
                fs=spec["fs"],
                transient=transient,
                force_noise=spec["force_noise"],
                motion_noise=spec["motion_noise"],
                seed=seed,
                velocities=rec.get("velocities", True),
            )
        )
    return scenarios, out


def _term_scales(result, names):
    """RMS of each term over the contact samples (force per unit coefficient)."""
    s = result.samples
    z, zd = np.maximum(s.zeta, 0.0), np.maximum(s.dzeta, 0.0)
    from ..model.law import Term

    return {n: float(np.sqrt(np.mean(Term.parse(n)(z, zd) ** 2))) for n in names}


def score(result, truth):
    """The run's measures (see the module docstring) of a ``DiscoveryResult`` against the
    true law."""
    sel = result.selected
    true_c, got_c = truth.as_dict(), sel.law.as_dict()
    T, S = set(true_c), set(got_c)
    lib = set(result.estimator.library_.names) if hasattr(result.estimator, "library_") else S
    union = sorted(T | S)
    scale = _term_scales(result, union)
    diff = np.array([(got_c.get(n, 0.0) - true_c.get(n, 0.0)) * scale[n] for n in union])
    ref = np.array([true_c.get(n, 0.0) * scale[n] for n in union])
    coef_error = float(np.linalg.norm(diff) / np.linalg.norm(ref)) if np.any(ref) else None
    exact = S == T
    equivalent = exact or any(set(e.get("terms", ())) == T for e in result.equivalent)
    coverage = {}
    if exact:
        se = sel.standard_errors
        iv = sel.intervals.bounds if sel.intervals is not None else {}
        for n in sorted(T):
            if n in iv:
                lo, hi = iv[n]
            elif n in se and np.isfinite(se[n]):
                lo, hi = got_c[n] - Z95 * se[n], got_c[n] + Z95 * se[n]
            else:
                continue
            coverage[n] = bool(lo <= true_c[n] <= hi)
    refine_sims = sum(
        m.refinement.n_simulations for m in result.ranking if m.refinement is not None
    )
    checks = sum(len(m.evaluations) for m in result.ranking)
    return {
        "selected": sorted(S),
        "coefficients": got_c,
        "exact": exact,
        "tp": len(S & T),
        "fp": len(S - T),
        "fn": len(T - S),
        "truth_in_library": T <= lib,
        "truth_equivalent": bool(equivalent),
        "coef_error": coef_error,
        "coverage": coverage,
        "interval_method": (
            "bootstrap"
            if sel.intervals is not None
            else "jacobian"
            if sel.standard_errors
            else None
        ),
        "criteria": sel.criteria,
        "noise_floor": sel.noise_floor,
        "consistent": bool(sel.consistent),
        "verdict": sel.verdict,
        "regime": sel.regime,
        "simulations": int(refine_sims + checks),
        "warnings": len(result.warnings),
    }


def score_contact(result, truth_text):
    """The run's measures (the module docstring) of a ``ContactModelsResult`` against the
    true law's text (a named model's, or a polynomial law's)."""
    name = parse_model(truth_text).name if is_model_text(truth_text) else None
    sel = result.selected
    selected = [sel] if sel else []
    exact = name is not None and sel == name
    coverage, coef_error = {}, None
    if name is not None:
        truth, fit = parse_model(truth_text).params, result.fit(name)
        keys = [k for k in CONTACT_MODELS[name].parameters if k in fit.parameters]
        rel = [(fit.parameters[k] - truth[k]) / truth[k] for k in keys if truth[k]]
        coef_error = float(np.sqrt(np.mean(np.square(rel)))) if rel else None
        if exact:
            for k in keys:
                lo, hi = fit.intervals.get(k, (np.nan, np.nan))
                if np.isfinite(lo) and np.isfinite(hi):
                    coverage[k] = bool(lo <= truth[k] <= hi)
    best = result.fit(sel) if sel else (result.fits[0] if result.fits else None)
    return {
        "selected": selected,
        "coefficients": dict(best.parameters) if best else {},
        "exact": bool(exact),
        "tp": int(exact),
        "fp": int(bool(sel) and not exact),
        "fn": int(name is not None and not exact),
        "truth_in_library": name is not None,
        "truth_equivalent": bool(exact or (name is not None and name in result.equivalent)),
        "coef_error": coef_error,
        "coverage": coverage,
        "interval_method": result.settings.get("interval_method"),
        "criteria": dict(best.criteria) if best else {},
        "noise_floor": None,
        "consistent": bool(sel),
        "verdict": result.conclusion,
        "regime": "",
        "simulations": int(sum(f.n_simulations for f in result.fits)),
        "warnings": 0,
    }


#: the sheet's error of each parameter, in units of the run's ``sheet_error``
SHEET_SPREAD = {"m1": 1.0, "m2": 1.0, "k1": 1.0, "c1": 3.0, "A": 1.0}


def _machine(spec, scenarios, records):
    """The machine the run's fit takes (the factors ``sheet_error`` and ``machine``), its
    scale's range (``None`` unless calibrated) and the measures of the sheet and the
    calibration against the machine that made the records."""
    error = float(spec.get("sheet_error", 0.0))
    rng = np.random.default_rng(np.random.SeedSequence([spec["seed"], 47]))
    draws = {p: rng.uniform(-1.0, 1.0) * error * f for p, f in SHEET_SPREAD.items()}
    sheets = [
        sc.replace(**{p: getattr(sc, p) * (1 + d) for p, d in draws.items()}) if error else sc
        for sc in scenarios
    ]
    out = {}
    if error:
        out["sheet"] = {p: getattr(sheets[0], p) / getattr(scenarios[0], p) - 1 for p in draws}
    if spec.get("machine", "sheet") != "record":
        return sheets, None, out
    from ..calibration import calibrate

    cal = calibrate(sheets, records, seed=spec["seed"])
    out["calibrated"] = {
        p: getattr(cal.scenarios[0], p) / getattr(scenarios[0], p) - 1 for p in draws
    }
    return list(cal.scenarios), cal.scale_range, out


def _fit(spec, scenarios, records):
    """The run's fit and its measures (``discover``, or the named contact models)."""
    from ..fit.discovery import discover

    scenarios, scale, machine = _machine(spec, scenarios, records)
    scs = scenarios if len(scenarios) > 1 else scenarios[0]
    recs = records if len(records) > 1 else records[0]
    if spec["library"] == "contact-models":
        from ..fit.contact_fit import fit_contact_models

        opts = {k: spec["fit"][k] for k in ("max_simulations",) if k in spec["fit"]}
        result = fit_contact_models(
            scs, recs, n_boot=spec["fit"].get("n_boot_intervals", 0), seed=spec["seed"], **opts
        )
        return {**score_contact(result, spec["law"]), **machine}
    result = discover(
        scs,
        recs,
        library=spec["library"],
        selection=spec["selection"],
        refine=spec["refine"],
        seed=spec["seed"],
        machine_scale=scale,
        **spec["fit"],
    )
    return {**score(result, parse_law(spec["law"])), **machine}


#: relative cost of a selection method per run (measured on the paper study: the
#: pysindy-based methods take about 3x a best-subset run)
_METHOD_COST = {"stlsq": 3.0, "sr3": 3.0, "constrained-sr3": 3.0}


def run_cost(spec):
    """A run's predicted cost, in arbitrary units, for scheduling the longest runs first:
    samples recorded (periods x sample rate, the record's own simulation and every
    refinement's scale with them), the library's terms, the selection method, and a
    refinement by simulation."""
    terms = max(1, len(str(spec.get("library", "")).split(",")))
    samples = float(spec.get("periods", 1)) * float(spec.get("fs", 1.0))
    method = _METHOD_COST.get(str(spec.get("selection")), 1.0)
    return samples * terms * method * (3.0 if spec.get("refine") else 1.0)


def run_one(context, spec):
    """Do one run (``context`` is unused: every run is self-contained).  Returns the run's
    description with its measures, ``status`` and ``seconds``."""
    t0 = time.perf_counter()
    out = dict(spec)
    truth = parse_law(spec["law"])
    try:
        scenarios, records = _records(spec, truth)
        out.update(_fit(spec, scenarios, records), status="ok", error="")
    except VidiError as exc:
        out.update(
            status="failed",
            error=f"{type(exc).__name__}: {exc}".splitlines()[0],
            exact=False,
            truth_equivalent=False,
        )
    out["seconds"] = time.perf_counter() - t0
    return out
