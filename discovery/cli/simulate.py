"""``vidi simulate``: a synthetic measurement CSV of a law's steady state.

Writes ``D.csv`` and ``D.summary.json`` (each atomically: temporary file + rename); the
summary records the sha256 of the CSV it describes (``outputs``), so a pair from two
different runs (a kill between the two renames) is detectable.
"""

import time

from ..errors import InputError
from ..vibroimpact.model.scenario import load_scenario
from . import _options
from ._common import (
    check_record_out,
    integer,
    law_or_default,
    number,
    provenance_of,
    write_record,
)


def run(args):
    from ..vibroimpact.data.measurement import MAX_SAMPLES
    from ..vibroimpact.dynamics.synthetic import SimulatedRecord, synthesize

    paths = out, summary_path = check_record_out(args)
    sc = load_scenario(args.scenario)
    law = law_or_default(args.law, sc)
    n = args.periods * sc.period * args.fs
    if n > MAX_SAMPLES:
        raise InputError(
            f"--periods {args.periods} at --fs {args.fs:g} Hz is {n:.3g} samples; "
            f"the limit is {MAX_SAMPLES:.0e}: lower --fs or --periods"
        )
    if n < 8:
        raise InputError(
            f"--periods {args.periods} at --fs {args.fs:g} Hz is only {n:.3g} "
            "samples; raise --fs or --periods"
        )
    t0 = time.perf_counter()
    meas = synthesize(
        sc,
        law,
        periods=args.periods,
        fs=args.fs,
        noise=args.noise,
        seed=args.seed,
        from_rest=args.from_rest,
        position_noise=args.position_noise,
        velocities=not args.no_velocities,
        integrator=args.integrator,
    )
    csv_text = meas.to_csv_text()
    summary = SimulatedRecord.of(
        sc,
        law,
        out.name,
        csv_text,
        samples=int(meas.t.size),
        seconds=time.perf_counter() - t0,
    ).record_run({"command": "simulate"}, provenance_of(args))
    write_record(paths, csv_text, summary)
    print(
        f"wrote {out} ({meas.t.size} samples, {args.periods} periods at {args.fs:g} Hz, "
        f"noise {args.noise:g}) and {summary_path}"
    )
    return 0


def register(sub):
    s = sub.add_parser("simulate", help="write a synthetic measurement CSV of a law's steady state")
    _options.add_scenario_option(s)
    _options.add_law_option(s)
    s.add_argument(
        "--periods",
        type=integer(1, 100_000),
        default=20,
        help="drive periods recorded (default: %(default)s)",
    )
    s.add_argument(
        "--fs",
        type=number(0, 1e8, lo_open=True, unit="Hz"),
        default=20000.0,
        help="sampling rate in Hz (default: %(default)g)",
    )
    s.add_argument(
        "--noise",
        type=number(0, 1),
        default=0.0,
        help="Gaussian noise on F as a fraction of the peak force, 0..1 (default: %(default)g)",
    )
    _options.add_seed_option(s, "noise seed, >= 0", most=None)
    s.add_argument(
        "--from-rest",
        action="store_true",
        help="record from the initial state (run-up with impacts at many "
        "velocities, then the steady state) instead of on the periodic orbit",
    )
    s.add_argument(
        "--position-noise",
        type=number(0, 1),
        default=0.0,
        help="Gaussian noise on w1, w2 as a fraction of the largest penetration, "
        "0..1 (default: %(default)g)",
    )
    s.add_argument(
        "--integrator",
        choices=("compiled", "scipy"),
        default="compiled",
        help="compiled: the kernel every fit uses; scipy: the independent slow "
        "path (scipy DOP853 restarted at every contact event), for records the "
        "fitting kernel did not make (default: %(default)s)",
    )
    s.add_argument(
        "--no-velocities",
        action="store_true",
        help="leave out the v1, v2 columns (discovery then differentiates w1 - w2)",
    )
    _options.add_out_option(s, "output CSV (t, F, w1, v1, w2, v2)")
    s.set_defaults(func=run)
