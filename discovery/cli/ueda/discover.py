"""``vidi ueda discover``: the equation recovered from a record with known forcing (weak-form
sparse regression, bootstrap standard errors), verified by simulation against the record's
attractor."""

from dataclasses import replace

import numpy as np

from ..._files._drawer import drawing
from ..._files._io import OutputDir
from .. import _options
from .._common import check_out, integer, number, outputs_line, provenance_of
from . import _record
from ._system import _add_forcing_options, _forcing

#: the figures and the results' module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_FIGURES = ("ueda.figures.discover_figure",)
_RESULTS = ("discovery.ueda.equation_discovery", "discovery.ueda.verification")


def run(args):
    check_out(args)
    with drawing(_FIGURES, _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ...ueda.equation_discovery import discover
    from ...ueda.record import read_record_csv
    from ...ueda.verification import verify

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
            **provenance_of(args, counted=False),
        },
        settings_key="discovery_settings",
    )
    with OutputDir(args.out, inputs=[args.data]) as out:
        stem = str(out.path("discover"))
        drawer.draw(stem, _FIGURES[0], d, ver, stem)
        _record.write_strobe(out.path("strobe_record.csv"), ver.record_strobe)
        _record.write_strobe(out.path("strobe_model.csv"), ver.model_strobe)
        d.write_into(out)
    print(f"discovered: {d.model.text()}")
    _record.print_coefficients(d)
    L = ver.lyapunov
    lyap = f"{L['value']:.4f} +- {L['stderr']:.4f}" if L else "n/a"
    print(
        f"verification: energy distance {ver.energy_distance:.4g} vs floor q95 "
        f"{ver.floor_q95:.4g} ({ver.floor_block_periods}-period blocks); regime record "
        f"{ver.regime_record}, model "
        f"{ver.regime_model}; model lyapunov {lyap}: "
        f"{'consistent' if ver.consistent else 'INCONSISTENT'}"
    )
    files = ["discover.png", "discover.pdf", "strobe_record.csv", "strobe_model.csv"]
    print(outputs_line(args, ["summary.json", *files]))
    return 0


def register(sub):
    """Add ``vidi ueda discover`` to the ueda subparsers ``sub``."""
    d = sub.add_parser(
        "discover",
        help="recover the equation from a record t, x with "
        "known forcing, and verify it by simulation",
    )
    _options.add_data_option(d, _record.RECORD_HELP)
    _add_forcing_options(d)
    _record.add_noise_option(d)
    d.add_argument(
        "--threshold",
        type=number(0, 1),
        default=0.02,
        help="STLSQ threshold on scaled coefficients (default: %(default)g)",
    )
    _record.add_weak_form_options(d)
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
    _record.add_verification_options(d, "the discovered model")
    _options.add_out_option(d)
    d.set_defaults(func=run)
