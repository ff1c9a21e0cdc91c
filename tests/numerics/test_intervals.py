"""Which sorted times widened cyclic intervals hold: the binary searches against the plain
pass over every time (the rule the criteria and the contact window used to write out)."""

import numpy as np
import pytest

from discovery.numerics.intervals import in_widened_intervals


def _slow(t, iv, pad, length):
    inside = np.zeros(t.size, dtype=bool)
    for a, b in iv:
        for shift in (-length, 0.0, length):
            inside |= (t >= a - pad + shift) & (t <= b + pad + shift)
    return inside


@pytest.mark.parametrize("seed", range(40))
def test_the_same_times_as_the_plain_pass(seed):
    rng = np.random.default_rng(seed)
    length = float(rng.uniform(0.01, 1.0))
    n = int(rng.integers(1, 400))
    t = np.sort(rng.uniform(0.0, length, n))
    if seed % 3 == 0:  # repeated times (a jump's two limits) and the ends themselves
        t = np.sort(np.concatenate([t, t[: n // 4], [0.0, length]]))
    m = int(rng.integers(0, 6))
    a = rng.uniform(-0.1 * length, length, m)
    iv = np.column_stack([a, a + rng.uniform(-0.05, 0.5, m) * length])  # some empty
    pad = float(rng.choice([0.0, 0.01 * length, 0.2 * length]))
    if seed % 5 == 0 and n > 3:  # an interval edge exactly on a sample time
        iv = np.vstack([iv, [t[1] + pad, t[n // 2] - pad]])
    np.testing.assert_array_equal(
        in_widened_intervals(t, iv, pad, length), _slow(t, iv, pad, length)
    )


def test_no_interval_holds_nothing():
    t = np.linspace(0.0, 1.0, 11)
    assert not in_widened_intervals(t, np.zeros((0, 2)), 0.1, 1.0).any()
