"""``vidi calibrate``: the machine as the record shows it."""

from .._files._drawer import drawing
from .._files._io import OutputDir
from ..errors import InputError
from . import _options
from ._common import (
    COLUMNS_HELP,
    check_out,
    data_entry,
    outputs_line,
    provenance_of,
    read_records,
)


def _keep(text):
    from ..vibroimpact.calibration import CALIBRATED

    names = [k.strip() for k in (text or "").split(",") if k.strip()]
    bad = [k for k in names if k not in CALIBRATED]
    if bad:
        raise InputError(
            f"--keep names {bad[0]!r}; give parameters of {', '.join(CALIBRATED)}, e.g. "
            "--keep c1,k1"
        )
    return tuple(names)


#: the figure and the result's module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_RESULTS = ("discovery.vibroimpact.calibration.result",)


def run(args):
    check_out(args)
    with drawing(["calibration_figure"], _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ..vibroimpact.calibration import calibrate

    keep = _keep(args.keep)
    scs, meas, _ = read_records(args, machine=False)
    res = calibrate(
        scs, meas, time_offset=args.time_offset, n_boot=args.n_boot, seed=args.seed, keep=keep
    )
    res.record_run({"command": "calibrate", "data": data_entry(args.data)}, provenance_of(args))
    files = ["summary.json"]
    with OutputDir(args.out) as out:
        res.write_into(out)
        if res.calibrated:
            for k, sc in enumerate(res.scenarios):
                name = "scenario.toml" if len(res.scenarios) == 1 else f"scenario_{k + 1}.toml"
                with open(out.path(name), "w", encoding="utf-8") as fh:
                    fh.write(sc.to_toml())
                files.append(name)
            if res.series is not None:  # a result made here has them (a loaded one not)
                stem = str(out.path("calibrate"))
                drawer.draw(stem, "calibration_figure", res, stem)
                files.append("calibrate.png/.pdf")
    print(res)
    print(outputs_line(args, files))
    return 0


def register(sub):
    s = sub.add_parser(
        "calibrate",
        help="the machine as the record shows it: masses, supports and drive estimated from "
        "the record's own motions and force, against the scenario's sheet",
    )
    _options.add_scenario_option(s, repeat=True, help_suffix=" (the designer's sheet)")
    _options.add_data_option(
        s,
        "CSV with t, F, w1, w2 (v1, v2 recommended); repeat it to calibrate one machine from "
        "several records (each its own drive amplitude)",
        repeat=True,
    )
    s.add_argument("--columns", metavar="MAP", help=COLUMNS_HELP)
    _options.add_time_offset_option(s)
    _options.add_n_boot_option(
        s, of="the parameters' intervals (over the record's cycles)", help_suffix=", 1..10000"
    )
    s.set_defaults(n_boot=200)
    _options.add_seed_option(s, "seed of the bootstrap, >= 0", most=None)
    s.add_argument(
        "--keep",
        metavar="NAMES",
        help="parameters held at the scenario's values, e.g. 'c1,k1' (of m1, c1, k1, k3, A, "
        "m2; default: none)",
    )
    _options.add_out_option(s)
    s.set_defaults(func=run)
    return s
