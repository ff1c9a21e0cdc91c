"""The catalogue's effects beyond the paper's polynomial, hidden in records made by the
independent scipy path (from rest through a transient, 1 % force noise, 0.2 % of each
motion channel's range, 20 kHz) and explained from the linear start ``z + zd``.

Each test asserts the issue's bar: the right effect is named, its parameter is close to
the hidden one, and the gap shrinks at least 3x or to within 1.5x of its noise floor.
"""

import json

import pytest

from discovery import ForceLaw, load_scenario
from discovery.cli import main
from discovery.vibroimpact.dynamics.reference import reference_simulate
from discovery.vibroimpact.explain import explain
from tests import realistic as R

BASE = "2.06e8*z + 4e6*zd"  # the paper's machine, a lighter damper (no dominant jump)
# the hidden laws (also cases of tests/survey_explain_cases.py)
UNLOADING = BASE + "; unloading: 4e6*zd"
SET = BASE + "; set: 0.4"
HERTZ = "1e8*z + 3e6*zd + 1e10*z^1.5"
COUPLED = "2.06e8*z + 0.9e7*zd + 2e10*z*zd"  # hidden with a mass loss


def _explain(sc, law, seed=0, periods=15, **changes):
    rec = R.reference_record(
        (sc.replace(**changes).with_law(law), law), periods=periods, seed=seed, check=False
    )
    return rec, explain(sc.with_law(ForceLaw.parse(BASE)), rec, "linear", n_boot_intervals=0)


def support_case(paper, k3=5e10, law=BASE, periods=16):
    """``(record, explain's result)`` of stiffening grid supports ``k3`` hidden on the
    paper's machine with ``law`` (text or a ForceLaw), explained from its linear start on the
    machine without them."""
    law = ForceLaw.parse(law) if isinstance(law, str) else law
    sc = paper.replace(k3=k3)
    rec = R.reference_record((sc.with_law(law), law), periods=periods, seed=0, check=False)
    return rec, explain(paper.with_law(law), rec, "linear", n_boot_intervals=0)


def shedding_record(paper, law, delta=0.005, trans=40):
    """A 40-period record of the paper's machine with ``law`` (a ForceLaw) whose moulding
    sheds ``delta`` of its mass per impact, starting at the scenario's mass after the
    transient's impacts."""
    true = paper.replace(mass_loss=delta)
    # the start mass whose transient (by the scipy path that makes the record) sheds down to
    # the scenario's: a heavier moulding makes another transient, so it is iterated
    for _ in range(5):
        m2_end = reference_simulate(true, law, (0, trans * paper.period))["m2_final"]
        if abs(m2_end - paper.m2) <= 1e-9 * paper.m2:
            break
        true = true.replace(m2=true.m2 * paper.m2 / m2_end)
    return R.reference_record((true, law), periods=40, transient=trans, seed=0, check=False)


def mass_loss_case(paper, law, delta=0.005, trans=40):
    """``(record, explain's result)`` of a moulding that sheds ``delta`` of its mass per
    impact (:func:`shedding_record`)."""
    rec = shedding_record(paper, law, delta, trans)
    return rec, explain(paper, rec, "linear", n_boot_intervals=0)


def _named(res):
    return [it.effect for it in res.iterations if it.effect]


def _shrinks(it, key="I2"):
    before, after = it.criteria_before[key], it.criteria_after[key]
    return after <= before / 3 or after <= 1.5 * it.noise_floor[key]


@pytest.fixture(scope="module")
def paper():
    return load_scenario("paper")


def test_hidden_unloading_damping_is_named(paper):
    """Damping that also acts while unloading (departs from the paper's condition (5)):
    measured I2 0.0575 -> 0.0188 (floor 0.0136), d = 4.07e6 for a hidden 4e6.  A stiffening
    support fits as well only by turning the contact spring into a pull: not named."""
    _, res = _explain(paper, ForceLaw.parse(UNLOADING))
    assert _named(res)[0] == "unloading_damping", [it.evidence for it in res.iterations]
    it = res.iterations[0]
    assert _shrinks(it)
    d = res.final_model.law.unloading_coefficients[0]
    assert 3e6 < d < 5e6
    assert 1.8e8 < res.final_model.law.as_dict()["z"] < 2.3e8  # the spring, not a soft one


def test_hidden_permanent_set_is_named(paper):
    """Walton-Braun plastic indentation, set 0.4: measured I2 0.044 -> 0.009, set 0.40."""
    _, res = _explain(paper, ForceLaw.parse(SET))
    assert _named(res)[0] == "permanent_set", [it.evidence for it in res.iterations]
    assert _shrinks(res.iterations[0])
    assert 0.3 < res.final_model.law.permanent_set < 0.5


def test_hidden_support_nonlinearity_is_named_in_a_subharmonic_regime(paper):
    """Stiffening grid supports (k3 = 5e10 N/m^3) turn the paper's machine with a lighter
    damper into a P4 orbit with three impacts.  The linear start compensated with a spring
    2.4x too soft and had no local score for k3 (a small step of it changes the regime);
    the supports' refit started from the certified regression with k3 from a ladder
    (measured: named, k3 = 4.99e10, I2 0.933 -> 0.033, floor 0.034).  Now the machine's own
    equations read k3 before the loop, and the start is fitted with it."""
    rec, res = support_case(paper)
    # read by the machine's own equations before the loop, and held there
    assert res.final_model.effects[0] == "support_nonlinearity", str(res)
    assert res.final_model.held == ("support_nonlinearity",)
    read = res.settings["read"]["support_nonlinearity"]
    assert read["low"] <= read["k3"] == res.final_model.scenario["k3"] <= read["high"]
    assert 3e10 < res.final_model.scenario["k3"] < 8e10
    assert res.consistent, res.stopped_because
    from discovery.vibroimpact.verify import Reference, evaluate

    ev = evaluate(
        paper.replace(k3=res.final_model.scenario["k3"]),
        res.final_model.law,
        Reference.from_measurement(rec, paper, n_boot=4, seed=0),
    )
    assert ev.regime == {"measured": "P4", "simulated": "P4"}
    assert ev.impacts == {"measured": 3, "simulated": 3}


def test_hidden_mass_loss_is_named_on_the_drift_channel(paper):
    """The moulding sheds 0.5 % of its mass per impact (17 % over a 40-period record): the
    averaged cycle is consistent with the linear law, but the drift channel's score test
    finds the trend; measured loss 0.0064 and D 0.073 -> 0.044 (floor 0.035)."""
    _, res = mass_loss_case(paper, paper.law)
    assert _named(res)[0] == "mass_loss", [it.evidence for it in res.iterations]
    it = res.iterations[0]
    assert _shrinks(it, "D")
    assert 0.0025 < res.final_model.scenario["mass_loss"] < 0.01


def test_a_clean_record_shows_no_drift(paper):
    rec = R.reference_record((paper, paper.law), periods=40, seed=5, check=False)
    res = explain(paper, rec, "linear", n_boot_intervals=0)
    assert _named(res) == []
    assert res.consistent and "no drift" in res.stopped_because
    assert res.criteria["D"] <= 2 * res.noise_floor["D"] + 0.005


def test_two_hidden_effects_are_both_found(paper):
    """A penetration-velocity coupling in the law and a moulding that sheds 0.5 % of its
    mass per impact, hidden together in a 40-period record: the drift is explained first,
    with the law refitted on blocks that start with the mass left, and the moulding's mass
    with the loss (I2 0.999 -> 0.109, loss 0.0052, the mass 0.5 % heavy: it stands in for
    the coupling not yet named), then the coupling (1.6e10; I2 0.109 -> 0.055), and the
    refit of every parameter after the loop reaches the truth: the coupling 2.03e10 for
    2e10, the loss 0.00500, the mass within 0.01 %, I2 0.017, consistent."""
    _, res = mass_loss_case(paper, ForceLaw.parse(COUPLED))
    named = _named(res)
    assert named[:2] == ["mass_loss", "penetration_velocity_coupling"], [
        it.evidence for it in res.iterations
    ]
    coupling = res.iterations[1]
    assert coupling.criteria_after["I2"] <= 0.6 * coupling.criteria_before["I2"]
    assert res.consistent, res
    final = res.final_model
    assert final.scenario["mass_loss"] == pytest.approx(0.005, rel=0.02)
    assert final.scenario["m2"] == pytest.approx(paper.m2, rel=0.002)
    assert final.law.as_dict()["z*zd"] == pytest.approx(2e10, rel=0.05)


def test_explain_cli_reports_the_unloading_branch(paper, tmp_path):
    law = ForceLaw.parse(SET)
    rec = R.reference_record((paper.with_law(law), law), periods=15, seed=0, check=False)
    data = tmp_path / "set.csv"
    rec.to_csv(data)
    out = tmp_path / "ex"
    scen = tmp_path / "base.toml"
    scen.write_text(
        'name = "paper-light-damper"\n[machine]\nm1 = 1.0e4\nm2 = 1.0e4\n'
        "k1 = 2.75e7\nc1 = 1.0e5\nA = 5.0e5\nfrequency = 25.0\n"
    )
    assert main(["explain", "--scenario", str(scen), "--data", str(data), "--out", str(out)]) == 0
    s = json.loads((out / "summary.json").read_text())
    assert s["iterations"][0]["effect"] == "permanent_set"
    assert 0.3 < s["final_model"]["permanent_set"] < 0.5
    assert "set:" in s["final_model"]["text"]


def test_hidden_hertzian_stiffening_is_named(paper):
    """A Hertz term 1e10*z^1.5 on a lightly damped contact: the linear start compensates
    with a spring 4.6x too stiff, and a small step of z^1.5 from it changes the regime (no
    local score), so the refit starts from the certified regression on z, zd, z^1.5 and
    is polished by the simplex.  Measured: named, k = 9.3e9, I2 0.16 -> 0.029 (floor
    0.032), consistent."""
    _, res = _explain(paper, ForceLaw.parse(HERTZ))
    assert _named(res) == ["hertzian_stiffening"], [it.evidence for it in res.iterations]
    assert _shrinks(res.iterations[0])
    assert 7e9 < res.final_model.law.as_dict()["z^1.5"] < 1.3e10
    assert res.consistent


def test_a_drift_fit_frees_the_machine_parameters_it_trades_against(paper):
    """A mass loss fitted on the records' spans carries the moulding's mass with it: the
    model's parameter vector ends with ``m2`` (from the records' machine), a new vector sets
    it, the fitted model applies it, and without the drift fit it is held."""
    from dataclasses import replace

    from discovery.vibroimpact.explain.effects import Model, drift_fitted, effect

    law = ForceLaw.parse("2e8*z + 1.3e7*zd")
    m = Model(law).with_effect(effect("mass_loss"), 0.004)
    assert m.names == ["z", "zd"] and m.free_machine() == ()
    fit = drift_fitted(m, [paper, paper])
    assert fit.names == ["z", "zd", "loss", "m2"]
    assert fit.coefficients == (2e8, 1.3e7, 0.004, paper.m2)
    moved = fit.with_coefficients([2.1e8, 1.2e7, 0.005, 1.01 * paper.m2])
    assert moved.scenario == {"mass_loss": 0.005, "m2": 1.01 * paper.m2}
    # what the model adds beside its law, as its printout and the loops figure state it
    assert moved.changes() == "m2 = 1.01e+04; mass_loss = 0.005"
    assert str(moved).endswith("(m2 = 1.01e+04; mass_loss = 0.005)")
    assert Model(law).changes() == ""

    class _Span:
        span = object()

    assert moved.apply(paper, _Span()).m2 == pytest.approx(1.01 * paper.m2)
    held = replace(moved, fit_drift=False)
    assert held.names == ["z", "zd"] and held.free_machine() == ()
    # machines that disagree on the moulding leave it alone
    assert drift_fitted(m, [paper, paper.replace(m2=2 * paper.m2)]).names == ["z", "zd", "loss"]
