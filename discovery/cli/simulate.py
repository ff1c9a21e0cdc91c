"""``vidi simulate``: a synthetic measurement CSV of a law's steady state."""

import json
import time
from pathlib import Path

from .._io import atomic_write_text, provenance, to_jsonable
from ..errors import InputError
from ..scenario import load_scenario
from ._common import LAW_HELP, SCENARIO_HELP, law_or_default


def run(args):
    from ..measurement import synthesize

    sc = load_scenario(args.scenario)
    law = law_or_default(args.law, sc)
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


def register(sub):
    s = sub.add_parser("simulate", help="write a synthetic measurement CSV of a law's "
                       "steady state")
    s.add_argument("--scenario", default="paper", help=SCENARIO_HELP)
    s.add_argument("--law", help=LAW_HELP)
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
    s.set_defaults(func=run)
