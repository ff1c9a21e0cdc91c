"""``vidi ueda attractor``: one attractor: strobe points, the two Lyapunov exponents with standard
errors, the regime with its evidence, figures (optionally the coexisting attractors from a grid
of initial states)."""

from ..._files._drawer import drawing
from ..._files._io import OutputDir, provenance
from .. import _options
from .._common import check_out, integer, number, outputs_line
from . import _record
from ._system import _add_start_options, _add_system_options, _system, _tolerances

#: the figures and the results' module the drawer loads while the command computes
#: (:mod:`discovery._files._drawer`)
_FIGURES = ("ueda.figures.attractor_figure", "ueda.figures.basins_figure")
_RESULTS = ("discovery.ueda.attractor_analysis", "discovery.ueda.coexisting")


def run(args):
    check_out(args)
    with drawing(_FIGURES, _RESULTS) as drawer:
        return _run(args, drawer)


def _run(args, drawer):
    from ...ueda import attractor, basins

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
    L = att.lyapunov
    gap = abs(L.sum - L.trace_mean)
    if not gap <= 1e-6 + 1e-3 * abs(L.trace_mean):  # NaN fails too
        from ...errors import IntegrationError

        raise IntegrationError(
            f"the Lyapunov exponents' sum {L.sum:.6g} disagrees with the mean trace "
            f"{L.trace_mean:.6g} of the flow (they are equal for an accurate integration) "
            f"from (x0, v0) = ({args.x0:g}, {args.v0:g}); start nearer the attractor or "
            "lower --rtol"
        )
    tail = {}
    bas = None
    if args.basins:
        bas = basins(
            system,
            (-args.grid_extent, args.grid_extent),
            (-args.grid_extent, args.grid_extent),
            n=args.basins,
            tolerances=tol,
        )
        tail["coexisting_attractors"] = bas.as_dict()
    att.record_run({"command": "ueda attractor"}, {**tail, **provenance(vars(args))})
    files = ["summary.json", "attractor.png", "attractor.pdf"]
    with OutputDir(args.out) as out:
        stem = str(out.path("attractor"))
        drawer.draw(stem, _FIGURES[0], att, stem)
        _record.write_strobe(out.path("strobe.csv"), att.strobe)
        files.append("strobe.csv")
        if bas is not None:
            stem = str(out.path("basins"))
            drawer.draw(stem, _FIGURES[1], bas, stem)
            files += ["basins.png", "basins.pdf"]
        att.write_into(out)
    print(f"{system.model}: {att.regime.regime} ({att.regime.evidence['rule']})")
    print(
        f"  lyapunov {L.value:.4f} +- {L.stderr:.4f}, second {L.second:.4f} +- "
        f"{L.second_stderr:.4f} per unit time; sum {L.sum:.6f} vs mean trace "
        f"{L.trace_mean:.6f}"
    )
    if bas is not None:
        for a in bas.attractors:
            print(f"  attractor {a['regime']}: basin {100 * a['fraction']:.0f} % of the grid")
    print(outputs_line(args, files))
    return 0


def register(sub):
    """Add ``vidi ueda attractor`` to the ueda subparsers ``sub``."""
    a = sub.add_parser("attractor", help="one attractor: strobe points, exponents, regime, figures")
    _add_system_options(a)
    _add_start_options(a)
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
    _options.add_out_option(a)
    a.set_defaults(func=run)
