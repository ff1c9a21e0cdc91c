"""``vidi ueda discover``: the equation recovered from a record with known forcing (weak-form
sparse regression, bootstrap standard errors), verified by simulation against the record's
attractor."""

from dataclasses import replace

import numpy as np

from ..._io import OutputDir, provenance
from .._common import check_out, integer, number
from ._system import _forcing


def run(args):
    from reports.ueda.figures import discover_figure

    from ...ueda.equation_discovery import discover
    from ...ueda.record import read_record_csv
    from ...ueda.verification import verify

    check_out(args)
    B, nu = _forcing(args)
    t, x = read_record_csv(args.data)
    d = discover(
        t,
        x,
        B,
        nu,
        threshold=args.threshold,
        half_width=args.half_width,
        fit_forcing=not args.fix_forcing,
        bootstrap=args.bootstrap,
        block_periods=args.block_periods,
        seed=args.seed,
    )
    sm = d.smoothed
    if args.noise is not None:
        sm = replace(sm, noise_sd=float(args.noise * np.ptp(x)))
    ver = verify(
        d.model,
        t,
        x,
        smoothed=sm,
        transient=args.transient,
        periods=args.model_periods,
        resamples=args.resamples,
        seed=args.seed,
    )
    # "settings" is provenance's (the command-line options); keep the discovery's own
    d.record_run(
        {"command": "ueda discover", "forcing": {"B": B, "nu": nu}},
        {
            "verification": ver.as_dict(),
            **provenance(vars(args), inputs={"data": args.data}),
        },
        settings_key="discovery_settings",
    )
    with OutputDir(args.out, inputs=[args.data]) as out:
        discover_figure(d, ver, str(out.path("discover")))
        np.savetxt(
            out.path("strobe_record.csv"),
            ver.record_strobe,
            delimiter=",",
            header="x,v",
            comments="",
        )
        np.savetxt(
            out.path("strobe_model.csv"), ver.model_strobe, delimiter=",", header="x,v", comments=""
        )
        d.write_into(out)
    print(f"discovered: {d.model.text()}")
    for k, c in d.coefficients.items():
        print(f"  {k:>12}: {c: .5f} +- {d.standard_errors[k]:.5f}")
    L = ver.lyapunov
    lyap = f"{L['value']:.4f} +- {L['stderr']:.4f}" if L else "n/a"
    print(
        f"verification: energy distance {ver.energy_distance:.4g} vs floor q95 "
        f"{ver.floor_q95:.4g} ({ver.floor_block_periods}-period blocks); regime record "
        f"{ver.regime_record}, model "
        f"{ver.regime_model}; model lyapunov {lyap}: "
        f"{'consistent' if ver.consistent else 'INCONSISTENT'}"
    )
    print(
        f"outputs in {args.out}/: summary.json, discover.png, discover.pdf, "
        "strobe_record.csv, strobe_model.csv"
    )
    return 0


def register(sub):
    """Add ``vidi ueda discover`` to the ueda subparsers ``sub``."""
    d = sub.add_parser(
        "discover",
        help="recover the equation from a record t, x with "
        "known forcing, and verify it by simulation",
    )
    d.add_argument("--data", required=True, help="CSV with columns t (uniform) and x")
    d.add_argument(
        "--model",
        choices=("negres", "duffing"),
        help="take the forcing B, nu from this model (override with --B, --nu)",
    )
    d.add_argument("--B", type=number(-1e3, 1e3), help="forcing amplitude")
    d.add_argument("--nu", type=number(0, 100, lo_open=True), help="forcing angular frequency, > 0")
    d.add_argument(
        "--noise",
        type=number(0, 1),
        help="known noise sd as a fraction of x's "
        "range (default: estimated from the smoothing residual)",
    )
    d.add_argument(
        "--threshold",
        type=number(0, 1),
        default=0.02,
        help="STLSQ threshold on scaled coefficients (default: %(default)g)",
    )
    d.add_argument(
        "--half-width",
        type=integer(2, 10**4),
        help="test-window half width in samples (default: a quarter period, at least 7)",
    )
    d.add_argument(
        "--fix-forcing",
        action="store_true",
        help="fix the forcing's coefficient at 1 instead of fitting it",
    )
    d.add_argument(
        "--bootstrap",
        type=integer(0, 10**5),
        default=200,
        help="block-bootstrap resamples for the standard errors (default: %(default)s)",
    )
    d.add_argument(
        "--block-periods",
        type=integer(1, 10**4),
        default=4,
        help="bootstrap block length in forcing periods (default: %(default)s)",
    )
    d.add_argument(
        "--model-periods",
        type=integer(50, 10**6),
        default=2000,
        help="periods of the discovered model simulated (default: %(default)s)",
    )
    d.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=200,
        help="periods of the discovered model discarded first (default: %(default)s)",
    )
    d.add_argument(
        "--resamples",
        type=integer(10, 10**5),
        default=200,
        help="random halves for the energy-distance noise floor (default: %(default)s)",
    )
    d.add_argument(
        "--seed", type=integer(0), default=0, help="seed of the resampling (default: %(default)s)"
    )
    d.add_argument("--out", required=True, help="output directory")
    d.set_defaults(func=run)
