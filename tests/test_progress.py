"""Progress on long commands: a bar with an ETA on a terminal, one line per stage
otherwise, nothing with --quiet; the API's callback sees every stage."""

import io

from discovery import ForceLaw, landscape, load_scenario
from discovery._progress import Reporter
from discovery.cli import main


def test_reporter_modes():
    plain = io.StringIO()
    r = Reporter(stream=plain, bar=False)
    for stage in ("a", "a", "b"):
        r(stage, 1, 3)
    r.close()
    assert plain.getvalue() == "a ...\nb ...\n"  # one line per stage
    bar = io.StringIO()
    with Reporter(stream=bar, bar=True) as r:
        for k in range(4):
            r("rows", k, 3)
    assert "rows:" in bar.getvalue() and "3/3" in bar.getvalue()  # capped at the total
    quiet = io.StringIO()
    with Reporter(quiet=True, stream=quiet, bar=True) as r:
        r("rows", 1, 2)
    assert quiet.getvalue() == ""


def test_the_api_reports_every_row():
    calls = []
    sc = load_scenario("paper")
    landscape(
        sc,
        ForceLaw.parse("2.06e8*z + 1.28e7*zd"),
        [1.5e8, 2.06e8, 2.5e8],
        [1e7, 1.28e7],
        workers=1,
        progress=lambda *a: calls.append(a),
    )
    assert calls == [("landscape: rows of the grid", k, 3) for k in (1, 2, 3)]


def test_cli_progress_lines_and_quiet(tmp_path, capsys):
    args = ["landscape", "--grid", "3x3", "--workers", "1"]
    assert main([*args, "--out", str(tmp_path / "a")]) == 0
    err = capsys.readouterr().err
    assert err == "landscape: rows of the grid ...\n"  # stderr is not a terminal here
    assert main([*args, "--quiet", "--out", str(tmp_path / "b")]) == 0
    assert capsys.readouterr().err == ""
