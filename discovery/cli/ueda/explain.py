"""``vidi ueda explain``: the missing-effect workflow: from a start model, name the missing effect
of this system's catalogue by score tests, add it, refit, and show the gap shrink."""

from ..._files._drawer import drawing
from ..._files._io import OutputDir
from ...errors import InputError
from .. import _options
from .._common import check_out, outputs_line, provenance_of
from . import _record
from ._system import _add_forcing_options, _forcing

#: the figures and the results' module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_FIGURES = ("ueda.explain_figure.explain_figure",)
_RESULTS = ("discovery.ueda.explanation",)


def run(args):
    check_out(args)
    with drawing(_FIGURES, _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ...ueda.explain_loop import explain, parse_terms
    from ...ueda.record import read_record_csv

    B, nu = _forcing(args)
    start = parse_terms(args.start)
    effects = None
    if args.effects is not None:
        effects = [e.strip() for e in args.effects.split(",") if e.strip()]
        if not effects:
            raise InputError(
                "--effects is empty; give catalogue ids separated by commas, e.g. "
                "van_der_pol_damping,linear_damping, or leave it out for all"
            )
    t, x = read_record_csv(args.data)
    ex = explain(
        t,
        x,
        B,
        nu,
        start,
        alpha=args.alpha,
        max_iterations=args.max_iterations,
        effects=effects,
        half_width=args.half_width,
        fit_forcing=not args.fix_forcing,
        noise=args.noise,
        transient=args.transient,
        periods=args.model_periods,
        resamples=args.resamples,
        seed=args.seed,
    )
    ex.record_run(  # "settings" is provenance's (the options): the method's is "method"
        {"command": "ueda explain", "forcing": {"B": B, "nu": nu}},
        provenance_of(args, counted=False),
        settings_key="method",
    )
    with OutputDir(args.out, inputs=[args.data]) as out:
        stem = str(out.path("explain"))
        drawer.draw(stem, _FIGURES[0], ex, stem)
        for name, ver in (("start", ex.start_verification), ("final", ex.final_verification)):
            _record.write_strobe(out.path(f"strobe_{name}.csv"), ver.model_strobe)
        _record.write_strobe(out.path("strobe_record.csv"), ex.final_verification.record_strobe)
        ex.write_into(out)
    print(f"start: {ex.start_model.text()}")
    for it in ex.iterations:
        if it.effect:
            print(f"named {it.effect}: {it.evidence['text']}")
    print(f"final: {ex.final_model.text()}")
    _record.print_coefficients(ex)
    for k, g in ex.gap.items():
        print(f"  gap {k}: {g['before']:.4g} -> {g['after']:.4g} ({g['ratio']:.3g}x)")
    print(f"stopped: {ex.stopped_because}")
    files = [
        "explain.png",
        "explain.pdf",
        *(f"strobe_{n}.csv" for n in ("record", "start", "final")),
    ]
    print(outputs_line(args, ["summary.json", *files]))
    return 0


def register(sub):
    """Add ``vidi ueda explain`` to the ueda subparsers ``sub``."""
    e = sub.add_parser(
        "explain",
        help="name the effect missing from a start model "
        "(score tests over this system's catalogue), add it, refit, and show "
        "the gap shrink by simulation",
    )
    _options.add_data_option(e, _record.RECORD_HELP)
    e.add_argument(
        "--start",
        default="x',x^3",
        help="library terms of the start model, "
        "separated by commas (x^2*x' or x^2 x'; v for x'; none: the forcing "
        "alone); x',x^3 is negres without its van der Pol damping x^2 x' "
        "(default: %(default)s)",
    )
    _add_forcing_options(e)
    e.add_argument(
        "--effects",
        help="catalogue ids to consider, separated by commas "
        "(default: all of van_der_pol_damping, linear_damping, cubic_stiffness, "
        "quadratic_stiffness, velocity_cubic_damping)",
    )
    _options.add_effect_search_options(
        e,
        alpha_most=1,
        alpha_help="family-wise level of the score tests, Bonferroni",
        max_iterations=20,
    )
    _record.add_noise_option(e)
    _record.add_weak_form_options(e)
    _record.add_verification_options(e, "each model")
    _options.add_out_option(e)
    e.set_defaults(func=run)
