"""``vidi ueda simulate``: a noisy record t, x (CSV) of a model, for discover."""

import numpy as np

from ..._io import provenance
from ...errors import InputError
from .._common import check_out, integer, number
from ._system import _add_system_options, _system


def run(args):
    import json
    import time

    from ..._io import atomic_write_text, check_output
    from ...ueda.record import simulate_record
    from ...ueda.simulated_record import SimulatedUedaRecord

    out = check_out(args, kind="file")
    if out.suffix.lower() != ".csv":
        raise InputError(f"--out {args.out!r} must name a .csv file, e.g. D.csv")
    summary_path = out.with_suffix(".summary.json")
    check_output(summary_path, [], kind="file", option="--out's summary")
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
    atomic_write_text(out, csv_text)
    atomic_write_text(summary_path, json.dumps(summary.to_dict(), indent=2) + "\n")
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
    m.add_argument("--seed", type=integer(0), default=0, help="noise seed (default: %(default)s)")
    m.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=200,
        help="periods discarded before the record (default: %(default)s)",
    )
    m.add_argument(
        "--x0", type=number(-1e3, 1e3), default=0.1, help="initial x (default: %(default)g)"
    )
    m.add_argument(
        "--v0", type=number(-1e3, 1e3), default=0.0, help="initial x' (default: %(default)g)"
    )
    m.add_argument(
        "--integrator",
        choices=("compiled", "scipy"),
        default="compiled",
        help="compiled (Dormand-Prince kernel) or scipy (solve_ivp DOP853, the "
        "independent path) (default: %(default)s)",
    )
    m.add_argument(
        "--out",
        required=True,
        help="output CSV (columns t, x); the summary goes to OUT.summary.json",
    )
    m.set_defaults(func=run)
