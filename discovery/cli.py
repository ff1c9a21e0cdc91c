"""``vidi``: a thin command line over the :mod:`discovery` API.

Every command writes ``summary.json`` (results, versions, settings) beside its
other outputs; outputs are staged and moved in only when the command succeeds.
Bad input gives one line on stderr and exit code 2.
"""

import argparse
import csv
import io
import json
import sys
import time
from pathlib import Path

import numpy as np

from ._io import OutputDir, atomic_write_text, provenance, to_jsonable
from .criteria import CRITERIA
from .errors import InputError, VidiError
from .law import ForceLaw
from .scenario import builtin_scenarios, load_scenario

__all__ = ["main"]


def _law(text, scenario, what="--law"):
    if text:
        return ForceLaw.parse(text)
    if scenario.law is None:
        raise InputError(f"scenario {scenario.name!r} has no reference law; pass {what}")
    return scenario.law


def _cmd_simulate(args):
    from .measurement import synthesize

    sc = load_scenario(args.scenario)
    law = _law(args.law, sc)
    out = Path(args.out)
    if out.suffix.lower() != ".csv":
        raise InputError(f"--out {args.out!r} must name a .csv file")
    t0 = time.perf_counter()
    meas = synthesize(sc, law, periods=args.periods, fs=args.fs, noise=args.noise,
                      seed=args.seed, from_rest=args.from_rest,
                      position_noise=args.position_noise, velocities=not args.no_velocities)
    summary = {"command": "simulate", "scenario": sc.as_dict(), "law": law.to_text(),
               "samples": int(meas.t.size), "seconds": time.perf_counter() - t0,
               **provenance(vars(args))}
    text = json.dumps(to_jsonable(summary), indent=2) + "\n"
    meas.to_csv(out)
    atomic_write_text(out.with_suffix(".summary.json"), text)
    print(f"wrote {out} ({meas.t.size} samples, {args.periods} periods at {args.fs:g} Hz, "
          f"noise {args.noise:g}) and {out.with_suffix('.summary.json')}")
    return 0


def _cmd_steady(args):
    from .response import response

    sc = load_scenario(args.scenario)
    law = _law(args.law, sc)
    r = response(sc, law)
    ss = r.steady
    info = ss.as_dict()
    if r.impulse is not None:
        info.update(peak_force=r.impulse.peak, contact_time=r.impulse.contact_time)
    print(f"{law}: {ss.regime}, {ss.impacts} impact(s) per orbit, "
          f"max |Floquet multiplier| {np.max(np.abs(ss.multipliers)):.4g}, "
          f"residual {ss.residual:.2g}")
    if r.impulse is not None:
        print(f"peak force {r.impulse.peak:.4g} N, contact time {r.impulse.contact_time:.4g} s")
    if args.out:
        with OutputDir(args.out) as out:
            out.write_json("summary.json", {"command": "steady", "law": law.to_text(),
                                            "scenario": sc.as_dict(), **info,
                                            **provenance(vars(args))})
        print(f"wrote {Path(args.out) / 'summary.json'}")
    return 0


def _grid_csv(land):
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow([land.terms[0], land.terms[1], "regime", *CRITERIA])
    for i, a in enumerate(land.axes[0]):
        for j, b in enumerate(land.axes[1]):
            w.writerow([f"{a:.10g}", f"{b:.10g}", land.regime[i, j],
                        *[f"{land.values[n][i, j]:.10g}" for n in CRITERIA]])
    return buf.getvalue()


def _cmd_landscape(args):
    from reports import landscape_figure

    from .landscape import landscape, parse_grid

    sc = load_scenario(args.scenario)
    law = _law(args.law, sc)
    n0, n1 = parse_grid(args.grid)
    r0 = _range(args.range0, (1.03e8, 3.09e8), "--range0")
    r1 = _range(args.range1, (0.64e7, 1.92e7), "--range1")
    a0, a1 = np.linspace(*r0, n0), np.linspace(*r1, n1)
    land = landscape(sc, law, a0, a1, workers=args.workers)
    with OutputDir(args.out) as out:
        summary = {"command": "landscape", "scenario": sc.as_dict(), "terms": land.terms,
                   "alpha1": a0, "alpha2": a1,
                   **{n: land.values[n] for n in CRITERIA},
                   "regime": land.regime.tolist(), "seconds": land.seconds,
                   "workers": land.workers,
                   "minima": {n: {"alpha1": a0[land.argmin(n)[0]], "alpha2": a1[land.argmin(n)[1]]}
                              for n in CRITERIA},
                   **provenance(vars(args))}
        out.write_json("summary.json", summary)
        out.path("landscape.csv").write_text(_grid_csv(land))
        truth = tuple(sc.law.coefficients[:2]) if sc.law is not None else None
        landscape_figure(land, str(out.path("landscape")), truth=truth)
    regimes = {r: int(np.sum(land.regime == r)) for r in set(land.regime.ravel())}
    print(f"landscape {n0}x{n1} in {land.seconds:.1f} s on {land.workers} processes; "
          f"regimes {regimes}")
    for n in CRITERIA:
        i, j = land.argmin(n)
        print(f"  {n}: minimum {np.nanmin(land.values[n]):.3g} at ({a0[i]:.4g}, {a1[j]:.4g})")
    print(f"outputs in {args.out}/: summary.json, landscape.csv, landscape.png, landscape.pdf")
    return 0


def _range(text, default, name):
    if text is None:
        return default
    try:
        lo, hi = (float(v) for v in text.split(":"))
    except ValueError:
        raise InputError(f"{name} {text!r} must look like LOW:HIGH, e.g. 1.03e8:3.09e8") from None
    if not (np.isfinite(lo) and np.isfinite(hi) and lo < hi):
        raise InputError(f"{name} needs LOW < HIGH, got {text!r}")
    return lo, hi


def _cmd_identify(args):
    from reports import identification_figure

    from .identify import identify
    from .landscape import Landscape
    from .measurement import Measurement
    from .response import response

    sc = load_scenario(args.scenario)
    meas = Measurement.from_csv(args.data, scenario=sc)
    for note in meas.notes:
        print(f"note: {note}")
    E = meas.impulse(sc.period)
    start = ForceLaw.parse(args.start)
    res = identify(sc, E, start, criterion=args.criterion, method=args.method,
                   max_simulations=args.max_simulations, xtol=args.xtol)
    land = None
    if args.landscape:
        land = _load_landscape(args.landscape, Landscape)
    picks = _pick_iterates(res.iterations, 5)
    imps = []
    for k in picks:
        law = start.with_coefficients(list(res.iterations[k]["coefficients"].values()))
        r = response(sc, law)
        imps.append((f"iterate {k} ({res.iterations[k]['n_simulations']} sims)",
                     r.like(E) if r.impulse is not None else None))
    with OutputDir(args.out) as out:
        summary = {"command": "identify", "scenario": sc.as_dict(), "data": str(args.data),
                   "measured": {"n_cycles": E.n_cycles, "n_periods": E.n_periods,
                                "noise": E.noise, "threshold": E.threshold,
                                "peak": E.peak, "contact_time": E.contact_time},
                   "criterion": res.criterion, "method": res.method,
                   "start": start.as_dict(), "coefficients": res.coefficients,
                   "law": res.law.to_text(), "latex": res.law.latex(),
                   "criteria": res.criteria, "n_simulations": res.n_simulations,
                   "iterations": res.iterations, "message": res.message,
                   "seconds": res.seconds, **provenance(vars(args))}
        out.write_json("summary.json", summary)
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["iterate", "n_simulations", res.criterion, *res.law.names])
        for k, it in enumerate(res.iterations):
            w.writerow([k, it["n_simulations"], f"{it['value']:.10g}",
                        *[f"{v:.10g}" for v in it["coefficients"].values()]])
        out.path("iterations.csv").write_text(buf.getvalue())
        identification_figure(res, E, imps, str(out.path("identification")), land)
    print(f"identified {res.law}")
    print(f"  {res.criterion} = {res.value:.4g} after {res.n_simulations} simulations "
          f"({res.method}, {res.seconds:.1f} s)")
    print("  criteria: " + ", ".join(f"{k} {v:.3g}" for k, v in res.criteria.items()))
    print(f"outputs in {args.out}/: summary.json, iterations.csv, identification.png, "
          "identification.pdf")
    return 0


def _cmd_fit(args):
    from reports import fit_impulse_figure, fit_loop_figure, fit_surface_figure, model_tex

    from .discover import discover
    from .measurement import Measurement
    from .response import response

    sc = load_scenario(args.scenario)
    meas = Measurement.from_csv(args.data, scenario=sc)
    for note in meas.notes:
        print(f"note: {note}")
    res = discover(sc, meas, library=args.library, selection=args.select, scoring=args.score,
                   max_terms=args.max_terms, criterion=args.criterion,
                   shortlist=args.shortlist, refine=args.refine, stability=args.stability,
                   derivative=args.derivative, average_cycles=args.average_cycles,
                   random_state=args.seed, margin=args.margin,
                   monotone=args.monotone)
    imps = []
    for k, m in enumerate(res.ranking[:3]):
        if m.criteria:
            imps.append((f"#{k + 1}: {', '.join(m.law.names)} "
                         f"({args.criterion} {m.criteria[args.criterion]:.3g})",
                         response(sc, m.law).like(res.measured)))
    cert = res.certificate
    summary = {
        "command": "fit", "scenario": sc.as_dict(), "data": str(args.data),
        "selected": res.selected.as_dict(),
        "ranking": [m.as_dict() for m in res.ranking],
        "certificate": {"method": cert.method, "holds": cert.holds,
                        "worst_violation": cert.worst_violation, "domain": cert.domain,
                        "conditions": cert.conditions},
        "stability": res.stability,
        "refinement": None if res.refinement is None else {
            "coefficients": res.refinement.coefficients, "criteria": res.refinement.criteria,
            "n_simulations": res.refinement.n_simulations},
        "samples": {"n": len(res.samples), "impacts": res.samples.n_impacts,
                    "derivative": res.samples.derivative, "noise": res.samples.noise},
        "measured": {"n_cycles": res.measured.n_cycles, "n_periods": res.measured.n_periods,
                     "noise": res.measured.noise, "threshold": res.measured.threshold},
        "n_solves": res.estimator.n_solves_, "seconds": res.seconds,
        "fit_settings": res.settings, **provenance(vars(args))}
    with OutputDir(args.out) as out:
        out.write_json("summary.json", summary)
        buf = io.StringIO()
        w = csv.writer(buf)
        w.writerow(["rank", "terms", "regime", "bic", "aic", "cv_error", *CRITERIA,
                    "coefficients"])
        for i, m in enumerate(res.ranking):
            w.writerow([i + 1, " + ".join(m.law.names), m.regime, f"{m.candidate.bic:.8g}",
                        f"{m.candidate.aic:.8g}", f"{m.candidate.cv_error:.6g}",
                        *[f"{m.criteria[n]:.6g}" if m.criteria else "" for n in CRITERIA],
                        m.law.to_text()])
        out.path("ranking.csv").write_text(buf.getvalue())
        out.path("model.tex").write_text(model_tex(res, sc))
        fit_impulse_figure(res, imps, str(out.path("fit_impulse")))
        fit_surface_figure(res, str(out.path("fit_surface")))
        fit_loop_figure(res, str(out.path("fit_loop")))
    sel = res.selected
    print(f"selected {sel.law}   [{sel.regime}]")
    if sel.criteria:
        print("  criteria (noise floor): " + ", ".join(
            f"{k} {v:.3g} ({sel.evaluation.noise_floor.get(k, float('nan')):.2g})"
            for k, v in sel.criteria.items()))
    print(f"  {sel.evaluation.verdict}")
    print(f"  certificate: {'holds' if cert.holds else 'FAILS'} on zeta <= "
          f"{cert.domain['zeta_max']:.3g} m, zd <= {cert.domain['zd_max']:.3g} m/s "
          f"(worst violation {cert.worst_violation:.2g})")
    print(f"  {len(res.ranking)} candidates ranked ({res.samples.n_impacts} impacts, "
          f"{len(res.samples)} contact samples, {res.seconds:.1f} s)")
    if res.stability:
        print("  stability: " + ", ".join(f"{k} {v:.2f}" for k, v in res.stability.items()
                                          if v > 0))
    print(f"outputs in {args.out}/: summary.json, ranking.csv, model.tex, fit_impulse.png/.pdf, "
          "fit_surface.png/.pdf, fit_loop.png/.pdf")
    return 0


def _cmd_verify(args):
    from reports import verify_figure

    from .measurement import Measurement
    from .verify import verify

    if args.law is not None and not args.law.strip():
        raise InputError("--law is empty; give a law such as '2.06e8*z + 1.28e7*zd' or leave "
                         "the option out to use the scenario's law")
    if args.n_boot < 1:
        raise InputError(f"--n-boot must be at least 1, got {args.n_boot}")
    sc = load_scenario(args.scenario)
    law = _law(args.law, sc)
    meas = Measurement.from_csv(args.data, scenario=sc)
    for note in meas.notes:
        print(f"note: {note}")
    res = verify(sc, meas, law, time_offset=args.time_offset, n_boot=args.n_boot,
                 seed=args.seed, check_default_start=not args.no_default_start)
    summary = {"command": "verify", "scenario": sc.as_dict(), "data": str(args.data),
               **res.as_dict(), "verify_settings": res.settings, **provenance(vars(args))}
    with OutputDir(args.out) as out:
        out.write_json("summary.json", summary)
        verify_figure(res, str(out.path("verify")))
    ev = res.evaluation
    print(f"{law}: {res.verdict}")
    print(f"  regime measured {ev.regime['measured']} ({ev.impacts['measured']} contact(s)), "
          f"simulated {ev.regime['simulated'] or ev.status} "
          f"({ev.impacts['simulated']} contact(s))")
    if ev.criteria:
        print("  criteria (noise floor): " + ", ".join(
            f"{k} {v:.3g} ({ev.noise_floor[k]:.2g})" for k, v in ev.criteria.items()))
    for note in res.notes:
        print(f"  note: {note}")
    print(f"outputs in {args.out}/: summary.json, verify.png, verify.pdf")
    return 0


def _pick_iterates(iterations, k):
    n = len(iterations)
    if n == 0:
        return []
    return sorted(set(np.unique(np.round(np.geomspace(1, n, k)).astype(int) - 1)))


def _load_landscape(path, cls):
    p = Path(path)
    p = p / "summary.json" if p.is_dir() else p
    try:
        d = json.loads(p.read_text())
    except (OSError, ValueError):
        raise InputError(f"--landscape {path!r}: no readable landscape summary.json") from None
    vals = {n: np.array(d[n], dtype=float) for n in CRITERIA}
    return cls(terms=tuple(d["terms"]), axes=(np.array(d["alpha1"]), np.array(d["alpha2"])),
               values=vals, regime=np.array(d["regime"], dtype=object),
               seconds=d["seconds"], workers=d["workers"])


def _parser():
    p = argparse.ArgumentParser(
        prog="vidi",
        description="Discover and verify contact-force laws F(zeta, dzeta) of vibro-impact "
                    "machines by simulation.")
    sub = p.add_subparsers(dest="command", required=True, metavar="COMMAND")
    scen_help = (f"built-in scenario ({', '.join(builtin_scenarios())}) or a TOML file "
                 "(default: paper)")
    law_help = "force law, e.g. '2.06e8*z + 1.28e7*zd' (default: the scenario's law)"

    s = sub.add_parser("simulate", help="write a synthetic measurement CSV of a law's "
                       "steady state")
    s.add_argument("--scenario", default="paper", help=scen_help)
    s.add_argument("--law", help=law_help)
    s.add_argument("--periods", type=int, default=20, help="drive periods recorded (20)")
    s.add_argument("--fs", type=float, default=20000.0, help="sampling rate in Hz (20000)")
    s.add_argument("--noise", type=float, default=0.0,
                   help="Gaussian noise on F as a fraction of the peak force (0)")
    s.add_argument("--seed", type=int, default=0, help="noise seed (0)")
    s.add_argument("--from-rest", action="store_true",
                   help="record from the initial state (run-up with impacts at many "
                   "velocities, then the steady state) instead of on the periodic orbit")
    s.add_argument("--position-noise", type=float, default=0.0,
                   help="Gaussian noise on w1, w2 as a fraction of the largest penetration (0)")
    s.add_argument("--no-velocities", action="store_true",
                   help="leave out the v1, v2 columns (discovery then differentiates w1 - w2)")
    s.add_argument("--out", required=True, help="output CSV (t, F, w1, v1, w2, v2)")
    s.set_defaults(func=_cmd_simulate)

    s = sub.add_parser("fit", help="discover a law: sparse certified regression, every "
                       "candidate checked by simulation")
    s.add_argument("--scenario", default="paper", help=scen_help)
    s.add_argument("--data", required=True, help="CSV with t, F, w1, w2 (v1, v2 optional)")
    s.add_argument("--library", default="poly:2",
                   help="candidate terms: poly:N, hc, a list 'z,zd,z*zd', or sums (poly:2)")
    s.add_argument("--select", default="best-subset",
                   choices=["best-subset", "l1-path", "stlsq", "sr3", "constrained-sr3"],
                   help="how supports are proposed (best-subset)")
    s.add_argument("--score", default="bic", choices=["bic", "aic", "cv"],
                   help="regression score that orders the candidates (bic)")
    s.add_argument("--max-terms", type=int, default=4, help="largest support (4)")
    s.add_argument("--criterion", default="I2", choices=list(CRITERIA),
                   help="simulation criterion of the ranking (I2)")
    s.add_argument("--shortlist", type=int, default=8, help="candidates simulated (8)")
    s.add_argument("--margin", type=float, default=0.0,
                   help="dissipativity strictness margin in N s/m (0)")
    s.add_argument("--monotone", action="store_true",
                   help="also require a monotone elastic branch")
    s.add_argument("--refine", action="store_true",
                   help="refine the chosen model's coefficients by simulation")
    s.add_argument("--stability", type=int, default=0,
                   help="bootstrap resamples of impacts for stability selection (0)")
    s.add_argument("--derivative", choices=["velocities", "savgol", "pysindy"],
                   help="source of dzeta (default: velocities if recorded, else savgol)")
    s.add_argument("--average-cycles", action="store_true",
                   help="average the steady cycles sample by sample before the regression")
    s.add_argument("--seed", type=int, default=0, help="seed of the stability selection")
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=_cmd_fit)

    s = sub.add_parser("verify", help="is a law consistent with a record? full simulation, "
                       "criteria I0..I4 against their noise floor")
    s.add_argument("--scenario", default="paper", help=scen_help)
    s.add_argument("--data", required=True, help="CSV with t [s], F [N] (w1, v1, w2, v2 "
                   "recommended: exact onsets and the machine's state)")
    s.add_argument("--law", help=law_help)
    s.add_argument("--time-offset", type=float, default=0.0,
                   help="drive-clock time [s] of the record's t = 0, when the record does not "
                   "start at drive phase 0 (0)")
    s.add_argument("--n-boot", type=int, default=16,
                   help="bootstrap replicates of the noise floor (16)")
    s.add_argument("--seed", type=int, default=0, help="seed of the bootstrap (0)")
    s.add_argument("--no-default-start", action="store_true",
                   help="skip the check of the attractor reached from the scenario's "
                   "initial state")
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=_cmd_verify)

    s = sub.add_parser("steady", help="periodic steady state of a law: regime, impacts, "
                       "Floquet multipliers")
    s.add_argument("--scenario", default="paper", help=scen_help)
    s.add_argument("--law", help=law_help)
    s.add_argument("--out", help="optional output directory for summary.json")
    s.set_defaults(func=_cmd_steady)

    s = sub.add_parser("landscape", help="criteria I0..I4 over a grid of the first two "
                       "coefficients (paper Figs. 4-5)")
    s.add_argument("--scenario", default="paper", help=scen_help)
    s.add_argument("--law", help="template law whose first two coefficients vary "
                   "(default: the scenario's law)")
    s.add_argument("--grid", default="41x41", help="points per axis, e.g. 41x41")
    s.add_argument("--range0", help="LOW:HIGH of the first coefficient (1.03e8:3.09e8)")
    s.add_argument("--range1", help="LOW:HIGH of the second coefficient (0.64e7:1.92e7)")
    s.add_argument("--workers", type=int, help="processes (default: all cores)")
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=_cmd_landscape)

    s = sub.add_parser("identify", help="identify a law's coefficients from a measured CSV by "
                       "simulation (paper Figs. 6-7)")
    s.add_argument("--scenario", default="paper", help=scen_help)
    s.add_argument("--data", required=True, help="CSV with t [s], F [N] (w1, w2 optional)")
    s.add_argument("--criterion", default="I2", choices=list(CRITERIA),
                   help="criterion to minimise (I2)")
    s.add_argument("--method", default="least-squares",
                   choices=["coordinate-descent", "nelder-mead", "least-squares"],
                   help="optimiser (least-squares)")
    s.add_argument("--start", required=True, help="terms and start values, e.g. "
                   "'1.5e8*z + 0.9e7*zd'")
    s.add_argument("--max-simulations", type=int, default=600, help="simulation budget (600)")
    s.add_argument("--xtol", type=float, default=1e-5, help="relative coefficient tolerance")
    s.add_argument("--landscape", help="a landscape output (directory or summary.json) to draw "
                   "the path on")
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=_cmd_identify)
    return p


def main(argv=None):
    """Run ``vidi``; returns the exit code (0 ok, 2 bad input or failed numerics)."""
    args = _parser().parse_args(argv)
    try:
        return args.func(args)
    except VidiError as exc:
        print(f"vidi: error: {exc}", file=sys.stderr)
        return 2
    except ValueError as exc:  # certificate/validation errors from the packages
        print(f"vidi: error: {exc}", file=sys.stderr)
        return 2
    except BrokenPipeError:  # output piped into e.g. `head`: stop quietly
        sys.stderr.close()
        return 0


if __name__ == "__main__":
    sys.exit(main())
