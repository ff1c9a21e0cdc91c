"""``vidi ueda``: Ueda's forced oscillators (the second system).

``vidi ueda attractor`` - one attractor: strobe points, the two Lyapunov exponents with
standard errors, the regime with its evidence, figures (optionally the coexisting
attractors from a grid of initial states).  ``vidi ueda chart`` - the regime chart over
``(nu, B)`` in parallel processes.  ``vidi ueda simulate`` - a noisy record ``t, x`` (CSV)
of a model.  ``vidi ueda discover`` - the equation recovered from a record with known
forcing (weak-form sparse regression, bootstrap standard errors), verified by simulation
against the record's attractor (energy distance of strobe points against a noise floor,
Lyapunov exponent, regime).  ``vidi ueda explain`` - the missing-effect workflow: from a
start model (default negres without its van der Pol damping), name the missing effect of
this system's catalogue by score tests, add it, refit, and show the gap shrink.
"""

import argparse
import csv
from dataclasses import replace

import numpy as np

from .._io import OutputDir, provenance
from ..errors import InputError
from ._common import SCHEDULER_HELP, check_out, executor_of, integer, number, reporter

_PARAMS = ("mu", "gamma", "k", "B", "nu")


def _system(args, **fixed):
    from ..oscillator import UedaSystem

    over = {p: getattr(args, p, None) for p in _PARAMS}
    over.update(fixed)
    return UedaSystem.from_model(args.model, **over)


def _tolerances(args):
    from ..dynamics import Tolerances

    return Tolerances(rtol=args.rtol)


def run_attractor(args):
    from reports.ueda_figures import attractor_figure, basins_figure

    from ..oscillator import attractor, basins

    check_out(args)
    system = _system(args)
    tol = _tolerances(args)
    att = attractor(
        system,
        (args.x0, args.v0),
        transient=args.transient,
        periods=args.periods,
        batches=args.batches,
        tolerances=tol,
    )
    summary = {"command": "ueda attractor", **att.as_dict()}
    bas = None
    if args.basins:
        bas = basins(
            system,
            (-args.grid_extent, args.grid_extent),
            (-args.grid_extent, args.grid_extent),
            n=args.basins,
            tolerances=tol,
        )
        summary["coexisting_attractors"] = bas.as_dict()
    summary.update(provenance(vars(args)))
    files = ["summary.json", "attractor.png", "attractor.pdf"]
    with OutputDir(args.out) as out:
        attractor_figure(att, str(out.path("attractor")))
        np.savetxt(out.path("strobe.csv"), att.strobe, delimiter=",", header="x,v", comments="")
        files.append("strobe.csv")
        if bas is not None:
            basins_figure(bas, str(out.path("basins")))
            files += ["basins.png", "basins.pdf"]
        out.write_json("summary.json", summary)
    L = att.lyapunov
    print(f"{system.model}: {att.regime.regime} ({att.regime.evidence['rule']})")
    print(
        f"  lyapunov {L.value:.4f} +- {L.stderr:.4f}, second {L.second:.4f} +- "
        f"{L.second_stderr:.4f} per unit time; sum {L.sum:.6f} vs mean trace "
        f"{L.trace_mean:.6f}"
    )
    if bas is not None:
        for a in bas.attractors:
            print(f"  attractor {a['regime']}: basin {100 * a['fraction']:.0f} % of the grid")
    print(f"outputs in {args.out}/: {', '.join(files)}")
    return 0


def _grid(text, option):
    parts = text.split(":")
    try:
        lo, hi, n = float(parts[0]), float(parts[1]), int(parts[2])
    except (ValueError, IndexError):
        raise argparse.ArgumentTypeError(f"{text!r}: write LOW:HIGH:N, e.g. 0.8:1.2:200") from None
    if (
        len(parts) != 3
        or not (np.isfinite(lo) and np.isfinite(hi) and lo < hi)
        or not 1 <= n <= 2000
    ):
        raise argparse.ArgumentTypeError(
            f"{text!r}: need LOW < HIGH (finite) and 1 <= N <= 2000, e.g. 0.8:1.2:200"
        )
    return np.linspace(lo, hi, n)


def run_chart(args):
    from reports.ueda_figures import chart_figure

    from ..oscillator.chart import chart

    check_out(args)
    if args.nu[0] <= 0:
        raise InputError("--nu: the frequencies must be > 0, e.g. --nu 0.8:1.2:200")
    system = _system(args, nu=None, B=None)

    if args.periods < 4 * args.max_period:
        raise InputError(
            f"--periods {args.periods} is too short for --max-period "
            f"{args.max_period}: give --periods {4 * args.max_period} or more "
            "(the recurrence test compares three cycles with the cycle before)"
        )
    with reporter(args) as rep, executor_of(args) as ex:
        ch = chart(
            system,
            args.nu,
            args.B,
            transient=args.transient,
            periods=args.periods,
            rtol=args.rtol,
            max_period=args.max_period,
            sweeps=2 if args.both_directions else 1,
            workers=args.workers,
            progress=lambda done, total: rep("chart: rows", done, total),
            executor=ex,
        )
    summary = {"command": "ueda chart", **ch.as_dict(), **provenance(vars(args))}

    def cell(value, column):
        if isinstance(value, float):
            return f"{value:.10g}" if column in ("nu", "B") else f"{value:.6g}"
        return value

    with OutputDir(args.out) as out:
        with open(out.path("chart.csv"), "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(ch.columns)
            for r in ch.rows():
                w.writerow([cell(v, c) for v, c in zip(r, ch.columns, strict=True)])
        chart_figure(ch, str(out.path("chart")))
        out.write_json("summary.json", summary)
    fr = ch.fractions()
    print(
        f"{system.model} chart {ch.nu.size}x{ch.B.size}: {ch.seconds:.1f} s on {ch.workers} "
        f"processes ({ch.cpu_seconds:.1f} CPU s); "
        + ", ".join(f"{k} {100 * v:.0f} %" for k, v in fr.items())
    )
    found = ch.period_counts()
    if found:
        print("  periods found (points): " + ", ".join(f"P{n} {c}" for n, c in found.items()))
    if ch.coexisting is not None:
        print(
            f"  coexisting attractors (the sweeps up and down in nu differ) at "
            f"{int(ch.coexisting.sum())} point(s), {100 * ch.coexisting.mean():.1f} %"
        )
    print(f"outputs in {args.out}/: summary.json, chart.csv, chart.png, chart.pdf")
    return 0


def run_simulate(args):
    import hashlib
    import json
    import time

    from .._io import atomic_write_text, check_output, to_jsonable
    from ..oscillator.discover import simulate_record

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
    summary = {
        "command": "ueda simulate",
        "system": system.as_dict(),
        "samples": int(t.size),
        "periods": args.periods,
        "samples_per_period": args.samples_per_period,
        "noise": {
            "fraction_of_range": args.noise,
            "sd": float(args.noise * np.ptp(xc)),
            "x_range": [float(xc.min()), float(xc.max())],
        },
        "integrator": args.integrator,
        "seconds": time.perf_counter() - t0,
        "outputs": {out.name: {"sha256": hashlib.sha256(csv_text.encode()).hexdigest()}},
        **provenance(vars(args)),
    }
    atomic_write_text(out, csv_text)
    atomic_write_text(summary_path, json.dumps(to_jsonable(summary), indent=2) + "\n")
    print(
        f"wrote {out} ({t.size} samples, {args.periods} periods of {system.model}, "
        f"{args.samples_per_period} samples per period, noise {args.noise:g} of the range) "
        f"and {summary_path}"
    )
    return 0


def _forcing(args):
    from ..oscillator import MODELS

    if args.model is None and (args.B is None or args.nu is None):
        raise InputError(
            "give the forcing: --B and --nu (e.g. --B 0.35 --nu 1.02), or --model "
            "negres|duffing for its forcing"
        )
    base = MODELS[args.model] if args.model else {}
    B = args.B if args.B is not None else base["B"]
    nu = args.nu if args.nu is not None else base["nu"]
    return B, nu


def run_discover(args):
    from reports.ueda_figures import discover_figure

    from ..oscillator.discover import discover, read_record_csv, verify

    check_out(args)
    B, nu = _forcing(args)
    t, x = read_record_csv(args.data)
    d = discover(
        t,
        x,
        B,
        nu,
        threshold=args.threshold,
        half_width=args.half_width,
        fit_forcing=not args.fix_forcing,
        bootstrap=args.bootstrap,
        block_periods=args.block_periods,
        seed=args.seed,
    )
    sm = d.smoothed
    if args.noise is not None:
        sm = replace(sm, noise_sd=float(args.noise * np.ptp(x)))
    ver = verify(
        d.model,
        t,
        x,
        smoothed=sm,
        transient=args.transient,
        periods=args.model_periods,
        resamples=args.resamples,
        seed=args.seed,
    )
    result = d.as_dict()
    # "settings" is provenance's (the command-line options); keep the discovery's own
    result["discovery_settings"] = result.pop("settings")
    summary = {
        "command": "ueda discover",
        "forcing": {"B": B, "nu": nu},
        **result,
        "verification": ver.as_dict(),
        **provenance(vars(args), inputs={"data": args.data}),
    }
    with OutputDir(args.out, inputs=[args.data]) as out:
        discover_figure(d, ver, str(out.path("discover")))
        np.savetxt(
            out.path("strobe_record.csv"),
            ver.record_strobe,
            delimiter=",",
            header="x,v",
            comments="",
        )
        np.savetxt(
            out.path("strobe_model.csv"), ver.model_strobe, delimiter=",", header="x,v", comments=""
        )
        out.write_json("summary.json", summary)
    print(f"discovered: {d.model.sympy()}")
    for k, c in d.coefficients.items():
        print(f"  {k:>12}: {c: .5f} +- {d.standard_errors[k]:.5f}")
    L = ver.lyapunov
    lyap = f"{L['value']:.4f} +- {L['stderr']:.4f}" if L else "n/a"
    print(
        f"verification: energy distance {ver.energy_distance:.4g} vs floor q95 "
        f"{ver.floor_q95:.4g} ({ver.floor_block_periods}-period blocks); regime record "
        f"{ver.regime_record}, model "
        f"{ver.regime_model}; model lyapunov {lyap}: "
        f"{'consistent' if ver.consistent else 'INCONSISTENT'}"
    )
    print(
        f"outputs in {args.out}/: summary.json, discover.png, discover.pdf, "
        "strobe_record.csv, strobe_model.csv"
    )
    return 0


def run_explain(args):
    from reports.ueda_explain_figure import explain_figure

    from ..oscillator.discover import read_record_csv
    from ..oscillator.explain import explain, parse_terms

    check_out(args)
    B, nu = _forcing(args)
    start = parse_terms(args.start)
    effects = None
    if args.effects is not None:
        effects = [e.strip() for e in args.effects.split(",") if e.strip()]
        if not effects:
            raise InputError(
                "--effects is empty; give catalogue ids separated by commas, e.g. "
                "van_der_pol_damping,linear_damping, or leave it out for all"
            )
    t, x = read_record_csv(args.data)
    ex = explain(
        t,
        x,
        B,
        nu,
        start,
        alpha=args.alpha,
        max_iterations=args.max_iterations,
        effects=effects,
        half_width=args.half_width,
        fit_forcing=not args.fix_forcing,
        noise=args.noise,
        transient=args.transient,
        periods=args.model_periods,
        resamples=args.resamples,
        seed=args.seed,
    )
    result = ex.as_dict()
    result["method"] = result.pop("settings")  # "settings" is provenance's (the options)
    summary = {
        "command": "ueda explain",
        "forcing": {"B": B, "nu": nu},
        **result,
        **provenance(vars(args), inputs={"data": args.data}),
    }
    with OutputDir(args.out, inputs=[args.data]) as out:
        explain_figure(ex, str(out.path("explain")))
        for name, ver in (("start", ex.start_verification), ("final", ex.final_verification)):
            np.savetxt(
                out.path(f"strobe_{name}.csv"),
                ver.model_strobe,
                delimiter=",",
                header="x,v",
                comments="",
            )
        np.savetxt(
            out.path("strobe_record.csv"),
            ex.final_verification.record_strobe,
            delimiter=",",
            header="x,v",
            comments="",
        )
        out.write_json("summary.json", summary)
    print(f"start: {ex.start_model.sympy()}")
    for it in ex.iterations:
        if it.effect:
            print(f"named {it.effect}: {it.evidence['text']}")
    print(f"final: {ex.final_model.sympy()}")
    for k, c in ex.coefficients.items():
        print(f"  {k:>12}: {c: .5f} +- {ex.standard_errors[k]:.5f}")
    for k, g in ex.gap.items():
        print(f"  gap {k}: {g['before']:.4g} -> {g['after']:.4g} ({g['ratio']:.3g}x)")
    print(f"stopped: {ex.stopped_because}")
    print(
        f"outputs in {args.out}/: summary.json, explain.png, explain.pdf, strobe_record.csv, "
        "strobe_start.csv, strobe_final.csv"
    )
    return 0


def _add_system_options(s, chart=False):
    s.add_argument(
        "--model",
        choices=("negres", "duffing"),
        default="negres",
        help="negres: x'' - mu (1 - gamma x^2) x' + x^3 = B cos(nu t) (mu 0.2, "
        "gamma 8, B 0.35, nu 1.02: the broken egg); duffing: x'' + k x' + x^3 = "
        "B cos(nu t) (k 0.05, B 7.5, nu 1) (default: %(default)s)",
    )
    s.add_argument("--mu", type=number(-10, 10), help="negative resistance (default: the model's)")
    s.add_argument(
        "--gamma", type=number(0, 1e3), help="amplitude dependence of the resistance, >= 0"
    )
    s.add_argument("--k", type=number(-10, 10), help="linear damping")
    if not chart:
        s.add_argument("--B", type=number(-1e3, 1e3), help="forcing amplitude")
        s.add_argument(
            "--nu", type=number(0, 100, lo_open=True), help="forcing angular frequency, > 0"
        )
    s.add_argument(
        "--rtol",
        type=number(1e-13, 1e-3),
        default=1e-9 if not chart else 1e-6,
        help="integrator tolerance (default: %(default)g)",
    )


def register(sub):
    u = sub.add_parser(
        "ueda",
        help="Ueda's forced oscillators: attractors, Lyapunov "
        "exponents, regime charts, equation discovery",
    )
    usub = u.add_subparsers(
        dest="ueda_command", required=True, metavar="SUBCOMMAND", parser_class=type(u)
    )
    a = usub.add_parser(
        "attractor", help="one attractor: strobe points, exponents, regime, figures"
    )
    _add_system_options(a)
    a.add_argument(
        "--x0", type=number(-1e3, 1e3), default=0.1, help="initial x (default: %(default)g)"
    )
    a.add_argument(
        "--v0", type=number(-1e3, 1e3), default=0.0, help="initial x' (default: %(default)g)"
    )
    a.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=500,
        help="periods discarded (default: %(default)s)",
    )
    a.add_argument(
        "--periods",
        type=integer(20, 10**7),
        default=5000,
        help="periods averaged (strobe points) (default: %(default)s)",
    )
    a.add_argument(
        "--batches",
        type=integer(2, 1000),
        default=20,
        help="batches for the standard error (default: %(default)s)",
    )
    a.add_argument(
        "--basins",
        type=integer(0, 100),
        default=0,
        help="also find coexisting attractors from an NxN grid of initial states "
        "(default: %(default)s, skip)",
    )
    a.add_argument(
        "--grid-extent",
        type=number(0, 1e3, lo_open=True),
        default=1.0,
        help="the grid of initial states covers [-E, E]^2 (default: %(default)g)",
    )
    a.add_argument("--out", required=True, help="output directory")
    a.set_defaults(func=run_attractor)
    c = usub.add_parser("chart", help="regime chart over (nu, B) in parallel processes")
    _add_system_options(c, chart=True)
    c.add_argument(
        "--nu",
        type=lambda t: _grid(t, "--nu"),
        default=_grid("0.8:1.2:200", "--nu"),
        metavar="LOW:HIGH:N",
        help="forcing frequencies (default: 0.8:1.2:200)",
    )
    c.add_argument(
        "--B",
        type=lambda t: _grid(t, "--B"),
        default=_grid("0:0.6:200", "--B"),
        metavar="LOW:HIGH:N",
        help="forcing amplitudes (default: 0:0.6:200)",
    )
    c.add_argument(
        "--transient",
        type=integer(0, 10**5),
        default=60,
        help="periods discarded at most at each point, after continuation from "
        "the previous nu; a point stops sooner once its strobe points repeat "
        "(a stable periodic orbit) (default: %(default)s)",
    )
    c.add_argument(
        "--periods",
        type=integer(20, 10**5),
        default=80,
        help="periods observed with the variational equations where no stable "
        "orbit was found; at least 4 x --max-period (default: %(default)s)",
    )
    c.add_argument(
        "--max-period",
        type=integer(1, 1000),
        default=16,
        help="longest period recognised, in forcing periods; longer locked "
        "orbits appear as beat (default: %(default)s)",
    )
    c.add_argument(
        "--both-directions",
        action="store_true",
        help="sweep every row up and back down in nu, and mark the points where "
        "the two sweeps end on different attractors (coexisting attractors, "
        "hysteresis); about twice the time (default: off)",
    )
    c.add_argument("--workers", type=integer(1, 1024), help="processes (default: all cores)")
    c.add_argument("--scheduler", metavar="ADDR", help=SCHEDULER_HELP)
    c.add_argument(
        "--progress", action="store_true", help="progress bar even when stderr is not a terminal"
    )
    c.add_argument("--out", required=True, help="output directory")
    c.set_defaults(func=run_chart)
    m = usub.add_parser("simulate", help="a noisy record t, x (CSV) of a model, for discover")
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
    m.set_defaults(func=run_simulate)
    d = usub.add_parser(
        "discover",
        help="recover the equation from a record t, x with "
        "known forcing, and verify it by simulation",
    )
    d.add_argument("--data", required=True, help="CSV with columns t (uniform) and x")
    d.add_argument(
        "--model",
        choices=("negres", "duffing"),
        help="take the forcing B, nu from this model (override with --B, --nu)",
    )
    d.add_argument("--B", type=number(-1e3, 1e3), help="forcing amplitude")
    d.add_argument("--nu", type=number(0, 100, lo_open=True), help="forcing angular frequency, > 0")
    d.add_argument(
        "--noise",
        type=number(0, 1),
        help="known noise sd as a fraction of x's "
        "range (default: estimated from the smoothing residual)",
    )
    d.add_argument(
        "--threshold",
        type=number(0, 1),
        default=0.02,
        help="STLSQ threshold on scaled coefficients (default: %(default)g)",
    )
    d.add_argument(
        "--half-width",
        type=integer(2, 10**4),
        help="test-window half width in samples (default: a quarter period, at least 7)",
    )
    d.add_argument(
        "--fix-forcing",
        action="store_true",
        help="fix the forcing's coefficient at 1 instead of fitting it",
    )
    d.add_argument(
        "--bootstrap",
        type=integer(0, 10**5),
        default=200,
        help="block-bootstrap resamples for the standard errors (default: %(default)s)",
    )
    d.add_argument(
        "--block-periods",
        type=integer(1, 10**4),
        default=4,
        help="bootstrap block length in forcing periods (default: %(default)s)",
    )
    d.add_argument(
        "--model-periods",
        type=integer(50, 10**6),
        default=2000,
        help="periods of the discovered model simulated (default: %(default)s)",
    )
    d.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=200,
        help="periods of the discovered model discarded first (default: %(default)s)",
    )
    d.add_argument(
        "--resamples",
        type=integer(10, 10**5),
        default=200,
        help="random halves for the energy-distance noise floor (default: %(default)s)",
    )
    d.add_argument(
        "--seed", type=integer(0), default=0, help="seed of the resampling (default: %(default)s)"
    )
    d.add_argument("--out", required=True, help="output directory")
    d.set_defaults(func=run_discover)
    e = usub.add_parser(
        "explain",
        help="name the effect missing from a start model "
        "(score tests over this system's catalogue), add it, refit, and show "
        "the gap shrink by simulation",
    )
    e.add_argument("--data", required=True, help="CSV with columns t (uniform) and x")
    e.add_argument(
        "--start",
        default="x',x^3",
        help="library terms of the start model, "
        "separated by commas (x^2*x' or x^2 x'; v for x'; none: the forcing "
        "alone); x',x^3 is negres without its van der Pol damping x^2 x' "
        "(default: %(default)s)",
    )
    e.add_argument(
        "--model",
        choices=("negres", "duffing"),
        help="take the forcing B, nu from this model (override with --B, --nu)",
    )
    e.add_argument("--B", type=number(-1e3, 1e3), help="forcing amplitude")
    e.add_argument("--nu", type=number(0, 100, lo_open=True), help="forcing angular frequency, > 0")
    e.add_argument(
        "--effects",
        help="catalogue ids to consider, separated by commas "
        "(default: all of van_der_pol_damping, linear_damping, cubic_stiffness, "
        "quadratic_stiffness, velocity_cubic_damping)",
    )
    e.add_argument(
        "--alpha",
        type=number(0, 1, lo_open=True),
        default=0.01,
        help="family-wise level of the score tests, Bonferroni (default: %(default)g)",
    )
    e.add_argument(
        "--max-iterations",
        type=integer(0, 20),
        default=3,
        help="effects added at most (default: %(default)s)",
    )
    e.add_argument(
        "--noise",
        type=number(0, 1),
        help="known noise sd as a fraction of x's "
        "range (default: estimated from the smoothing residual)",
    )
    e.add_argument(
        "--half-width",
        type=integer(2, 10**4),
        help="test-window half width in samples (default: a quarter period, at least 7)",
    )
    e.add_argument(
        "--fix-forcing",
        action="store_true",
        help="fix the forcing's coefficient at 1 instead of fitting it",
    )
    e.add_argument(
        "--model-periods",
        type=integer(50, 10**6),
        default=2000,
        help="periods of each model simulated (default: %(default)s)",
    )
    e.add_argument(
        "--transient",
        type=integer(0, 10**6),
        default=200,
        help="periods of each model discarded first (default: %(default)s)",
    )
    e.add_argument(
        "--resamples",
        type=integer(10, 10**5),
        default=200,
        help="random halves for the energy-distance noise floor (default: %(default)s)",
    )
    e.add_argument(
        "--seed", type=integer(0), default=0, help="seed of the resampling (default: %(default)s)"
    )
    e.add_argument("--out", required=True, help="output directory")
    e.set_defaults(func=run_explain)
