"""The search of the machine's scale (``verify(..., machine_scale=...)``): successive
parabolic interpolation, checked against closed forms and against a dense grid of full
verifications on a record made by the independent scipy path."""

import numpy as np
import pytest

from discovery import ForceLaw, calibrate, load_scenario
from discovery.vibroimpact.verify import Reference, evaluate, verify
from discovery.vibroimpact.verify.verdict import SCALE_EVALUATIONS, SCALE_XTOL, _scale_minimum

from .test_verify import _record


def _counted(f):
    calls = []

    def g(x):
        calls.append(x)
        return f(x)

    return g, calls


@pytest.mark.parametrize("x0", [0.9912, 0.997, 1.0004, 1.0071])
def test_an_inner_minimum_of_a_smooth_curve_is_found_to_the_tolerance(x0):
    """A curve with a minimum inside the range (a quadratic plus a cubic term, so that no
    parabola is exact): found to within a few tolerances, in at most the budget."""
    f, calls = _counted(lambda x: 0.05 + 40.0 * (x - x0) ** 2 + 300.0 * (x - x0) ** 3)
    best, value = _scale_minimum(f, 0.99, 1.01)
    assert abs(best - x0) < 3 * SCALE_XTOL
    assert value == pytest.approx(f(best))
    assert len(calls) <= SCALE_EVALUATIONS


@pytest.mark.parametrize("slope", [+1.0, -1.0])
def test_a_minimum_at_a_bound_takes_the_three_starting_simulations(slope):
    """I2 rising across the range (the commonest case on a stiff machine): the bound, found
    by the bounds and the calibration's own scale alone."""
    f, calls = _counted(lambda x: 1.3 + slope * 0.3 * (x - 1.0) + 2.0 * (x - 1.0) ** 2)
    best, _ = _scale_minimum(f, 0.9894, 1.0106)
    assert best == (0.9894 if slope > 0 else 1.0106)
    assert len(calls) == 3


def test_a_flat_curve_keeps_the_calibrations_scale():
    """Nothing to choose between (every simulation failed, say): the scale is the
    calibration's own, 1."""
    f, calls = _counted(lambda x: 1e3)
    assert _scale_minimum(f, 0.99, 1.01) == (1.0, 1e3)
    assert len(calls) == 3


@pytest.mark.parametrize(
    "curve",
    [
        lambda x: abs(x - 1.003),  # a kink (a contact appearing) at the minimum
        lambda x: min(abs(x - 0.995), 0.5 * abs(x - 1.006)),  # two minima, the parabola concave
        lambda x: 1.0 - 60.0 * abs(x - 1.003) ** 1.5,  # a maximum inside: the best at a bound
    ],
)
def test_a_rough_curve_ends_within_the_budget_at_its_best_simulation(curve):
    """Curves no parabola fits: the search ends within its budget, at the lowest of its
    own simulations, no worse than the bounds and the calibration's scale."""
    f, calls = _counted(curve)
    best, value = _scale_minimum(f, 0.99, 1.01)
    assert len(calls) <= SCALE_EVALUATIONS
    assert value == curve(best) == min(curve(x) for x in list(calls))
    assert value <= min(curve(0.99), curve(1.0), curve(1.01))


@pytest.fixture(scope="module")
def sheet_record():
    """A record of the paper's machine with a moulding 4 % heavier than its sheet says
    (scipy path, from rest, 1 % force noise), and the machine calibrated from it."""
    sheet = load_scenario("paper")
    true = sheet.replace(m2=1.04 * sheet.m2)
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    rec = _record(true, law, periods=8, transient=30, seed=3)
    return calibrate(sheet, rec, seed=0), rec, law


def test_the_scale_chosen_is_as_good_as_a_dense_grid_of_verifications(sheet_record):
    """On a real record, the scale the search takes has an I2 within 1e-4 (relative) of the
    best of a 21-point grid over the calibration's range: the cheaper search loses
    nothing a user could see in the verdict."""
    cal, rec, law = sheet_record
    lo, hi = cal.scale_range
    ref = Reference.from_measurement(rec, cal.scenario, n_boot=16, seed=0)

    def i2(f):
        ev = evaluate(cal.scenario.scaled(f), law, ref, floor=False, objective=("I2",))
        return ev.criteria["I2"]

    grid = min(i2(f) for f in np.linspace(lo, hi, 21))
    res = verify(cal.scenario, ref, law, machine_scale=cal.scale_range)
    note = next(n for n in res.notes if "fits this law best at" in n)
    chosen = float(note.split("fits this law best at ")[1].split()[0])
    assert i2(chosen) <= grid * (1.0 + 1e-4) + 1e-9, (note, grid)
