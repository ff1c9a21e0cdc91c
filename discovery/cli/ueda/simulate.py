"""``vidi ueda simulate``: a noisy record t, x (CSV) of a model, for discover."""

import numpy as np

from ..._files._io import provenance
from ...errors import InputError
from .. import _options
from .._common import check_record_out, integer, number, write_record
from ._system import _add_start_options, _add_system_options, _system


def run(args):
    import time

    from ...ueda.record import simulate_record
    from ...ueda.simulated_record import SimulatedUedaRecord

    paths = out, summary_path = check_record_out(args)
    n = args.periods * args.samples_per_period
    if n > 10_000_000:
        raise InputError(
            f"--periods {args.periods} x --samples-per-period "
            f"{args.samples_per_period} is {n} samples; the limit is 1e7"
        )
    system = _system(args)
    t0 = time.perf_counter()
    t, x, xc, _ = simulate_record(
        system,
        args.periods,
        args.samples_per_period,
        args.noise,
        args.seed,
        transient=args.transient,
        y0=(args.x0, args.v0),
        integrator=args.integrator,
        rtol=args.rtol,
    )
    if not np.all(np.isfinite(x)):
        raise InputError("the simulation produced non-finite values; check the parameters")
    lines = ["t,x"] + [f"{a:.12g},{b:.12g}" for a, b in zip(t, x, strict=True)]
    csv_text = "\n".join(lines) + "\n"
    summary = SimulatedUedaRecord.of(
        system,
        xc,
        args.noise,
        out.name,
        csv_text,
        samples=int(t.size),
        periods=args.periods,
        samples_per_period=args.samples_per_period,
        integrator=args.integrator,
        seconds=time.perf_counter() - t0,
    ).record_run({"command": "ueda simulate"}, provenance(vars(args)))
    write_record(paths, csv_text, summary)
    print(
        f"wrote {out} ({t.size} samples, {args.periods} periods of {system.model}, "
        f"{args.samples_per_period} samples per period, noise {args.noise:g} of the range) "
        f"and {summary_path}"
    )
    return 0


def register(sub):
    """Add ``vidi ueda simulate`` to the ueda subparsers ``sub``."""
    m = sub.add_parser("simulate", help="a noisy record t, x (CSV) of a model, for discover")
    _add_system_options(m)
    m.set_defaults(rtol=1e-10)
    m.add_argument(
        "--periods",
        type=integer(2, 10**6),
        default=200,
        help="forcing periods recorded (default: %(default)s)",
    )
    m.add_argument(
        "--samples-per-period",
        type=integer(8, 10**4),
        default=40,
        help="samples per forcing period (default: %(default)s)",
    )
    m.add_argument(
        "--noise",
        type=number(0, 1),
        default=0.0,
        help="Gaussian noise on x, standard deviation as a fraction of x's range, "
        "0..1 (default: %(default)g)",
    )
    _options.add_seed_option(m, "noise seed", most=None)
    m.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=200,
        help="periods discarded before the record (default: %(default)s)",
    )
    _add_start_options(m)
    m.add_argument(
        "--integrator",
        choices=("compiled", "scipy"),
        default="compiled",
        help="compiled (Dormand-Prince kernel) or scipy (solve_ivp DOP853, the "
        "independent path) (default: %(default)s)",
    )
    _options.add_out_option(m, "output CSV (columns t, x); the summary goes to OUT.summary.json")
    m.set_defaults(func=run)
