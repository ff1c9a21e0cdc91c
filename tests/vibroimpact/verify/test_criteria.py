"""The verification criteria I0..I4: properties (9), (10), exact integrals, periodic extension."""

import dataclasses
import math

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.vibroimpact.data.impulse import Impulse
from discovery.vibroimpact.dynamics.law_response import impulse_from_steady_state
from discovery.vibroimpact.dynamics.steady_states import steady_state
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.verify.criteria import CRITERIA, compare, criterion, evaluate_criteria

NAMES = ["I0", "I1", "I2", "I3", "I4"]


def imp(t, F, duration, support, n_periods=1, onset=0.0):
    return Impulse(
        t=np.asarray(t, float),
        F=np.asarray(F, float),
        duration=float(duration),
        support=np.asarray(support, float).reshape(-1, 2),
        n_periods=n_periods,
        onset=onset,
    )


# ------------------------------------------------------- simulated impulses (paper)

PERTURBED = ["2.2e8*z + 1.28e7*zd", "2.06e8*z + 1.0e7*zd", "3e8*z^1.5 + 1e7*zd"]


@pytest.fixture(scope="module")
def perturbed_impulses(paper):
    out = []
    for text in PERTURBED:
        law = ForceLaw.parse(text)
        ss = steady_state(paper, law)
        assert ss.periodic
        out.append(impulse_from_steady_state(paper, law, ss))
    return out


def test_properties_9_and_10_on_simulated_impulses(paper_impulse, perturbed_impulses):
    same = evaluate_criteria(paper_impulse, paper_impulse)
    assert list(same) == NAMES
    assert all(v == 0.0 for v in same.values())  # (10): exactly zero, same grid and values
    for other in perturbed_impulses:
        for a, b in ((paper_impulse, other), (other, paper_impulse)):
            vals = evaluate_criteria(a, b)
            assert all(v >= 0.0 for v in vals.values())  # (9)
            # different laws give visibly different impulses (smallest measured: I1 4e-4)
            assert vals["I1"] > 1e-4 and vals["I2"] > 1e-3 and vals["I3"] > 1e-3
            # I0 is defined as the mean of I1 and I4 (rel 1e-15: one addition, one halving)
            assert vals["I0"] == pytest.approx(0.5 * (vals["I1"] + vals["I4"]), rel=1e-15)


def test_criteria_grow_with_the_perturbation(paper_impulse, perturbed_impulses):
    # the 7% stiffer law is closer to the truth than the 22% less viscous one
    small, big = (evaluate_criteria(paper_impulse, p) for p in perturbed_impulses[:2])
    for k in ("I1", "I2", "I3"):
        assert small[k] < big[k]


def test_shift_invariance_with_simulation(paper, paper_impulse):
    """The same orbit sampled 3 and 1000 periods later: same impulse, other onset."""
    ss = steady_state(paper, paper.law)
    for k in (3, 1000):
        later = impulse_from_steady_state(
            paper, paper.law, dataclasses.replace(ss, t0=ss.t0 + k * paper.period)
        )
        # onset moves by exactly k periods (abs 1e-12 s: roundoff of times ~40 s)
        assert later.onset - paper_impulse.onset == pytest.approx(k * paper.period, abs=1e-12)
        vals = evaluate_criteria(paper_impulse, later)
        # measured <= 1.2e-10: event times carry roundoff of the larger absolute time
        assert max(vals.values()) < 1e-8


def test_shift_invariance_by_hand():
    e = imp([0, 0.3, 0.3, 1], [2, 2, 0, 0], 1, [[0, 0.3]], onset=0.0)
    n = imp([0, 0.2, 0.2, 1], [3, 3, 0, 0], 1, [[0, 0.2]], onset=5.0)
    base = evaluate_criteria(e, n)
    for onset_e, onset_n in ((17.0, 5.0), (1e6, -3.0)):
        shifted = evaluate_criteria(
            dataclasses.replace(e, onset=onset_e), dataclasses.replace(n, onset=onset_n)
        )
        assert shifted == base  # exact: the onsets only label the records


# ---------------------------------------------------------- closed forms by hand


def test_rectangles_with_jumps_closed_form():
    # E: 2 on [0, 0.3); N: 3 on [0, 0.2). Both jump at onset and at their end.
    e = imp([0, 0.3, 0.3, 1], [2, 2, 0, 0], 1, [[0, 0.3]])
    n = imp([0, 0.2, 0.2, 1], [3, 3, 0, 0], 1, [[0, 0.2]])
    v = evaluate_criteria(e, n)
    # exact values (piecewise constant); rel 1e-14 for roundoff of a few sums
    assert v["I1"] == pytest.approx(2 / 2, rel=1e-14)  # |0 - 2| on [0.2, 0.3)
    assert v["I2"] == pytest.approx((1 * 0.2 + 2 * 0.1) / (2 * 0.3), rel=1e-14)
    assert v["I3"] == pytest.approx(math.sqrt((1 * 0.2 + 4 * 0.1) / (4 * 0.3)), rel=1e-14)
    assert v["I4"] == pytest.approx(0.1 / 0.3, rel=1e-14)  # nested: |tau_N - tau_E| / tau_E
    assert v["I0"] == pytest.approx((1 + 1 / 3) / 2, rel=1e-14)
    c = compare(e, n)
    # each jump time is on the grid twice (left then right limit)
    assert np.sum(c.t == 0.2) == 2 and np.sum(c.t == 0.3) == 2
    assert c.fe[0] == 2 and c.fn[0] == 3  # right limits at the onset


def test_exact_abs_integral_when_difference_changes_sign():
    # E jumps to 2 and falls linearly to 0 at 0.4; N is 1 on [0, 0.4).
    # d = N - E = 5t - 1 changes sign at t = 0.2 inside the single segment [0, 0.4].
    e = imp([0, 0.4, 1], [2, 0, 0], 1, [[0, 0.4]])
    n = imp([0, 0.4, 0.4, 1], [1, 1, 0, 0], 1, [[0, 0.4]])
    c = compare(e, n)
    assert not np.any(np.isclose(c.t, 0.2))  # the crossing is not a grid point
    v = evaluate_criteria(e, n)
    # int |5t-1| = 0.2, int E = 0.4; a trapezoid of |d| would give 0.4/0.4 = 1
    assert v["I2"] == pytest.approx(0.5, rel=1e-14)
    # int (5t-1)^2 = 2/15, int (2-5t)^2 = 8/15
    assert v["I3"] == pytest.approx(0.5, rel=1e-14)
    assert v["I1"] == pytest.approx(0.5, rel=1e-14)  # |d| = 1 at 0 and at 0.4-
    assert v["I4"] == 0.0  # same support


def test_triangles_closed_form():
    # E: triangle 0 -> 4 (t = 0.1) -> 0 (t = 0.3); N: jump to 2, flat to 0.2, jump down
    e = imp([0, 0.1, 0.3, 1], [0, 4, 0, 0], 1, [[0, 0.3]])
    n = imp([0, 0.2, 0.2, 1], [2, 2, 0, 0], 1, [[0, 0.2]])
    v = evaluate_criteria(e, n)
    # d = N - E: on [0, 0.1]: 2 - 40t (zero at 0.05); on [0.1, 0.2]: 2 - (6 - 20t) = 20t - 4
    # (zero at 0.2); on [0.2, 0.3]: -(6 - 20t)
    int_abs_d = 0.5 * 0.05 * 2 + 0.5 * 0.05 * 2 + 0.5 * 0.1 * 2 + 0.5 * 0.1 * 2
    int_e = 0.5 * 0.3 * 4
    assert v["I2"] == pytest.approx(int_abs_d / int_e, rel=1e-14)
    # int of a linear piece from a to b over h: h (a^2 + ab + b^2) / 3; pieces (2, -2),
    # (-2, 0), (-2, 0), each h = 0.1
    int_d2 = 0.1 * (4 - 4 + 4) / 3 + 2 * 0.1 * 4 / 3
    int_e2 = 0.1 * 16 / 3 + 0.2 * 16 / 3
    assert v["I3"] == pytest.approx(math.sqrt(int_d2 / int_e2), rel=1e-14)
    assert v["I1"] == pytest.approx(2 / 4, rel=1e-14)
    assert v["I4"] == pytest.approx(0.1 / 0.3, rel=1e-14)


@pytest.mark.parametrize(
    ("sup_e", "sup_n", "expected"),
    [
        ([[0, 0.3]], [[0, 0.2]], 0.1 / 0.3),  # N inside E
        ([[0, 0.2]], [[0, 0.3]], 0.1 / 0.2),  # E inside N
        ([[0, 0.3]], [[0, 0.1], [0.2, 0.5]], 1.0),  # not nested: symmetric difference
        ([[0, 0.3]], [[0, 0.3]], 0.0),
    ],
)
def test_i4_support_measure(sup_e, sup_n, expected):
    e = imp([0, 1], [1, 0], 1, sup_e)
    n = imp([0, 1], [1, 0], 1, sup_n)
    assert criterion("I4")(compare(e, n)) == pytest.approx(expected, rel=1e-14, abs=1e-15)


# -------------------------------------------------------- periodic extension P1 / P2


def test_p1_against_itself_written_as_p2_is_zero():
    e1 = imp([0, 0.5, 0.5, 1], [1, 1, 0, 0], 1, [[0, 0.5]])
    e2 = imp(
        [0, 0.5, 0.5, 1, 1, 1.5, 1.5, 2],
        [1, 1, 0, 0, 1, 1, 0, 0],
        2,
        [[0, 0.5], [1, 1.5]],
        n_periods=2,
    )
    for a, b in ((e1, e2), (e2, e1)):
        c = compare(a, b)
        assert c.length == 2.0
        assert all(v == 0.0 for v in evaluate_criteria(a, b).values())


def test_p1_against_p2_without_jump_at_cycle_start():
    # E (P1): triangle 0 -> 1 -> 0 on [0, 0.5]; N (P2): the same, then one half as high
    e = imp([0, 0.25, 0.5, 1], [0, 1, 0, 0], 1, [[0, 0.5]])
    n = imp(
        [0, 0.25, 0.5, 1, 1.25, 1.5, 2],
        [0, 1, 0, 0, 0.5, 0, 0],
        2,
        [[0, 0.5], [1, 1.5]],
        n_periods=2,
    )
    v = evaluate_criteria(e, n)
    assert v["I1"] == pytest.approx(0.5, rel=1e-14)
    assert v["I2"] == pytest.approx((0.5 * 0.5 * 0.5) / (2 * 0.5 * 0.5 * 1), rel=1e-14)
    assert v["I3"] == pytest.approx(math.sqrt((0.25 * 0.5 / 3) / (2 * 0.5 / 3)), rel=1e-14)
    assert v["I4"] == 0.0


def test_p1_with_onset_jump_against_p2():
    # E (P1): 1 on [0, 0.5) every period; N (P2): 1 on [0, 0.5) once every two periods
    e = imp([0, 0.5, 0.5, 1], [1, 1, 0, 0], 1, [[0, 0.5]])
    n = imp([0, 0.5, 0.5, 2], [1, 1, 0, 0], 2, [[0, 0.5]], n_periods=2)
    v = evaluate_criteria(e, n)
    assert v["I4"] == pytest.approx(0.5, rel=1e-14)
    assert v["I1"] == pytest.approx(1.0, rel=1e-14)
    assert v["I2"] == pytest.approx(0.5, rel=1e-14)  # |diff| = 1 on [1, 1.5); int E = 1
    assert v["I3"] == pytest.approx(math.sqrt(0.5), rel=1e-14)


# ----------------------------------------------------------------------- registry / errors


def test_unknown_criterion_lists_valid_names():
    with pytest.raises(InputError) as exc:
        criterion("I9")
    msg = str(exc.value)
    assert "I9" in msg and all(name in msg for name in NAMES)
    e = imp([0, 0.5, 0.5, 1], [1, 1, 0, 0], 1, [[0, 0.5]])
    with pytest.raises(InputError, match="unknown criterion"):
        evaluate_criteria(e, e, names=["I2", "I9"])


def test_registry_and_subset():
    assert list(CRITERIA) == NAMES
    e = imp([0, 0.3, 0.3, 1], [2, 2, 0, 0], 1, [[0, 0.3]])
    n = imp([0, 0.2, 0.2, 1], [3, 3, 0, 0], 1, [[0, 0.2]])
    sub = evaluate_criteria(e, n, names=["I3", "I1"])
    assert list(sub) == ["I3", "I1"]
    full = evaluate_criteria(e, n)
    assert sub["I3"] == full["I3"] and sub["I1"] == full["I1"]


def test_compare_errors():
    e = imp([0, 0.5, 0.5, 1], [1, 1, 0, 0], 1, [[0, 0.5]])
    with pytest.raises(InputError, match="both impulses"):
        compare(e, None)
    with pytest.raises(InputError, match="both impulses"):
        evaluate_criteria(None, e)
    other_period = imp([0, 0.5, 0.5, 1.3], [1, 1, 0, 0], 1.3, [[0, 0.5]])
    with pytest.raises(InputError, match="drive periods"):
        compare(e, other_period)
    zero = imp([0, 1], [0, 0], 1, np.zeros((0, 2)))
    with pytest.raises(InputError, match="undefined"):
        evaluate_criteria(zero, e, names=["I2"])


@pytest.mark.parametrize("seed", range(12))
def test_one_folds_two_sides_compare_as_through_the_union(seed, monkeypatch):
    """Two impulses on the same knots (a fold's measured and simulated cycles) take the
    grid once; the comparison and every criterion are bitwise those of the general union
    of two grids."""
    import discovery.vibroimpact.verify.criteria as C

    rng = np.random.default_rng(seed)
    n = int(rng.integers(5, 60))
    t = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, n)]))
    if seed % 2:  # a jump inside the cycle: a repeated knot
        t = np.sort(np.concatenate([t, t[n // 2 : n // 2 + 1]]))
    Fe = np.abs(rng.normal(size=t.size))
    Fn = np.abs(Fe + 0.2 * rng.normal(size=t.size))
    sup = np.array([[0.0, float(t[-2])]])
    e = dataclasses.replace(imp(t, Fe, 1.0, sup), noise=0.01 * (seed % 3), threshold=0.01)
    s = imp(t.copy() if seed % 3 else t, Fn, 1.0, sup)
    fast, fast_v = compare(e, s), evaluate_criteria(e, s)
    monkeypatch.setattr(C, "_same_grid", lambda a, b: False)
    slow, slow_v = compare(e, s), evaluate_criteria(e, s)
    for f in ("t", "fe", "fn", "support_e", "support_n"):
        assert np.array_equal(getattr(fast, f), getattr(slow, f))
    assert fast_v == slow_v


def test_a_measured_side_is_made_once_and_kept(monkeypatch):
    """The fitting loops compare one measured block with every law: its side of a comparison
    on its own grid is made once and kept (read-only where a comparison holds it), and each
    later comparison is bitwise a fresh one."""
    import discovery.vibroimpact.verify.criteria as C

    rng = np.random.default_rng(5)
    t = np.sort(np.concatenate([[0.0, 1.0], rng.uniform(0, 1, 40)]))
    sup = np.array([[0.0, float(t[-2])]])
    e = dataclasses.replace(imp(t, np.abs(rng.normal(size=t.size)), 1.0, sup), noise=0.01)
    sims = [imp(t, np.abs(rng.normal(size=t.size)), 1.0, sup) for _ in range(3)]
    made = []
    grid_points = C._grid_points
    monkeypatch.setattr(C, "_grid_points", lambda *a: made.append(1) or grid_points(*a))
    kept = [(compare(e, s), evaluate_criteria(e, s)) for s in sims]
    assert len(made) == 1
    assert not kept[0][0].t.flags.writeable and not kept[0][0].support_e.flags.writeable
    for s, (c, v) in zip(sims, kept, strict=True):
        C._OWN_GRIDS.clear()
        fresh = compare(e, s)
        for f in ("t", "fe", "fn", "support_e", "support_n"):
            assert np.array_equal(getattr(c, f), getattr(fresh, f))
        C._OWN_GRIDS.clear()
        assert evaluate_criteria(e, s) == v
