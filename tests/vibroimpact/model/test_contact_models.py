"""The named contact models: the per-impact approach velocity in both simulators, the law
text, the result's round trip, and the fit that names the model of a record."""

import math
from pathlib import Path

import numpy as np
import pytest

from discovery.errors import InputError, IntegrationError
from discovery.numerics.tolerances import Tolerances
from discovery.vibroimpact.dynamics.reference import reference_simulate
from discovery.vibroimpact.dynamics.simulation import simulate
from discovery.vibroimpact.dynamics.steady_states import steady_state
from discovery.vibroimpact.fit.contact_fit import (
    ContactFit,
    ContactModelsResult,
    fit_contact_models,
)
from discovery.vibroimpact.model.contact_models import (
    ContactModel,
    parse_law,
    parse_model,
    restitution_from_ratio,
    restitution_ratio,
    same_force,
)
from discovery.vibroimpact.model.contact_registry import CONTACT_MODELS
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import load_scenario
from tests.realistic import reference_record


def _paper_model(name, n=1.3, e=0.6):
    """A model on the paper's machine: the paper's stiffness at the typical penetration."""
    sc = load_scenario("paper")
    mu = sc.m1 * sc.m2 / (sc.m1 + sc.m2)
    v = sc.scales()[1]
    k_lin = 2.06e8
    z0 = v * math.sqrt(mu / k_lin)
    n = {"kelvin-voigt": 1.0, "hertz-damper": 1.5}.get(name, n)
    k = k_lin * z0 ** (1 - n)
    if name in ("kelvin-voigt", "hertz-damper"):
        return sc, ContactModel(name, (k, 0.4 * math.sqrt(k_lin * mu)))
    if name == "hunt-crossley":
        return sc, ContactModel(name, (k, n, k * restitution_ratio("flores", e) / v))
    return sc, ContactModel(name, (k, n, e))


@pytest.mark.parametrize("name", list(CONTACT_MODELS))
def test_kernel_and_scipy_path_agree(name):
    sc, model = _paper_model(name)
    law = model.law
    T = sc.period
    te = np.linspace(0.0, 12 * T, 2401)
    tr = simulate(sc, law, (0.0, 12 * T), t_eval=te)
    ref = reference_simulate(sc, law, (0.0, 12 * T), t_eval=te, rtol=1e-10)
    scale = np.max(ref["force"])
    assert scale > 0
    assert np.max(np.abs(tr.force - ref["force"])) < 1e-5 * scale
    # the impacts really differ in velocity from rest, so the per-impact memory is exercised
    onsets = [y for _, kind, y in ref["events"] if kind == "onset"]
    v0 = [y[1] - y[3] for y in onsets]
    assert len(v0) >= 3 and max(v0) > 1.05 * min(v0)


def test_impact_scaling_is_per_impact():
    """An impact-scaled law is the plain law of each impact's own approach velocity."""
    _, model = _paper_model("flores")
    law = model.law
    assert law.impact_scaled and law.has_memory
    plain = law.at_impact(0.5)
    assert not plain.impact_scaled
    np.testing.assert_allclose(law(1e-4, 0.2, v0=0.5), plain(1e-4, 0.2), rtol=1e-14)
    with pytest.raises(InputError, match="v0"):
        law(1e-4, 0.2)


def test_steady_state_with_impact_scaling():
    sc, model = _paper_model("flores", n=1.3, e=0.45)
    ss = steady_state(sc, model.law)
    assert ss.periodic and ss.impact_v0 > 0
    n = ss.n_periods
    tr = simulate(
        sc,
        model.law,
        (ss.t0, ss.t0 + n * sc.period),
        y0=ss.y0,
        zeta_max0=ss.zeta_max0,
        impact_v0=ss.impact_v0,
    )
    x, v = sc.scales()
    assert np.max(np.abs(tr.y_final - ss.y0) / np.array([x, v, x, v])) < 1e-6


def test_a_start_inside_a_contact_takes_its_approach_velocity():
    """Started inside a contact with that contact's approach velocity, both simulators
    continue the run they were cut from; with another velocity they do not."""
    sc, model = _paper_model("flores", n=1.3, e=0.45)
    law, T = model.law, sc.period
    te = np.linspace(0.0, 6 * T, 60001)
    full = simulate(sc, law, (0.0, 6 * T), t_eval=te)
    inside = np.flatnonzero((full.zeta > 0) & (full.mode == 1) & (te > 3 * T))
    i = int(inside[len(inside) // 2])
    onset = np.flatnonzero((full.event_kind == 1) & (full.event_t < te[i]))[-1]
    v0 = float(full.event_y[onset, 1] - full.event_y[onset, 3])
    t_end = te[i] + 0.3 * T
    x, v = sc.scales()
    scale = np.array([x, v, x, v])
    whole = simulate(sc, law, (0.0, t_end)).y_final
    for v_start, close in ((v0, True), (2 * v0, False)):
        k = simulate(sc, law, (te[i], t_end), y0=full.y[:, i], impact_v0=v_start).y_final
        r = reference_simulate(
            sc, law, (te[i], t_end), y0=full.y[:, i], rtol=1e-10, impact_v0=v_start
        )["y_final"]
        assert np.max(np.abs(k - r) / scale) < 1e-6  # the two simulators agree
        assert (np.max(np.abs(k - whole) / scale) < 1e-5) == close


def _resting_contact():
    """Issue 33's stall (the survey's Lankarani-Nikravesh record of seed 3009, its first
    random second point): a drive too weak to lift the moulding off the table at once, so
    the contact that starts at rest stays closed; its damping over an approach velocity of
    ``1e-12`` m/s had taken steps of ``1e-8`` s."""
    sc = load_scenario("paper").replace(
        m1=16400.0, m2=5400.0, k1=1.86e9, c1=1.83e6, A=240050.12, frequency=25.437287
    )
    model = ContactModel(
        "lankarani-nikravesh", (1.1214401691859e10, 1.138026560021, 0.755500748532)
    )
    return sc, model.law


def _resting_flores():
    """The memory-orbit survey's draw 92: a Flores law on a machine whose moulding lies on
    the frame at rest; the run from rest had spent the kernel's step budget in 0.034 s."""
    sc = load_scenario("paper").replace(
        m1=7300.0, m2=5020.0, k1=1.74e8, c1=2.66e5, A=1.55e5, frequency=12.6
    )
    return sc, ContactModel("flores", (1.11e9, 1.04, 0.708)).law


@pytest.mark.parametrize("case", [_resting_contact, _resting_flores])
def test_a_contact_that_begins_at_rest_is_divided_by_the_machines_floor(case):
    """A contact without an approach velocity (the moulding lying on the frame) divides an
    impact-scaled law's velocity terms by the machine's floor, in both simulators: each
    integrates the run from rest in a few thousand steps, and they agree."""
    sc, law = case()
    T = sc.period
    assert sc.impact_v0_floor() == pytest.approx(1e-3 * sc.scales()[1], rel=1e-15)
    te = np.linspace(0.0, 3 * T, 3001)
    tight = Tolerances(rtol=1e-10)
    tr = simulate(sc, law, (0.0, 3 * T), t_eval=te, tolerances=tight)
    assert tr.event_kind[0] == 1 and tr.event_y[0, 1] == tr.event_y[0, 3]  # onset at rest
    assert tr.impact_v0_floor == sc.impact_v0_floor()
    assert simulate(sc, law, (0.0, 3 * T)).n_steps < 20_000
    r = reference_simulate(sc, law, (0.0, 3 * T), t_eval=te, rtol=1e-10)
    F = r["force"]
    assert np.max(F) > 1e4  # the contact carries the moulding
    assert np.max(np.abs(tr.force - F)) < 1e-5 * np.max(np.abs(F))
    # the force limits at the events are those of the run's own floor
    lims = tr.event_forces(law)
    assert np.all(np.isfinite(lims))
    # the scipy path still stops at its budget where a run needs more (issue 33: with no
    # budget it had run for hours)
    with pytest.raises(IntegrationError, match="step budget"):
        reference_simulate(sc, law, (0.0, 3 * T), rtol=1e-10, max_nfev=100)


def test_impacts_above_the_floor_are_unchanged():
    """The floor acts only below it: an impact at its own approach velocity gives the
    force of the plain law of that velocity (ForceLaw.at_impact), in both simulators."""
    sc, model = _paper_model("flores", n=1.3, e=0.45)
    law, T = model.law, sc.period
    te = np.linspace(0.0, 4 * T, 4001)
    tr = simulate(sc, law, (0.0, 4 * T), t_eval=te)
    onsets = np.flatnonzero(tr.event_kind == 1)
    v0 = tr.event_y[onsets, 1] - tr.event_y[onsets, 3]
    real = v0[v0 > 10 * sc.impact_v0_floor()]
    assert real.size >= 3  # the orbit's impacts, far above the floor
    j = onsets[np.flatnonzero(v0 > 10 * sc.impact_v0_floor())[-1]]
    y0, t0 = tr.event_y[j], tr.event_t[j]
    plain = law.at_impact(float(y0[1] - y0[3]))
    a = simulate(sc, law, (t0, t0 + 0.2 * T), y0=y0, impact_v0=float(y0[1] - y0[3])).y_final
    b = simulate(sc, plain, (t0, t0 + 0.2 * T), y0=y0).y_final
    x, v = sc.scales()
    assert np.max(np.abs(a - b) / np.array([x, v, x, v])) < 1e-9


@pytest.mark.parametrize("name", list(CONTACT_MODELS))
def test_text_round_trip(name):
    _, model = _paper_model(name)
    assert parse_model(model.to_text()) == model
    law = model.law
    assert ForceLaw.parse(law.to_text()) == law
    assert parse_law(model.to_text()) == law  # --law takes the model's text
    assert parse_law(law.to_text()) == law
    assert parse_model(model.format(17).replace(" ", "  ")).values == pytest.approx(model.values)


@pytest.mark.parametrize(
    "text, match",
    [
        ("hunt-crossley: k=2e9, n=1.5", "needs lambda"),
        ("hunt-crossley: k=2e9, n=1.5, lambda=1e9, e=0.5", "once each"),
        ("flores: k=2e9, n=1.5, e=1.5", "restitution"),
        ("flores: k=-2e9, n=1.5, e=0.5", "stiffness"),
        ("kelvin-voigt: k=2e8, c=abc", "number"),
        ("flores: k=\uff18e8, n=1.25, e=0.5", "k needs a number"),  # a full-width 8
        ("2e8*z; scale: v1", "scale"),
        ("hunt-crosley: k=2e9, n=1.5, lambda=3e9", "did you mean 'hunt-crossley'"),
        ("Kelvin Voigt: k=2e8, c=1e6", "did you mean 'kelvin-voigt'"),
        ("hertz: k=2e9", "did you mean 'hertz-damper'"),
        ("maxwell: k=2e9", "'maxwell' is no contact model; the models are kelvin-voigt"),
        ("unloading: 4e6*zd", "force law"),
    ],
)
def test_bad_text_is_one_input_error(text, match):
    with pytest.raises(InputError, match=match):
        parse_law(text)


@pytest.mark.parametrize("name", list(CONTACT_MODELS))
def test_the_papers_conditions(name):
    _, model = _paper_model(name)
    cond = model.conditions()
    assert cond["(3)"]["holds"] and cond["(4)"]["holds"] and cond["(6)"]["holds"]
    assert not cond["(5)"]["holds"]  # damping while unloading: outside (5) on purpose
    plain = model.with_coefficients(
        [
            0.0 if k in ("c", "lambda") else (1.0 if k == "e" else v)
            for k, v in zip(model.names, model.values, strict=True)
        ]
    )
    assert plain.conditions()["(5)"]["holds"]  # no damping: (5) holds


def test_restitution_maps_invert():
    for name in ("lankarani-nikravesh", "flores"):
        for e in (0.3, 0.6, 0.9):
            assert restitution_from_ratio(name, restitution_ratio(name, e)) == pytest.approx(e)
    assert math.isnan(restitution_from_ratio("lankarani-nikravesh", 0.8))


def test_lankarani_nikravesh_and_flores_are_one_force_family():
    ln = ContactModel("lankarani-nikravesh", (2e9, 1.3, 0.5))
    other, p = same_force("lankarani-nikravesh", {"k": 2e9, "n": 1.3, "e": 0.5})
    fl = ContactModel(other, (p["k"], p["n"], p["e"]))
    # the same force at any impact velocity: the two laws' terms are the same
    for v0 in (0.05, 0.3, 2.0):
        a, b = ln.law.at_impact(v0), fl.law.at_impact(v0)
        assert a.names == b.names
        assert a.unloading == b.unloading
        assert np.allclose(a.coefficients, b.coefficients, rtol=1e-12)
        assert np.allclose(a.unloading_coefficients, b.unloading_coefficients, rtol=1e-12)
    back = same_force("flores", p)
    assert back[0] == "lankarani-nikravesh" and back[1]["e"] == pytest.approx(0.5)
    assert same_force("flores", {"k": 2e9, "n": 1.3, "e": 0.3}) is None  # r > 3/4
    assert same_force("hunt-crossley", {"k": 2e9, "n": 1.3, "lambda": 1e9}) is None


def test_the_conclusion_says_when_no_record_can_separate_two_models():
    def fit(model, params):
        return ContactFit(
            model=model,
            parameters=params,
            intervals={},
            criteria={"I2": 0.01},
            value=0.01,
            consistent=True,
            law="",
        )

    ln = fit("lankarani-nikravesh", {"k": 2e9, "n": 1.3, "e": 0.5})
    fl = fit("flores", {"k": 2e9, "n": 1.3, "e": 0.74})
    hc = fit("hunt-crossley", {"k": 2e9, "n": 1.3, "lambda": 1e9})
    res = ContactModelsResult(
        fits=(ln, fl, hc), selected="lankarani-nikravesh", equivalent=("flores", "hunt-crossley")
    )
    text = res.conclusion
    assert "flores with e = 0.74 makes the same force at every impact velocity" in text
    assert "no record can separate them" in text
    assert "cannot tell it from hunt-crossley" in text and "from flores" not in text
    assert res.to_dict()["conclusion"] == text
    alone = ContactModelsResult(fits=(hc,), selected="hunt-crossley")
    assert alone.same_force is None and "same force" not in alone.conclusion


def test_result_round_trip(tmp_path):
    fit = ContactFit(
        model="flores",
        parameters={"k": 2e9, "n": 1.3, "e": 0.6},
        intervals={"k": (1.9e9, 2.1e9), "n": (1.2, 1.4), "e": (0.55, 0.65)},
        criteria={"I2": 0.01},
        value=0.01,
        consistent=True,
        law="2e9*z^1.3",
        conditions=ContactModel("flores", (2e9, 1.3, 0.6)).conditions(),
    )
    res = ContactModelsResult(fits=(fit,), selected="flores", equivalent=(), settings={"a": 1})
    d = res.to_dict()
    assert d["schema_version"] == 1
    assert ContactModelsResult.from_dict(d) == res
    assert ContactFit.from_dict(fit.to_dict()) == fit
    assert (res.save(tmp_path)).exists()
    assert "supports flores" in str(res)
    # the report of a contact-models run: the models' table and the conclusion
    from reports.document import render

    tex = render({**d, "command": "fit"}, tmp_path)
    assert r"flores $\star$" in tex and "The record supports flores" in tex


def test_fit_names_the_model_of_a_clean_record():
    """A Hunt-Crossley record of the paper's machine (scipy path, from rest, no noise) is
    named Hunt-Crossley, its parameters inside their intervals; Kelvin-Voigt and the
    Hertz-damper are not consistent with it."""
    sc, model = _paper_model("hunt-crossley", n=1.2, e=0.8)
    meas = reference_record(
        (sc.replace(law=model.law), model.law),
        periods=8,
        transient=60,
        force_noise=0.0,
        motion_noise=0.0,
        check=False,
    )
    res = fit_contact_models(
        sc,
        meas,
        models=("kelvin-voigt", "hertz-damper", "hunt-crossley"),
        max_simulations=120,
        n_boot=0,
    )
    assert res.selected == "hunt-crossley", str(res)
    fit = res.fit("hunt-crossley")
    for key, true in model.params.items():
        assert fit.parameters[key] == pytest.approx(true, rel=0.02)
    assert "kelvin-voigt" not in res.equivalent and "hertz-damper" not in res.equivalent


def _hunt_crossley_records(points, seed=3):
    """Records of one Hunt-Crossley machine (the paper's, ``n = 1.2``, the damping of
    Flores' ``e = 0.6`` at the paper's impact velocity) by the scipy path, 1 % force
    noise, at the drive settings ``points = [(A, f), ...]``."""
    sc, model = _paper_model("hunt-crossley", n=1.2, e=0.6)
    scs, recs = [], []
    for A, f in points:
        s = sc.replace(law=model.law, A=A, frequency=f)
        scs.append(s)
        recs.append(reference_record((s, model.law), periods=8, seed=seed, check=False))
    return model, scs, recs


def test_two_operating_points_tell_hunt_crossley_from_flores():
    """One operating point: every impact arrives at one velocity, and Flores makes the
    Hunt-Crossley record too (equivalent).  Fitted jointly with a record at another drive
    (shared k, n, lambda / e), the impacts arrive at two velocities: Hunt-Crossley is
    selected, Flores and Lankarani-Nikravesh are no longer consistent."""
    from discovery.vibroimpact.fit.contact_starts import record_samples

    model, scs, recs = _hunt_crossley_records([(5e5, 25.0), (6.25e5, 35.0)])
    models = ("hunt-crossley", "lankarani-nikravesh", "flores")
    one = fit_contact_models(scs[0], recs[0], models=models, max_simulations=60, n_boot=0)
    assert one.selected in ("hunt-crossley", "flores"), str(one)
    assert {one.selected, *one.equivalent} >= {"hunt-crossley", "flores"}, str(one)
    # the start's contact samples hold both records' impacts, each its own group
    both = record_samples(scs, recs)
    parts = [record_samples(s, r) for s, r in zip(scs, recs, strict=True)]
    assert len(both) == sum(len(p) for p in parts)
    assert both.n_impacts == sum(p.n_impacts for p in parts)
    joint = fit_contact_models(scs, recs, models=models, max_simulations=60, n_boot=0)
    assert joint.selected == "hunt-crossley" and joint.equivalent == (), str(joint)
    fit = joint.fit("hunt-crossley")
    for key, true in model.params.items():
        assert fit.parameters[key] == pytest.approx(true, rel=0.05)
    assert fit.criteria and joint.fit("flores").consistent is False


def test_a_study_scores_a_contact_models_fit():
    """A study file takes named-model laws and the contact-models library; a run's
    measures are the named model's."""
    from discovery.vibroimpact.studies.config import load_study
    from discovery.vibroimpact.studies.run import score_contact

    cfg = load_study(Path(__file__).resolve().parents[3] / "examples/study_contact_models.toml")
    runs = cfg.runs()
    assert {r["library"] for r in runs} == {"contact-models"}
    assert any(r["law"].startswith("flores:") for r in runs)
    fit = ContactFit(
        model="flores",
        parameters={"k": 1.5e9, "n": 1.3, "e": 0.45},
        intervals={"k": (1.4e9, 1.6e9), "n": (1.2, 1.4), "e": (0.46, 0.5)},
        criteria={"I2": 0.01},
        value=0.01,
        consistent=True,
        law="",
    )
    other = ContactFit(
        model="hunt-crossley",
        parameters={"k": 1.5e9, "n": 1.3, "lambda": 4e9},
        intervals={},
        criteria={"I2": 0.011},
        value=0.011,
        consistent=True,
        law="",
    )
    res = ContactModelsResult(fits=(fit, other), selected="flores", equivalent=("hunt-crossley",))
    m = score_contact(res, "flores: k=1.43e9, n=1.3, e=0.45")
    assert m["exact"] and m["truth_equivalent"] and m["selected"] == ["flores"]
    assert m["coverage"] == {"k": True, "n": True, "e": False}
    assert m["coef_error"] == pytest.approx(np.sqrt(np.mean([(0.07 / 1.43) ** 2, 0, 0])))
    m = score_contact(res, "hunt-crossley: k=1.43e9, n=1.3, lambda=4.1e9")
    assert not m["exact"] and m["truth_equivalent"] and m["fp"] == 1
    m = score_contact(res, "2.06e8*z + 1.28e7*zd")  # a polynomial truth: never in the family
    assert not m["exact"] and not m["truth_in_library"] and m["selected"] == ["flores"]


def test_cli_takes_a_named_model_as_law(tmp_path, capsys):
    from discovery.cli import main

    rec = tmp_path / "KV.csv"
    law = "kelvin-voigt: k=2.06e8, c=4.06e5"
    assert main(["simulate", "--law", law, "--integrator", "scipy", "--out", str(rec)]) == 0
    capsys.readouterr()
    bad = ["simulate", "--law", "kelvin-voigt: k=2.06e8", "--out", str(tmp_path / "x.csv")]
    assert main(bad) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "needs c" in err[0]


@pytest.mark.slow
def test_cli_fit_contact_models(tmp_path, capsys):
    """``vidi fit --library contact-models`` end to end: summary.json is the result's
    ``to_dict()`` (with the provenance), the printout names the model."""
    import json

    from discovery.cli import main

    rec = tmp_path / "F.csv"
    law = "flores: k=1.43e9, n=1.3, e=0.45"
    argv = ["simulate", "--law", law, "--integrator", "scipy", "--periods", "12"]
    assert main([*argv, "--noise", "0.01", "--seed", "2", "--out", str(rec)]) == 0
    out = tmp_path / "fit"
    argv = ["fit", "--data", str(rec), "--library", "contact-models", "--intervals", "0"]
    assert main([*argv, "--out", str(out)]) == 0
    text = capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["schema_version"] == 1 and summary["library"] == "contact-models"
    # one impact velocity: Flores and Hunt-Crossley make the same force; both are named
    assert {summary["selected"], *summary["equivalent"]} >= {"flores", "hunt-crossley"}
    assert "cannot tell" in text
    res = ContactModelsResult.from_dict(summary)
    e = res.fit("flores").intervals["e"]
    assert e[0] <= 0.45 <= e[1] or abs(res.fit("flores").parameters["e"] - 0.45) < 0.01


@pytest.mark.slow
def test_cli_fit_contact_models_on_two_operating_points(tmp_path, capsys):
    """``vidi fit --library contact-models`` with two records of one machine at two drive
    settings (``--data`` and ``--scenario`` once each, in order) fits every model jointly;
    the Hunt-Crossley truth is named alone, and ``vidi advise --fit`` on the first record's
    fit takes its selected and equivalent models as the candidates."""
    import json

    from discovery.cli import main

    _, model = _paper_model("hunt-crossley", n=1.2, e=0.6)
    root = Path(__file__).resolve().parents[3]
    text = (root / "discovery/vibroimpact/model/scenarios/paper.toml").read_text()
    recs, tomls = [], []
    for i, (A, f) in enumerate(((5e5, 25.0), (6.25e5, 35.0))):
        toml = tmp_path / f"s{i}.toml"
        toml.write_text(text.replace("A = 5.0e5", f"A = {A!r}").replace("= 25.0", f"= {f!r}"))
        rec = tmp_path / f"HC{i}.csv"
        argv = ["simulate", "--scenario", str(toml), "--law", model.to_text()]
        argv += ["--integrator", "scipy", "--periods", "12", "--noise", "0.01"]
        assert main([*argv, "--seed", str(2 + i), "--out", str(rec)]) == 0
        recs.append(rec)
        tomls.append(toml)
    fit = ["fit", "--library", "contact-models", "--intervals", "0", "--max-simulations", "60"]
    one = tmp_path / "one"
    assert main([*fit, "--data", str(recs[0]), "--scenario", str(tomls[0]), "--out", str(one)]) == 0
    s = json.loads((one / "summary.json").read_text())
    assert {s["selected"], *s["equivalent"]} >= {"hunt-crossley", "flores"}
    joint = tmp_path / "joint"
    argv = [*fit, "--out", str(joint)]
    for rec, toml in zip(recs, tomls, strict=True):
        argv += ["--data", str(rec), "--scenario", str(toml)]
    assert main(argv) == 0
    s = json.loads((joint / "summary.json").read_text())
    assert s["selected"] == "hunt-crossley" and s["equivalent"] == [], s["conclusion"]
    # the machine calibrated from both records jointly, each with its own drive amplitude
    assert len(s["scenarios"]) == 2 and s["scenarios"][1]["A"] == pytest.approx(6.25e5, rel=0.01)
    assert s["machine"]["used"] == "record" and s["machine"]["sheet"][1]["A"] == 6.25e5
    capsys.readouterr()
    adv = tmp_path / "adv"
    argv = ["advise", "--fit", str(one), "--noise", "0.01", "--amplitude", "2.5e5:1e6"]
    argv += ["--frequency", "17.5:35", "--grid", "2x2", "--refine", "0", "--workers", "1"]
    assert main([*argv, "--out", str(adv)]) == 0
    a = json.loads((adv / "summary.json").read_text())
    assert len(a["laws"]) >= 2 and any("scale: v0" in law for law in a["laws"])
    assert "advised: A = " in capsys.readouterr().out


@pytest.mark.slow
def test_the_survey_closes_the_loop_on_one_record():
    """One case of ``tests/survey_contact_models.py --second-point advised``: a
    Hunt-Crossley record whose fit leaves Flores equivalent; the advised point lies within
    the bounds, and the record made there, fitted with the first, settles the family."""
    from tests import survey_contact_models as S

    row = S.one_record("hunt-crossley", 2001, 60, n_boot=0, second=("advised",))
    assert row["equivalent"], row["selected"]
    got = row["second"]["advised"]
    assert got["made"], got
    sc = row["scenario"]
    A, f = got["point"]
    assert 0.5 * sc["A"] <= A <= 2 * sc["A"] and 0.7 * sc["frequency"] <= f <= 1.4 * sc["frequency"]
    assert S.settled(row, "advised") and not S.settled(row, "none")
    assert S.final(row, "advised")[0] == "hunt-crossley"


def test_the_conclusion_follows_the_number_of_records(tmp_path):
    """Two records "support" a model (not "the record supports"), and the sentence ends."""
    fit = ContactFit(
        model="kelvin-voigt",
        parameters={"k": 2e8, "c": 4e6},
        intervals={},
        criteria={"I2": 0.01},
        value=0.01,
        consistent=True,
        law="2e8*z + 4e6*zd",
    )
    hc = ContactFit(**{**fit.__dict__, "model": "hunt-crossley"})
    two = ContactModelsResult(
        fits=(fit, hc), selected="kelvin-voigt", equivalent=("hunt-crossley",), n_records=2
    )
    assert two.conclusion.startswith("The 2 records support kelvin-voigt; they cannot tell")
    assert two.conclusion.endswith(".") and not two.conclusion.endswith("..")
    assert ContactModelsResult.from_dict(two.to_dict()) == two
    one = ContactModelsResult(fits=(fit,), selected="kelvin-voigt")
    assert one.conclusion == "The record supports kelvin-voigt."
    none = ContactModelsResult(fits=(fit,), selected=None, n_records=2)
    assert "consistent with all 2 records" in none.conclusion
    assert none.conclusion.endswith(".")
    from reports.document import render

    tex = render({**two.to_dict(), "command": "fit"}, tmp_path)
    assert "the model the 2 records support." in tex and "The 2 records support" in tex
