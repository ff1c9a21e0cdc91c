"""``vidi explain``: name the physical effect a model misses, add it, show the gap shrink."""

import time

from .._io import OutputDir, provenance
from ..vibroimpact.verify.criteria import CRITERIA
from ._common import (
    SCENARIO_HELP,
    SCHEDULER_HELP,
    add_interval_refit_option,
    add_record_options,
    add_workers_option,
    check_out,
    coefficients_line,
    criteria_line,
    executor_of,
    inputs_of,
    integer,
    interval_count,
    number,
    read_records,
    reporter,
)


def _final_loops(res, scenario, measurement, args):
    """``(loops, evaluation)`` of the final model against the first record (its
    force-penetration loops: :func:`~discovery.vibroimpact.verify.motion.
    force_penetration_loops`), None without positions."""
    from ..vibroimpact.verify import Reference, evaluate
    from ..vibroimpact.verify.motion import force_penetration_loops

    if isinstance(measurement, Reference):
        return None
    fm = res.final_model
    ref = Reference.from_measurement(measurement, scenario, n_boot=args.n_boot, seed=args.seed)
    ev = evaluate(fm.apply(scenario), fm.law, ref, observe=fm.observe())
    loops = force_penetration_loops(ref, ev)
    return None if loops is None else (loops, ev)


def run(args):
    from reports import explain_figure, loops_figure

    from ..catalogue import select
    from ..vibroimpact.explain import EFFECTS, explain

    t_start = time.perf_counter()
    check_out(args)
    data = args.data
    effects = None
    if args.effects:
        effects = [e.strip() for e in args.effects.split(",") if e.strip()]
        select(EFFECTS, effects, where="--effects")
    scs, meas = read_records(args)
    with reporter(args) as rep, executor_of(args) as ex:
        res = explain(
            scs,
            meas,
            args.start,
            criterion=args.criterion,
            alpha=args.alpha,
            max_iterations=args.max_iterations,
            max_simulations=args.max_simulations,
            n_boot=args.n_boot,
            seed=args.seed,
            effects=effects,
            workers=args.workers,
            n_boot_intervals=args.intervals,
            interval_refit=args.interval_refit,
            progress=rep,
            executor=ex,
        )
    head = {
        "command": "explain",
        "scenario": scs[0].as_dict(),
        "data": [str(p) for p in data] if len(data) > 1 else str(data[0]),
    }
    tail = {"catalogue": [e.as_dict() for e in EFFECTS], "explain_settings": res.settings}
    loops = _final_loops(res, scs[0], meas[0], args)
    with OutputDir(args.out) as out:
        files = []
        for k, it in enumerate(res.iterations, start=1):
            explain_figure(it, it.measured, str(out.path(f"explain_{k}")), k)
            files.append(f"explain_{k}.png/.pdf")
        if loops is not None:
            loops_figure(
                *loops,
                str(out.path("explain_loops")),
                res.final_model.law,
                "final model against the first record",
            )
            files.append("explain_loops.png/.pdf")
        tail["seconds"] = time.perf_counter() - t_start
        tail.update(provenance(vars(args), inputs=inputs_of(args)))
        res.record_run(head, tail).write_into(out)
    for k, it in enumerate(res.iterations, start=1):
        name = it.effect or "nothing named"
        print(f"iteration {k}: {name}: {it.evidence}")
        if it.equivalent:
            print(f"  equally good: {', '.join(it.equivalent)}")
    fm = res.final_model
    print(f"final model: {fm}")
    if res.uncertainties:
        print(
            coefficients_line(
                dict(zip(fm.names, fm.coefficients, strict=True)), res.uncertainties, res.intervals
            )
        )
    if res.criteria:
        print(criteria_line(res.criteria, res.noise_floor))
    print(
        f"  {'consistent' if res.consistent else 'not consistent'} with the record(s); "
        f"stopped because {res.stopped_because}"
    )
    for s in res.separability:
        how = s.get("note") or (
            f"{s['criterion']} {s['before']:.3g} -> {s['after']:.3g} "
            f"refitted with it, noise floor {s['floor']:.3g}"
        )
        print(
            f"  {s['effect']}: {'separable' if s['separable'] else 'not separable'} by this "
            f"record ({how})"
        )
    print(f"outputs in {args.out}/: summary.json" + "".join(f", {f}" for f in files))
    return 0


def _catalogue():
    from ..vibroimpact.explain.effects import EFFECTS

    return EFFECTS


def register(sub):
    s = sub.add_parser(
        "explain",
        help="find where a model and a record disagree, name the "
        "missing physical effect, add it, refit, show the gap shrink",
    )
    s.add_argument(
        "--scenario",
        action="append",
        help=SCENARIO_HELP + "; repeat it, once per --data in the same order",
    )
    s.add_argument(
        "--data",
        required=True,
        action="append",
        help="CSV with t, F, w1, w2 (v1, v2 recommended); repeat it to explain "
        "several records jointly",
    )
    add_record_options(s)
    s.add_argument(
        "--start",
        default="linear",
        help="start model: 'linear' (z, zd), a term list 'z,zd,z^1.5' (start values "
        "from the regression and the record) or a law with coefficients "
        "(default: %(default)s)",
    )
    s.add_argument(
        "--effects",
        help="comma-separated catalogue ids to consider (default: all "
        "of " + ", ".join(e.id for e in _catalogue()) + ")",
    )
    s.add_argument(
        "--criterion",
        default="I2",
        choices=list(CRITERIA),
        help="criterion of the refits (default: %(default)s)",
    )
    s.add_argument(
        "--alpha",
        type=number(0.0, 0.5, lo_open=True),
        default=0.01,
        help="family-wise significance level of the score tests (default: %(default)g)",
    )
    s.add_argument(
        "--max-iterations",
        type=integer(0, 10),
        default=3,
        help="effects added at most (default: %(default)s)",
    )
    s.add_argument(
        "--max-simulations",
        type=integer(10, 100_000),
        default=150,
        help="simulation budget of each refit (default: %(default)s)",
    )
    s.add_argument(
        "--n-boot",
        type=integer(1, 10_000),
        default=16,
        help="bootstrap replicates of the noise floor (default: %(default)s)",
    )
    s.add_argument(
        "--intervals",
        type=interval_count,
        default=30,
        help="bootstrap replicates of the final model's 95 %% parameter intervals "
        "through the full processing (0 = none) (default: %(default)s)",
    )
    s.add_argument(
        "--seed",
        type=integer(0, 2**32 - 1),
        default=0,
        help="seed of the noise-floor bootstrap (default: %(default)s)",
    )
    add_interval_refit_option(s)
    add_workers_option(s, "the screening refits and the bootstrap intervals' refits")
    s.add_argument("--scheduler", metavar="ADDR", help=SCHEDULER_HELP)
    s.add_argument("--out", required=True, help="output directory")
    s.set_defaults(func=run)
