"""`vidi calibrate` and the machine every command judges a record with (`--machine`)."""

import json
from pathlib import Path

import numpy as np
import pytest

from discovery import load, load_scenario
from discovery.cli import main

CORPUS = Path(__file__).resolve().parents[3] / "shared" / "corpus"
C14 = CORPUS / "c14-heavy-moulding"
needs_corpus = pytest.mark.skipif(not C14.is_dir(), reason="the corpus is not here")


def _args(record=C14):
    return ["--scenario", str(record / "scenario.toml"), "--data", str(record / "measured.csv")]


@needs_corpus
def test_calibrate_writes_the_table_the_scenario_and_the_figure(tmp_path, capsys):
    out = tmp_path / "cal"
    assert main(["calibrate", *_args(), "--n-boot", "50", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "the record's moulding mass is 6.3" in printed and "the scenario says 6 t" in printed
    sc = load_scenario(str(out / "scenario.toml"))
    assert sc.m2 == pytest.approx(6300, rel=0.02) and sc.m1 == pytest.approx(9000, rel=0.02)
    assert (out / "calibrate.png").stat().st_size > 0
    res = load(out)
    assert res.calibrated and res.scenario == sc.replace(name=res.scenario.name)
    s = json.loads((out / "summary.json").read_text())
    assert s["command"] == "calibrate" and s["settings"]["n_boot"] == 50


@needs_corpus
def test_verify_judges_the_record_s_machine_by_default_and_the_sheet_on_request(tmp_path, capsys):
    law = ["--law", "1.5e8*z + 5e6*zd"]
    assert main(["verify", *_args(), *law, "--out", str(tmp_path / "v")]) == 0
    printed = capsys.readouterr().out
    assert "machine: calibrated from the record" in printed and ": consistent" in printed
    s = json.loads((tmp_path / "v" / "summary.json").read_text())
    assert s["machine"]["used"] == "record" and s["consistent"]
    assert s["scenario"]["m2"] == pytest.approx(6300, rel=0.02)
    assert s["machine"]["sheet"][0]["m2"] == 6000
    args = ["verify", *_args(), *law, "--machine", "sheet", "--out", str(tmp_path / "s")]
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "(not used: --machine sheet)" in printed and ": inconsistent" in printed


def _write(path, t, F, w1, v1, w2, v2):
    rows = np.column_stack([t, F, w1, v1, w2, v2])
    np.savetxt(path, rows, delimiter=",", header="t,F,w1,v1,w2,v2", comments="")


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    path = tmp_path_factory.mktemp("rec") / "d.csv"
    assert main(["simulate", "--periods", "10", "--fs", "19310", "--out", str(path)]) == 0
    return np.loadtxt(path, delimiter=",", skiprows=1)


@pytest.mark.parametrize(
    "change, words",
    [
        ({1: 1e-3}, "is F in kN"),
        ({2: 1e3, 4: 1e3}, "positions in mm"),
        ({2: -1, 3: -1, 4: -1, 5: -1}, "measured downwards"),
    ],
)
@pytest.mark.parametrize("command", ["verify", "fit", "calibrate"])
def test_units_and_signs_are_one_line_on_every_command(
    record, tmp_path, capsys, change, words, command
):
    cols = record.copy()
    for k, f in change.items():
        cols[:, k] *= f
    path = tmp_path / "bad.csv"
    _write(path, *cols.T)
    assert main([command, "--data", str(path), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err
    assert not (tmp_path / "o").exists()


def test_a_bad_keep_is_one_line(record, tmp_path, capsys):
    path = tmp_path / "d.csv"
    _write(path, *record.T)
    assert (
        main(["calibrate", "--data", str(path), "--keep", "m3", "--out", str(tmp_path / "o")]) == 2
    )
    assert "--keep names 'm3'" in capsys.readouterr().err


def test_the_readme_s_scipy_record_from_rest_is_verified_not_refused(tmp_path, capsys):
    """The README's 20-period record from rest (scipy path) is still settling: its force does
    not repeat at a whole number of drive periods (0.965 of one), but its frame is driven at
    the scenario's 25 Hz (the drive line), so it is judged over its span, not refused as a
    record of another drive frequency."""
    law = "2.06e8*z + 4e6*zd; unloading: 4e6*zd"
    rec = tmp_path / "R.csv"
    args = ["simulate", "--law", law, "--from-rest", "--integrator", "scipy", "--noise", "0.01"]
    assert main([*args, "--out", str(rec)]) == 0
    assert main(["verify", "--data", str(rec), "--law", law, "--out", str(tmp_path / "v")]) == 0
    assert ": consistent" in capsys.readouterr().out


@needs_corpus
def test_the_reports_show_the_machine_used(tmp_path):
    """A calibrate run's report and a verify run's report, with the calibrated machine, both
    hold the table sheet vs record."""
    cal, ver = tmp_path / "cal", tmp_path / "ver"
    assert main(["calibrate", *_args(), "--n-boot", "30", "--out", str(cal)]) == 0
    law = ["--law", "1.5e8*z + 5e6*zd"]
    assert main(["verify", *_args(), *law, "--n-boot", "8", "--out", str(ver)]) == 0
    for run in (cal, ver):
        assert main(["report", str(run), "--no-pdf"]) == 0
        tex = (run / "report.tex").read_text()
        assert "The machine as the record shows it" in tex and "record (95 \\% interval)" in tex
        assert "m2 [" in tex
    assert "the machine calibrated from" in (ver / "report.tex").read_text()


def test_identify_s_intervals_carry_the_calibrated_machine_s_scale(tmp_path):
    """A law identified on the machine calibrated from the record carries the scale's error
    (the README quickstart's record: the machine read 0.75 % heavy, the law as much stiffer);
    its bootstrap intervals are widened to the scale's range, as verify, fit and explain
    widen theirs, and hold the true law (they were 1e-5 wide around the scaled law)."""
    rec = tmp_path / "q.csv"
    words = ["simulate", "--scenario", "paper", "--periods", "12", "--noise", "0.01"]
    assert main([*words, "--seed", "1", "--out", str(rec)]) == 0
    out = tmp_path / "id"
    start = ["--start", "1.5e8*z + 1e7*zd"]
    assert main(["identify", "--data", str(rec), *start, "--out", str(out), "--quiet"]) == 0
    s = json.loads((out / "summary.json").read_text())
    low, high = s["machine"]["scale_range"]
    assert low < 1.0 < high and "machine's scale" in s["intervals"]["method"]
    for name, truth in (("z", 2.06e8), ("zd", 1.28e7)):
        lo, hi = s["intervals"]["bounds"][name]
        assert lo < truth < hi
