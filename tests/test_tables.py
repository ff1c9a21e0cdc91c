"""The measured tables of the README and docs/ are what ``make tables`` renders from the
saved survey runs (``docs/_measured/``), so they cannot go stale, and each names the commit
and date of the runs that made it."""

import re

import pytest

from tests import measured, tables

PAGES = [
    "README.md",
    *sorted(str(p.relative_to(tables.ROOT)) for p in (tables.ROOT / "docs").glob("*.md")),
]


@pytest.mark.parametrize("page", tables.pages())
def test_the_pages_tables_are_what_the_saved_runs_render(page):
    assert (tables.ROOT / page).read_text() == tables.rendered_page(page), (
        f"{page}: a measured table differs from the saved runs; run make tables"
    )


def test_every_marked_table_has_a_definition_and_one_page():
    marked = {name: page for page in PAGES for name in tables.markers(page)}
    assert set(marked) == set(tables.TABLES)
    assert all(tables.TABLES[name].page == page for name, page in marked.items())


def test_each_table_names_the_commit_and_date_of_its_runs():
    for name, table in tables.TABLES.items():
        stamp = tables.render(name)[-1]
        for _, patterns in table.rows:
            for path in tables.run_files(patterns):
                header, rows = measured.read(path)
                assert rows and header.get("started"), path
                assert f"`{path.name}` (" in stamp and header["started"][:10] in stamp
                assert (
                    f"commit {header['commit']}" if header.get("commit") else "not recorded"
                ) in stamp


def test_a_run_file_is_headed_by_its_commit_and_code_version(tmp_path):
    out = measured.RunFile(tmp_path / "run.jsonl", "survey_intervals", ["--records", "1"])
    out.write({"i": 1, "x": 0.5})
    header, rows = measured.read(tmp_path / "run.jsonl")
    assert rows == [{"i": 1, "x": 0.5}]
    assert header["command"] == "python -m tests.survey_intervals --records 1"
    if measured.git("rev-parse", "HEAD"):  # a checkout (an unpacked archive has none)
        assert re.fullmatch(r"[0-9a-f]{7,}(\+dirty)?", header["commit"])
    assert header["code"].split("+src.")[1] and re.fullmatch(
        r"\d{4}-\d\d-\d\dT\d\d:\d\dZ", header["started"]
    )


def test_a_changed_run_makes_the_check_fail(tmp_path, monkeypatch, capsys):
    """The check compares with what the runs give: a row added to a run is a stale page."""
    saved = tmp_path / "_measured"
    saved.mkdir()
    for p in measured.MEASURED.glob("*.jsonl"):
        (saved / p.name).write_text(p.read_text())
    with open(saved / "advise-1.jsonl", "a") as fh:
        fh.write('{"i": 99, "counted": false, "machine": "paper", "law": "z"}\n')
    monkeypatch.setattr(measured, "MEASURED", saved)
    assert tables.main(["--check"]) == 1
    assert "stale measured tables in docs/validation.md" in capsys.readouterr().err


def test_the_corpus_tables_have_a_row_per_record_of_their_run():
    """tests.survey_corpus's rows: each of the thirteen records in one of the two tables,
    and the cells say what the numbers say."""
    from tests import survey_corpus

    labels = [
        label for name in ("corpus", "corpus-effects") for label, _ in tables.TABLES[name].rows
    ]
    rows = survey_corpus.read_rows(tables.run_files(tables.TABLES["corpus"].rows[0][1]))
    assert sorted(r["i"].split("-")[0] for r in rows) == sorted(x.split()[0] for x in labels)
    row = {
        "i": "c99-test",
        "verified": {"consistent": True, "I2": 0.0271, "I2_floor": 0.0249, "regime": {}},
        "scaled": {"total": 4, "inconsistent": 3, "consistent": ["zd x0.7"]},
        "explain": {"named": [], "consistent": True, "separability": [], "limits": {}},
    }
    assert survey_corpus._law_cell(row, floors=True) == "consistent (I2 0.027, floor 0.025)"
    assert survey_corpus._scaled_cell(row) == "3 of 4 inconsistent (zd x0.7 not)"
    assert survey_corpus._explain_cell(row) == "nothing named"
