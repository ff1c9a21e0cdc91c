"""``vidi fit``: discover a law (certified sparse regression, every candidate simulated)."""

import argparse
import csv
import io
import time
from concurrent.futures import ThreadPoolExecutor

from .._files._drawer import drawing
from .._files._io import OutputDir
from ..errors import InputError
from ..vibroimpact.model.contact_registry import CONTACT_MODELS
from ..vibroimpact.verify.criteria import CRITERIA
from . import _options
from ._common import (
    add_record_options,
    check_out,
    coefficients_line,
    criteria_line,
    data_entry,
    integer,
    machine_scale,
    number,
    outputs_line,
    provenance_of,
    read_records,
    reporter,
    sensor_lag_of,
)


def _discover(args, records, progress):
    """The API call the options describe."""
    from ..errors import SolverError
    from ..vibroimpact.fit.discovery import discover

    try:
        return _call(discover, args, records, progress)
    except SolverError as exc:
        if not args.margin:
            raise
        raise SolverError(
            f"the regression's solvers failed with --margin {args.margin:g} N s/m "
            f"({str(exc).splitlines()[0][:120]}); give a smaller --margin, e.g. 0 or "
            "a fraction of the damping coefficients you expect"
        ) from None


def _call(discover, args, records, progress):
    """``discover`` on ``records`` (the scenarios, the records and the machine's summary of
    :func:`._common.read_records`) with the options of the command line."""
    scs, meas, machine = records
    return discover(
        scs,
        meas,
        library=args.library,
        selection=args.select,
        scoring=args.score,
        max_terms=args.max_terms,
        criterion=args.criterion,
        shortlist=args.shortlist,
        refine=not args.no_refine,
        max_simulations=args.max_simulations or 120,
        stability=args.stability,
        derivative=args.derivative,
        average_cycles=args.average_cycles,
        seed=args.seed,
        margin=args.margin,
        monotone=args.monotone,
        physics=not args.allow_unphysical,
        require=args.require or (),
        n_boot_intervals=args.intervals,
        interval_refit=args.interval_refit,
        workers=args.workers,
        progress=progress,
        machine_scale=machine_scale(machine),
        sensor_lag=sensor_lag_of(args, machine),
        **({"signs": args.signs} if args.signs else {}),
    )


def _ranking_csv(res):
    """``ranking.csv``: one row per ranked candidate."""
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["rank", "terms", "regime", "bic", "aic", "cv_error", *CRITERIA, "coefficients"])
    for i, m in enumerate(res.ranking):
        w.writerow(
            [
                i + 1,
                " + ".join(m.law.names),
                m.regime,
                f"{m.candidate.bic:.8g}",
                f"{m.candidate.aic:.8g}",
                f"{m.candidate.cv_error:.6g}",
                *[f"{m.criteria[n]:.6g}" if m.criteria else "" for n in CRITERIA],
                m.law.to_text(),
            ]
        )
    return buf.getvalue()


#: what the drawer loads while the command computes: the figures and the results' modules
#: (:mod:`discovery._files._drawer`)
_RESULTS = ("discovery.vibroimpact.fit.discovery_result",)
_FIGURES = ("fit_impulse_figure", "fit_surface_figure", "fit_loop_figure")


def _write_outputs(args, res, t_start, drawer):
    """The output directory: ranking, figures (drawn by ``drawer``), model.tex (and its
    PDF), summary.json.  Returns ``(pdf, why)`` (``why``: the reason there is no PDF)."""
    from reports.document import compile_tex, render

    imps = []
    for k, m in enumerate(res.ranking[:3]):
        if m.criteria:  # aligned with the first record and sampled like it
            imps.append(
                (
                    f"#{k + 1}: {', '.join(m.law.names)} "
                    f"({args.criterion} {m.criteria[args.criterion]:.3g})",
                    m.evaluation.simulated,
                )
            )
    with OutputDir(args.out) as out, ThreadPoolExecutor(1) as latex:
        out.path("ranking.csv").write_text(_ranking_csv(res))
        # every figure sent at once: the drawer draws the next while the last's PDF prints
        stem = str(out.path("fit_impulse"))
        drawer.draw(stem, "fit_impulse_figure", res, imps, stem)
        for name in ("fit_surface", "fit_loop"):
            stem = str(out.path(name))
            drawer.draw(stem, f"{name}_figure", res, stem)
        # model.tex is a template of the report system, rendered from the summary itself
        # (it shows the first figure: it waits for that one alone)
        out.path("model.tex").write_text(render(res.to_dict(), out.stage, template="model"))
        # LaTeX runs while the other two figures are drawn (a subprocess: this thread only
        # waits for it); it needs only the first figure
        compiled = (
            latex.submit(compile_tex, out.path("model.tex"), ["fit_impulse.pdf"], once=True)
            if not args.no_pdf
            else None
        )
        pdf, why = compiled.result() if compiled is not None else (None, None)
        why = None if pdf is not None else why
        # the run's record, with the PDF and the whole command's wall time
        res.record_run(
            res.run_record["head"],
            {
                **res.run_record["tail"],
                "pdf": None if pdf is None else "model.pdf",
                "seconds": time.perf_counter() - t_start,
            },
            **res.run_record["options"],
        ).write_into(out)
    return pdf, why


def _print_result(args, res, pdf, why):
    """The command's printout: the selected law, its checks, the ranking's notes."""
    from ..vibroimpact.fit.discovery_result import equivalent_text
    from ..vibroimpact.verify.sensors import lag_note

    sel = res.selected
    print(f"selected {sel.law}   [{sel.regime}]")
    if sel.standard_errors:
        print(coefficients_line(sel.law.as_dict(), sel.standard_errors, sel.intervals))
    if sel.criteria:
        print(criteria_line(sel.criteria, sel.noise_floor))
    print(f"  {sel.verdict}")
    if res.settings.get("sensor_lag"):
        print(f"  note: {lag_note(res.settings['sensor_lag'])}")
    cert = res.certificate
    print(
        f"  certificate: {'holds' if cert.holds else 'FAILS'} on zeta <= "
        f"{cert.domain['zeta_max']:.3g} m, zd <= {cert.domain['zd_max']:.3g} m/s "
        f"(worst violation {cert.worst_violation:.2g})"
    )
    print(
        f"  {len(res.ranking)} candidates ranked ({res.samples.n_impacts} impacts, "
        f"{len(res.samples)} contact samples, {res.seconds:.1f} s)"
    )
    if res.stability:
        print(
            "  stability: " + ", ".join(f"{k} {v:.2f}" for k, v in res.stability.items() if v > 0)
        )
    for e in res.equivalent:
        print(f"  equivalent: {equivalent_text(e)}")
    for w in res.warnings:
        print(f"  warning: {w}")
    if why:
        print(f"  note: {why}")
    pdfs = ["model.pdf"] if pdf else []
    figures = ["fit_impulse.png/.pdf", "fit_surface.png/.pdf", "fit_loop.png/.pdf"]
    print(outputs_line(args, ["summary.json", "ranking.csv", "model.tex", *pdfs, *figures]))


#: the options of the polynomial path (its regression, ranking and stability selection),
#: which mean nothing to the named models' fits
_REGRESSION = (
    "--select",
    "--score",
    "--max-terms",
    "--shortlist",
    "--margin",
    "--signs",
    "--require",
    "--allow-unphysical",
    "--monotone",
    "--no-refine",
    "--stability",
    "--derivative",
    "--average-cycles",
)


def _refuse_regression_options(args, defaults):
    """A regression option given with ``--library contact-models`` is one line, not
    ignored (``defaults``: the parser's default of each)."""
    given = [
        o for o, d in defaults.items() if getattr(args, o.lstrip("-").replace("-", "_"), d) != d
    ]
    if given:
        raise InputError(
            f"{', '.join(given)} belong(s) to the polynomial library's regression; the "
            "named contact models are fitted by simulation alone: drop "
            f"{' and '.join(given)} or give a polynomial --library"
        )


def _run_contact_models(args, scs, meas, machine, t_start):
    """``--library contact-models``: every named contact model fitted, the one the record
    supports and those it cannot tell from it (``summary.json`` is the result's
    ``to_dict()`` with the provenance)."""
    from ..vibroimpact.fit.contact_fit import fit_contact_models

    with reporter(args) as rep:
        res = fit_contact_models(
            scs,
            meas,
            max_simulations=args.max_simulations or 200,
            n_boot=args.intervals,
            seed=args.seed or 0,
            workers=args.workers,
            progress=rep,
            sensor_lag=sensor_lag_of(args, machine),
        )
    tail = {**provenance_of(args), "seconds": time.perf_counter() - t_start}
    with OutputDir(args.out) as out:
        res.record_run(_head(args, scs, machine), tail).write_into(out)
    print(res)
    print(outputs_line(args, ["summary.json"]))
    return 0


def _head(args, scs, machine):
    """The command's part of ``summary.json``: the records and their scenarios."""
    return {
        "command": "fit",
        "scenario": scs[0].as_dict(),
        "scenarios": [sc.as_dict() for sc in scs] if len(scs) > 1 else None,
        "data": data_entry(args.data),
        "machine": machine,
    }


def run(args):
    t_start = time.perf_counter()
    check_out(args)
    defaults = vars(args).pop("regression_only", None) or {}  # not a setting of the run
    if args.library == "contact-models":
        _refuse_regression_options(args, defaults)
    if args.library == "contact-models":
        scs, meas, machine = read_records(args)
        return _run_contact_models(args, scs, meas, machine, t_start)
    with drawing(_FIGURES, _RESULTS) as drawer:
        scs, meas, machine = read_records(args)
        with reporter(args) as rep:
            res = _discover(args, (scs, meas, machine), rep)
        res.record_run(
            _head(args, scs, machine), provenance_of(args), names=[str(p) for p in args.data]
        )
        pdf, why = _write_outputs(args, res, t_start, drawer)
    _print_result(args, res, pdf, why)
    return 0


def _signs(text):
    """``'z:+,zd:-'`` -> ``{"z": 1, "zd": -1}`` (argparse type)."""
    out = {}
    for part in text.split(","):
        if not part.strip():
            continue
        term, _, sign = part.rpartition(":")
        value = {"+": 1, "+1": 1, "1": 1, "-": -1, "-1": -1, "0": 0}.get(sign.strip())
        if not term.strip() or value is None:
            raise argparse.ArgumentTypeError(
                f"{part.strip()!r} is not TERM:SIGN; write e.g. --signs 'z:+,zd:+' (signs + - 0)"
            )
        out[term.strip()] = value
    if not out:
        raise argparse.ArgumentTypeError("no TERM:SIGN given; write e.g. --signs 'z:+,zd:+'")
    return out


def _terms(text):
    """``'z,zd'`` -> ``["z", "zd"]`` (argparse type)."""
    out = [t.strip() for t in text.split(",") if t.strip()]
    if not out:
        raise argparse.ArgumentTypeError("no term given; write e.g. --require z")
    return out


def _add_inputs(p):
    """The records and their machines."""
    _options.add_scenario_option(
        p, repeat=True, help_suffix=", when the records come from different operating points"
    )
    _options.add_data_option(
        p,
        "CSV with t, F, w1, w2 (v1, v2 optional); repeat it to fit several records jointly",
        repeat=True,
    )
    add_record_options(p)


def _add_regression_options(p):
    """Candidate library and the regression that proposes supports."""
    p.add_argument(
        "--library",
        default="poly:2",
        help="candidate terms: poly:N (every z^a zd^b with 1 <= a+b <= N), hc (the "
        "Hunt-Crossley terms z^1.5 and z^1.5*zd), a list 'z,zd,z*zd', or sums (poly:2+hc); "
        "or 'contact-models': "
        f"the named models ({', '.join(CONTACT_MODELS)}) fitted by name "
        "(default: %(default)s)",
    )
    p.add_argument(
        "--select",
        default="best-subset",
        choices=["best-subset", "l1-path", "stlsq", "sr3", "constrained-sr3"],
        help="how supports are proposed (default: %(default)s)",
    )
    p.add_argument(
        "--score",
        default="bic",
        choices=["bic", "aic", "cv"],
        help="regression score that orders the candidates (default: %(default)s)",
    )
    p.add_argument(
        "--max-terms", type=integer(1, 12), default=4, help="largest support (default: %(default)s)"
    )
    _options.add_criterion_option(p, "simulation criterion of the ranking")
    p.add_argument(
        "--shortlist",
        type=integer(1, 200),
        default=8,
        help="candidates simulated (default: %(default)s)",
    )
    p.add_argument(
        "--margin",
        type=number(0.0, 1e12, unit="N s/m"),
        default=0.0,
        help="dissipativity strictness margin in N s/m (default: %(default)g)",
    )
    p.add_argument(
        "--signs",
        type=_signs,
        default=None,
        help="coefficient signs of library terms, e.g. 'z:+,zd:+,zd^2:-' (a term "
        "not named is free; default: none)",
    )
    p.add_argument(
        "--require",
        type=_terms,
        default=None,
        help="terms every candidate must contain, e.g. 'z' (a spring) or 'z,zd' (default: none)",
    )


def _add_check_options(p):
    """Simulation checks, refinement, intervals and stability selection."""
    _options.add_intervals_option(p, "the selected law's 95 % coefficient intervals")
    _options.add_interval_refit_option(p)
    _options.add_workers_option(
        p,
        "the refinements of each search step (a lone one: its record blocks; with "
        "contact-models each fit's record blocks) and the bootstrap intervals' refits",
    )
    p.add_argument(
        "--allow-unphysical",
        action="store_true",
        help="rank laws that are no contact laws (no spring: F(zeta, 0) = 0; a "
        "negative damper) by the records alone; by default they come last",
    )
    p.add_argument("--monotone", action="store_true", help="also require a monotone elastic branch")
    p.add_argument(
        "--no-refine",
        action="store_true",
        help="skip the refinement of every shortlisted support by simulation "
        "(output error: unbiased coefficients and their standard errors)",
    )
    _options.add_max_simulations_option(
        p,
        least=2,
        most=100_000,
        default=None,
        of=" of each support's refinement",
        default_help="default: 120; with --library contact-models each model's fit, default 200",
        excludes="--no-refine",
    )
    p.add_argument(
        "--stability",
        type=integer(0, 10_000),
        default=0,
        help="bootstrap resamples of impacts for stability selection "
        "(default: %(default)s, no stability selection)",
    )
    p.add_argument(
        "--derivative",
        choices=["velocities", "savgol", "pysindy"],
        help="source of dzeta (default: velocities if recorded, else savgol)",
    )
    p.add_argument(
        "--average-cycles",
        action="store_true",
        help="average the steady cycles sample by sample before the regression",
    )
    _options.add_seed_option(
        p,
        "seed of the resampling: the stability selection's resamples, each record's "
        "noise-floor bootstrap and the bootstrap coefficient intervals (with --library "
        "contact-models: the models' intervals)",
    )
    _options.add_sensor_lag_option(p)


def _add_output_options(p):
    """Outputs."""
    p.add_argument(
        "--no-pdf",
        action="store_true",
        help="do not compile model.tex to model.pdf (compiled when latexmk is installed)",
    )
    _options.add_out_option(p)


def register(sub):
    s = sub.add_parser(
        "fit",
        help="discover a law: sparse certified regression, every candidate checked by simulation",
    )
    _add_inputs(s)
    _add_regression_options(s)
    _add_check_options(s)
    _add_output_options(s)
    s.set_defaults(
        func=run,
        regression_only={o: s.get_default(o.lstrip("-").replace("-", "_")) for o in _REGRESSION},
    )
