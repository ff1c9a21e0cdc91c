"""``vidi ueda``: Ueda's forced oscillators (the second system).

``vidi ueda attractor`` - one attractor: strobe points, the two Lyapunov exponents with
standard errors, the regime with its evidence, figures (optionally the coexisting
attractors from a grid of initial states).  ``vidi ueda chart`` - the regime chart over
``(nu, B)`` in parallel processes.
"""

import argparse
import csv
import sys

import numpy as np

from .._io import OutputDir, provenance
from ..errors import InputError
from ._common import check_out, integer, number

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
    att = attractor(system, (args.x0, args.v0), transient=args.transient, periods=args.periods,
                    batches=args.batches, tolerances=tol)
    summary = {"command": "ueda attractor", **att.as_dict()}
    bas = None
    if args.basins:
        bas = basins(system, (-args.grid_extent, args.grid_extent),
                     (-args.grid_extent, args.grid_extent), n=args.basins, tolerances=tol)
        summary["coexisting_attractors"] = bas.as_dict()
    summary.update(provenance(vars(args)))
    files = ["summary.json", "attractor.png", "attractor.pdf"]
    with OutputDir(args.out) as out:
        attractor_figure(att, str(out.path("attractor")))
        np.savetxt(out.path("strobe.csv"), att.strobe, delimiter=",", header="x,v",
                   comments="")
        files.append("strobe.csv")
        if bas is not None:
            basins_figure(bas, str(out.path("basins")))
            files += ["basins.png", "basins.pdf"]
        out.write_json("summary.json", summary)
    L = att.lyapunov
    print(f"{system.model}: {att.regime.regime} ({att.regime.evidence['rule']})")
    print(f"  lyapunov {L.value:.4f} +- {L.stderr:.4f}, second {L.second:.4f} +- "
          f"{L.second_stderr:.4f} per unit time; sum {L.sum:.6f} vs mean trace "
          f"{L.trace_mean:.6f}")
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
        raise argparse.ArgumentTypeError(
            f"{text!r}: write LOW:HIGH:N, e.g. 0.8:1.2:200") from None
    if len(parts) != 3 or not (np.isfinite(lo) and np.isfinite(hi) and lo < hi) \
            or not 1 <= n <= 2000:
        raise argparse.ArgumentTypeError(f"{text!r}: need LOW < HIGH (finite) and 1 <= N <= "
                                         "2000, e.g. 0.8:1.2:200")
    return np.linspace(lo, hi, n)


def run_chart(args):
    from reports.ueda_figures import chart_figure

    from ..oscillator.chart import chart

    check_out(args)
    if args.nu[0] <= 0:
        raise InputError("--nu: the frequencies must be > 0, e.g. --nu 0.8:1.2:200")
    system = _system(args, nu=None, B=None)

    def progress(done, total):
        if sys.stderr.isatty() or args.progress:
            w = 30
            f = done / total
            print(f"\r  [{'#' * int(w * f):<{w}}] {done}/{total} rows", end="",
                  file=sys.stderr, flush=True)
            if done == total:
                print(file=sys.stderr)

    ch = chart(system, args.nu, args.B, transient=args.transient, periods=args.periods,
               rtol=args.rtol, workers=args.workers, progress=progress)
    summary = {"command": "ueda chart", **ch.as_dict(), **provenance(vars(args))}
    with OutputDir(args.out) as out:
        with open(out.path("chart.csv"), "w", newline="", encoding="utf-8") as fh:
            w = csv.writer(fh)
            w.writerow(["nu", "B", "regime", "period", "lyapunov", "rotation_number"])
            for r in ch.rows():
                w.writerow([f"{r[0]:.10g}", f"{r[1]:.10g}", r[2], r[3], f"{r[4]:.6g}",
                            f"{r[5]:.6g}"])
        chart_figure(ch, str(out.path("chart")))
        out.write_json("summary.json", summary)
    fr = ch.fractions()
    print(f"{system.model} chart {ch.nu.size}x{ch.B.size}: {ch.seconds:.1f} s on {ch.workers} "
          f"processes; " + ", ".join(f"{k} {100 * v:.0f} %" for k, v in fr.items()))
    print(f"outputs in {args.out}/: summary.json, chart.csv, chart.png, chart.pdf")
    return 0


def _add_system_options(s, chart=False):
    s.add_argument("--model", choices=("negres", "duffing"), default="negres",
                   help="negres: x'' - mu (1 - gamma x^2) x' + x^3 = B cos(nu t) (mu 0.2, "
                   "gamma 8, B 0.35, nu 1.02: the broken egg); duffing: x'' + k x' + x^3 = "
                   "B cos(nu t) (k 0.05, B 7.5, nu 1)")
    s.add_argument("--mu", type=number(-10, 10), help="negative resistance (model's default)")
    s.add_argument("--gamma", type=number(0, 1e3), help="amplitude dependence of the "
                   "resistance, >= 0")
    s.add_argument("--k", type=number(-10, 10), help="linear damping")
    if not chart:
        s.add_argument("--B", type=number(-1e3, 1e3), help="forcing amplitude")
        s.add_argument("--nu", type=number(0, 100, lo_open=True), help="forcing angular "
                       "frequency, > 0")
    s.add_argument("--rtol", type=number(1e-13, 1e-3), default=1e-9 if not chart else 1e-6,
                   help="integrator tolerance (%(default)g)")


def register(sub):
    u = sub.add_parser("ueda", help="Ueda's forced oscillators: attractors, Lyapunov "
                       "exponents, regime charts")
    usub = u.add_subparsers(dest="ueda_command", required=True, metavar="SUBCOMMAND",
                            parser_class=type(u))
    a = usub.add_parser("attractor", help="one attractor: strobe points, exponents, regime, "
                        "figures")
    _add_system_options(a)
    a.add_argument("--x0", type=number(-1e3, 1e3), default=0.1, help="initial x (0.1)")
    a.add_argument("--v0", type=number(-1e3, 1e3), default=0.0, help="initial x' (0)")
    a.add_argument("--transient", type=integer(0, 10**6), default=500,
                   help="periods discarded (500)")
    a.add_argument("--periods", type=integer(20, 10**7), default=5000,
                   help="periods averaged (strobe points) (5000)")
    a.add_argument("--batches", type=integer(2, 1000), default=20,
                   help="batches for the standard error (20)")
    a.add_argument("--basins", type=integer(0, 100), default=0,
                   help="also find coexisting attractors from an NxN grid of initial states "
                   "(0: skip)")
    a.add_argument("--grid-extent", type=number(0, 1e3, lo_open=True), default=1.0,
                   help="the grid of initial states covers [-E, E]^2 (1)")
    a.add_argument("--out", required=True, help="output directory")
    a.set_defaults(func=run_attractor)
    c = usub.add_parser("chart", help="regime chart over (nu, B) in parallel processes")
    _add_system_options(c, chart=True)
    c.add_argument("--nu", type=lambda t: _grid(t, "--nu"), default=_grid("0.8:1.2:200", "--nu"),
                   metavar="LOW:HIGH:N", help="forcing frequencies (0.8:1.2:200)")
    c.add_argument("--B", type=lambda t: _grid(t, "--B"), default=_grid("0:0.6:200", "--B"),
                   metavar="LOW:HIGH:N", help="forcing amplitudes (0:0.6:200)")
    c.add_argument("--transient", type=integer(0, 10**5), default=60,
                   help="periods discarded at each point, after continuation from the "
                   "previous nu (60)")
    c.add_argument("--periods", type=integer(20, 10**5), default=80,
                   help="periods observed at each point (80)")
    c.add_argument("--workers", type=integer(1, 1024), help="processes (all cores)")
    c.add_argument("--progress", action="store_true", help="progress bar even when stderr "
                   "is not a terminal")
    c.add_argument("--out", required=True, help="output directory")
    c.set_defaults(func=run_chart)
