"""Criteria landscapes: every point through discovery.vibroimpact.verify.evaluate, failures kept
apart from physics, records as references, default ranges centred on the law, bad input."""

import hashlib
import json

import numpy as np
import pytest

from discovery import ForceLaw, load_scenario
from discovery.cli import main
from discovery.errors import InputError
from discovery.vibroimpact.dynamics import Tolerances
from discovery.vibroimpact.dynamics.law_response import response
from discovery.vibroimpact.verify import Reference
from discovery.vibroimpact.verify.criteria import CRITERIA
from discovery.vibroimpact.verify.criteria_landscape import Landscape, default_range, landscape


def test_workers_do_not_change_the_result(paper):
    c0, c1 = paper.law.coefficients
    a0, a1 = np.linspace(0.8 * c0, 1.2 * c0, 5), np.linspace(0.8 * c1, 1.2 * c1, 5)
    one = landscape(paper, paper.law, a0, a1, workers=1)
    two = landscape(paper, paper.law, a0, a1, workers=2)
    assert two.workers == 2 and one.workers == 1
    for n in CRITERIA:
        np.testing.assert_array_equal(one.values[n], two.values[n])
        assert one.values[n].shape == (5, 5)
    np.testing.assert_array_equal(one.regime, two.regime)
    np.testing.assert_array_equal(one.consistent, two.consistent)
    assert (one.regime == "P1").all()
    # the centre is the reference law itself: criteria vanish, consistent there only
    assert max(one.values[n][2, 2] for n in CRITERIA) < 1e-6
    assert one.consistent[2, 2] and one.consistent.sum() == 1
    assert one.argmin("I2") == (2, 2)
    assert one.values["I2"][0, 0] > 0.05
    assert one.reference["source"] == "law" and one.reference["exact"]
    assert one.noise_floor == {n: 0.0 for n in CRITERIA}


def test_a_failed_simulation_is_failed_not_nonperiodic(paper, tmp_path):
    from reports import landscape_figure

    # enough for the paper's stiffness, not for 1e2 x it, with the contacts stepped (in closed
    # form they take no steps: both paths find these laws' orbits nonperiodic then)
    tol = Tolerances(max_steps=10_000, contact="integrate")
    land = landscape(paper, paper.law, [2.06e8, 2e10], [1.28e7, 1.5e7], workers=1, tolerances=tol)
    assert list(land.regime[0]) == ["P1", "P1"]
    assert list(land.regime[1]) == ["failed", "failed"]
    assert np.isnan(land.values["I2"][1]).all() and np.isfinite(land.values["I2"][0]).all()
    count, first, at = land.failures
    assert count == 2 and at == (1, 0) and "step budget" in first
    assert land.regime_counts() == {"P1": 2, "failed": 2}
    paths = landscape_figure(land, str(tmp_path / "fig"))
    assert all((tmp_path / p).stat().st_size > 0 for p in paths)


@pytest.fixture(scope="module")
def noisy_record(tmp_path_factory):
    d = tmp_path_factory.mktemp("rec")
    path = d / "noisy.csv"
    assert (
        main(
            [
                "simulate",
                "--periods",
                "12",
                "--noise",
                "0.01",
                "--position-noise",
                "0.01",
                "--seed",
                "1",
                "--out",
                str(path),
            ]
        )
        == 0
    )
    # an extra column: the record's loading notes must be printed
    lines = path.read_text().splitlines()
    path.write_text(
        "\n".join([lines[0] + ",temperature"] + [ln + ",20" for ln in lines[1:]]) + "\n"
    )
    return path


def test_landscape_against_a_record(noisy_record, tmp_path, capsys):
    from discovery.cli.identify import _load_landscape

    out = tmp_path / "land"
    assert (
        main(
            [
                "landscape",
                "--data",
                str(noisy_record),
                "--grid",
                "5x5",
                "--workers",
                "2",
                "--n-boot",
                "8",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    assert "note: ignored column(s): temperature" in printed
    assert "I2: minimum" in printed and "(noise floor " in printed
    # the law printed as every printout writes it, not its exact text
    assert "noise floor under 2.06e+08*z + 1.28e+07*zd" in printed
    assert "206000000" not in printed
    s = json.loads((out / "summary.json").read_text())
    ref = s["reference"]
    assert ref["source"] == str(noisy_record)
    assert ref["sha256"] == hashlib.sha256(noisy_record.read_bytes()).hexdigest()
    assert ref["regime"] == "P1" and ref["start"] == "measured state"
    floor = s["noise_floor"]
    # the force's criteria and I5, the recorded penetration's (the record has positions)
    assert set(floor) == {*CRITERIA, "I5"} and all(v > 0 for v in floor.values())
    assert s["noise_floor_under"] == "206000000*z + 12800000*zd"
    # default ranges: 0.5x..1.5x the scenario's law, whose point is the centre
    assert s["alpha1"][2] == 2.06e8 and s["alpha2"][2] == 1.28e7
    assert np.array(s["I2"]).shape == (5, 5) and s["grid"] == [5, 5]
    # the true law agrees with its noisy record within the floor; half its damping does not
    assert s["consistent"][2][2] is True and s["consistent"][2][0] is False
    assert s["I2"][2][2] <= 2 * floor["I2"] + 0.005 < s["I2"][2][0]
    assert s["failed"]["count"] == 0 and s["minima"]["I2"]["noise_floor"] == floor["I2"]
    assert (out / "landscape.png").stat().st_size > 0
    csv_head = (out / "landscape.csv").read_text().splitlines()[0]
    assert csv_head == "z,zd,regime,I0,I1,I2,I3,I4,impacts,consistent"
    # `vidi identify --landscape` still reads it
    sc = load_scenario("paper")
    land = _load_landscape(out, Landscape, ForceLaw.parse("1e8*z + 1e7*zd"), sc)
    assert land.terms == ("z", "zd") and land.values["I2"].shape == (5, 5)
    # ... and refuses one for other terms, another scenario or of the wrong shape, before
    # any simulation
    base = ["identify", "--data", str(noisy_record), "--out", str(tmp_path / "id")]
    cases = [
        (["--start", "1e8*z^1.5 + 1e7*zd", "--landscape", str(out)], "not the start's"),
        (
            ["--scenario", "light", "--start", "1e10*z + 1e11*zd", "--landscape", str(out)],
            "made for scenario 'paper'",
        ),
    ]
    broken = tmp_path / "broken.json"
    s["I2"] = s["I2"][:3]
    broken.write_text(json.dumps(s))
    cases.append(
        (["--start", "1e8*z + 1e7*zd", "--landscape", str(broken)], "do not match its axes")
    )
    for extra, needle in cases:
        capsys.readouterr()
        assert main(base + extra) == 2
        err = capsys.readouterr().err
        assert err.count("\n") == 1 and needle in err, err
        assert not (tmp_path / "id").exists()


def test_default_ranges_are_centred_on_the_template(tmp_path):
    out = tmp_path / "light"
    assert (
        main(
            [
                "landscape",
                "--scenario",
                "light",
                "--grid",
                "3x3",
                "--workers",
                "1",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    s = json.loads((out / "summary.json").read_text())
    assert s["alpha1"] == [1e10, 2e10, 3e10] and s["alpha2"] == [2.5e11, 5e11, 7.5e11]
    assert s["regime"][1][1] == "P1" and s["I2"][1][1] < 1e-6
    assert s["ranges"]["alpha1"] == [1e10, 3e10] and s["reference"]["source"] == "law"
    out = tmp_path / "tmpl"
    assert (
        main(
            [
                "landscape",
                "--law",
                "1.5e8*z + 1e7*zd",
                "--range1",
                "1.2e7:1.4e7",
                "--grid",
                "3x3",
                "--workers",
                "1",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    s = json.loads((out / "summary.json").read_text())
    assert s["alpha1"] == [0.75e8, 1.5e8, 2.25e8] and s["alpha2"] == [1.2e7, 1.3e7, 1.4e7]
    assert s["ranges"]["from"][1] == "--range1 1.2e7:1.4e7"
    assert default_range(-4.0, "z", "--range0") == (-6.0, -2.0)


@pytest.mark.parametrize(
    "argv, needle",
    [
        (["--law", "2e8*z"], "at least two terms"),
        (["--range0", "3e8:1e8"], "--range0 needs LOW < HIGH"),
        (["--range1", "1e7:1e7"], "--range1 needs LOW < HIGH"),
        (["--law", "0*z + 1e7*zd"], "give --range0 LOW:HIGH"),
        (["--law", "2e8*z + 0*zd"], "give --range1 LOW:HIGH"),
        (["--workers", "0"], "--workers: '0' is out of range"),
        (["--grid", "1x5"], "at least 2 points per axis"),
        (["--data", "missing.csv"], "does not exist"),
    ],
)
def test_bad_input_one_line_exit_2(argv, needle, capsys, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    grid = [] if "--grid" in argv else ["--grid", "3x3"]
    assert main(["landscape", *grid, *argv, "--out", "o"]) == 2
    err = capsys.readouterr().err.strip()
    assert needle in err and "\n" not in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_api_input_checks(paper):
    ref = response(paper, paper.law).impulse
    with pytest.raises(TypeError, match="Reference.exact"):
        landscape(paper, paper.law, [1e8, 2e8], [1e7, 2e7], ref, workers=1)
    with pytest.raises(InputError, match="strictly increasing"):
        landscape(paper, paper.law, [2e8, 1e8], [1e7, 2e7], Reference.exact(ref), workers=1)


def test_continuation_gives_the_cold_search_result(paper):
    """Each point started from its neighbour's orbit (the default) lands on the orbit the
    cold search from the start state finds: same regimes, impacts and consistency, criteria
    within the shooting tolerance; and a continued steady state agrees with a cold one."""
    from discovery.vibroimpact.dynamics.steady_states import steady_state

    a0, a1 = np.linspace(1.2e8, 3.0e8, 5), np.linspace(0.7e7, 1.9e7, 7)
    cold = landscape(paper, paper.law, a0, a1, workers=1, continuation=False)
    cont = landscape(paper, paper.law, a0, a1, workers=1)
    assert cont.continuation and not cold.continuation
    assert np.array_equal(cold.regime, cont.regime)
    assert np.array_equal(cold.impacts, cont.impacts)
    assert np.array_equal(cold.consistent, cont.consistent)
    for n in CRITERIA:
        assert np.allclose(cold.values[n], cont.values[n], rtol=0, atol=1e-7, equal_nan=True), n
    near = paper.law.with_coefficients([2.2e8, 1.3e7])
    ss0 = steady_state(paper, paper.law)
    a, b = steady_state(paper, near), steady_state(paper, near, guess=ss0)
    assert "continued_from" in b.evidence and "continued_from" not in a.evidence
    assert a.regime == b.regime and a.impacts == b.impacts
    assert np.max(np.abs(a.y0 - b.y0) / np.abs(a.y0).max()) < 1e-6
    assert np.allclose(a.multipliers, b.multipliers, atol=1e-5)
