"""advise: the separation of two laws' predicted records by the verdict's rule, the safe
region, the knobs' bounds, the result's round trip, the CLI and its report; and (slow) the
loop closed: a record at the advised point settles the law."""

import json

import numpy as np
import pytest

from discovery import AdviseResult, ForceLaw, Knobs, NoiseModel, SafeRegion, advise, load_scenario
from discovery.cli import main
from discovery.errors import InputError
from discovery.vibroimpact.advise import candidates_from_fit, contact_candidates
from discovery.vibroimpact.advise.separation import inseparable

BASE = "2.06e8*z + 1.28e7*zd"


def _one_point(laws, noise=0.01, safe=None, amplitude=5e5, frequency=25.0, position=None):
    knobs = Knobs((amplitude, amplitude), (frequency, frequency), grid=(1, 1), refine=0)
    noise = NoiseModel(noise, position=position)
    return advise(load_scenario("paper"), laws, knobs, noise, safe, workers=1)


def test_separation_grows_with_the_difference_of_the_laws():
    # the damper 10 % and 40 % off: the farther law's predicted record is farther away in
    # units of the verdict's limit, in both directions (tolerance: strict order)
    r = _one_point([BASE, "2.06e8*z + 1.408e7*zd", "2.06e8*z + 1.792e7*zd"])
    (p,) = r.points
    assert p.usable and len(p.pairs) == 3
    sep = {q.pair: q for q in p.pairs}
    near, far = sep[(0, 1)], sep[(0, 2)]
    assert far.separation > near.separation
    assert far.directions[0] > near.directions[0] and far.directions[1] > near.directions[1]
    # 40 % off is rejected by the verdict's rule (I2 over its limit) at 1 % noise
    assert far.separated and far.separation > 1.0
    assert set(far.criteria[0]) == {"I2", "I4"} and set(far.limits[0]) == {"I2", "I4"}
    assert all(pr.regime == "P1" for pr in p.predictions)


def test_with_positions_the_pairs_are_judged_by_i5_too():
    # the predicted records carry positions: the verdict's record-span comparison, I5 held
    r = _one_point([BASE, "2.06e8*z + 1.792e7*zd"], position=0.01)
    (q,) = r.points[0].pairs
    assert set(q.criteria[0]) == {"I2", "I4", "I5"} and set(q.limits[1]) == {"I2", "I4", "I5"}
    assert q.separated and q.separation > 1.0
    same = _one_point([BASE, "2.06e8*z + 1.2808e7*zd"], position=0.01)
    assert same.points[0].pairs[0].separation < 1.0  # 0.06 % apart: within the noise
    assert AdviseResult.from_dict(r.to_dict()) == r and r.noise.position == 0.01


def test_more_noise_means_less_separation():
    laws = [BASE, "2.06e8*z + 1.6e7*zd"]
    quiet = _one_point(laws, noise=0.005).points[0].pairs[0].separation
    loud = _one_point(laws, noise=0.05).points[0].pairs[0].separation
    assert loud < quiet


def test_a_law_and_itself_with_a_tiny_term_are_inseparable():
    r = _one_point([BASE, "2.06e8*z + 1.28e7*zd + 1e3*z*zd"])
    assert r.points[0].pairs[0].separation < 0.2
    assert inseparable(r.points) == {(0, 1)} and r.inseparable == [(0, 1)]
    assert "no point of the bounds separates them" in str(r) and not r.separates


def test_the_safe_region_excludes_points():
    laws = [BASE, "2.06e8*z + 1.6e7*zd"]
    free = _one_point(laws)
    peak = max(pr.peak_force for pr in free.points[0].predictions)
    tight = _one_point(laws, safe=SafeRegion(max_force=0.5 * peak))
    (p,) = tight.points
    assert p.unsafe and not p.usable and "peak force" in p.excluded
    assert tight.best is None and "no usable point" in str(tight)
    loose = _one_point(laws, safe=SafeRegion(max_force=2 * peak, max_penetration=1.0))
    assert loose.best is not None and not loose.points[0].unsafe
    pen = _one_point(laws, safe=SafeRegion(max_penetration=1e-6))
    assert pen.points[0].unsafe and "penetration" in pen.points[0].excluded


def test_grid_refines_and_stays_in_bounds_and_round_trips(tmp_path):
    knobs = Knobs((4e5, 6e5), (22.0, 28.0), grid=(2, 2), refine=1)
    r = advise(load_scenario("paper"), [BASE, "2.06e8*z + 1.6e7*zd"], knobs, NoiseModel(0.01))
    assert len([p for p in r.points if p.stage == "coarse"]) == 4
    assert any(p.stage == "refine" for p in r.points)
    assert all(knobs.contains(p.amplitude, p.frequency) for p in r.points)
    assert r.best is r.ranked()[0]
    d = r.to_dict()
    assert d["schema_version"] == 1
    back = AdviseResult.from_dict(json.loads(json.dumps(d)))
    assert back == r
    r.save(tmp_path)
    assert AdviseResult.from_dict(json.loads((tmp_path / "summary.json").read_text())) == r
    m = r.map()
    assert m["smallest"].shape == m["amplitude"].shape and np.isfinite(m["smallest"]).all()


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: Knobs((6e5, 3e5), (20, 30)), "LOW <= HIGH"),
        (lambda: Knobs((3e5, 6e5), (-1, 30)), "frequency bounds"),
        (lambda: Knobs((3e5, 6e5), (20, 30), grid=(0, 3)), "grid"),
        (lambda: SafeRegion(max_force=-1), "max_force"),
        (lambda: NoiseModel(1.5), "noise relative"),
        (lambda: _one_point([BASE, BASE]), "two or more candidate laws"),
    ],
)
def test_bad_settings_are_one_input_error(make, words):
    with pytest.raises(InputError, match=words):
        make()


def _cli(tmp_path, *extra):
    return [
        "advise",
        "--law",
        BASE,
        "--law",
        "2.06e8*z + 1.6e7*zd",
        "--noise",
        "0.01",
        "--grid",
        "2x2",
        "--refine",
        "0",
        "--workers",
        "1",
        "--quiet",
        *extra,
    ]


@pytest.mark.parametrize(
    "bounds, words",
    [
        (["--amplitude", "6e5:3e5", "--frequency", "20:30"], "--amplitude"),
        (["--amplitude", "3e5:6e5", "--frequency", "twenty:30"], "--frequency"),
        (["--amplitude", "-3e5:6e5", "--frequency", "20:30"], "positive bounds"),
    ],
)
def test_cli_bad_bounds_are_one_line_exit_2(tmp_path, capsys, bounds, words):
    code = main(_cli(tmp_path, *bounds, "--out", str(tmp_path / "o")))
    err = capsys.readouterr().err.strip()
    assert code == 2 and len(err.splitlines()) == 1 and words in err
    assert "Traceback" not in err


def test_cli_needs_candidates_and_one_noise(tmp_path, capsys):
    out = str(tmp_path / "o")
    common = ["--amplitude", "3e5:6e5", "--frequency", "20:30", "--out", out]
    assert main(["advise", "--noise", "0.01", *common]) == 2
    assert "no candidates" in capsys.readouterr().err
    assert main(["advise", "--law", BASE, "--law", "2e8*z + 1e7*zd", *common]) == 2
    assert "noise level" in capsys.readouterr().err


def test_cli_writes_map_summary_and_report(tmp_path, capsys):
    out = tmp_path / "adv"
    args = _cli(tmp_path, "--amplitude", "4e5:6e5", "--frequency", "22:28", "--out", str(out))
    assert main(args) == 0
    printed = capsys.readouterr().out
    assert "advised: A = " in printed and "pair 1-2: separation" in printed
    for name in ("summary.json", "advise.csv", "advise_map.png", "advise_map.pdf"):
        assert (out / name).is_file()
    s = json.loads((out / "summary.json").read_text())
    assert s["command"] == "advise" and s["schema_version"] == 1 and "versions" in s
    assert AdviseResult.from_dict(s).best.amplitude == s["advised"]["amplitude"]
    assert main(["report", str(out), "--no-pdf"]) == 0
    tex = (out / "report.tex").read_text()
    assert "Ranked points" in tex and "advise_map.pdf" in tex and "Take the next record" in tex


def test_candidates_from_a_fit_directory(tmp_path):
    law, other = ForceLaw.parse(BASE), ForceLaw.parse("2e8*z + 5e9*z*zd")
    s = {
        "command": "fit",
        "scenario": {"name": "paper"},
        "selected": {"coefficients": law.as_dict()},
        "equivalent": [{"coefficients": other.as_dict()}],
    }
    (tmp_path / "summary.json").write_text(json.dumps(s))
    laws, name = candidates_from_fit(tmp_path)
    assert [x.to_text() for x in laws] == [law.to_text(), other.to_text()] and name == "paper"
    s["equivalent"] = []
    (tmp_path / "summary.json").write_text(json.dumps(s))
    with pytest.raises(InputError, match="lists no equivalent model"):
        candidates_from_fit(tmp_path)
    with pytest.raises(InputError, match="does not exist"):
        candidates_from_fit(tmp_path / "nowhere")


def _contact_fit(selected="hunt-crossley", equivalent=("flores",)):
    """A contact-models fit of a Hunt-Crossley record of the paper's machine at one
    operating point (the parameters of ``tests/vibroimpact/model/test_contact_models.py``'s
    record): Flores makes the same force at its one impact velocity."""
    from discovery.vibroimpact.fit.contact_fit import ContactFit, ContactModelsResult

    params = {
        "hunt-crossley": {"k": 7.4833e8, "n": 1.1997, "lambda": 2.5074e9},
        "flores": {"k": 7.4832e8, "n": 1.1997, "e": 0.41365},
        "kelvin-voigt": {"k": 2.06e8, "c": 1.28e7},
    }
    fits = tuple(
        ContactFit(
            model=name,
            parameters=p,
            intervals={},
            criteria={"I2": 0.0078},
            value=0.0078,
            consistent=name in (selected, *equivalent),
            law="",
        )
        for name, p in params.items()
    )
    return ContactModelsResult(fits=fits, selected=selected, equivalent=tuple(equivalent))


def test_advise_takes_named_contact_models_and_a_contact_models_fit(tmp_path):
    """The candidates may be a contact-models fit (its selected model and those it reports
    equivalent), named models, or their text; a point with another impact velocity
    separates Hunt-Crossley from Flores, which make the same record at the fit's point."""
    from discovery import ContactModel
    from discovery.vibroimpact.advise.candidates import unique_laws

    res = _contact_fit()
    models = contact_candidates(res)
    assert [m.name for m in models] == ["hunt-crossley", "flores"]
    assert models[1] == ContactModel("flores", (7.4832e8, 1.1997, 0.41365))
    laws = [m.law for m in models]
    assert unique_laws(res) == unique_laws(models) == unique_laws([m.to_text() for m in models])
    assert unique_laws(models) == tuple(laws)
    assert contact_candidates(res.to_dict()) == models
    with pytest.raises(InputError, match="selected no model"):
        contact_candidates(_contact_fit(selected=None, equivalent=()))
    # Flores's same-force twin is no candidate; alone, it leaves nothing to advise
    from discovery.vibroimpact.fit.contact_fit import ContactFit, ContactModelsResult

    ln = ContactFit(
        model="lankarani-nikravesh",
        parameters={"k": 7.4832e8, "n": 1.1997, "e": 0.8},
        intervals={},
        criteria={"I2": 0.0078},
        value=0.0078,
        consistent=True,
        law="",
    )
    fl = ContactFit(**{**ln.__dict__, "model": "flores", "parameters": {**ln.parameters}})
    twins = ContactModelsResult(
        fits=(ln, fl), selected="lankarani-nikravesh", equivalent=("flores",)
    )
    with pytest.raises(InputError, match="same force at every impact velocity"):
        contact_candidates(twins)
    with_hc = ContactModelsResult(
        fits=(ln, fl, res.fit("hunt-crossley")),
        selected="lankarani-nikravesh",
        equivalent=("flores", "hunt-crossley"),
    )
    assert [m.name for m in contact_candidates(with_hc)] == ["lankarani-nikravesh", "hunt-crossley"]
    # at the fit's own point the two are one record; at a faster drive they separate
    same = _one_point(res)
    assert same.best is None or same.best.smallest < 1
    knobs = Knobs((2.5e5, 1e6), (17.5, 35.0), grid=(3, 3), refine=0)
    r = advise(load_scenario("paper"), res, knobs, NoiseModel(0.01), workers=1)
    b = r.best
    assert b is not None and knobs.contains(b.amplitude, b.frequency)
    assert r.laws == tuple(law.to_text() for law in laws) and b.smallest >= 1
    # a contact-models fit directory
    (tmp_path / "summary.json").write_text(
        json.dumps({**res.to_dict(), "command": "fit", "scenario": {"name": "paper"}})
    )
    got, name = candidates_from_fit(tmp_path)
    assert got == tuple(laws) and name == "paper"
    lone = _contact_fit(equivalent=())
    (tmp_path / "summary.json").write_text(json.dumps({**lone.to_dict(), "command": "fit"}))
    with pytest.raises(InputError, match="lists no equivalent model"):
        candidates_from_fit(tmp_path)


def test_cli_advise_takes_named_models_as_laws(tmp_path, capsys):
    models = [m.to_text() for m in contact_candidates(_contact_fit())]
    out = tmp_path / "adv"
    argv = ["advise", "--law", models[0], "--law", models[1], "--noise", "0.01"]
    argv += ["--amplitude", "2.5e5:1e6", "--frequency", "17.5:35", "--grid", "2x2"]
    assert main([*argv, "--refine", "0", "--workers", "1", "--out", str(out)]) == 0
    assert "advised: A = " in capsys.readouterr().out
    s = json.loads((out / "summary.json").read_text())
    assert s["laws"][1].endswith("scale: v0")
    assert main(["report", str(out), "--no-pdf"]) == 0
    assert "Ranked points" in (out / "report.tex").read_text()
    bad = ["advise", "--law", models[0], "--law", "flores: k=1e9, n=1.2", "--noise", "0.01"]
    assert main([*bad, "--amplitude", "1:2", "--frequency", "1:2", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "needs e" in err[0]


@pytest.mark.slow
def test_a_record_at_the_advised_point_settles_the_law():
    """The loop on one case of ``tests/survey_advise.py``: scipy records, a first fit with
    equivalent models, advise, a second record there, the joint fit selects the truth."""
    from tests import survey_advise as S

    row = S.run_case(0)
    assert row["counted"], row.get("why")
    assert len(row["candidates"]) >= 2
    a = row["advised"]["point"]
    assert 0.7 * 5e5 <= a[0] <= 1.3 * 5e5 and 0.8 * 25 <= a[1] <= 1.2 * 25
    assert row["with_advised"]["settled"], row["with_advised"]


def test_the_moulding_mass_is_a_third_knob_and_the_map_keeps_the_best_over_it():
    knobs = Knobs((5e5, 5e5), (25.0, 25.0), m2=(8e3, 1.2e4), grid=(1, 1), m2_points=2, refine=0)
    r = advise(load_scenario("paper"), [BASE, "2.06e8*z + 1.6e7*zd"], knobs, NoiseModel(0.01))
    assert sorted(p.m2 for p in r.points) == [8e3, 1.2e4]
    m = r.map()
    assert m["amplitude"].shape == (1,)
    assert m["smallest"][0] == pytest.approx(max(p.smallest for p in r.points if p.usable))
    assert AdviseResult.from_dict(r.to_dict()) == r


def test_a_rival_certified_on_its_own_rates_is_advised_on_not_refused():
    """A fit's equivalent model with a negative zd^2 is dissipative up to 0.92 m/s (its
    record's rates) and not beyond: advise refused the run (condition (6) at 1.22 m/s).
    It is judged where its orbit stays in that domain, and a point whose orbit leaves it
    separates the pair on physics."""
    rival = "2.02625e8*z + 2.18996e7*zd - 2.37176e7*zd^2"
    assert ForceLaw.parse(rival).dissipative_rate(load_scenario("paper")) == pytest.approx(
        2.18996e7 / 2.37176e7, rel=0.01
    )
    r = _one_point(["2.06e8*z + 5.12e6*zd + 6e10*z*zd", rival], noise=0.02, amplitude=3e5)
    (p,) = r.points
    assert p.usable and not p.predictions[1].leaves_domain
    assert p.predictions[0].domain == float("inf")  # dissipative at every rate on its box
    # a narrower domain that this point's orbit leaves: separated on physics, and said so
    narrow = "2.02625e8*z + 2.18996e7*zd - 8e7*zd^2"
    q = _one_point(["2.06e8*z + 5.12e6*zd + 6e10*z*zd", narrow], noise=0.02, amplitude=3e5)
    (p,) = q.points
    # its impacts gain energy at the rates the other's orbit reaches: no orbit of its own,
    # which a record here shows (it was an excluded point)
    assert p.usable and p.predictions[1].status == "nonperiodic"
    assert p.predictions[1].leaves_domain and p.pairs[0].physics and p.pairs[0].separated
    assert "rejects it on physics" in str(q)
    assert AdviseResult.from_dict(q.to_dict()) == q
    # a law no machine could have anywhere is still refused
    with pytest.raises(InputError, match="negative stiffness"):
        _one_point([BASE, "-2.06e8*z + 1.28e7*zd"])


@pytest.mark.parametrize(
    "make, words",
    [
        (lambda: NoiseModel(0.01, n_boot=2.5), "n_boot must be an integer"),
        (lambda: NoiseModel(0.01, seed="x"), "seed must be an integer"),
        (lambda: NoiseModel(0.01, seed=-1), "seed must be an integer"),
        (
            lambda: Knobs((3e5, 6e5), (20, 30), grid=(200, 200), m2=(5e3, 1e4), m2_points=50),
            "at most 10000",
        ),
        (
            lambda: advise(
                load_scenario("paper"),
                [f"2.06e8*z + {1e7 + k * 1e5:g}*zd" for k in range(50)],
                Knobs((3e5, 6e5), (20, 30), grid=(2, 2)),
                NoiseModel(0.01),
            ),
            "50 candidate laws: at most 12",
        ),
        (
            lambda: advise(
                load_scenario("paper"),
                [BASE, "2.06e8*z + 2e7*zd"],
                Knobs((3e5, 6e5), (20, 30), grid=(2, 2)),
                NoiseModel(0.01, dt=1e-9, periods=1000),
            ),
            "lower --sample-rate or --periods",
        ),
    ],
)
def test_work_no_run_should_start_is_refused_up_front(make, words):
    """Issue 53: 50 candidates on a 2x2 grid ran for minutes, a 1 GHz record ran out of
    memory, seeds and replicates took any value."""
    with pytest.raises(InputError, match=words):
        make()


@pytest.mark.parametrize(
    "tamper",
    [
        lambda d: d["selected"].__setitem__("coefficients", "2e8*z"),
        lambda d: d["selected"].__setitem__("coefficients", {"z": "abc"}),
        lambda d: d.__setitem__("settings", ["x"]),
        lambda d: d.__setitem__("settings", "text"),
    ],
)
def test_a_tampered_fit_directory_is_one_line_or_read_as_far_as_it_goes(tmp_path, tamper):
    """Issue 53: coefficients as text and settings as a list or text were internal errors."""
    doc = {
        "command": "fit",
        "library": "poly:2",
        "selected": {"coefficients": {"z": 2e8, "zd": 1e7}},
        "equivalent": [{"coefficients": {"z": 2e8, "zd": 1.1e7}}],
        "settings": {"scenario": "paper"},
    }
    tamper(doc)
    (tmp_path / "summary.json").write_text(json.dumps(doc))
    try:
        laws, scenario = candidates_from_fit(tmp_path)
    except InputError as exc:
        assert "run vidi fit again" in str(exc)
    else:
        assert len(laws) == 2 and scenario is None  # the settings unreadable: no scenario


def test_a_scenario_edited_after_the_fit_is_refused(tmp_path, capsys):
    """Issue 53: advise --fit re-read the fit's scenario file, so a file edited after the fit
    (m2 1e4 -> 2.5e4) gave advice for another machine without a word."""
    from discovery._files._provenance import file_sha256

    scenario = tmp_path / "machine.toml"
    scenario.write_text(load_scenario("paper").to_toml())
    doc = {
        "command": "fit",
        "library": "poly:2",
        "selected": {"coefficients": {"z": 2e8, "zd": 1e7}},
        "equivalent": [{"coefficients": {"z": 2e8, "zd": 1.1e7}}],
        "settings": {"scenario": str(scenario)},
        "inputs": {"scenario": {"path": str(scenario), "sha256": file_sha256(scenario)}},
    }
    fit = tmp_path / "fit"
    fit.mkdir()
    (fit / "summary.json").write_text(json.dumps(doc))
    from discovery.vibroimpact.advise import fit_scenario_changed

    assert fit_scenario_changed(fit, str(scenario)) is None
    scenario.write_text(scenario.read_text().replace("m2 = 10000.0", "m2 = 25000.0"))
    assert "changed after the fit" in fit_scenario_changed(fit, str(scenario))
    out = tmp_path / "o"
    argv = ["advise", "--fit", str(fit), "--noise", "0.01", "--amplitude", "3e5:6e5"]
    assert main([*argv, "--frequency", "20:30", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "changed after the fit" in err and "\n" not in err and not out.exists()


def test_record_options_with_a_record_are_refused(tmp_path, capsys):
    """Issue 53: --position-noise (and the next record's sampling and length) were ignored
    with --data."""
    out = tmp_path / "o"
    argv = ["advise", "--law", BASE, "--law", "2e8*z + 5e9*z*zd", "--data", "D.csv"]
    argv += ["--position-noise", "0.01", "--amplitude", "3e5:6e5", "--frequency", "20:30"]
    assert main([*argv, "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "--position-noise" in err and "\n" not in err and not out.exists()


def test_the_advised_point_is_judged_again_with_each_rival_refitted(tmp_path):
    """Issue 49: advise judged each rival at its fitted coefficients, where the next fit
    refits it.  At the advised point each rival is refitted to the other's predicted record:
    the law with a coupling term refitted to the plain law's record fits it (a nested
    direction, told apart by the term's interval, not a rejection), while the plain law
    refitted to the record of a strong coupling stays rejected.  (With a weak coupling,
    1e9*z*zd, the advised point's separation 10.6 falls to 0.27 once the plain law is
    refitted: the record there would not tell them apart.)"""
    plain, coupled = "2.06e8*z + 1.28e7*zd", "2.06e8*z + 5e6*zd + 6e10*z*zd"
    sc = load_scenario("paper")
    res = advise(
        sc,
        [plain, coupled],
        Knobs((3e5, 6e5), (20.0, 30.0), grid=(3, 3), refine=0),
        NoiseModel(0.01),
        workers=1,
        progress=False,
    )
    (r,) = res.refit
    assert r.pair == (0, 1) and r.nested == (True, False)
    assert r.directions[0] < 1 and r.separation == r.directions[1] > 1  # absorbed; rejected
    assert "z*zd" in r.laws[0] and "z*zd" not in r.laws[1]
    assert "reduces to it on 1's record" in str(res)
    back = AdviseResult.from_dict(json.loads(json.dumps(res.to_dict())))
    assert back.refit == res.refit
    off = advise(
        sc,
        [plain, coupled],
        Knobs((3e5, 6e5), (20.0, 30.0), grid=(2, 2), refine=0),
        NoiseModel(0.01),
        workers=1,
        progress=False,
        refit_simulations=0,
    )
    assert off.refit == ()
