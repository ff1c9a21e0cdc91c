"""The older sweep's remaining failures: each one line with exit 2, or a documented result."""

import shutil
import subprocess
import sys

import pytest

from discovery.cli import main

VIDI = [sys.executable, "-c", "import sys; from discovery.cli import main; sys.exit(main())"]

SCENARIO = """name = "s"
[machine]
m1 = 1.0e4
m2 = {m2}
k1 = 2.75e7
c1 = 1.0e5
A = {A}
frequency = 25.0
[law]
text = "2.06e8*z + 1.28e7*zd"
"""


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    d = tmp_path_factory.mktemp("rec")
    path = d / "d.csv"
    assert main(["simulate", "--periods", "6", "--out", str(path)]) == 0
    return path


def _one_line(capsys):
    err = capsys.readouterr().err.strip().splitlines()[-1]  # after any progress lines
    assert err.startswith("vidi: error:") and "Traceback" not in err, err
    return err


def test_fit_margin_far_too_large_names_the_option(record, tmp_path, capsys):
    out = tmp_path / "f"
    assert main(["fit", "--data", str(record), "--margin", "1e300", "--out", str(out)]) == 2
    assert "--margin" in _one_line(capsys) and not out.exists()


def test_a_landscape_whose_every_point_failed_is_one_line(record, tmp_path, capsys):
    out = tmp_path / "l"
    argv = ["landscape", "--data", str(record), "--range0", "1e300:1e308"]
    assert main([*argv, "--grid", "3x3", "--out", str(out)]) == 2
    assert "every one of the 9 simulations" in _one_line(capsys)
    assert sorted(p.name for p in tmp_path.iterdir()) == []


def test_a_record_name_with_dollars_is_text_in_the_figures(record, tmp_path, capsys):
    odd = tmp_path / "r$\\undefinedmacro{x}$.csv"
    shutil.copy(record, odd)
    out = tmp_path / "l"
    argv = ["landscape", "--data", str(odd), "--grid", "3x3", "--out", str(out)]
    assert main(argv) == 0, capsys.readouterr().err
    assert (out / "landscape.png").stat().st_size > 0


def test_ueda_option_takes_a_negative_value(tmp_path, capsys):
    out = tmp_path / "a"
    argv = ["ueda", "attractor", "--x0", "-1e-3", "--periods", "200", "--transient", "20"]
    assert main([*argv, "--batches", "4", "--out", str(out)]) == 0
    capsys.readouterr()
    assert (out / "summary.json").exists()


def test_a_missing_value_hint_fits_the_option(capsys):
    assert main(["ueda", "attractor", "--x0"]) == 2
    err = _one_line(capsys)
    assert "--x0=-1e-3" in err and "*z" not in err


def test_a_csv_row_with_more_fields_than_headers_is_refused(tmp_path, capsys):
    bad = tmp_path / "bad.csv"
    bad.write_text("t,F,w1,v1,w2,v2\n0,0,0,0,0,0\n1e-4,0,0,0,0,0,7\n")
    assert main(["verify", "--data", str(bad), "--out", str(tmp_path / "v")]) == 2
    assert "line 3 has 7 fields under a header of 6 columns" in _one_line(capsys)


def test_a_huge_drive_amplitude_is_a_failed_simulation(tmp_path, capsys):
    sc = tmp_path / "big.toml"
    sc.write_text(SCENARIO.format(m2="1.0e4", A="1e12"))
    assert main(["steady", "--scenario", str(sc)]) == 2
    assert "could not be computed" in _one_line(capsys)


def test_a_tiny_mass_is_refused_without_numpy_warnings(tmp_path):
    sc = tmp_path / "tiny.toml"
    sc.write_text(SCENARIO.format(m2="1e-300", A="5e5"))
    p = subprocess.run(
        [*VIDI, "steady", "--scenario", str(sc)], capture_output=True, text=True, timeout=120
    )
    assert p.returncode == 2
    assert "Warning" not in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr


def test_an_attractor_its_own_check_disputes_is_not_a_result(tmp_path, capsys, monkeypatch):
    """The Lyapunov sum must equal the mean trace of the flow; when the integration from
    the given start makes them disagree, `ueda attractor` says so (exit 2), no output."""
    import dataclasses

    import discovery.ueda as ueda

    real = ueda.attractor  # the command reads the package's name

    def off(*a, **k):
        att = real(*a, **k)
        lyap = dataclasses.replace(att.lyapunov, sum=att.lyapunov.sum + 0.5)
        return dataclasses.replace(att, lyapunov=lyap)

    monkeypatch.setattr(ueda, "attractor", off)
    out = tmp_path / "a"
    argv = ["ueda", "attractor", "--x0", "1000", "--periods", "200", "--transient", "20"]
    assert main([*argv, "--batches", "4", "--out", str(out)]) == 2
    assert "disagrees with the mean trace" in _one_line(capsys)
    assert not out.exists()
