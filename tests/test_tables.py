"""The measured tables of the README and docs/ are what ``make tables`` renders from the
saved survey runs (``docs/_measured/``), so they cannot go stale, and each names the commit
and date of the runs that made it."""

import json
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
    """Every table is marked in its page, except a draft whose runs are not saved yet."""
    marked = {name: page for page in PAGES for name in tables.markers(page)}
    drafts = {name for name, table in tables.TABLES.items() if table.draft}
    assert set(marked) <= set(tables.TABLES)
    assert set(tables.TABLES) - set(marked) <= drafts
    assert all(tables.TABLES[name].page == page for name, page in marked.items())


def _rendered(name):
    """Whether table ``name`` is in its page (a draft may not be yet)."""
    return name in tables.markers(tables.TABLES[name].page)


def test_each_table_names_the_commit_and_date_of_its_runs():
    for name, table in tables.TABLES.items():
        if table.stamp or not _rendered(name):  # its own line: the tests of its module below
            continue
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
    """tests.survey_corpus's rows: each of the sixteen records in one of the two tables,
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


def test_the_explain_table_counts_the_draws_by_their_outcome(tmp_path):
    """tests.survey_explain's rows: a later row of a draw replaces an earlier one; each draw
    in one column by its outcome (the bar: a third of the start's I2, or 1.5 floors); the
    misses listed by draw; an error in ``explain`` on a valid draw is a column of its own,
    not a draw that tests nothing."""
    from tests import survey_explain as s

    def row(i, cat="p1", hidden="permanent_set", named=(), start=0.3, final=0.05, **kw):
        return {
            "i": i,
            "category": cat,
            "regime": "P1",
            "impacts": 1,
            "hidden": hidden,
            "true": "1e8*z + 1e6*zd; set: 0.3",
            "k3": 0.0,
            "true_consistent": True,
            "named": list(named),
            "I2_start": start,
            "I2_final": final,
            "floor": 0.02,
            "start_consistent": False,
            "stopped": "",
            **kw,
        }

    rows = [
        {"i": 0, "category": "p1", "skip": "hertz law (no linear start)"},
        row(1, hidden="none"),
        row(2, hidden="none", named=["sensor_lag"]),
        row(3, start_consistent=True),
        row(4, stopped="I4 alone fails"),
        row(5, named=["permanent_set"], final=0.099),  # under a third of 0.3: the bar
        row(6, named=["permanent_set"], final=0.11),  # short of it
        row(7, named=["permanent_set"], final=0.029),  # under 1.5 floors
        row(8, named=["unloading_damping", "permanent_set"]),
        row(9),
        row(10, true_consistent=False),
        row(11, cat="subharmonic", named=["permanent_set"]),
        row(12, cat="subharmonic", error="TypeError: x"),  # explain raised
        row(13, cat="subharmonic", true_consistent=False, error="TypeError: x"),
    ]
    path = tmp_path / "explain-random-test.jsonl"
    out = measured.RunFile(path, "survey_explain", ["--draws", "0", "12"])
    for r in rows:
        out.write(r)
    out.write(row(9, named=["permanent_set"], final=0.06))  # draw 9 again: now to the bar
    read = s.read_rows([path])
    assert [r["i"] for r in read] == list(range(14)) and read[9]["named"] == ["permanent_set"]
    assert s.markdown_row(read, "P1") == (
        "| P1 | 11 | 1 | 1 | 1 of 2 | 2 (1 by I4 alone) | 0 | 5 | 3 (60 %) | 1 | 1 | 0 | 1 |"
    )
    assert s.markdown_row(read, "all").startswith("| **all** | 14 | 1 | 2 | 1 of 2 | 2 (1 ")
    assert "| **1** | 6 | **4 (67 %)** | 1 | **1** | 0 | 1 |" in s.markdown_row(read, "all")
    misses = s.misses_rows(read)
    assert [int(m.split("|")[1]) for m in misses] == [2, 6, 8, 12, 13]
    assert misses[3].endswith("| TypeError: x | explain raised an error |")
    assert "| 0.3 -> 0.11 (floor 0.02) | named, gap short of the bar |" in misses[1]
    assert s.misses_rows(read[:2]) == ["| none |  |  |  |  |  |  |"]
    assert s.readme_row(read, "random") == "| 14 random | 4 of 6 (67 %) | 1 | 1 of 2 | 1 |"


def test_a_draft_table_renders_from_the_run_files_given(tmp_path, capsys):
    """A draft table (its page keeps a hand-written table until its runs are saved) is left
    out of its page while the page has no markers for it, and --show prints it from any
    run files."""
    path = tmp_path / "explain-cases-test.jsonl"
    measured.RunFile(path, "survey_explain_cases", ["--only", "set"]).write(
        {"case": "set", "hidden": "set 0.4 (same)", "error": "RuntimeError: x"}
    )
    assert tables.main(["--show", "explain-cases", "--runs", str(path)]) == 0
    out = capsys.readouterr().out
    assert "| set 0.4 (same) | - | - | - | RuntimeError: x |" in out
    assert "| sensor lag 0.1 ms (paper) | not run |" in out
    assert "`explain-cases-test.jsonl` (" in out.splitlines()[-1]
    for name, table in tables.TABLES.items():
        if table.draft and not _rendered(name):
            assert f"table:{name}" not in tables.rendered_page(table.page)


def _contact_row(truth, seed, selected, equivalent=(), covered=None, boot=None, **kw):
    """A row of tests.survey_contact_models: the true model's fit with an interval per
    parameter (``covered``: which hold the true value), and the bootstrap's (``boot``)."""
    from discovery.vibroimpact.model.contact_registry import CONTACT_MODELS

    keys = CONTACT_MODELS[truth].parameters if truth in CONTACT_MODELS else ()
    true = {k: 1.0 for k in keys}
    inside = {k: [0.5, 1.5] if (covered or {}).get(k, True) else [2.0, 3.0] for k in keys}
    row = {
        "truth": truth,
        "seed": seed,
        "true_params": true if keys else None,
        "selected": selected,
        "equivalent": list(equivalent),
        "seconds": 20.0,
        "fits": [{"model": truth, "intervals": inside}] if keys else [],
        "settings": {"max_simulations": 200, "boot": 30},
        **kw,
    }
    if boot is not None:
        row["boot_intervals"] = {k: [0.5, 1.5] if boot.get(k, True) else [2.0, 3.0] for k in keys}
    return row


def test_the_contact_models_table_combines_several_runs(tmp_path):
    """tests.survey_contact_models's rows of several runs (seeds) make one table: per
    truth, the right name, right or equivalent, and each parameter inside the true model's
    Jacobian and bootstrap intervals; a polynomial truth counts named models selected; a
    record made twice counts once (its last row); a skipped seed is no record; the line
    under it pools every parameter."""
    from tests import survey_contact_models as s

    first = [
        _contact_row("kelvin-voigt", 1, "kelvin-voigt", covered={"c": False}),
        _contact_row("hunt-crossley", 1001, "flores", ["hunt-crossley"], boot={"n": False}),
        _contact_row("polynomial", 9001, None),
        {"truth": "flores", "seed": 4001, "skipped": True},
    ]
    second = [
        _contact_row("kelvin-voigt", 2, "hertz-damper", boot={}),
        _contact_row("kelvin-voigt", 1, "kelvin-voigt"),  # seed 1 again: replaces it
        _contact_row("polynomial", 9002, "flores"),
    ]
    files = []
    for k, rows in enumerate((first, second)):
        path = tmp_path / f"contact-models-{k}.jsonl"
        run = measured.RunFile(path, "survey_contact_models", ["--seed", str(k)])
        for r in rows:
            run.write(r)
        files.append(path)
    rows = s.read_rows(files)
    assert len(rows) == 6
    row = s.models_row
    assert (
        row(rows, "kelvin-voigt")
        == "| kelvin-voigt | 2 | 1/2 | 1/2 | k 2/2, c 2/2 | k 1/1, c 1/1 |"
    )
    assert row(rows, "hunt-crossley") == (
        "| hunt-crossley | 1 | 0/1 | 1/1 | k 1/1, n 1/1, lambda 1/1 | k 1/1, n 0/1, lambda 1/1 |"
    )
    assert row(rows, "flores") == "| flores | 0 | 0/0 | 0/0 | - | - |"
    assert row(rows, "polynomial") == (
        "| polynomial | 2 | a named model selected 1/2 (no named model consistent with 1 of "
        "the 2) | | | |"
    )
    assert row(rows, "all") == [
        "",
        "All parameters together: 7/7 = 100.0 % inside the Jacobian's intervals, "
        "4/5 = 80.0 % inside the bootstrap's intervals.",
    ]
    stamp = s.models_stamp(files, rows)
    for path in files:
        header, _ = measured.read(path)
        assert f"`{path.name}` (commit {header['commit']}, {header['started'][:10]})" in stamp
    assert ": 5 records (and 1 seed skipped: no usable draw), each fitted by every model" in stamp
    assert "(up to 200 simulations a fit; median 20 s a record)" in stamp
    assert "the bootstrap (30 replicates) for the true model's fit on 2.*" in stamp
    lines = tables.render("contact-models", files)
    assert lines[:2] == list(s.MODELS_HEADER) and lines[-1] == stamp
    assert len(lines) == 2 + 6 + 2 + 2  # header, truths, the pooled line, the stamp


def test_the_explain_cases_table_reads_each_cases_steps(tmp_path):
    """tests.survey_explain_cases's rows: the regime read from the record (bold beyond
    P1), the effects named (one taken out, a wrong one first), the values kept with their
    standard errors (a support's with the law), each named step's gap and the bar; a later
    row of a case replaces an earlier one."""
    from tests import survey_explain_cases as s

    def row(case, named, values, steps, **kw):
        label, hidden, drifting = s.CASES[case]
        return {
            "case": case,
            "hidden": label,
            "hidden_effects": list(hidden),
            "drifting": drifting,
            "regime": "P1",
            "impacts": 1,
            "named": named,
            "kept": list(values),
            "dropped": [],
            "steps": [
                {"effect": e, "key": k, "before": b, "after": a, "floor": f}
                for e, k, b, a, f in steps
            ],
            "values": values,
            "errors": {e: None for e in values},
            "law": {"z": 2.13e8, "zd": 4.03e6},
            "criteria": {"I2": 0.05},
            "noise_floor": {"I2": 0.02},
            "seconds": 60.0,
            **kw,
        }

    pvc = "penetration_velocity_coupling"
    rows = [
        row("coupling", [pvc], {pvc: 1.0e10}, [(pvc, "I2", 0.1, 0.05, 0.01)]),
        row(
            "coupling",
            [pvc],
            {pvc: 2.007e10},
            [(pvc, "I2", 0.112, 0.0068, 0.033)],
            errors={pvc: 1.8e8},
        ),
        row(
            "supports",
            ["support_nonlinearity"],
            {"support_nonlinearity": 4.98e10},
            [("support_nonlinearity", "I2", 0.927, 0.035, 0.029)],
            regime="P4",
            impacts=3,
        ),
        row(
            "set-subharmonic",
            ["permanent_set"],
            {"permanent_set": 0.2},
            [("permanent_set", "I2", 0.668, 0.234, 0.122)],
            regime="P4",
            impacts=3,
        ),
        row(
            "coupling-mass-loss",
            ["sensor_lag", "mass_loss", pvc],
            {"mass_loss": 0.0063, pvc: 2.63e10},
            [
                ("sensor_lag", "I2", 0.2, 0.15, 0.05),
                ("mass_loss", "D", 0.065, 0.031, 0.03),
                (pvc, "I2", 0.124, 0.044, 0.04),
            ],
            dropped=["sensor_lag"],
        ),
        row("set", [], {}, [], criteria={"I2": 0.0412}),
    ]
    path = tmp_path / "explain-cases.jsonl"
    run = measured.RunFile(path, "survey_explain_cases", [])
    for r in rows:
        run.write(r)
    read = s.read_rows([path])
    assert [r["case"] for r in read] == [
        "coupling",
        "supports",
        "set-subharmonic",
        "coupling-mass-loss",
        "set",
    ]
    assert s.markdown_row(read, "coupling") == (
        "| `2e10*z*zd` (paper) | P1 | `penetration_velocity_coupling` | 2.01e10 +- 1.8e8 | "
        "I2 0.112 -> 0.0068 (floor 0.033) |"
    )
    assert s.markdown_row(read, "supports") == (
        "| supports `k3 = 5e10` (same as unloading) | **P4, 3 impacts** | "
        "`support_nonlinearity` | 4.98e10; law 2.13e8, 4.03e6 | I2 0.927 -> 0.035 (floor "
        "0.029) |"
    )
    assert s.markdown_row(read, "set-subharmonic").endswith(
        "| 0.2 | I2 0.668 -> 0.234 (floor 0.122): 2.9x, short of the 3x bar |"
    )
    both = s.markdown_row(read, "coupling-mass-loss")
    assert "| P1, drifting | `sensor_lag` (taken out), `mass_loss`, `penetration_velocity_" in both
    assert "coupling` (not the hidden effect first) | 0.0063, 2.63e10 | " in both
    assert both.endswith("D 0.065 -> 0.031 (floor 0.03); I2 0.124 -> 0.044 (floor 0.04) |")
    assert "I2 0.2 -> 0.15 (floor 0.05): 1.3x, short of the 3x bar; " in both
    assert s.markdown_row(read, "set").endswith(
        "| nothing | - | I2 0.0412 (floor 0.02), nothing named |"
    )
    assert s.markdown_row(read, "hertz").endswith("| not run |  |  |  |")
    lines = tables.render("explain-cases", [path])
    assert lines[:2] == list(s.HEADER) and len(lines) == 2 + len(s.CASES) + 2
    assert "`explain-cases.jsonl` (" in lines[-1]


# --------------------------------------------------------------------------- make bench's


def _results(commit, created, **sections):
    """A results file of ``bench/run.py`` with ``sections``."""
    return {
        **sections,
        "cores": 2,
        "versions": {"python": "3.11"},
        "git": {"commit": commit * 40, "dirty": False},
        "platform": "test",
        "created": created,
        "settings": {},
    }


def test_the_speed_history_names_each_columns_commit_and_date():
    from tests import bench_history

    table = tables.TABLES["bench-history"]
    runs = bench_history.read_rows(tables.run_files(table.rows[0][1]))
    cols = bench_history.columns(runs)
    lines = tables.render("bench-history")
    assert 0 < len(cols) <= bench_history.COLUMNS and cols[-1] is runs[-1]
    assert lines[0] == "| figure | " + " | ".join(bench_history.label(r) for r in cols) + " |"
    for r in cols:
        assert f"{bench_history.label(r)} ({r['created'][:10]}" in lines[-1]
    assert all(r["created"] and (r["commit"] or r["saved_in"]) for r in runs)


def test_the_speed_history_holds_every_run_bench_results_saved():
    """Every run of every committed bench/results.json is a row of bench-history.jsonl."""
    from tests import bench_history

    if not measured.git("rev-parse", "HEAD"):
        pytest.skip("not a git checkout")
    saved = {bench_history.key(r) for r in measured.read(bench_history.PATH)[1]}
    assert {bench_history.key(r) for r in bench_history.from_git()} <= saved


def test_a_kernel_run_after_the_bench_is_a_run_of_its_own(tmp_path):
    """python run.py kernel's figures (with their own provenance) are a partial run; make
    bench's append adds each run once; a partial run measured again by the next one is not
    a column; a figure a run lacks is a blank cell."""
    from tests import bench_history as h

    kernel = {"speedup": 44.4, "long_run_40_periods_speedup": 60.5}
    full = _results(
        "a",
        "2026-01-01T00:00:00+00:00",
        kernel_vs_scipy=kernel,
        start_up={"vidi_help_seconds": 0.1326},
        explain={"seconds": 7.07, "ratio_to_one_steady_state": 604.4, "parallel_speedup": 1.258},
    )
    path = tmp_path / "history.jsonl"
    assert [r["commit"] for r in h.append(full, path)] == ["aaaaaaa"]
    again = {**full, "kernel_vs_scipy": {**kernel, "speedup": 70.0}}
    for commit, created in (("b", "2026-01-02T00:00:00+00:00"), ("c", "2026-01-03T00:00:00+00:00")):
        again["kernel_vs_scipy_provenance"] = _results(commit, created)
        new = h.append(again, path)
        assert [(r["commit"], r["partial"], r["sections"]) for r in new] == [
            (f"{commit * 7}", True, ["kernel_vs_scipy"])
        ]
    assert h.append(again, path) == []
    runs = h.read_rows([path])
    assert [r["commit"] for r in runs] == ["aaaaaaa", "bbbbbbb", "ccccccc"]
    assert [h.label(r) for r in h.columns(runs)] == ["aaaaaaa", "ccccccc"]
    assert h.header(runs)[0] == "| figure | aaaaaaa | ccccccc |"
    assert h.markdown_row(runs, "`vidi --help`") == "| `vidi --help` | 0.13 s |  |"
    assert h.markdown_row(runs, "`explain`, full catalogue").endswith("| 7.1 s, 604 x |  |")
    assert "| 44x / 60x | 70x / 60x |" in h.markdown_row(
        runs, "kernel vs scipy at equal accuracy, one period / 40 periods"
    )
    assert h.markdown_row(runs, "Ueda chart 60x60") == "| Ueda chart 60x60 |  |  |"


def _full_run(h, tmp_path):
    """A full bench run's results, appended to a fresh history file: ``(results, path)``."""
    full = _results(
        "a",
        "2026-01-01T00:00:00+00:00",
        kernel_vs_scipy={"speedup": 44.4, "long_run_40_periods_speedup": 60.5},
        pipeline={"one_steady_state_seconds": 1e-3},
        explain={"seconds": 6.1, "cores": 2},
    )
    path = tmp_path / "history.jsonl"
    h.append(full, path)
    return full, path


def test_a_paired_study_run_is_a_run_of_its_own_the_readme_names(tmp_path):
    """python run.py paper-study's section (with its own provenance) is a partial run: a
    column of the speed history with its ratio, and a line of the README's paragraph with
    its run named under it; before any such run the README has no line on it."""
    from tests import bench_history as h

    full, path = _full_run(h, tmp_path)
    assert not any("paper study" in line for line in h.readme_lines(h.read_rows([path])))
    study = {
        "ratio": 0.571,
        "simulations_new": 62049,
        "simulations_old": 104436,
        "same_cells": 59,
        "cells": 60,
    }
    again = {
        **full,
        "paired_study": {"baseline": "44858e9", "pairs": 3, "commands": {"paper-study": study}},
        "paired_study_provenance": _results("b", "2026-01-02T00:00:00+00:00"),
    }
    new = h.append(again, path)
    assert [(r["commit"], r["partial"], r["sections"]) for r in new] == [
        ("bbbbbbb", True, ["paired_study"])
    ]
    runs = h.read_rows([path])
    label = "the paper study over the baseline's, paired (`make bench-study`)"
    assert h.markdown_row(runs, label) == f"| {label} |  | 0.57 (59/60 cells same) |"
    lines = h.readme_lines(runs)
    assert "2026-01-01 on" in lines[0]  # the paragraph is the last full run's
    assert lines[-1] == (
        "  the shipped paper study (`make bench-study`, 120 runs, tables only; at bbbbbbb, "
        "2026-01-02, medians of 3 pairs) 0.57, with 0.59 of the simulations and the same "
        "table in 59 of its 60 cells;"
    )
    assert h.readme_stamp([path], runs).endswith(
        "at aaaaaaa (2026-01-01) and the last `make bench-study` run, at bbbbbbb (2026-01-02).*"
    )


def test_a_paired_corpus_run_is_a_run_of_its_own_the_readme_names(tmp_path):
    """python run.py corpus's section (with its own provenance) is a partial run: a column
    of the speed history with explain's ratio and agreement, and a line of the README's
    paragraph with each command's ratio, agreement and rightness, its run named under it."""
    from tests import bench_history as h

    full, path = _full_run(h, tmp_path)
    assert not any("corpus" in line for line in h.readme_lines(h.read_rows([path])))

    def command(ratio, same, right_new, right_old):
        return {
            "ratio": ratio,
            "records": 16,
            "same": same,
            "judged": 15,
            "right_new": right_new,
            "right_old": right_old,
        }

    corpus = {
        "baseline": "44858e9",
        "commands": {
            "verify": command(0.612, 15, 15, 12),
            "explain": command(0.789, 13, 14, 11),
        },
    }
    again = {
        **full,
        "paired_corpus": corpus,
        "paired_corpus_provenance": _results("c", "2026-01-03T00:00:00+00:00"),
    }
    new = h.append(again, path)
    assert [(r["commit"], r["partial"], r["sections"]) for r in new] == [
        ("ccccccc", True, ["paired_corpus"])
    ]
    runs = h.read_rows([path])
    label = "`explain` on the corpus over the baseline's, paired (`make bench-corpus`)"
    assert h.markdown_row(runs, label) == f"| {label} |  | 0.79 (13/16 records same) |"
    assert h.readme_lines(runs)[-1] == (
        "  on the corpus (`make bench-corpus`, every record once a side; at ccccccc, "
        "2026-01-03, medians over the records): `verify` with the true law 0.61 (the same "
        "verdicts on 15 of 16 records; right 15/15 against 12/15); `explain` 0.79 (the same "
        "named effects and verdicts on 13 of 16 records; right 14/15 against 11/15);"
    )
    assert h.readme_stamp([path], runs).endswith(
        "at aaaaaaa (2026-01-01) and the last `make bench-corpus` run, at ccccccc (2026-01-03).*"
    )


def test_a_scaling_run_adds_its_machines_rows(tmp_path):
    """A scaling run file (as run.py scaling --out FILE.jsonl writes it) is headed by its
    command, commit and machine; the table has a row per machine and work, a later run on as
    many cores replacing an earlier one, and a column per worker count measured."""
    from tests import bench_scaling as s

    def result(cores, study, explain):
        return {
            "cores": cores,
            "study": {"runs": 24, "by_workers": study, "same_table": True},
            "explain": {"by_workers": explain, "named": [], "same_named": True},
        }

    def saved(name, result):  # a run file of an earlier run
        path = tmp_path / name
        path.write_text('{"run": {"started": "2000-01-01"}}\n' + json.dumps(result) + "\n")
        return path

    explain = [{"workers": 1, "seconds": 10.0}, {"workers": 4, "seconds": 5.0}]
    old = saved("scaling-old.jsonl", result(4, [], explain))
    big = saved("scaling-big.jsonl", result(32, [], [{"workers": 32, "seconds": 2.0}]))
    path = tmp_path / "scaling-new.jsonl"
    study = [{"workers": 4, "seconds": 120.4, "parallel_efficiency": 0.9}]
    s.write_run(path, result(4, study, explain), "cd bench && python run.py scaling")
    header, rows = measured.read(path)
    assert header["command"] == "cd bench && python run.py scaling" and header["started"]
    assert header["cores"] == rows[0]["cores"] == 4 and "code" in header

    files = [old, big, path]
    runs = s.read_rows(files)
    assert [r["cores"] for r in runs] == [32, 4]
    assert s.header(runs)[0] == "| work | machine | 1 worker | 4 | 32 |"
    assert s.markdown_row(runs, s.STUDY)[1].endswith(
        "| 4 cores" + (f", {s.cpu_model()}" if s.cpu_model() else "") + " |  | 120 s (0.90) |  |"
    )
    assert s.markdown_row(runs, s.EXPLAIN)[1].endswith("| 10.0 s | 5.0 s (2.00x) |  |")
    stamp = s.stamp(files, runs)
    assert "scaling-old.jsonl" not in stamp and "`scaling-new.jsonl` (" in stamp


def test_the_study_table_is_each_methods_cells_and_pooled_counts(tmp_path):
    """The shipped study's table: per method, each force noise's recoveries at each record
    length, then the pooled count with its Wilson interval, false terms and coverage; the
    line under it names the run's commit, cells, runs and time."""
    from tests import survey_study

    rows = []
    for noise in (0.01, 0.05):
        for periods in (4, 40):
            for method, k in (("best-subset", 2), ("stlsq", 0)):
                rows.append(
                    {"kind": "cell", "selection": method, "force_noise": noise}
                    | {"periods": periods, "runs": 2, "recovered": k - (noise == 0.05)}
                )
    rows += [
        {"kind": "pooled", "selection": "best-subset", "runs": 8, "recovered": 4}
        | {"recovery_ci": [0.2, 0.8], "fp_per_run": 0.25, "covered": 9, "intervals": 10}
        | {"coverage_ci": [0.6, 0.98]},
        {"kind": "pooled", "selection": "stlsq", "runs": 8, "recovered": 0}
        | {"recovery_ci": [0.0, 0.3], "fp_per_run": None, "covered": 0, "intervals": 0}
        | {"coverage_ci": [None, None]},
        {"kind": "timing", "seconds": 600.0},
    ]
    head = survey_study.header(rows)
    assert head[0].startswith("| method | 1 % | 5 % | all (95 % CI) |")
    assert head[1].count("---") == 6
    best = survey_study.markdown_row(rows, "best-subset")
    assert best == "| best-subset | 2/2 2/2 | 1/2 1/2 | 4/8 (0.20-0.80) | 0.25 | 9/10 (0.60-0.98) |"
    assert survey_study.markdown_row(rows, "stlsq").endswith("| 0/8 (0.00-0.30) | -- | -- |")
    path = tmp_path / "study-paper.jsonl"
    run = measured.RunFile(path, "survey_study", ["--workers", "2"], workers=2)
    for r in rows:
        run.write(r)
    line = survey_study.stamp([path], rows)
    assert "4 / 40 recorded periods" in line and "8 cells, 16 runs, 10.0 min on 2" in line


def test_the_fit_sheet_table_counts_each_record_once_by_its_outcome(tmp_path):
    """tests.survey_fit_sheet's rows: a later row of a draw and noise level replaces an
    earlier one; refusals and errors are columns of their own; a true law outside the
    library is counted apart (with how many of those are consistent); the rates are among
    the fitted records the library holds; a draw whose quieter record loses the right
    support that its noisier one has is a pair."""
    from tests import survey_fit_sheet as s

    def row(i, noise, cat="p1", inside=True, **kw):
        return {"draw": i, "category": cat, "noise": noise, "in_library": inside, **kw}

    good = dict(right_support=True, consistent=True, worst_coefficient_error=0.01)
    rows = [
        row(0, "high", **good),
        row(0, "low", right_support=False, consistent=True),  # worse on better data
        row(1, "high", refused="fewer than 10 contact samples"),
        row(1, "low", **{**good, "worst_coefficient_error": 0.08}),  # right, 8 % off
        row(2, "high", inside=False, right_support=False, consistent=True),
        row(2, "low", inside=False, right_support=False, consistent=False),
        row(3, "high", cat="subharmonic", error="TypeError: x"),
        row(3, "low", cat="subharmonic", right_support=True, consistent=False),
    ]
    path = tmp_path / "fit-sheet-test.jsonl"
    out = measured.RunFile(path, "survey_fit_sheet", ["--draws", "0", "4"])
    for r in rows:
        out.write(r)
    out.write(row(3, "low", cat="subharmonic", **good))  # draw 3 again: now right
    read = s.read_rows([path])
    assert len(read) == 8 and read[-1]["consistent"]
    assert s.markdown_row(read, "p1") == "| p1 | 6 | 1 | 0 | 2 (1) | 2/3 | 3/3 | 1/3 | 1 |"
    assert s.markdown_row(read, "subharmonic") == (
        "| subharmonic | 2 | 0 | 1 | 0 (0) | 1/1 | 1/1 | 1/1 | 0 |"
    )
    assert s.markdown_row(read, "all") == "| all | 8 | 1 | 1 | 2 (1) | 3/4 | 4/4 | 2/4 | 1 |"
