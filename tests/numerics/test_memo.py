"""The simulation memo: a second ask for the same simulation is answered from the cache
and gives what the simulation gives, bit for bit (:mod:`discovery.numerics.memo`)."""

import sys

import numpy as np
import pytest

from discovery import ForceLaw, Measurement, load_scenario
from discovery.numerics.memo import Memo, value_key
from discovery.vibroimpact.dynamics.reference import reference_simulate
from discovery.vibroimpact.verify import Reference, evaluate


def test_value_key_compares_by_value():
    a = np.array([1.0, 2.0])
    assert value_key(a, {"x": 1.0}) == value_key(a.copy(), {"x": 1.0})
    assert value_key(a) != value_key(a.astype(np.float32))
    assert value_key(a) != value_key(a.reshape(2, 1))
    assert value_key({"x": 1.0, "y": 2.0}) == value_key({"y": 2.0, "x": 1.0})


def test_memo_is_least_recently_used_and_stores_no_failure():
    m, calls = Memo(2), []

    def f(v):
        calls.append(v)
        return v * 10

    assert m.get("a", lambda: f(1)) == 10
    assert m.get("b", lambda: f(2)) == 20
    assert m.get("a", lambda: f(99)) == 10  # a hit: "a" is now the most recent
    m.get("c", lambda: f(3))  # evicts "b"
    assert m.get("b", lambda: f(4)) == 40
    assert calls == [1, 2, 3, 4] and (m.hits, m.misses) == (1, 4) and len(m) == 2

    def fail():
        raise ValueError("no")

    with pytest.raises(ValueError):
        m.get("d", fail)
    assert m.get("d", lambda: 5) == 5  # the failure was not stored
    # an unhashable key is computed every time, never stored
    assert m.get(([1],), lambda: 6) == 6 and len(m) == 2


@pytest.fixture(scope="module")
def span_record():
    sc = load_scenario("light")
    T = sc.period
    t = 60 * T + np.arange(int(12 * T * 20000.0)) / 20000.0
    r = reference_simulate(sc, sc.law, (0.0, t[-1]), t_eval=t, rtol=1e-9)
    rng = np.random.default_rng(5)
    F = r["force"] + rng.normal(0.0, 0.01 * np.max(np.abs(r["force"])), t.size)
    ch = {
        n: r["y"][k] + rng.normal(0.0, 0.002 * np.ptp(r["y"][k]), t.size)
        for k, n in enumerate(("w1", "v1", "w2", "v2"))
    }
    return sc, Reference.from_measurement(Measurement(t, F, ch), sc, n_boot=4)


def _same(a, b):
    assert a.criteria == b.criteria and a.noise_floor == b.noise_floor
    assert a.consistent == b.consistent and a.verdict == b.verdict
    np.testing.assert_array_equal(a.simulated.F, b.simulated.F)


def test_a_residual_after_a_verification_reuses_its_simulations(span_record):
    """The block runs a verification made are reused by the smoothed residual of the
    same law (the optimisers' form), and both equal a run without the memo."""
    traj = sys.modules["discovery.vibroimpact.verify.trajectory"]
    sc, ref = span_record
    law = ForceLaw.parse("2.1e8*z + 1.1e7*zd")
    traj.MEMO.clear()
    full = evaluate(sc, law, ref)
    runs = traj.MEMO.misses
    assert runs == len(ref.span.blocks)
    smooth = evaluate(sc, law, ref, floor=False, objective=("I2",))
    # no new run: the floor and the residual asked the verification's runs again
    assert traj.MEMO.misses == runs and traj.MEMO.hits >= runs
    again = evaluate(sc, law, ref)
    _same(full, again)
    traj.MEMO.clear()
    _same(smooth, evaluate(sc, law, ref, floor=False, objective=("I2",)))
    # another law is another simulation
    other = evaluate(sc, ForceLaw.parse("2.2e8*z + 1.1e7*zd"), ref, floor=False)
    assert traj.MEMO.misses == 2 * runs and other.criteria != smooth.criteria


def test_a_steady_state_is_reused_for_the_same_law_and_start(span_record):
    ev = sys.modules["discovery.vibroimpact.verify.evaluation"]
    sc, _ = span_record
    ref = Reference.from_measurement(
        Measurement(*_steady_record(sc)), sc, n_boot=4, use_state=False
    )
    ev.MEMO.clear()
    a = evaluate(sc, sc.law, ref)
    n = ev.MEMO.misses
    b = evaluate(sc, sc.law, ref, floor=False)
    assert ev.MEMO.misses == n and ev.MEMO.hits >= 2  # the steady state and its force
    assert a.criteria == b.criteria and a.steady is b.steady


def _steady_record(sc):
    T = sc.period
    t = 80 * T + np.arange(int(8 * T * 20000.0)) / 20000.0
    r = reference_simulate(sc, sc.law, (0.0, t[-1]), t_eval=t, rtol=1e-9)
    rng = np.random.default_rng(2)
    return t, r["force"] + rng.normal(0.0, 0.01 * np.max(np.abs(r["force"])), t.size)


def test_of_keeps_a_result_per_object_and_never_answers_another():
    """``Memo.of``: one computation per object while it is kept; an object whose id is that of
    one no longer alive is computed afresh, never given the other's result."""
    memo, calls = Memo(4), []

    def for_(a):
        return lambda: calls.append(id(a)) or float(a.sum())

    a = np.arange(3.0)
    assert memo.of(a, for_(a)) == 3.0 and memo.of(a, for_(a)) == 3.0
    assert len(calls) == 1
    b = np.arange(4.0)
    memo._d[id(b)] = (a, 3.0)  # a stale entry under b's id (as after a's id was reused)
    assert memo.of(b, for_(b)) == 6.0 and len(calls) == 2
