"""The experiment loop as one call (``discovery.campaign``, ``vidi advise --until-settled``):
records of the independent scipy path, the sheet a few percent off the machine that makes
them, each next record taken where the loop advises; its result, its stops and its refusals."""

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from discovery import (
    CampaignResult,
    DiscoverSettings,
    ForceLaw,
    Knobs,
    NextRecord,
    SafeRegion,
    campaign,
    load,
    load_scenario,
)
from discovery.cli import main
from discovery.cli.advise_loop import acquire_command
from discovery.errors import InputError, VidiTypeError
from discovery.vibroimpact.advise.campaign_loop import CampaignStep
from tests import realistic as R

LAW = ForceLaw.parse("2.06e8*z + 8e6*zd + 4e9*z*zd")


def _machine():
    """The machine that makes the records: the paper's sheet, its masses and supports off."""
    sheet = load_scenario("paper")
    return sheet, sheet.replace(m1=sheet.m1 * 1.03, m2=sheet.m2 * 0.97, c1=sheet.c1 * 1.05)


def _record(machine, seed):
    return R.reference_record(
        (machine.with_law(LAW), LAW), force_noise=0.01, motion_noise=0.002, seed=seed
    )


def test_the_loop_settles_a_law_its_first_record_leaves_open():
    sheet, truth = _machine()
    asked = []

    def acquire(request):
        assert isinstance(request, NextRecord) and request.step == len(asked) + 2
        assert 0.7 * sheet.A <= request.amplitude <= 1.3 * sheet.A
        # the rig is set by its knobs; the machine is what it is, not the sheet
        asked.append(request)
        rec = truth.replace(A=request.amplitude, frequency=request.frequency)
        return _record(rec, 100 + request.step)

    first = _record(truth, 100)
    knobs = Knobs((0.7 * sheet.A, 1.3 * sheet.A), (20.0, 30.0), grid=(4, 4))
    res = campaign(
        sheet,
        first,
        acquire,
        knobs,
        safe=SafeRegion(max_force=3 * float(np.max(first.F))),
        fit=DiscoverSettings(n_boot_intervals=0),
        workers=2,
    )
    assert res.settled, str(res)
    # the true support is selected and every rival left only adds terms to it
    assert sorted(ForceLaw.parse(res.law).names) == sorted(LAW.names)
    assert all(set(LAW.names) <= set(ForceLaw.parse(t).names) for t in res.remaining)
    assert len(res.records) == len(asked) + 1 == len(res.steps)
    assert res.steps[0].point is not None and res.steps[-1].point is None
    pairs = res.steps[0].point["pairs"]  # each advised pair, for the calibration table
    assert pairs and all(q["by"] in ("criteria", "regime", "physics") for q in pairs)
    assert res.machine_from == "record" and res.fit is not None
    text = str(res)
    assert text.startswith("campaign: settled after") and "step 1:" in text
    back = CampaignResult.from_dict(res.to_dict())
    assert back == res and str(back) == text


def test_a_campaign_round_trips_and_prints(tmp_path):
    step = CampaignStep(
        1,
        "2e8*z + 1e7*zd",
        True,
        ("2e8*z + 1e7*zd", "2e8*z + 9e6*zd + 1e9*z*zd"),
        {
            "amplitude": 5e5,
            "frequency": 22.0,
            "m2": None,
            "separation": 3.2,
            "refitted": 1.4,
            "regime_change": False,
        },
        1.5,
    )
    res = CampaignResult(
        steps=(step,),
        stopped="budget",
        reason="the records reached max_records (2); 2 candidates remain",
        law="2e8*z + 1e7*zd",
        remaining=step.candidates,
        records=({"amplitude": 5e5, "frequency": 25.0, "m2": 6000.0, "source": "D.csv"},),
    )
    res.save(tmp_path / "c")
    back = load(tmp_path / "c")
    assert isinstance(back, CampaignResult) and back == res
    text = str(back)
    assert "next record at A = 5e+05 N, f = 22 Hz (separation 3.2; with each rival " in text
    assert "refitted 1.4)" in text
    assert "remaining candidates:" in text and not back.settled
    # a regime change separates without a number: said in words, and it reads back
    regime = CampaignStep(**{**step.__dict__, "point": {**step.point, "separation": None}})
    res = CampaignResult(**{**res.__dict__, "steps": (regime,)})
    back = CampaignResult.from_dict(res.to_dict())
    assert "(separation infinite: a regime change; with each rival refitted 1.4)" in str(back)


def test_a_campaign_has_a_report(tmp_path):
    import discovery

    step = CampaignStep(
        1,
        "2e8*z + 1e7*zd",
        True,
        ("2e8*z + 1e7*zd", "2e8*z + 9e6*zd + 1e9*z*zd"),
        {"amplitude": 5e5, "frequency": 22.0, "m2": None, "separation": None, "refitted": 0.4},
    )
    last = CampaignStep(2, "2e8*z + 1e7*zd", True, ("2e8*z + 1e7*zd",))
    res = CampaignResult(
        steps=(step, last),
        stopped="settled",
        reason="one law remains: the joint fit lists no equivalent model (2e8*z + 1e7*zd)",
        law="2e8*z + 1e7*zd",
        remaining=("2e8*z + 1e7*zd",),
        records=(
            {"amplitude": 5e5, "frequency": 25.0, "m2": 6000.0, "source": "D.csv"},
            {"amplitude": 5e5, "frequency": 22.0, "m2": 6000.0, "source": "r/record_2.csv"},
        ),
    )
    rep = discovery.report(res, out=tmp_path / "c", compile=False)
    tex = (tmp_path / "c" / "report.tex").read_text()
    assert "The experiment loop" in tex and "a regime change" in tex and "record\\_2.csv" in tex
    assert "One law remains." in tex and rep is not None


def test_acquire_must_be_a_callable_that_returns_a_record():
    sheet, truth = _machine()
    knobs = Knobs((4e5, 6e5), (20.0, 30.0), grid=(2, 2))
    with pytest.raises(VidiTypeError, match="acquire must be a callable"):
        campaign(sheet, _record(truth, 1), "rig.py", knobs)
    with pytest.raises(VidiTypeError, match="unexpected keyword 'max_record'"):
        campaign(sheet, _record(truth, 1), print, knobs, max_record=3)


@pytest.mark.parametrize(
    "template, words",
    [
        ("rig --A {amplitude} --out {out}", None),
        ("rig --A {amp} --out {out}", "placeholder {amp}"),
        ("rig --A {amplitude}", "must write the record to {out}"),
        ("rig --A '{amplitude} --out {out}", "cannot be split"),
        ("rig --A {amplitude --out {out}", "brace that is no placeholder"),
        ("", "is empty"),
    ],
)
def test_the_acquire_command_is_checked_before_anything_runs(template, words):
    if words is None:
        assert acquire_command(template)[-1] == "{out}"
        return
    with pytest.raises(InputError, match=words.replace("{", r"\{").replace("}", r"\}")):
        acquire_command(template)


@pytest.mark.parametrize(
    "extra, words",
    [
        (["--until-settled", "--law", "2e8*z", "--law", "3e8*z"], "leave out --law"),
        (["--until-settled", "--noise", "0.01", "--periods", "9"], "--noise and --periods"),
        (["--until-settled", "--data", "D.csv"], "--acquire CMD"),
        (["--acquire", "rig {out}"], "--acquire acts only with --until-settled"),
        (["--max-records", "3"], "--max-records acts only with --until-settled"),
        (
            ["--until-settled", "--data", "D.csv", "--acquire", "rig --A {amp} {out}"],
            "placeholder {amp}",
        ),
        (
            ["--until-settled", "--data", "D.csv", "--acquire", "no-such-rig --out {out}"],
            "no program 'no-such-rig' on the PATH (the command runs without a shell)",
        ),
        (
            ["--until-settled", "--data", "D.csv", "--acquire", "true {out}", "--resume"],
            "--resume: 'loop.records' holds no record_K.csv of an earlier loop",
        ),
    ],
)
def test_cli_loop_options_are_checked_in_one_line(tmp_path, capsys, monkeypatch, extra, words):
    monkeypatch.chdir(tmp_path)
    if "D.csv" in extra:
        main(["simulate", "--periods", "6", "--out", "D.csv"])
    capsys.readouterr()
    argv = ["advise", "--amplitude", "3e5:6e5", "--frequency", "20:30", "--out", "loop"]
    assert main(argv + extra) == 2
    err = capsys.readouterr().err.strip()
    assert err.count("\n") == 0 and words in err and "Traceback" not in err
    assert not (tmp_path / "loop").exists()


def test_cli_a_failing_acquire_stops_the_loop_and_writes_nothing(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    law = "2.06e8*z + 8e6*zd + 4e9*z*zd"
    rec = ["--integrator", "scipy", "--noise", "0.01", "--position-noise", "0.002"]
    main(["simulate", "--law", law, *rec, "--periods", "15", "--out", "D.csv"])
    capsys.readouterr()
    argv = [
        "advise", "--until-settled", "--data", "D.csv", "--amplitude", "3e5:7e5",
        "--frequency", "20:30", "--grid", "3x3", "--refit-simulations", "0",
        "--acquire", "false {out}", "--out", "loop",
    ]  # fmt: skip
    assert main(argv) == 2
    out = capsys.readouterr()
    assert "--acquire exited with 1 for record 2" in out.err, out.err
    assert "the records so far are in 'loop.records' (--resume goes on from them)" in out.err
    assert not (tmp_path / "loop").exists()
    # the sheet of the record asked for is kept; a loop there again must say what it does
    assert (tmp_path / "loop.records" / "scenario_2.toml").is_file()
    (tmp_path / "loop.records" / "record_2.csv").write_text("t,F\n")
    assert main(argv) == 2
    assert "holds 1 record(s) of an earlier loop: give --resume" in capsys.readouterr().err


@pytest.mark.slow
def test_cli_until_settled_with_vidi_simulate_as_the_rig(tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)
    law = "2.06e8*z + 8e6*zd + 4e9*z*zd"
    rec = ["--integrator", "scipy", "--noise", "0.01", "--position-noise", "0.002"]
    assert main(["simulate", "--law", law, *rec, "--periods", "15", "--out", "D.csv"]) == 0
    vidi = Path(sys.executable).parent / "vidi"  # the installed command, beside this Python
    rig = (
        f"{vidi} simulate --scenario {{scenario}} --law '{law}' {' '.join(rec)} --periods 15 "
        "--seed {step} --out {out}"
    )
    argv = [
        "advise", "--until-settled", "--data", "D.csv", "--amplitude", "3e5:7e5",
        "--frequency", "20:30", "--grid", "4x4", "--acquire", rig, "--out", "loop",
    ]  # fmt: skip
    assert main(argv) == 0
    printed = capsys.readouterr().out
    assert "campaign: settled after" in printed
    doc = json.loads((tmp_path / "loop" / "summary.json").read_text())
    assert doc["result"] == "campaign" and doc["stopped"] == "settled"
    assert sorted(ForceLaw.parse(doc["law"]).names) == sorted(ForceLaw.parse(law).names)
    for k in range(2, len(doc["records"]) + 1):
        assert (tmp_path / "loop" / f"record_{k}.csv").is_file()
        assert (tmp_path / "loop" / f"scenario_{k}.toml").is_file()
    assert isinstance(load(tmp_path / "loop"), CampaignResult)
