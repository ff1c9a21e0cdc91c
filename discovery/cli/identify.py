"""``vidi identify``: identify a law's coefficients by simulation."""

import csv
import io

import numpy as np

from .._files._drawer import drawing
from .._files._io import OutputDir
from ..errors import InputError
from ..vibroimpact.model.law import ForceLaw
from ..vibroimpact.model.scenario import load_scenario
from ..vibroimpact.verify.criteria import CRITERIA
from . import _options
from ._common import (
    add_record_options,
    check_out,
    coefficients_line,
    criteria_line,
    machine_for,
    machine_scale,
    number,
    outputs_line,
    provenance_of,
    read_record,
    reporter,
    sensor_lag_of,
)


def _pick_iterates(iterations, k):
    n = len(iterations)
    if n == 0:
        return []
    return sorted(set(np.unique(np.round(np.geomspace(1, n, k)).astype(int) - 1)))


def _load_landscape(path, cls, start, scenario):
    """The landscape to draw the path on: made by ``vidi landscape`` for the start's first
    two terms and the same scenario, every criterion a grid of its two axes."""
    land, d = _read_landscape(path, cls)
    terms = tuple(t.name for t in start.terms[:2])
    if tuple(land.terms) != terms:
        raise InputError(
            f"--landscape {path!r} varies {', '.join(land.terms)}, not the start's "
            f"{', '.join(terms)}; make one with vidi landscape --law "
            "(the start law) or leave out --landscape"
        )
    shape = (land.axes[0].size, land.axes[1].size)
    bad = [n for n, v in land.values.items() if v.shape != shape]
    if bad or land.regime.shape != shape or min(shape) < 2:
        raise InputError(
            f"--landscape {path!r}: its grids do not match its axes "
            f"({shape[0]} x {shape[1]}); make it again with vidi landscape"
        )
    made_for = (d.get("scenario") or {}).get("name")
    if made_for is not None and made_for != scenario.name:
        raise InputError(
            f"--landscape {path!r} was made for scenario {made_for!r}, not "
            f"{scenario.name!r}; make one for this scenario or leave out "
            "--landscape"
        )
    return land


def _read_landscape(path, cls):
    """``(Landscape, its document)`` of a saved landscape (through :func:`discovery.load`:
    a summary from before the schema version is one clear error)."""
    from .._api._result import load

    try:
        land = load(path)
    except InputError as exc:
        raise InputError(f"--landscape {path!r}: {exc}") from None
    if not isinstance(land, cls):
        raise InputError(
            f"--landscape {path!r} is not a landscape result (made by vidi "
            "landscape); give its output directory or summary.json"
        )
    try:
        bad = [n for n in CRITERIA if n not in land.values] or land.regime is None
    except (AttributeError, TypeError):
        bad = True
    if bad:
        raise InputError(
            f"--landscape {path!r} is not a complete landscape result; make it again with "
            "vidi landscape"
        )
    return land, land.to_dict()


def _iterate_impulses(sc, start, ref, res):
    """The impulses the figure shows: a few best-so-far laws found before the identified
    law, labelled by the simulations spent (``res.iterations`` lists every new best, the
    finite-difference probes included), then the identified law itself."""
    from ..vibroimpact.verify import evaluate

    its = res.iterations
    found = next(
        (k for k, it in enumerate(its) if it["coefficients"] == res.coefficients), len(its)
    )
    imps = []
    for k in _pick_iterates(its[:found], 4):
        it = its[k]
        law = start.with_coefficients(list(it["coefficients"].values()))
        ev = evaluate(sc, law, ref, floor=False)
        n = it["n_simulations"]
        imps.append(
            (
                "start"
                if it["coefficients"] == start.as_dict()
                else f"best after {n} simulation{'s' if n != 1 else ''}",
                ev.simulated,
            )
        )
    imps.append(("identified law", res.checks[0].simulated))
    return imps


def _iterations_csv(res):
    """``iterations.csv``: one row per new best-so-far law (optimiser steps and
    finite-difference probes)."""
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["best_so_far", "n_simulations", res.criterion, *res.law.names])
    for k, it in enumerate(res.iterations):
        w.writerow(
            [
                k,
                it["n_simulations"],
                f"{it['value']:.10g}",
                *[f"{v:.10g}" for v in it["coefficients"].values()],
            ]
        )
    return buf.getvalue()


def _summary(args, sc, start, ref, res):
    """``summary.json`` of the command."""
    final = res.checks[0]  # the identified law against the record, with its noise floor
    head = {
        "command": "identify",
        "scenario": sc.as_dict(),
        "data": str(args.data),
        "measured": ref.measured(),
        "start": start.as_dict(),
    }
    tail = {
        "criteria": final.criteria,
        "noise_floor": final.noise_floor,
        "consistent": final.consistent,
        "verdict": final.verdict,
        "regime": final.regime,
        **provenance_of(args),
    }
    return res.record_run(head, tail)


def _print_result(args, res, tau=0.0):
    final = res.checks[0]
    print(f"identified {res.law}")
    # the criterion of the identified law (res.value can be that of a standard-error probe)
    value = res.criteria.get(res.criterion, res.value)
    print(
        f"  {res.criterion} = {value:.4g} after {res.n_simulations} simulations "
        f"({res.method}, {res.seconds:.1f} s)"
    )
    if res.standard_errors:
        print(coefficients_line(res.coefficients, res.standard_errors, res.intervals))
    if final.criteria:
        print(criteria_line(final.criteria, final.noise_floor))
    print(f"  {final.verdict}")
    if tau:
        from ..vibroimpact.verify.sensors import lag_note

        print(f"  note: {lag_note(tau)}")
    if res.failures:
        print(
            f"  note: {len(res.failures)} trial law(s) had no periodic steady state with "
            "contact (listed in summary.json)"
        )
    files = ["summary.json", "iterations.csv", "identification.png", "identification.pdf"]
    print(outputs_line(args, files))


#: the results' module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_RESULTS = ("discovery.vibroimpact.fit.identification",)


def run(args):
    check_out(args)
    with drawing(["identification_figure"], _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ..vibroimpact.fit.identification import identify
    from ..vibroimpact.verify import Reference
    from ..vibroimpact.verify.criteria_landscape import Landscape
    from ..vibroimpact.verify.sensors import lag_observation

    sc = load_scenario(args.scenario)
    if not args.start.strip():
        raise InputError(
            "--start is empty; give the terms and start values, e.g. '1.5e8*z + 0.9e7*zd'"
        )
    start = ForceLaw.parse(args.start)
    if any(c == 0 for c in start.coefficients):  # said before what the zero makes of the law
        raise InputError(
            "--start: every start coefficient must be non-zero (they set the scale of the "
            f"search); got '{start}'"
        )
    start.check_physical(sc, "--start")
    land = _load_landscape(args.landscape, Landscape, start, sc) if args.landscape else None
    meas = read_record(args, sc)
    for note in meas.notes:
        print(f"note: {note}")
    (sc,), machine = machine_for(args, [sc], [meas])
    tau = sensor_lag_of(args, machine)  # the force sensor's, read through as verify and fit do
    ref = Reference.from_measurement(meas, sc, n_boot=args.n_boot, seed=args.seed)
    with reporter(args) as rep:
        res = identify(
            sc,
            ref,
            start,
            criterion=args.criterion,
            method=args.method,
            max_simulations=args.max_simulations,
            xtol=args.xtol,
            n_boot_intervals=args.intervals,
            interval_refit=args.interval_refit,
            seed=args.seed,
            workers=args.workers,
            machine_scale=machine_scale(machine),
            observe=lag_observation(tau),
            progress=rep,
        )
    imps = _iterate_impulses(sc, start, ref, res)
    with OutputDir(args.out) as out:
        summary = _summary(args, sc, start, ref, res)
        run = summary.run_record
        summary.record_run({**run["head"], "machine": machine, "sensor_lag": tau}, run["tail"])
        summary.write_into(out)
        out.path("iterations.csv").write_text(_iterations_csv(res))
        stem = str(out.path("identification"))
        drawer.draw(
            stem, "identification_figure", res, ref.impulse, imps, stem, land=land, start=start
        )
    _print_result(args, res, tau)
    return 0


def register(sub):
    s = sub.add_parser(
        "identify",
        help="identify a law's coefficients from a measured CSV by simulation (paper Figs. 6-7)",
    )
    _options.add_scenario_option(s)
    _options.add_data_option(s)
    add_record_options(s)
    _options.add_criterion_option(s, "criterion to minimise")
    s.add_argument(
        "--method",
        default="least-squares",
        choices=["coordinate-descent", "nelder-mead", "least-squares"],
        help="optimiser (default: %(default)s)",
    )
    s.add_argument(
        "--start", required=True, help="terms and start values, e.g. '1.5e8*z + 0.9e7*zd'"
    )
    _options.add_max_simulations_option(s, least=2, most=1_000_000, default=600)
    s.add_argument(
        "--xtol",
        type=number(0.0, 1.0, lo_open=True),
        default=1e-5,
        help="relative coefficient tolerance (default: %(default)g)",
    )
    s.add_argument(
        "--landscape",
        help="a landscape output (directory or summary.json) to draw the path on (default: none)",
    )
    _options.add_n_boot_option(s)
    _options.add_intervals_option(
        s, "the 95 % coefficient intervals", "records with positions; 0 = none"
    )
    _options.add_interval_refit_option(s)
    _options.add_sensor_lag_option(s)
    _options.add_workers_option(s, "the fit's record blocks and the bootstrap intervals' refits")
    _options.add_seed_option(s, "seed of the noise-floor and interval bootstraps")
    _options.add_out_option(s)
    s.set_defaults(func=run)
