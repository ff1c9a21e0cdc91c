"""``vidi verify``: is a law consistent with a record?"""



from .._io import OutputDir, provenance
from ..errors import InputError
from ..scenario import load_scenario
from ._common import LAW_HELP, SCENARIO_HELP, law_or_default


def run(args):
    from reports import verify_figure

    from ..measurement import Measurement
    from ..verify import verify

    if args.law is not None and not args.law.strip():
        raise InputError("--law is empty; give a law such as '2.06e8*z + 1.28e7*zd' or leave "
                         "the option out to use the scenario's law")
    if args.n_boot < 1:
        raise InputError(f"--n-boot must be at least 1, got {args.n_boot}")
    sc = load_scenario(args.scenario)
    law = law_or_default(args.law, sc)
    meas = Measurement.from_csv(args.data, scenario=sc)
    for note in meas.notes:
        print(f"note: {note}")
    res = verify(sc, meas, law, time_offset=args.time_offset, n_boot=args.n_boot,
                 seed=args.seed, check_default_start=not args.no_default_start)
    summary = {"command": "verify", "scenario": sc.as_dict(), "data": str(args.data),
               **res.as_dict(), "verify_settings": res.settings, **provenance(vars(args))}
    with OutputDir(args.out) as out:
        out.write_json("summary.json", summary)
        verify_figure(res, str(out.path("verify")))
    ev = res.evaluation
    print(f"{law}: {res.verdict}")
    print(f"  regime measured {ev.regime['measured']} ({ev.impacts['measured']} contact(s)), "
          f"simulated {ev.regime['simulated'] or ev.status} "
          f"({ev.impacts['simulated']} contact(s))")
    if ev.criteria:
        print("  criteria (noise floor): " + ", ".join(
            f"{k} {v:.3g} ({ev.noise_floor[k]:.2g})" for k, v in ev.criteria.items()))
    for note in res.notes:
        print(f"  note: {note}")
    print(f"outputs in {args.out}/: summary.json, verify.png, verify.pdf")
    return 0


def register(sub):
    s = sub.add_parser("verify", help="is a law consistent with a record? full simulation, "
                       "criteria I0..I4 against their noise floor")
    s.add_argument("--scenario", default="paper", help=SCENARIO_HELP)
    s.add_argument("--data", required=True, help="CSV with t [s], F [N] (w1, v1, w2, v2 "
                   "recommended: exact onsets and the machine's state)")
    s.add_argument("--law", help=LAW_HELP)
    s.add_argument("--time-offset", type=float, default=0.0,
                   help="drive-clock time [s] of the record's t = 0, when the record does not "
                   "start at drive phase 0 (0)")
    s.add_argument("--n-boot", type=int, default=16,
                   help="bootstrap replicates of the noise floor (16)")
    s.add_argument("--seed", type=int, default=0, help="seed of the bootstrap (0)")
    s.add_argument("--no-default-start", action="store_true",
                   help="skip the check of the attractor reached from the scenario's "
                   "initial state")
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=run)
