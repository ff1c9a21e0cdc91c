"""``vidi advise``: where should the next record be taken to separate the candidate laws?"""

from .._files._drawer import drawing
from .._files._io import OutputDir
from ..errors import InputError
from . import _options
from ._common import (
    add_record_options,
    check_out,
    executor_of,
    integer,
    machine_for,
    number,
    outputs_line,
    parse_range,
    provenance_of,
    read_record,
    reporter,
)
from .advise_loop import add_loop_options


def _grid(text):
    from ..vibroimpact.verify.criteria_landscape import parse_grid

    return parse_grid(text)


def _candidates(args):
    """``(laws, scenario name from the fit or None)``."""
    from ..vibroimpact.advise.candidates import candidates_from_fit, unique_laws
    from ..vibroimpact.model.contact_models import parse_law

    if args.fit is not None and args.law:
        raise InputError("give either --fit DIR or --law (twice or more), not both")
    if args.fit is not None:
        return candidates_from_fit(args.fit)
    if not args.law:
        raise InputError(
            "no candidates: give --fit DIR (a vidi fit run with equivalent models) or "
            "--law twice or more, e.g. --law '2e8*z + 1e7*zd' --law '2e8*z + 5e9*z*zd'"
        )
    return unique_laws([parse_law(t) for t in args.law]), None


def _noise(args, sc):
    from ..vibroimpact.advise.candidates import NoiseModel

    if (args.data is None) == (args.noise is None):
        raise InputError(
            "give the noise level either from a record (--data D.csv) or as --noise "
            "(a fraction of the peak force, e.g. 0.01), not both and not neither"
        )
    if args.data is not None:
        given = [
            o
            for o, v in (
                ("--position-noise", args.position_noise),
                ("--sample-rate", args.sample_rate),
                ("--periods", args.periods),
            )
            if v is not None
        ]
        if given:
            raise InputError(
                f"{', '.join(given)} describe(s) a next record given by --noise; with --data "
                "the record's own noise, sampling and length are used: drop "
                f"{' and '.join(given)}"
            )
        meas = read_record(args, sc)
        for note in meas.notes:
            print(f"note: {note}")
        (sc,), machine = machine_for(args, [sc], [meas])
        noise = NoiseModel.from_measurement(meas, sc, n_boot=args.n_boot, seed=args.seed)
        return noise, sc, machine
    return (
        NoiseModel(
            relative=args.noise,
            dt=1.0 / (args.sample_rate or 20000.0),
            periods=args.periods or 12.0,
            n_boot=args.n_boot,
            seed=args.seed,
            source="given as a fraction of the peak force",
            position=args.position_noise,
        ),
        sc,
        None,
    )


def _knobs(args):
    from ..vibroimpact.advise.candidates import Knobs

    amp = parse_range(args.amplitude, None, "--amplitude")
    freq = parse_range(args.frequency, None, "--frequency")
    m2 = parse_range(args.m2, None, "--m2")
    for name, (lo, _) in (("--amplitude", amp), ("--frequency", freq), ("--m2", m2 or (1, 1))):
        if lo <= 0:
            raise InputError(f"{name} needs positive bounds LOW:HIGH, got a low of {lo:g}")
    return Knobs(amp, freq, m2, grid=_grid(args.grid), refine=args.refine)


def _until_settled(args, knobs, safe):
    from ..vibroimpact.model.scenario import load_scenario
    from .advise_loop import run_loop

    given = [
        o
        for o, v in (
            ("--fit", args.fit),
            ("--law", args.law),
            ("--noise", args.noise),
            ("--position-noise", args.position_noise),
            ("--sample-rate", args.sample_rate),
            ("--periods", args.periods),
            ("--scheduler", getattr(args, "scheduler", None)),
        )
        if v is not None and v != []
    ]
    if given:
        raise InputError(
            f"--until-settled fits its own records, takes their noise and runs on this "
            f"machine's processes: leave out {' and '.join(given)} (the first record is "
            "--data, the fits' terms --library, the processes --workers)"
        )
    if args.data is None or args.acquire is None:
        raise InputError(
            "--until-settled needs the first record (--data D.csv) and the command that "
            'takes the next ones (--acquire CMD, e.g. "python rig.py --A {amplitude} '
            '--f {frequency} --out {out}")'
        )
    return run_loop(args, load_scenario(args.scenario or "paper"), knobs, safe)


#: the results' module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_RESULTS = ("discovery.vibroimpact.advise.result",)


def run(args):
    check_out(args)
    if args.until_settled:
        return _until_settled(args, _knobs(args), _safe(args))
    with drawing(["advise_figure"], _RESULTS) as drawer:
        return _run(args, drawer)


def _safe(args):
    from ..vibroimpact.advise import SafeRegion

    return SafeRegion(args.max_force, args.max_penetration)


def _run(args, drawer):
    from ..vibroimpact.advise import advise
    from ..vibroimpact.advise.candidates import fit_scenario_changed
    from ..vibroimpact.advise.result import point_lines
    from ..vibroimpact.model.scenario import load_scenario

    knobs, safe = _knobs(args), _safe(args)
    laws, fit_scenario = _candidates(args)
    if args.fit is not None and not args.scenario and fit_scenario:
        changed = fit_scenario_changed(args.fit, fit_scenario)
        if changed:
            raise InputError(changed)
        args.scenario = fit_scenario  # recorded in the run's inputs, with its checksum
    try:
        sc = load_scenario(args.scenario or fit_scenario or "paper")
    except InputError as exc:
        if args.scenario:
            raise
        raise InputError(
            f"the fit's scenario {fit_scenario!r} cannot be loaded here ({exc}); give "
            "--scenario (a built-in name or the fit's TOML file)"
        ) from None
    noise, sc, machine = _noise(args, sc)
    with reporter(args) as rep, executor_of(args) as ex:
        res = advise(
            sc,
            laws,
            knobs,
            noise,
            safe,
            workers=args.workers,
            refit_simulations=args.refit_simulations,
            progress=rep,
            executor=ex,
        )
    prov = provenance_of(args)
    prov["settings"] = {**res.settings, **prov["settings"]}
    with OutputDir(args.out) as out:
        res.record_run({"machine": machine} if machine else None, prov).write_into(out)
        stem = str(out.path("advise_map"))
        drawer.draw(stem, "advise_figure", res, stem)
    print(res)
    for k, p in enumerate(res.ranked()[1:4], start=2):
        print(f"rank {k}: A = {p.amplitude:.4g} N, f = {p.frequency:.4g} Hz")
        print("\n".join(point_lines(p, res)[: len(p.pairs)]))
    print(outputs_line(args, ["summary.json", "advise.csv", "advise_map.png/.pdf"]))
    return 0


#: ``vidi advise --help``'s description
DESCRIPTION = (
    "Simulate every candidate law to its steady state over a grid of the "
    "drive amplitude and frequency (optionally the moulding mass), judge every pair by "
    "the verdict's rule (criteria I2, I4, and I5 where positions are recorded, against "
    "their noise-floor limits at the record's noise level), and rank the points by the "
    "smallest pair separation (>= 1: a record there rejects the false law of every "
    "pair). Points where a candidate exceeds --max-force or --max-penetration are "
    "excluded. With --until-settled: the experiment loop, each next record taken by "
    "--acquire CMD, until one law remains."
)


def register(sub):
    s = sub.add_parser(
        "advise",
        help="the operating point (drive amplitude, frequency) where a next record "
        "separates the laws a record cannot tell apart; --until-settled runs the whole loop "
        "of fit, advice and record",
        description=DESCRIPTION,
    )
    s.add_argument(
        "--fit",
        metavar="DIR",
        help="a vidi fit run: its law and equivalent models (with --library contact-models: "
        "its selected named model and those it reports equivalent)",
    )
    s.add_argument(
        "--law",
        action="append",
        help="a candidate law or named contact model, e.g. 'flores: k=1.4e9, n=1.3, "
        "e=0.45' (repeat: two or more), instead of --fit",
    )
    s.add_argument(
        "--scenario",
        help=_options.SCENARIO_HELP.replace(
            "(default: paper)", "(default: the fit's; with --law, paper)"
        ),
    )
    s.add_argument(
        "--data",
        help="the record whose noise level the next one will have (with --until-settled: "
        "the loop's first record, taken at the --scenario's drive amplitude and frequency)",
    )
    add_record_options(s).needs = "--data"
    s.add_argument(
        "--noise",
        type=number(0, 1, lo_open=True),
        help="force noise as a fraction of the peak force, instead of --data (e.g. 0.01)",
    )
    s.add_argument(
        "--position-noise",
        type=number(0, 1, lo_open=True),
        help="with --noise: the next record also holds positions w1, w2 with this noise (a "
        "fraction of the largest penetration); the pairs are then judged by I2, I4 and I5 "
        "(default: a force record, I2 and I4; with --data: as the record)",
    )
    s.add_argument(
        "--sample-rate",
        type=number(1, 1e9, unit="Hz"),
        help="with --noise: the next record's sampling rate [Hz] (default: 20000)",
    )
    s.add_argument(
        "--periods",
        type=number(1, 1e5),
        help="with --noise: drive periods the next record holds (default: 12)",
    )
    s.add_argument(
        "--amplitude", required=True, help="drive amplitude bounds LOW:HIGH [N], e.g. 3e5:6e5"
    )
    s.add_argument(
        "--frequency", required=True, help="drive frequency bounds LOW:HIGH [Hz], e.g. 20:30"
    )
    s.add_argument("--m2", help="moulding mass bounds LOW:HIGH [kg] (default: the scenario's)")
    s.add_argument(
        "--max-force",
        type=number(0, lo_open=True, unit="N"),
        help="largest safe peak force [N] (default: none, no bound)",
    )
    s.add_argument(
        "--max-penetration",
        type=number(0, lo_open=True, unit="m"),
        help="largest safe penetration w1 - w2 [m] (default: none, no bound)",
    )
    s.add_argument(
        "--grid", default="5x5", help="coarse points over amplitude x frequency (default: 5x5)"
    )
    s.add_argument(
        "--refine",
        type=integer(0, 100),
        default=3,
        help="best coarse points refined by a 3x3 grid at half the spacing (default: 3)",
    )
    s.add_argument(
        "--refit-simulations",
        type=integer(0, 10_000),
        default=40,
        help="simulations of each rival's refit at the advised point, where every pair is "
        "judged again with each rival refitted to the other's predicted record; 0: none "
        "(default: %(default)s)",
    )
    add_loop_options(s)
    _options.add_n_boot_option(s, of="each noise floor")
    _options.add_seed_option(s, "seed of the noise floors' bootstrap")
    _options.add_parallel_options(s)
    _options.add_out_option(s)
    s.set_defaults(func=run)
