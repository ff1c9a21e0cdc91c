"""``vidi ueda explain``: the missing-effect workflow: from a start model, name the missing effect
of this system's catalogue by score tests, add it, refit, and show the gap shrink."""

import numpy as np

from ..._io import OutputDir, provenance
from ...errors import InputError
from .._common import check_out, integer, number
from ._system import _forcing


def run(args):
    from reports.ueda.explain_figure import explain_figure

    from ...ueda.explain_loop import explain, parse_terms
    from ...ueda.record import read_record_csv

    check_out(args)
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
        provenance(vars(args), inputs={"data": args.data}),
        settings_key="method",
    )
    with OutputDir(args.out, inputs=[args.data]) as out:
        explain_figure(ex, str(out.path("explain")))
        for name, ver in (("start", ex.start_verification), ("final", ex.final_verification)):
            np.savetxt(
                out.path(f"strobe_{name}.csv"),
                ver.model_strobe,
                delimiter=",",
                header="x,v",
                comments="",
            )
        np.savetxt(
            out.path("strobe_record.csv"),
            ex.final_verification.record_strobe,
            delimiter=",",
            header="x,v",
            comments="",
        )
        ex.write_into(out)
    print(f"start: {ex.start_model.text()}")
    for it in ex.iterations:
        if it.effect:
            print(f"named {it.effect}: {it.evidence['text']}")
    print(f"final: {ex.final_model.text()}")
    for k, c in ex.coefficients.items():
        print(f"  {k:>12}: {c: .5f} +- {ex.standard_errors[k]:.5f}")
    for k, g in ex.gap.items():
        print(f"  gap {k}: {g['before']:.4g} -> {g['after']:.4g} ({g['ratio']:.3g}x)")
    print(f"stopped: {ex.stopped_because}")
    print(
        f"outputs in {args.out}/: summary.json, explain.png, explain.pdf, strobe_record.csv, "
        "strobe_start.csv, strobe_final.csv"
    )
    return 0


def register(sub):
    """Add ``vidi ueda explain`` to the ueda subparsers ``sub``."""
    e = sub.add_parser(
        "explain",
        help="name the effect missing from a start model "
        "(score tests over this system's catalogue), add it, refit, and show "
        "the gap shrink by simulation",
    )
    e.add_argument("--data", required=True, help="CSV with columns t (uniform) and x")
    e.add_argument(
        "--start",
        default="x',x^3",
        help="library terms of the start model, "
        "separated by commas (x^2*x' or x^2 x'; v for x'; none: the forcing "
        "alone); x',x^3 is negres without its van der Pol damping x^2 x' "
        "(default: %(default)s)",
    )
    e.add_argument(
        "--model",
        choices=("negres", "duffing"),
        help="take the forcing B, nu from this model (override with --B, --nu)",
    )
    e.add_argument("--B", type=number(-1e3, 1e3), help="forcing amplitude")
    e.add_argument("--nu", type=number(0, 100, lo_open=True), help="forcing angular frequency, > 0")
    e.add_argument(
        "--effects",
        help="catalogue ids to consider, separated by commas "
        "(default: all of van_der_pol_damping, linear_damping, cubic_stiffness, "
        "quadratic_stiffness, velocity_cubic_damping)",
    )
    e.add_argument(
        "--alpha",
        type=number(0, 1, lo_open=True),
        default=0.01,
        help="family-wise level of the score tests, Bonferroni (default: %(default)g)",
    )
    e.add_argument(
        "--max-iterations",
        type=integer(0, 20),
        default=3,
        help="effects added at most (default: %(default)s)",
    )
    e.add_argument(
        "--noise",
        type=number(0, 1),
        help="known noise sd as a fraction of x's "
        "range (default: estimated from the smoothing residual)",
    )
    e.add_argument(
        "--half-width",
        type=integer(2, 10**4),
        help="test-window half width in samples (default: a quarter period, at least 7)",
    )
    e.add_argument(
        "--fix-forcing",
        action="store_true",
        help="fix the forcing's coefficient at 1 instead of fitting it",
    )
    e.add_argument(
        "--model-periods",
        type=integer(50, 10**6),
        default=2000,
        help="periods of each model simulated (default: %(default)s)",
    )
    e.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=200,
        help="periods of each model discarded first (default: %(default)s)",
    )
    e.add_argument(
        "--resamples",
        type=integer(10, 10**5),
        default=200,
        help="random halves for the energy-distance noise floor (default: %(default)s)",
    )
    e.add_argument(
        "--seed", type=integer(0), default=0, help="seed of the resampling (default: %(default)s)"
    )
    e.add_argument("--out", required=True, help="output directory")
    e.set_defaults(func=run)
