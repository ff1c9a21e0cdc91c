"""``vidi ueda chart``: the regime chart over (nu, B) in parallel processes."""

import argparse
import csv

import numpy as np

from ..._files._drawer import drawing
from ..._files._io import OutputDir, provenance
from ...errors import InputError
from .. import _options
from .._common import check_out, executor_of, integer, reporter
from ._system import _add_system_options, _system

#: each axis's values within the bounds of its single-value option (``--nu``, ``--B`` of
#: ``vidi ueda simulate``): ``(low, high, low excluded)``
_AXIS_BOUNDS = {"--nu": (0.01, 100.0, False), "--B": (-1e3, 1e3, False)}


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
    low, high, open_low = _AXIS_BOUNDS.get(option, (-np.inf, np.inf, False))
    if lo < low or (open_low and lo == low) or hi > high:
        raise argparse.ArgumentTypeError(
            f"{text!r}: the values must lie in {'(' if open_low else '['}{low:g}, {high:g}], "
            f"as {option} of vidi ueda simulate"
        )
    return np.linspace(lo, hi, n)


def _add_grid_option(c, option, default, what):
    """``option`` LOW:HIGH:N, the points of one axis of the chart (see :func:`_grid`)."""
    c.add_argument(
        option,
        type=lambda t: _grid(t, option),
        default=_grid(default, option),
        metavar="LOW:HIGH:N",
        help=f"{what} (default: {default})",
    )


#: the figures and the results' module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_FIGURES = ("ueda.figures.chart_figure",)
_RESULTS = ("discovery.ueda.regime_chart",)


def run(args):
    check_out(args)
    with drawing(_FIGURES, _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ...ueda.regime_chart import chart

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
            progress=rep,
            executor=ex,
        )
    ch.record_run({"command": "ueda chart"}, provenance(vars(args)))

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
        stem = str(out.path("chart"))
        drawer.draw(stem, _FIGURES[0], ch, stem)
        ch.write_into(out)
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


def register(sub):
    """Add ``vidi ueda chart`` to the ueda subparsers ``sub``."""
    c = sub.add_parser("chart", help="regime chart over (nu, B) in parallel processes")
    _add_system_options(c, chart=True)
    _add_grid_option(c, "--nu", "0.8:1.2:200", "forcing frequencies")
    _add_grid_option(c, "--B", "0:0.6:200", "forcing amplitudes")
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
    _options.add_parallel_options(c)
    c.add_argument(
        "--progress", action="store_true", help="progress bar even when stderr is not a terminal"
    )
    _options.add_out_option(c)
    c.set_defaults(func=run)
