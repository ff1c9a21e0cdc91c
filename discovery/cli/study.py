"""``vidi study``: a model-term selection study from a TOML file (resumable)."""


def run(args):
    from reports.vibroimpact.study_figures import study_figures

    from .._files._io import set_run
    from ..vibroimpact.studies.driver import study
    from ._common import reporter

    set_run("study", getattr(args, "overwrite", False))
    with reporter(args) as rep:
        r = study(
            args.config,
            args.out,
            workers=args.workers,
            scheduler=args.scheduler,
            progress=rep,
            max_runs=args.max_runs,
            figures=None if args.no_figures else study_figures,
        )
    print(r)
    left = r.config.n_runs - len(r.runs)
    if left:
        print(f"{left} run(s) left: run the same command again to continue")
    return 0


def register(sub):
    from . import _options
    from ._common import integer

    s = sub.add_parser(
        "study",
        help="model-term selection study: which terms a record like yours supports",
        description="Run a study described in a TOML file: every combination of its factors "
        "(true law, scenario(s), noise, record length, sample rate, library, selection "
        "method, refinement) and seeds. Each run makes its record(s) with the independent "
        "scipy path from rest, discovers a law, checks it by simulation and scores it "
        "against the truth. Each run is one file named by a hash of its configuration, kept "
        "in .DIR.vidi-study beside DIR until the whole study replaces DIR at the end: an "
        "interrupted study (Ctrl-C, kill -9) leaves DIR as it was and continues where it "
        "stopped when the same command is run again; a study of other cells into a "
        "finished DIR needs --overwrite. Writes cells.csv (recovery with its 95 % "
        "interval, false positives, interval coverage, coefficient error per cell), "
        "runs.csv, inclusion.csv, figures and summary.json.",
    )
    s.add_argument(
        "--config",
        required=True,
        metavar="FILE",
        help="the study file (see examples/study_paper.toml)",
    )
    s.add_argument(
        "--out",
        required=True,
        metavar="DIR",
        help="the study directory (runs already there are reused)",
    )
    s.add_argument(
        "--workers",
        type=integer(1, 4096),
        help="worker processes (default: one per core; 1 runs in this process)",
    )
    _options.add_scheduler_option(s)
    s.add_argument(
        "--max-runs",
        type=integer(0, 10**9),
        metavar="N",
        help="do at most N missing runs now (the rest on the next call)",
    )
    s.add_argument("--no-figures", action="store_true", help="tables only")
    s.set_defaults(func=run)
