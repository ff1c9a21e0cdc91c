"""Explain's refits stop where going on repeats work (issue 52): the winner's polish, its
least squares at its noise floor, is neither restarted nor polished by the simplex, and a
drift effect's refit from a second start that reaches the first one's point goes no further.

A record of the paper's machine by the independent scipy path, from rest through a
transient, 1 % force noise and 0.2 % of each motion channel's range, with damping while
unloading hidden (``vidi explain``'s bench record, 12 periods here).
"""

import numpy as np
import pytest

from discovery import ForceLaw, load_scenario
from discovery.vibroimpact.explain.effects import Model, effect
from discovery.vibroimpact.explain.starts import _output_error, _records_of
from discovery.vibroimpact.explain.trials import floor_of
from tests import realistic as R

TRUTH = "2.06e8*z + 1.28e7*zd; unloading: 4e6*zd"


@pytest.fixture(scope="module")
def unloading_fits():
    """The true model's fit from a start 5 % off: least squares alone, polished, the
    records and the polished fit's evaluations with their noise floors."""
    sc = load_scenario("paper")
    law = ForceLaw.parse(TRUTH)
    rec = R.reference_record((sc.with_law(law), law), periods=12, seed=3, check=False)
    _, records = _records_of(sc, rec, 20, 0)
    start = Model(ForceLaw.parse("2.16e8*z + 1.22e7*zd")).with_effect(
        effect("unloading_damping"), 4.2e6
    )
    plain = _output_error(records, start, "I2", 150, None)
    polished = _output_error(records, start, "I2", 150, None, polish=True)
    return records, start, plain, polished


def test_a_fit_at_its_noise_floor_is_neither_restarted_nor_polished(unloading_fits, monkeypatch):
    """Where least squares ends at or below the gate, the result is the first least-squares
    fit's own: no restart from its best point scaled, no simplex (fewer simulations).
    Below every value the fit runs as before, bit for bit.  Nelder-Mead minimises the
    criterion alone (the force), least squares the force's and the penetration's
    residuals: at the floor the simplex trades the penetration for noise in the force."""
    from discovery.vibroimpact.explain import starts

    records, start, plain, polished = unloading_fits
    methods, identify = [], starts.identify

    def spied(*args, **kwargs):
        methods.append(kwargs["method"])
        return identify(*args, **kwargs)

    monkeypatch.setattr(starts, "identify", spied)
    again = _output_error(records, start, "I2", 150, None, polish=True)
    assert methods == ["least-squares", "nelder-mead"]  # the simplex ran
    assert again.law.coefficients == polished.law.coefficients
    methods.clear()
    high = 10.0 * polished.value
    first = _output_error(records, start, "I2", 150, None, floor=high)
    gated = _output_error(records, start, "I2", 150, None, polish=True, floor=high)
    assert methods == ["least-squares", "least-squares"]  # no simplex at the floor
    assert gated.law.coefficients == first.law.coefficients
    assert gated.n_simulations == first.n_simulations < plain.n_simulations
    assert f"at every record's noise floor ({high:.3g} or more)" in first.message
    below = _output_error(records, start, "I2", 150, None, polish=True, floor=0.0)
    assert below.law.coefficients == polished.law.coefficients
    assert below.n_simulations == polished.n_simulations


def test_the_gate_is_the_smallest_floor_over_the_records(unloading_fits):
    """The gate explain passes (:func:`floor_of`): the smallest noise floor of the criterion
    over a model's evaluations, none where an evaluation has no finite floor."""
    from discovery.vibroimpact.fit.problem import ModelProblem

    records, _, plain, _ = unloading_fits
    evs = ModelProblem(records, None).evaluations(plain.law, floor=True)
    floor = floor_of(evs, "I2")
    assert floor == min(e.noise_floor["I2"] for e in evs)
    assert 0 < floor < np.inf
    # the true model's fit ends at its floor here: the polish would only fit noise
    assert plain.value <= 1.25 * floor
    assert floor_of(evs, "I9") is None
    assert floor_of([], "I2") is None


def test_a_drift_refit_that_reaches_a_point_met_before_goes_no_further(unloading_fits):
    """A mass loss's refit (the law with the loss held, then with it, then with the
    moulding's mass) from a start whose first refit ends where an earlier start's did
    (``met``) stops after that first refit: the rest would repeat the earlier chain."""
    from discovery.vibroimpact.explain import trials
    from discovery.vibroimpact.fit.problem import ModelProblem

    records, _, plain, _ = unloading_fits
    refits = trials._Refits(
        problem=ModelProblem(records, None),
        records=records,
        criterion="I2",
        budget=40,
        tolerances=None,
    )
    calls = []

    class Counted(trials._Refits):
        def fitted(self, start, budget=None):
            calls.append(start)
            return super().fitted(start, budget)

    counted = Counted(**{f: getattr(refits, f) for f in refits.__dataclass_fields__})
    start = Model(plain.law.law).with_effect(effect("mass_loss"), 2e-4)
    first = refits.fitted(start)
    met = []
    trials._drift_refit(counted, start, 40, "I2", met)
    # held, with the loss, with the moulding's mass (the record has no loss: the last
    # starts from a loss of 0, which no fit scales, and the chain ends there)
    assert len(calls) == 3
    assert len(met) == 1 and met[0].coefficients == first.law.coefficients
    calls.clear()
    again = trials._drift_refit(counted, start, 40, "I2", met)
    assert again == (start, None, np.inf) and len(calls) == 1
    # a point 1e-5 away is another point
    shifted = first.law.with_coefficients([c * (1 + 1e-5) for c in first.law.coefficients])
    assert not trials._met(shifted, [first.law])
    assert trials._met(first.law, [shifted, first.law])


def test_the_winner_is_polished_down_to_its_own_noise_floor(monkeypatch, unloading_fits):
    """The gate of the winner's polish is the winner's own floor (:func:`floor_of` its
    evaluations), not the model's before it, which on a record that model misses can be
    near 1; a polish that fails leaves the trial as it was."""
    from types import SimpleNamespace

    from discovery.errors import IntegrationError
    from discovery.vibroimpact.explain import trials
    from discovery.vibroimpact.fit.problem import ModelProblem

    records, _, plain, _ = unloading_fits
    evs = ModelProblem(records, None).evaluations(plain.law, floor=True)
    got = {}

    def polish(records, start, criterion, budget, tol, **options):
        got.update(options, start=start)
        raise IntegrationError("the test's polish stops here")

    monkeypatch.setattr(trials, "_output_error", polish)
    best = trials._Trial(
        ratio=0.5, score={}, model=plain.law, result=plain, evaluations=evs, key="I2"
    )
    run = SimpleNamespace(records=records, criterion="I2", budget=150, tolerances=None)
    assert trials._polish_winner(run, best, effect("unloading_damping")) == best
    assert got == {"polish": True, "floor": floor_of(evs, "I2"), "start": plain.law}
