"""The compiled periodic piecewise-linear evaluation against a plain one written from its
definition: random knots with jumps (repeated times), sorted, unsorted and wrapping
queries, queries on knots, either side, and a flag per query."""

import numpy as np
import pytest

from discovery.numerics.piecewise import periodic_values


def _plain(t, F, W, x, left):
    """The signal at ``x`` from the definition: the last knot at or before ``q = x mod W``
    (strictly before for the left limit; ``q = W`` for a left limit at a positive whole
    period), then linear to the next knot."""
    q = x % W
    if left and q == 0.0 and x > 0.0:
        q = W
    before = [i for i in range(len(t)) if t[i] < q or (not left and t[i] == q)]
    i = min(max((before[-1] if before else -1), 0), len(t) - 2)
    t0, t1 = t[i], t[i + 1]
    w = min(max((q - t0) / (t1 - t0), 0.0), 1.0) if t1 > t0 else (1.0 if left else 0.0)
    return F[i] + w * (F[i + 1] - F[i])


def _signal(rng, n):
    W = float(rng.uniform(0.5, 2.0))
    inner = np.sort(rng.uniform(0, W, n))
    # repeated times: jumps (a pair) and a run of three
    inner = np.sort(np.concatenate([inner, inner[rng.choice(n, 3, replace=False)], inner[:1]]))
    t = np.concatenate([[0.0], inner, [W]])
    return t, rng.normal(size=t.size), W


@pytest.mark.parametrize("seed", range(40))
def test_periodic_values_match_the_definition(seed):
    rng = np.random.default_rng(seed)
    t, F, W = _signal(rng, int(rng.integers(3, 30)))
    # queries: the knots themselves (sorted, each twice), random times over three periods
    # (sorted and not), and the period's multiples
    knots = np.sort(np.concatenate([t, t, t + W]))
    free = rng.uniform(-W, 3 * W, 60)
    for tq in (knots, np.sort(free), free, np.array([0.0, W, 2 * W, W, 0.0])):
        for side in ("left", "right"):
            got = periodic_values(t, F, W, tq, side)
            want = [_plain(t, F, W, x, side == "left") for x in tq]
            assert np.array_equal(got, want)
        lefts = rng.random(tq.size) < 0.5
        got = periodic_values(t, F, W, tq, lefts)
        want = [_plain(t, F, W, x, bool(a)) for x, a in zip(tq, lefts, strict=True)]
        assert np.array_equal(got, want)


def test_periodic_values_shapes_and_flags():
    t, F, W = np.array([0.0, 0.5, 0.5, 1.0]), np.array([1.0, 1.0, 0.0, 0.0]), 1.0
    assert periodic_values(t, F, W, 0.5, "left") == 1.0
    assert periodic_values(t, F, W, 0.5, "right") == 0.0
    assert periodic_values(t, F, W, np.zeros((2, 3))).shape == (2, 3)
    got = periodic_values(t, F, W, np.array([0.5, 0.5]), np.array([True, False]))
    assert got.tolist() == [1.0, 0.0]
    with pytest.raises(ValueError, match="one side flag per query"):
        periodic_values(t, F, W, np.array([0.5, 0.5]), np.array([True]))
