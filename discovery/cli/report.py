"""``vidi report``: a run directory's LaTeX report, compiled to PDF."""


def run(args):
    from pathlib import Path

    from .._files._io import MANIFEST, read_manifest
    from ..reporting import report

    # a malformed manifest (files not a list of names, not an object) is one line, exit 2;
    # a path that is no directory is report()'s to refuse
    if Path(args.run_dir).is_dir():
        read_manifest(Path(args.run_dir) / MANIFEST, strict=True)

    r = report(args.run_dir, snippet=args.snippet, compile=not args.no_pdf)
    print(r)
    return 0


def register(sub):
    from reports.document import SNIPPETS

    s = sub.add_parser(
        "report",
        help="LaTeX report of a run directory, compiled to PDF (latexmk)",
        description="Turn the --out directory of a vidi run (verify, fit, identify, "
        "landscape, explain, ueda ...) into report.tex with its figures and compile "
        "report.pdf, from the run's summary.json. Every text from a user or a file is "
        "escaped; TeX runs without shell escape. Without TeX the .tex is written and the "
        "Debian packages to install are named.",
    )
    s.add_argument("run_dir", metavar="DIR", help="the --out directory of a vidi run")
    s.add_argument(
        "--snippet",
        choices=SNIPPETS,
        help="write one piece to paste into a paper (snippet-KIND.tex) instead of the whole report",
    )
    s.add_argument("--no-pdf", action="store_true", help="write the .tex only")
    s.set_defaults(func=run)
