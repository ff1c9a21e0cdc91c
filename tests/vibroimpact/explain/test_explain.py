"""The missing-effect workflow (discovery.explain) on records with hidden effects.

Every record comes from the independent scipy path (tests/realistic.py), from rest
through a transient, with 1 % force noise and 0.2 % of each motion channel's range;
every explanation starts from the linear law z + zd.
"""

import json

import numpy as np
import pytest

from discovery import ForceLaw, load_scenario
from discovery.cli import main
from discovery.errors import InputError
from discovery.vibroimpact.data.measurement import Measurement
from discovery.vibroimpact.dynamics.law_response import response
from discovery.vibroimpact.explain import EFFECTS, effect, explain, first_order_lag
from discovery.vibroimpact.explain.effects import TARGETS
from tests import realistic as R

HC = ForceLaw.parse("2.06e8*z + 0.9e7*zd + 2e10*z*zd")  # Hunt-Crossley-type coupling hidden


def _record(sc, law, seed=0, **kw):
    return R.reference_record((sc.with_law(law), law), periods=15, seed=seed, check=False, **kw)


@pytest.fixture(scope="module")
def paper():
    return load_scenario("paper")


def hidden_coupling_case(paper):
    """``(record, explain's result)`` of the hidden coupling ``HC`` on the paper's machine
    (also a case of ``tests/survey_explain_cases.py``)."""
    rec = _record(paper, HC, seed=0)
    return rec, explain(paper, rec, "linear", n_boot_intervals=0)


@pytest.fixture(scope="module")
def hidden_coupling(paper):
    return hidden_coupling_case(paper)


def test_hidden_coupling_is_named_and_the_gap_shrinks(hidden_coupling):
    _, res = hidden_coupling
    named = [it.effect for it in res.iterations if it.effect]
    assert named == ["penetration_velocity_coupling"]
    it = res.iterations[0]
    # measured: I2 0.118 -> 0.0070 (noise floor 0.031)
    before, after = it.criteria_before["I2"], it.criteria_after["I2"]
    assert after <= before / 3 or after <= 1.5 * it.noise_floor["I2"]
    assert res.consistent and "consistent" in res.stopped_because
    c = res.final_model.law.as_dict()["z*zd"]
    assert abs(c - 2e10) < max(3 * res.uncertainties["z*zd"], 0.1 * 2e10)
    # the evidence: a significant score, and the localisation puts the disagreement where
    # the effect acts (compared over the record's span, the start law's misfit in the contact
    # also moves the separation, so unloading can carry the largest share), with the onset,
    # where a linear damper's force jump is too high, beyond the noise
    # The score's rank is not asserted: at this start (I2 1.35) it is fragile.  A change of
    # 2e-4 in the start's stiffness (exact against finite-difference Jacobians in the start's
    # fit) moved the coupling's LM statistic from 2.7e5 (the largest) to 1.1e5, below the
    # unloading damping's 1.8e5.  The refits decide what is named: the coupling's refit
    # lowers I2 the most.
    s = next(x for x in it.scores if x.effect == "penetration_velocity_coupling")
    assert s.significant
    refitted = [x for x in it.scores if x.refitted]
    best = min(refitted, key=lambda x: x.criteria_after["I2"])
    assert best.effect == "penetration_velocity_coupling"
    # the evidence states the decision: the floor is the start's, and the other refits
    # (which decide over the scores) are named with their criterion
    assert "the noise floor of the model before" in it.evidence
    # one statement, led by the decision (issue 50: "signature does not agree ... named on
    # the score test and the refit, which decide" contradicted itself)
    assert it.evidence.startswith("named because its refit lowers I2 the most: ")
    assert "does not agree" not in it.evidence
    others = [x for x in refitted if x is not s and x.criteria_after.get("I2") is not None]
    if others:
        assert "the other effects refitted reach I2 " in it.evidence
        assert min(others, key=lambda x: x.criteria_after["I2"]).effect in it.evidence
    phases = it.localisation["phases"]
    # the contact's phases carry most of it (measured 0.57: onset 0.18, unloading 0.39; the
    # separation 0.40 and unloading 0.39 swap places with that 2e-4 change of the start)
    assert sum(phases[p]["share"] for p in ("onset", "loading", "peak", "unloading")) > 0.5
    assert phases["onset"]["exceeds_noise"]
    top = ", ".join(sorted(phases, key=lambda p: -phases[p]["share"])[:2])
    assert f"the residual is largest at the {top}" in it.evidence  # a hint, said as one


def _clean_survey(paper, seeds):
    """Explain on clean records (no hidden effect): the seeds where an effect was named,
    and how many ended inconsistent without naming anything."""
    false, i4_alone = [], 0
    for seed in seeds:
        res = explain(paper, _record(paper, paper.law, seed=seed), "linear", n_boot_intervals=0)
        if any(it.effect for it in res.iterations):
            false.append(seed)
        if not res.consistent:
            assert (
                "I4 alone" in res.stopped_because or "do not shrink the gap" in res.stopped_because
            ), (seed, res.stopped_because)
            i4_alone += 1
    return false, i4_alone


def test_clean_records_add_nothing(paper):
    """No hidden effect, three noise seeds: no false discovery."""
    false, i4_alone = _clean_survey(paper, range(100, 103))
    assert false == []
    assert i4_alone <= 1


@pytest.mark.slow  # 20 explain runs: about 2 min
def test_clean_records_add_nothing_survey(paper):
    """No hidden effect, 20 noise seeds: no false discovery (the README's count).  A few
    records end inconsistent without naming anything: failing I4 alone (the contact
    supports of a noisy record) with I2 within its noise, or with a drift score no effect's
    refit lowers; nothing is fitted to that, and the stop says so."""
    false, i4_alone = _clean_survey(paper, range(100, 120))
    assert false == []
    assert i4_alone <= 3


def test_an_effect_too_weak_to_matter_is_not_named(paper):
    weak = ForceLaw.parse("2.06e8*z + 1.28e7*zd + 2e7*z*zd")  # 0.1 % of the peak force
    res = explain(paper, _record(paper, weak, seed=3), "linear", n_boot_intervals=0)
    assert [it.effect for it in res.iterations if it.effect] == []


#: the effects explain screens on the lagged record
LAG_EFFECTS = ["sensor_lag", "penetration_velocity_coupling"]


def lagged_record(paper, tau=1e-4, seed=4, law=None):
    """The paper's record (of its law, or of ``law``) with its force channel seen through
    a first-order sensor (time constant ``tau``): the clean record's force is filtered, then
    noise is added."""
    law = paper.law if law is None else law
    rec = _record(paper, law, seed=seed, force_noise=0.0)
    E = response(paper, law).impulse
    T = paper.period
    lagged = first_order_lag(E, tau)
    phase = np.mod(rec.t - (E.onset % T), T)  # P1: one cycle per period
    F = lagged.evaluate(phase, "right")
    F = F + np.random.default_rng(seed).normal(0.0, 0.01 * F.max(), F.size)
    return Measurement(rec.t, F, rec.channels, source="lagged")


def hidden_lag_case(paper, **kw):
    """``(record, explain's result)`` of the hidden sensor lag (``kw``: explain's
    ``workers``; also a case of ``tests/survey_explain_cases.py``)."""
    rec = lagged_record(paper)
    return rec, explain(paper, rec, "linear", effects=LAG_EFFECTS, n_boot_intervals=0, **kw)


def test_hidden_sensor_lag_is_named(paper):
    """The force channel seen through a first-order sensor (tau = 0.1 ms, a 2.4 ms contact):
    the clean record's force is filtered, then noise is added."""
    rec, res = hidden_lag_case(paper, workers=2)
    pick = LAG_EFFECTS
    named = [it.effect for it in res.iterations if it.effect]
    assert named and named[0] == "sensor_lag", [it.evidence for it in res.iterations]
    tau = res.final_model.observation["sensor_lag"]
    assert 0.5e-4 < tau < 2e-4
    it = res.iterations[0]
    assert (
        it.criteria_after["I2"] <= it.criteria_before["I2"] / 3
        or it.criteria_after["I2"] <= 1.5 * it.noise_floor["I2"]
    )
    # the screening refits run in two processes; one process gives the same result
    one = explain(paper, rec, "linear", effects=pick, workers=1, n_boot_intervals=0)
    assert one.final_model == res.final_model
    assert [x.as_dict()["scores"] for x in one.iterations] == [
        x.as_dict()["scores"] for x in res.iterations
    ]


def test_the_papers_claim_coupling_moves_the_force_maximum_into_the_impact(paper):
    """With a strong z*zd term the force maximum moves from the onset toward the middle of
    the impact (the paper's Fig. 8); a linear damper's maximum is at the onset."""
    lin = response(paper, paper.law).impulse
    hc = response(paper, ForceLaw.parse("2.06e8*z + 1e5*zd + 5e9*z*zd + 1e5*zd^2")).impulse

    def where(imp):
        ((a, b),) = imp.support[:1]
        m = (imp.t >= a) & (imp.t < b)
        return (imp.t[m][np.argmax(imp.F[m])] - a) / (b - a)

    assert where(lin) < 0.02
    assert where(hc) > 0.1


def test_first_order_lag_is_exact_for_a_step():
    """A unit step through tau F' + F = F_true reaches 1 - exp(-t / tau)."""
    from discovery.vibroimpact.data.impulse import Impulse

    W, tau = 1.0, 0.01
    t = np.array([0.0, 0.5, 0.5, 1.0])
    imp = Impulse(
        t=t,
        F=np.array([1.0, 1.0, 0.0, 0.0]),
        duration=W,
        support=np.array([[0.0, 0.5]]),
        n_periods=1,
        onset=0.0,
    )
    out = first_order_lag(imp, tau)
    for s in (0.01, 0.03, 0.1):
        # periodic steady state of the filter: the step starts from the decayed tail; the
        # closed form written on 16 points per tau, read back by linear interpolation
        # (measured within 2e-4)
        assert out.evaluate(s) == pytest.approx(1 - np.exp(-s / tau), abs=1e-3)
    assert out.evaluate(0.5 + 0.02) == pytest.approx(np.exp(-0.02 / tau), abs=1e-3)
    assert np.all(out.F >= 0)
    # at given times the closed form itself (a record's block needs only its sample
    # times): exact, within the grid's interpolation error of the impulse's values, also
    # periodic and through a model's observation
    from discovery.vibroimpact.explain.effects import Model, first_order_lag_at

    s = np.array([0.01, 0.03, 0.1, 0.52, 1.03, -0.97])
    want = np.where(np.mod(s, W) < 0.5, 1 - np.exp(-np.mod(s, W) / tau), 0.0)
    want[3] = np.exp(-0.02 / tau)
    got = first_order_lag_at(imp, tau, s)
    np.testing.assert_allclose(got, want, atol=1e-12)
    np.testing.assert_allclose(got, out.evaluate(s), atol=1e-3)
    observe = Model(ForceLaw.parse("1e8*z")).with_effect(effect("sensor_lag"), tau).observe()
    np.testing.assert_array_equal(observe.at(imp, s), got)


def test_first_order_lag_matches_an_integration_of_its_equation():
    """A piecewise-linear periodic pulse with a jump at the cycle's origin: the closed form
    at the knots and between them against scipy's integration of tau G' + G = F over many
    cycles (measured 6e-9 of the peak)."""
    from scipy.integrate import solve_ivp

    from discovery.numerics.lag import lag_at, lag_at_knots

    W, tau = 0.04, 3e-4
    t = np.array([0.0, 0.002, 0.005, 0.008, 0.03, W])
    F = np.array([5e4, 2e5, 1e5, 0.0, 0.0, 0.0])
    G = lag_at_knots(t, F, tau)
    sol = solve_ivp(
        lambda s, g: (np.interp(s % W, t, F) - g) / tau,
        (0.0, 20 * W),
        [0.0],
        rtol=1e-11,
        atol=1e-6,
        max_step=1e-5,
        dense_output=True,
    )
    tq = np.linspace(0.0, W, 777)
    ref = sol.sol(19 * W + tq)[0]
    got = lag_at(t, F, G, tau, tq)
    assert np.max(np.abs(got - ref)) < 1e-7 * F.max()
    # queries in any order (the walk over the knots goes back as well as forward), and on
    # the knots themselves (continuous there)
    perm = np.random.default_rng(3).permutation(tq.size)
    assert np.array_equal(lag_at(t, F, G, tau, tq[perm]), got[perm])
    np.testing.assert_allclose(lag_at(t, F, G, tau, t), G, rtol=1e-12, atol=1e-9 * F.max())


def test_catalogue_entries_are_complete():
    for e in EFFECTS:
        assert e.id and e.explanation and e.enters and e.signature and e.parameters
        assert e.target in TARGETS and e.key
        d = e.as_dict()
        lo, hi = d["parameters"][0]["bounds"]
        # zero (the effect absent) is within bounds; only an offset can be negative
        assert lo <= 0 <= hi and (lo == 0 or e.id == "contact_offset"), e.id
    # the effects the paper's model cannot have say which of its conditions they leave
    assert "condition (5)" in effect("unloading_damping").departs
    assert {e.id for e in EFFECTS} >= {
        "penetration_velocity_coupling",
        "hertzian_stiffening",
        "unloading_damping",
        "permanent_set",
        "support_nonlinearity",
        "sensor_lag",
    }
    with pytest.raises(InputError, match="unknown effect"):
        effect("gremlins")


def test_explain_cli_end_to_end(hidden_coupling, tmp_path, capsys):
    rec, _ = hidden_coupling
    data = tmp_path / "hc.csv"
    rec.to_csv(data)
    out = tmp_path / "ex"
    assert main(["explain", "--data", str(data), "--start", "linear", "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert [it["effect"] for it in s["iterations"]] == ["penetration_velocity_coupling"]
    it = s["iterations"][0]
    assert set(it) >= {"effect", "evidence", "criteria_before", "criteria_after", "parameters"}
    assert "c_z_zd" in it["parameters"]  # the catalogue parameter name
    fm = s["final_model"]
    assert set(fm) >= {"terms", "coefficients", "uncertainties", "latex", "effects"}
    assert fm["effects"] == ["penetration_velocity_coupling"]
    # I0..I4 of the averaged cycle, I5 of the recorded penetration, and D of the drift
    # channel (orbit by orbit)
    assert set(s["noise_floor"]) == {"I0", "I1", "I2", "I3", "I4", "I5", "D"}
    assert s["stopped_because"]
    assert (out / "explain_1.png").stat().st_size > 10_000
    # the final model's force-penetration loops against the record (it has positions)
    assert (out / "explain_loops.png").stat().st_size > 10_000
    assert "penetration_velocity_coupling" in capsys.readouterr().out
    bad = tmp_path / "bad"
    assert main(["explain", "--data", str(data), "--effects", "gremlins", "--out", str(bad)]) == 2
    assert "unknown effect" in capsys.readouterr().err and not bad.exists()


def test_localisation_of_a_law_with_no_periodic_orbit(paper, hidden_coupling):
    """A law judged over the record's span whose trajectory settles on no periodic orbit
    (its steady state ``nonperiodic``): the disagreement is localised by phase and the drift
    is read; the orbit's plane and grid are left out (there is no orbit to sample), where
    this once raised a TypeError inside ``explain``."""
    from dataclasses import replace

    from discovery.vibroimpact.explain.disagreement import localise
    from discovery.vibroimpact.explain.effects import Model
    from discovery.vibroimpact.verify import Reference, evaluate

    rec, _ = hidden_coupling
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    ref = Reference.from_measurement(rec, paper, n_boot=8, seed=0)
    ev = evaluate(paper, law, ref)
    assert ev.steady.periodic
    periodic = localise(paper, Model(law), ref, ev, rec)
    assert periodic["plane"] is not None and periodic["drift"] is not None
    none = replace(ev.steady, regime="nonperiodic", n_periods=0)
    out = localise(paper, Model(law), ref, replace(ev, steady=none), rec)
    assert out["phases"] == periodic["phases"] and out["drift"] == periodic["drift"]
    assert out["plane"] is None and out["grid"] is None


def _pruning_run(model, evaluations, uncertainties):
    """A stand-in for explain's run as pruning reads it: one record, I2, the model's
    evaluations by ``evaluations``."""
    from types import SimpleNamespace

    return SimpleNamespace(
        model=model,
        records=[None],
        criterion="I2",
        budget=100,
        regress=None,
        problem=SimpleNamespace(evaluations=evaluations),
        uncertainties=uncertainties,
    )


def _refit_as_is(run, model, budget):
    """A stand-in for ``pruning._law_refit``: the model "refitted" is the model itself."""
    from types import SimpleNamespace

    evs = run.problem.evaluations(model)
    return SimpleNamespace(law=model, standard_errors={}), dict(evs[0].criteria), evs


def test_an_effect_named_for_the_other_parameters_refit_is_taken_out(monkeypatch):
    """Survey draw 74's quieter record: a coupling's refit stopped at I2 0.743, and the next
    iteration's refits of a set, a Hertz term and an offset all reached 0.058-0.059, so a
    set was named beside the coupling.  Unrefitted, the model without the set is far off
    (its law had moved with it); refitted without it, the model is consistent at 0.0589,
    within the floor of the model with it: the set is taken out.  Without the coupling the
    refit stays inconsistent, and the coupling is kept."""
    from types import SimpleNamespace

    from discovery.vibroimpact.explain import pruning
    from discovery.vibroimpact.explain.effects import Model

    sets, coupling = effect("permanent_set"), effect("penetration_velocity_coupling")
    law = ForceLaw.parse("4.05e9*z + 1.88e7*zd")
    model = Model(law).with_effect(coupling, 6.73e10).with_effect(sets, 0.0021)
    monkeypatch.setattr(pruning, "_small_step", lambda eff, records: 1e-9)

    def evaluations(mod, floor=True):
        i2 = 0.0581 if len(mod.effects) == 2 else 0.3  # unrefitted: far off
        return [
            SimpleNamespace(consistent=i2 < 0.127, criteria={"I2": i2}, noise_floor={"I2": 0.0622})
        ]

    def refit(run, mod, budget):
        i2 = 0.0589 if "penetration_velocity_coupling" in mod.effects else 0.74
        evs = [SimpleNamespace(consistent=i2 < 0.127, criteria={"I2": i2}, noise_floor={})]
        refitted = mod.with_effect(coupling, 6.76e10, add=False) if mod.effects else mod
        return SimpleNamespace(law=refitted, standard_errors={"zd": 1.0}), {"I2": i2}, evs

    monkeypatch.setattr(pruning, "_law_refit", refit)
    run = _pruning_run(model, evaluations, {"set": 1e-4})
    dropped = pruning.drop_collapsed(run)
    assert [d["effect"] for d in dropped] == ["permanent_set"]
    assert "refitted without it" in dropped[0]["reason"]
    assert "0.0581 -> 0.0589, within its noise floor 0.0622" in dropped[0]["reason"]
    assert run.model.effects == ("penetration_velocity_coupling",)
    assert run.model.value(coupling) == 6.76e10  # the refitted model, not the reduced one
    assert run.uncertainties == {"zd": 1.0}


def test_an_effect_a_later_refit_made_negligible_is_taken_out(monkeypatch):
    """``without_effect`` takes each kind of effect out; the pruning step takes out a named
    effect whose parameter is below a tenth of its small step when the model without it is
    as consistent, and keeps it when taking it out loses a record's consistency."""
    from types import SimpleNamespace

    from discovery.vibroimpact.explain import pruning
    from discovery.vibroimpact.explain.effects import Model

    law = ForceLaw.parse("2e8*z + 1e7*zd")
    m = Model(law)
    for eid, v in [
        ("penetration_velocity_coupling", 2e10),
        ("unloading_damping", 4e6),
        ("permanent_set", 0.3),
        ("support_nonlinearity", 1e11),
        ("sensor_lag", 1e-5),
    ]:
        with_it = m.with_effect(effect(eid), v)
        assert eid in with_it.effects and with_it.value(effect(eid)) == v
        back = with_it.without_effect(effect(eid))
        assert back == m, eid

    lag, coupling = effect("sensor_lag"), effect("penetration_velocity_coupling")
    model = m.with_effect(lag, 1e-10).with_effect(coupling, 2e10)
    monkeypatch.setattr(pruning, "_small_step", lambda eff, records: 1e-5)

    def run_with(consistent_without):
        def evaluations(mod, floor=True):
            ok = consistent_without or "sensor_lag" in mod.effects
            # the coupling explains the record: without it I2 rises far past its floor
            i2 = 0.02 if "penetration_velocity_coupling" in mod.effects else 0.5
            return [SimpleNamespace(consistent=ok, criteria={"I2": i2}, noise_floor={"I2": 0.01})]

        return _pruning_run(model, evaluations, {"tau": 1e-11, "z": 1.0})

    monkeypatch.setattr(pruning, "_law_refit", _refit_as_is)
    run = run_with(True)
    dropped = pruning.drop_collapsed(run)
    assert [d["effect"] for d in dropped] == ["sensor_lag"]
    assert run.model.effects == ("penetration_velocity_coupling",)
    assert "tau" not in run.uncertainties
    # the coupling (2e10, far above a tenth of its step) stays
    assert run.model.value(coupling) == 2e10
    run = run_with(False)  # without the lag the record is no longer consistent: kept
    assert pruning.drop_collapsed(run) == [] and "sensor_lag" in run.model.effects


def test_an_effect_that_explains_less_than_the_floor_is_taken_out(monkeypatch):
    """A contact offset named beside stiffening supports at their local minimum: after the
    joint refit the model without it is as consistent and I2 moves 0.0087 -> 0.0094 (floor
    0.0075), so it is taken out; one whose removal costs more than the floor stays."""
    from types import SimpleNamespace

    from discovery.vibroimpact.explain import pruning
    from discovery.vibroimpact.explain.effects import Model

    offset, supports = effect("contact_offset"), effect("support_nonlinearity")
    model = Model(ForceLaw.parse("2.7e10*z + 7.8e7*zd")).with_effect(supports, 2.1e15)
    model = model.with_effect(offset, -1.6e-7)
    monkeypatch.setattr(pruning, "_small_step", lambda eff, records: 1e-9)

    def evaluations(mod, floor=True):
        i2 = 0.0087 if "contact_offset" in mod.effects else 0.0094
        if "support_nonlinearity" not in mod.effects:
            i2 = 0.127
        return [
            SimpleNamespace(consistent=i2 < 0.02, criteria={"I2": i2}, noise_floor={"I2": 0.0075})
        ]

    run = _pruning_run(model, evaluations, {"delta0": 1e-8, "k3": 1e13})
    monkeypatch.setattr(pruning, "_law_refit", _refit_as_is)
    dropped = pruning.drop_collapsed(run)
    assert [d["effect"] for d in dropped] == ["contact_offset"]
    assert "0.0087 -> 0.0094, within its noise floor 0.0075" in dropped[0]["reason"]
    assert run.model.effects == ("support_nonlinearity",)
    assert run.uncertainties == {"k3": 1e13}


def test_an_effect_is_taken_out_by_continuation_where_its_drop_lands_in_another_basin(
    monkeypatch,
):
    """Survey draw 75's quieter record: a Hertz law under a 20 um contact, a 3.2 um offset
    named beside the Hertz term (I2 0.0379, floor 0.108).  Refitted with the offset simply
    dropped, the law stops at I2 0.178, not consistent; refitted with the offset held at half
    its value and then without it, each from the last, it reaches 0.0881, consistent: the
    offset is taken out.  A term of the law (the Hertz term) is not held halfway."""
    from types import SimpleNamespace

    from discovery.vibroimpact.explain import pruning
    from discovery.vibroimpact.explain.effects import Model

    offset, hertz = effect("contact_offset"), effect("hertzian_stiffening")
    law = ForceLaw.parse("2.82e10*z + 2.26e7*zd")
    model = Model(law).with_effect(hertz, 1.80e12).with_effect(offset, 3.22e-6)
    monkeypatch.setattr(pruning, "_small_step", lambda eff, records: 1e-12)
    basin = 1.7537e12  # the Hertz coefficient the continuation carries the law to

    def evaluations(mod, floor=True):
        i2 = 0.0379 if len(mod.effects) == 2 else 0.5
        return [
            SimpleNamespace(consistent=i2 < 0.245, criteria={"I2": i2}, noise_floor={"I2": 0.108})
        ]

    starts = []

    def refit(run, mod, budget):
        starts.append(mod)
        if "hertzian_stiffening" not in mod.effects:
            i2, out = 0.5, mod  # the record needs the Hertz term
        elif "contact_offset" in mod.held:  # halfway: the law moves toward the other basin
            i2, out = 0.067, mod.with_effect(hertz, basin, add=False)
        else:
            i2, out = (0.0881 if mod.value(hertz) == basin else 0.178), mod
        evs = [SimpleNamespace(consistent=i2 < 0.12, criteria={"I2": i2}, noise_floor={})]
        return SimpleNamespace(law=out, standard_errors={"z^1.5": 1.0}), {"I2": i2}, evs

    monkeypatch.setattr(pruning, "_law_refit", refit)
    run = _pruning_run(model, evaluations, {"delta0": 1e-6})
    dropped = pruning.drop_collapsed(run)
    assert [d["effect"] for d in dropped] == ["contact_offset"]
    assert "0.0379 -> 0.0881, within its noise floor 0.108" in dropped[0]["reason"]
    assert run.model.effects == ("hertzian_stiffening",)
    assert run.model.value(hertz) == basin
    halfway = [m for m in starts if "contact_offset" in m.held]
    assert len(halfway) == 1 and halfway[0].value(offset) == pytest.approx(1.61e-6)
    assert not any("hertzian_stiffening" in m.held for m in starts)  # a term: not held
    # without the continuation's start the offset stays (the drop alone stops at 0.178)
    monkeypatch.setattr(pruning, "_halfway", lambda run, eff: None)
    run = _pruning_run(model, evaluations, {"delta0": 1e-6})
    assert pruning.drop_collapsed(run) == [] and "contact_offset" in run.model.effects


def test_a_refit_judged_by_the_motion_that_breaks_the_force_names_nothing():
    """With the gap measured on the penetration (I5; the force within its limit), a refit
    that takes the force's I2 further away and beyond its limit is a fit of the motion by
    another force: ``_force_worse`` holds it, as ``_motion_worse`` holds the converse."""
    from types import SimpleNamespace

    from discovery.vibroimpact.explain.judging import _force_worse, _motion_worse

    before = {"I2": 0.090, "I5": 0.375}
    after = {"I2": 0.108, "I5": 0.239}
    evs = [SimpleNamespace(limits={"I2": 0.096, "I5": 0.088}, criteria=after)]
    assert _force_worse("I2", "I5", before, after, evs)
    assert not _force_worse("I2", "I2", before, after, evs)  # gap on the force: not this rule
    assert not _motion_worse(before, after, evs)
    within = [SimpleNamespace(limits={"I2": 0.2, "I5": 0.088}, criteria=after)]
    assert not _force_worse("I2", "I5", before, after, within)  # worse, but within its limit


class _Scored:
    """An evaluation's verdict parts (regime, floor, criteria, limits) with the real rules of
    :class:`~discovery.vibroimpact.verify.evaluation.Evaluation` for within and failing."""

    def __init__(self, criteria, limits, same_regime=True):
        from discovery.vibroimpact.verify.evaluation import Evaluation

        self.criteria, self.limits = criteria, limits
        self.same_regime, self.noise_floor = same_regime, dict(limits)
        self.within = lambda k, absent=False: Evaluation.within(self, k, absent=absent)
        self.failing = lambda: Evaluation.failing(self)


def test_the_contact_time_is_the_gap_only_where_it_alone_fails():
    """``supports_gap``: the force (I2) and the penetration (I5) within their limits and the
    contact time (I4) alone beyond its own, on every record, makes I4 the gap that refits
    are judged by (survey draw 45's noisier Hertz record); any other failure, a regime
    mismatch, or a consistent model does not."""
    from discovery.vibroimpact.explain.judging import SUPPORTS_CRITERION, supports_gap

    limits = {"I2": 0.03, "I4": 0.04, "I5": 0.1}
    alone = _Scored({"I2": 0.02, "I4": 0.07, "I5": 0.05}, limits)
    consistent = _Scored({"I2": 0.02, "I4": 0.03, "I5": 0.05}, limits)
    assert SUPPORTS_CRITERION == "I4"
    assert supports_gap([alone], "I2")
    assert supports_gap([alone, consistent], "I2")  # failing I4 alone on one record
    assert not supports_gap([consistent], "I2")  # nothing fails
    force = _Scored({"I2": 0.05, "I4": 0.07, "I5": 0.05}, limits)
    motion = _Scored({"I2": 0.02, "I4": 0.07, "I5": 0.2}, limits)
    assert not supports_gap([force], "I2") and not supports_gap([alone, force], "I2")
    assert not supports_gap([motion], "I2")  # the penetration's gap comes first
    other = _Scored({"I2": 0.02, "I4": 0.07, "I5": 0.05}, limits, same_regime=False)
    assert not supports_gap([other], "I2")
    no_motion = _Scored({"I2": 0.02, "I4": 0.07}, {"I2": 0.03, "I4": 0.04})
    assert supports_gap([no_motion], "I2")  # a record without positions


def test_the_loops_end_is_reported_before_the_intervals(paper, hidden_coupling):
    """``on_loop_end`` gets the result's iterations and final model, once, before the
    bootstrap intervals start (``vidi explain`` draws their figures meanwhile)."""
    rec, _ = hidden_coupling
    events = []
    res = explain(
        paper,
        rec,
        "linear",
        max_iterations=0,
        n_boot_intervals=5,
        workers=1,
        progress=lambda stage, done, total: events.append(stage),
        on_loop_end=lambda iterations, model: events.append((iterations, model)),
    )
    ends = [e for e in events if isinstance(e, tuple)]
    assert len(ends) == 1
    iterations, model = ends[0]
    assert iterations == res.iterations and model is res.final_model
    at = events.index(ends[0])
    assert "explain: bootstrap intervals" in events[at + 1 :]
    assert "explain: bootstrap intervals" not in events[:at]
    assert res.intervals is not None


def test_a_failed_explain_leaves_the_earlier_result(hidden_coupling, tmp_path, monkeypatch, capsys):
    """The output directory is staged before explain runs (its figures are drawn while the
    intervals run): a run that fails removes the staging and leaves the earlier result."""
    import discovery.vibroimpact.explain as package
    from discovery.errors import IntegrationError

    rec, _ = hidden_coupling
    data = tmp_path / "hc.csv"
    rec.to_csv(data)
    out = tmp_path / "ex"
    out.mkdir()
    earlier = {"command": "explain", "earlier": True}  # an earlier run's result
    (out / "summary.json").write_text(json.dumps(earlier))

    def fails(*args, **kwargs):
        raise IntegrationError("the law has no orbit")

    monkeypatch.setattr(package, "explain", fails)
    argv = ["explain", "--data", str(data), "--out", str(out), "--overwrite", "--intervals", "0"]
    assert main(argv) == 2
    assert "the law has no orbit" in capsys.readouterr().err
    assert json.loads((out / "summary.json").read_text()) == earlier
    assert sorted(p.name for p in tmp_path.iterdir()) == ["ex", "hc.csv"]
