"""``vidi verify``: is a law consistent with a record?"""

from .._files._drawer import drawing
from .._files._io import OutputDir
from ..vibroimpact.model.scenario import load_scenario
from . import _options
from ._common import (
    add_record_options,
    check_out,
    criteria_line,
    law_or_default,
    machine_for,
    machine_scale,
    outputs_line,
    provenance_of,
    read_record,
    sensor_lag_of,
)

#: the results' modules the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_RESULTS = ("discovery.vibroimpact.verify.verdict",)


def run(args):
    check_out(args)
    with drawing(["verify_figure"], _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ..vibroimpact.verify import verify

    sc = load_scenario(args.scenario)
    law = law_or_default(args.law, sc)
    meas = read_record(args, sc)
    for note in meas.notes:
        print(f"note: {note}")
    (sc,), machine = machine_for(args, [sc], [meas], args.time_offset)
    res = verify(
        sc,
        meas,
        law,
        time_offset=args.time_offset,
        n_boot=args.n_boot,
        seed=args.seed,
        check_default_start=not args.no_default_start,
        machine_scale=machine_scale(machine),
        sensor_lag=sensor_lag_of(args, machine),
    )
    res.record_run(
        {
            "command": "verify",
            "scenario": sc.as_dict(),
            "machine": machine,
            "data": str(args.data),
        },
        provenance_of(args),
    )
    with OutputDir(args.out) as out:
        res.write_into(out)
        stem = str(out.path("verify"))
        drawer.draw(stem, "verify_figure", res, stem)
    ev = res.evaluation
    print(f"{law}: {res.verdict}")
    print(f"  {res.regime_line()}")
    if ev.criteria:
        print(criteria_line(ev.criteria, ev.noise_floor))
    for note in res.notes:
        print(f"  note: {note}")
    print(outputs_line(args, ["summary.json", "verify.png", "verify.pdf"]))
    return 0


def register(sub):
    s = sub.add_parser(
        "verify",
        help="is a law consistent with a record? full simulation, "
        "criteria I0..I4 (force) and I5 (penetration, with positions) against their noise floors",
    )
    _options.add_scenario_option(s)
    _options.add_data_option(s)
    _options.add_law_option(s)
    add_record_options(s)
    _options.add_time_offset_option(s)
    _options.add_n_boot_option(s, help_suffix=", 1..10000")
    _options.add_seed_option(s, "seed of the bootstrap, >= 0", most=None)
    s.add_argument(
        "--no-default-start",
        action="store_true",
        help="skip the check of the attractor reached from the scenario's initial state",
    )
    _options.add_sensor_lag_option(s)
    _options.add_out_option(s)
    s.set_defaults(func=run)
