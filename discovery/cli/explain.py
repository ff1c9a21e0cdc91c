"""``vidi explain``: name the physical effect a model misses, add it, show the gap shrink."""

import time

from .._files._drawer import drawing
from .._files._io import OutputDir
from . import _options
from ._common import (
    add_record_options,
    check_out,
    coefficients_line,
    criteria_line,
    data_entry,
    executor_of,
    machine_known,
    machine_scale,
    outputs_line,
    provenance_of,
    read_records,
    reporter,
)


def _final_loops(model, scenario, measurement, args):
    """``(loops, evaluation)`` of the final ``model`` against the first record (its
    force-penetration loops: :func:`~discovery.vibroimpact.verify.motion.
    force_penetration_loops`), None without positions."""
    from ..vibroimpact.verify import Reference, evaluate
    from ..vibroimpact.verify.motion import force_penetration_loops

    if isinstance(measurement, Reference):
        return None
    ref = Reference.from_measurement(measurement, scenario, n_boot=args.n_boot, seed=args.seed)
    ev = evaluate(model.apply(scenario, ref), model.law, ref, observe=model.observe())
    loops = force_penetration_loops(ref, ev)
    return None if loops is None else (loops, ev)


class _Figures:
    """The figures of one run, sent to the drawer as soon as the loop is over (explain's
    ``on_loop_end``): each iteration's, and the final model's loops against the first
    record, simulated here, drawn while the bootstrap intervals run (they had waited for
    the intervals: 0.5 s of the bench record's 8.8 s, and the drawing 0.8 s after them).
    ``files``: the names drawn, None until then."""

    def __init__(self, drawer, out, scenario, measurement, args):
        self.drawer, self.out, self.args = drawer, out, args
        self.scenario, self.measurement = scenario, measurement
        self.files = None

    def __call__(self, iterations, model):
        drawer, out, files = self.drawer, self.out, []
        for k, it in enumerate(iterations, start=1):
            stem = str(out.path(f"explain_{k}"))
            drawer.draw(stem, "explain_figure", it, it.measured, stem, k)
            files.append(f"explain_{k}.png/.pdf")
        loops = _final_loops(model, self.scenario, self.measurement, self.args)
        if loops is not None:
            stem = str(out.path("explain_loops"))
            drawer.draw(
                stem,
                "loops_figure",
                *loops,
                stem,
                model.law,
                "final model against the first record",
                note=model.changes(),
            )
            files.append("explain_loops.png/.pdf")
        self.files = files


#: what the drawer loads while the command computes: the figures and the results' modules
#: (:mod:`discovery._files._drawer`)
_FIGURES = ("explain_figure", "loops_figure")
_RESULTS = ("discovery.vibroimpact.explain.result",)


def run(args):
    check_out(args)
    with drawing(_FIGURES, _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ..catalogue import select
    from ..vibroimpact.explain import EFFECTS, explain
    from ..vibroimpact.explain.result import read_text

    t_start = time.perf_counter()
    effects = None
    if args.effects:
        effects = [e.strip() for e in args.effects.split(",") if e.strip()]
        select(EFFECTS, effects, where="--effects")
    scs, meas, machine = read_records(args)
    # the output directory is staged from here (removed, the earlier result untouched, if
    # the run fails) so that the figures are drawn into it while the intervals run
    with OutputDir(args.out) as out:
        figures = _Figures(drawer, out, scs[0], meas[0], args)
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
                machine_scale=machine_scale(machine),
                known=machine_known(machine),
                progress=rep,
                executor=ex,
                on_loop_end=figures,
            )
        head = {
            "command": "explain",
            "scenario": scs[0].as_dict(),
            "machine": machine,
            "data": data_entry(args.data),
        }
        tail = {"catalogue": [e.as_dict() for e in EFFECTS], "explain_settings": res.settings}
        tail["seconds"] = time.perf_counter() - t_start
        tail.update(provenance_of(args))
        res.record_run(head, tail).write_into(out)
        files = figures.files
    if (res.settings or {}).get("start_note"):
        print(f"start: {res.settings['start_note']}")
    for eid, r in (res.settings or {}).get("read", {}).items():
        print(f"read before the loop: {read_text(eid, r)}")
    for k, it in enumerate(res.iterations, start=1):
        name = it.effect or "nothing named"
        print(f"iteration {k}: {name}: {it.evidence}")
        if it.equivalent:
            print(f"  equally good: {', '.join(it.equivalent)}")
    fm = res.final_model
    print(f"final model: {fm}")
    if res.uncertainties:
        print(coefficients_line(_parameters(res, scs), res.uncertainties, res.intervals))
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
    print(outputs_line(args, ["summary.json", *files]))
    return 0


def _parameters(res, scenarios):
    """``{name: value}`` of the final model's parameters the printout shows: the law's, then
    every other one with a standard error or an interval (a mass loss, and the moulding's
    mass refitted with it)."""
    from ..vibroimpact.explain.effects import drift_fitted

    fm = res.final_model
    full = drift_fitted(fm, scenarios)
    known = set(res.uncertainties or {}) | set(getattr(res.intervals, "bounds", None) or {})
    return {
        n: c
        for n, c in zip(full.names, full.coefficients, strict=True)
        if n in fm.names or n in known
    }


def _catalogue():
    from ..vibroimpact.explain.effects import EFFECTS

    return EFFECTS


def register(sub):
    s = sub.add_parser(
        "explain",
        help="find where a model and a record disagree, name the "
        "missing physical effect, add it, refit, show the gap shrink",
    )
    _options.add_scenario_option(s, repeat=True)
    _options.add_data_option(
        s,
        "CSV with t, F, w1, w2 (v1, v2 recommended); repeat it to explain several records jointly",
        repeat=True,
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
    _options.add_criterion_option(s, "criterion of the refits")
    _options.add_effect_search_options(
        s,
        alpha_most=0.5,
        alpha_help="family-wise significance level of the score tests",
        max_iterations=10,
    )
    _options.add_max_simulations_option(s, least=10, most=100_000, default=150, of=" of each refit")
    _options.add_n_boot_option(s)
    _options.add_intervals_option(s, "the final model's 95 % parameter intervals")
    _options.add_seed_option(s, "seed of the noise-floor bootstrap and of the intervals")
    _options.add_interval_refit_option(s)
    _options.add_parallel_options(
        s, "the screening refits, the bootstrap intervals' refits and the record's blocks"
    )
    _options.add_out_option(s)
    s.set_defaults(func=run)
