"""End-to-end tests of the vidi command line (each command calls the API only)."""

import json

import numpy as np
import pytest

from discovery.cli import main


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    d = tmp_path_factory.mktemp("rec")
    path = d / "d.csv"
    assert main(["simulate", "--periods", "8", "--out", str(path)]) == 0
    return path


def test_simulate_writes_csv_and_summary(record):
    header = record.read_text().splitlines()[0]
    assert header == "t,F,w1,v1,w2,v2"
    s = json.loads(record.with_suffix(".summary.json").read_text())
    assert s["samples"] == 8 * 800
    assert s["versions"]["numpy"] and s["settings"]["seed"] == 0


def test_landscape_small_grid(tmp_path):
    out = tmp_path / "land"
    assert main(["landscape", "--grid", "3x3", "--workers", "1", "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert len(s["alpha1"]) == 3 and s["alpha1"][0] == 1.03e8 and s["alpha1"][-1] == 3.09e8
    assert np.array(s["I2"]).shape == (3, 3)
    # the centre of the paper's box is the true law: every criterion vanishes there
    # (exact impulses on both sides; 1e-9 covers the integrator tolerance)
    for name in ("I0", "I1", "I2", "I3", "I4"):
        assert s[name][1][1] < 1e-6
    assert s["regime"][1][1] == "P1"
    for f in ("landscape.csv", "landscape.png", "landscape.pdf"):
        assert (out / f).stat().st_size > 0


def test_identify_recovers_true_law(record, tmp_path):
    out = tmp_path / "id"
    rc = main(
        [
            "identify",
            "--data",
            str(record),
            "--start",
            "1.5e8*z + 0.9e7*zd",
            "--method",
            "least-squares",
            "--out",
            str(out),
        ]
    )
    assert rc == 0
    s = json.loads((out / "summary.json").read_text())
    c = s["coefficients"]
    # noise-free data sampled at 20 kHz: the onset is known to O(dt^3), 0.3 % is ample
    assert abs(c["z"] / 2.06e8 - 1) < 3e-3 and abs(c["zd"] / 1.28e7 - 1) < 3e-3
    assert s["iterations"] and s["n_simulations"] >= s["iterations"][-1]["n_simulations"]
    # I0..I4 of the force, I5 of the recorded penetration (the record has positions)
    assert set(s["criteria"]) == {"I0", "I1", "I2", "I3", "I4", "I5"}


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["simulate", "--law", "2*q", "--out", "x.csv"], "cannot read force law"),
        (["simulate", "--scenario", "nope.toml", "--out", "x.csv"], "does not exist"),
        (["identify", "--data", "missing.csv", "--start", "z", "--out", "o"], "does not exist"),
        (["landscape", "--grid", "4by4", "--out", "o"], "must look like 41x41"),
    ],
)
def test_bad_input_one_line_exit_2(argv, needle, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and "\n" not in err and "Traceback" not in err


def test_bad_csv_does_not_destroy_earlier_results(record, tmp_path, capsys):
    out = tmp_path / "id"
    out.mkdir()
    (out / "summary.json").write_text('{"command": "identify", "earlier": true}')
    bad = tmp_path / "bad.csv"
    bad.write_text("t,F\n0,0\n1e-4,1\n1e-4,2\n3e-4,0\n4e-4,0\n")
    assert main(["identify", "--data", str(bad), "--start", "z", "--out", str(out)]) == 2
    assert "duplicate time" in capsys.readouterr().err
    assert json.loads((out / "summary.json").read_text()) == {
        "command": "identify",
        "earlier": True,
    }
    assert list(tmp_path.glob(".id.*")) == []


@pytest.mark.parametrize(
    "body, needle",
    [
        ("t,F\n0,0\n1,nan\n2,0\n3,0\n", "non-finite"),
        ("t,F\n0,0\n2,1\n1,0\n3,0\n", "not increasing"),
        ("time,F\n0,0\n", "no column t"),
        ("t,F\n" + "".join(f"{k * 1e-4!r},0\n" for k in range(2000)), "no contact"),
    ],
)
def test_bad_csv_messages(body, needle, tmp_path, capsys):
    p = tmp_path / "d.csv"
    p.write_text(body)
    assert main(["identify", "--data", str(p), "--start", "z", "--out", str(tmp_path / "o")]) == 2
    assert needle in capsys.readouterr().err


@pytest.mark.parametrize(
    "command", [["verify"], ["fit"], ["explain"], ["identify", "--start", "z"]]
)
def test_a_time_column_in_milliseconds_is_refused_in_one_line(command, record, tmp_path, capsys):
    """A record whose t is in ms has under one sample per drive period: one line naming the
    sampling and the likely cause, exit 2 (it was an internal error)."""
    rows = record.read_text().splitlines()
    ms = [rows[0]] + [
        ",".join([repr(1e3 * float(r.split(",")[0]))] + r.split(",")[1:]) for r in rows[1:]
    ]
    p = tmp_path / "ms.csv"
    p.write_text("\n".join(ms) + "\n")
    assert main([*command, "--data", str(p), "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err.strip()
    assert "0.8 samples per drive period" in err and "t column is in seconds" in err
    assert "\n" not in err and "Traceback" not in err


def test_verify_command_writes_summary_and_figure(tmp_path):

    from discovery import load_scenario
    from discovery.vibroimpact.data.measurement import Measurement
    from discovery.vibroimpact.dynamics.reference import reference_simulate

    sc = load_scenario("light")
    T = sc.period
    t = 60 * T + np.arange(int(12 * T * 20000)) / 20000.0
    r = reference_simulate(sc, sc.law, (0.0, t[-1]), t_eval=t, rtol=1e-9)
    rng = np.random.default_rng(5)
    ch = {
        n: r["y"][k] + rng.normal(0, 0.002 * np.ptp(r["y"][k]), t.size)
        for k, n in enumerate(("w1", "v1", "w2", "v2"))
    }
    F = r["force"] + rng.normal(0, 0.01 * r["force"].max(), t.size)
    Measurement(t, F, ch).to_csv(tmp_path / "rec.csv")
    out = tmp_path / "v"
    assert (
        main(
            [
                "verify",
                "--scenario",
                "light",
                "--data",
                str(tmp_path / "rec.csv"),
                "--out",
                str(out),
                "--n-boot",
                "8",
            ]
        )
        == 0
    )
    d = json.loads((out / "summary.json").read_text())
    assert d["consistent"] is True and d["regime"] == {"measured": "P1", "simulated": "P1"}
    assert set(d["noise_floor"]) == {"I0", "I1", "I2", "I3", "I4", "I5"}
    assert d["criteria"]["I2"] <= 2 * d["noise_floor"]["I2"] + 0.005
    assert (out / "verify.png").stat().st_size > 0
    # a wrong law is inconsistent; an empty law is one clear line, exit 2
    assert (
        main(
            [
                "verify",
                "--scenario",
                "light",
                "--data",
                str(tmp_path / "rec.csv"),
                "--law",
                "3e10*z^1.5 + 5e11*z^1.5*zd",
                "--out",
                str(tmp_path / "w"),
                "--n-boot",
                "8",
            ]
        )
        == 0
    )
    assert json.loads((tmp_path / "w" / "summary.json").read_text())["consistent"] is False
    assert (
        main(
            [
                "verify",
                "--scenario",
                "light",
                "--data",
                str(tmp_path / "rec.csv"),
                "--law",
                " ",
                "--out",
                str(tmp_path / "e"),
            ]
        )
        == 2
    )
    assert not (tmp_path / "e").exists()


def test_steady_says_nonperiodic_without_calling_it_a_failure(tmp_path, capsys):
    """A motion without a periodic steady state is a finding, not a failed simulation."""
    sc = tmp_path / "drawn.toml"
    sc.write_text(
        'name = "drawn"\n[machine]\nm1 = 3940.0\nm2 = 5610.0\nk1 = 5.23e7\nc1 = 1.35e5\n'
        "A = 1.21e5\nfrequency = 32.4\n"
    )
    law = "flores: k=7.063e+09, n=1.52, e=0.878"
    out = tmp_path / "ss"
    assert main(["steady", "--scenario", str(sc), "--law", law, "--out", str(out)]) == 0
    said = capsys.readouterr().out
    assert "no periodic steady state" in said and "failed" not in said
    assert json.loads((out / "summary.json").read_text())["regime"] == "nonperiodic"
