"""The compiled loops over sampled signals against the numpy expressions they replace
(written out here as the slow path): the same results to the last bit on random signals,
noisy and clean, with runs at the ends, flicker, steep and flat edges."""

import numpy as np
import pytest

from discovery.numerics.intervals import in_widened_intervals
from discovery.numerics.sampled import abs_areas, bin_means, running_mean
from discovery.vibroimpact.data.contact_edges import _edges, moving_mean
from discovery.vibroimpact.verify.criteria import _int_abs


def _slow_moving_mean(x, width):
    h = width // 2
    p = np.concatenate([np.full(h, x[0]), x, np.full(h, x[-1])])
    first = np.cumsum(p[:width])[-1]
    return np.cumsum(np.concatenate([[first], p[width:] - p[: p.size - width]])) / width


def _slow_edges(t, F, thr, min_len, *, max_extrap=4.0, noise=0.0):
    above = F > thr
    idx = np.flatnonzero(np.diff(above.astype(np.int8)))
    starts = list(idx[~above[idx]] + 1)
    ends = list(idx[above[idx]] + 1)
    if above[0]:
        starts.insert(0, 0)
    if above[-1]:
        ends.append(len(F))
    merged = []
    for r in [[s, e] for s, e in zip(starts, ends, strict=True)]:
        if merged and (
            r[0] - merged[-1][1] < min_len
            or (noise > 0 and F[merged[-1][1] : r[0]].min() > thr - 3.0 * noise)
        ):
            merged[-1][1] = r[1]
        else:
            merged.append(r)
    runs = [
        r
        for r in merged
        if r[1] - r[0] >= min_len or (r[1] - r[0] >= 3 and F[r[0] : r[1]].max() >= 3.0 * thr)
    ]
    out = []
    for s, e in runs:
        if s == 0 or e >= len(F):
            continue
        f0, f1 = F[s - 1], F[s]
        steep = max_extrap is not None and f1 - f0 > 3.0 * noise
        lo = -max_extrap if steep else 0.0
        frac = ((0.0 if steep else thr) - f0) / (f1 - f0) if f1 > f0 else 1.0
        t_on = t[s - 1] + min(max(float(frac), lo), 1.0) * (t[s] - t[s - 1])
        g0, g1 = F[e - 1], F[e]
        steep = max_extrap is not None and g0 - g1 > 3.0 * noise
        hi = 1.0 + max_extrap if steep else 1.0
        frac = ((0.0 if steep else thr) - g0) / (g1 - g0) if g1 < g0 else 0.0
        t_off = t[e - 1] + min(max(float(frac), 0.0), hi) * (t[e] - t[e - 1])
        if out and t_on <= out[-1][1]:
            out[-1] = (out[-1][0], max(out[-1][1], t_off), out[-1][2])
        else:
            out.append((t_on, t_off, s))
    return out


def _slow_int_abs(h, d):
    a, b = d[:-1], d[1:]
    same = a * b >= 0
    m = np.abs(d)
    total = m[:-1] + m[1:]
    area = np.where(same, 0.5 * total, 0.5 * (a * a + b * b) / np.where(same, 1.0, total))
    return float(np.sum(h * area))


def _slow_in_widened(t, iv, pad, length):
    shifts = np.array([-length, 0.0, length])
    lo = ((iv[:, :1] - pad) + shifts).ravel()
    hi = ((iv[:, 1:] + pad) + shifts).ravel()
    start = np.searchsorted(t, lo, "left")
    end = np.searchsorted(t, hi, "right")
    keep = start < end
    n = t.size + 1
    marks = np.bincount(start[keep], minlength=n) - np.bincount(end[keep], minlength=n)
    return np.cumsum(marks[:-1]) > 0


def _signal(rng, n=400):
    """Impacts (half-sines, some with a jump at the onset) on a noisy baseline, runs
    touching either end at times."""
    t = np.sort(rng.uniform(0.0, 1.0, n)) if rng.random() < 0.3 else np.linspace(0.0, 1.0, n)
    F = np.zeros(n)
    for _ in range(rng.integers(0, 4)):
        a = rng.uniform(-0.1, 0.9)
        w = rng.uniform(0.003, 0.2)
        inside = (t >= a) & (t <= a + w)
        F[inside] += rng.uniform(0.5, 3.0) * np.sin(np.pi * (t[inside] - a) / w)
        if rng.random() < 0.5:
            F[inside] += rng.uniform(0.0, 1.0)  # a viscous contact's jump
    noise = rng.choice([0.0, 1e-3, 0.05, 0.2])
    return t, F + noise * rng.standard_normal(n), noise


@pytest.mark.parametrize("seed", range(40))
def test_the_contact_edges_are_the_numpy_ones_to_the_bit(seed):
    rng = np.random.default_rng(seed)
    t, F, noise = _signal(rng)
    for thr in (0.05, 0.3, 1.0):
        for min_len in (1, 3, 12):
            for extrap in (None, 4.0, 0.0):
                got = _edges(t, F, thr, min_len, max_extrap=extrap, noise=noise)
                want = _slow_edges(t, F, thr, min_len, max_extrap=extrap, noise=noise)
                assert len(got) == len(want)
                for g, w in zip(got, want, strict=True):
                    assert g[0] == w[0] and g[1] == w[1] and g[2] == w[2]


@pytest.mark.parametrize("seed", range(20))
def test_the_running_mean_is_numpys_to_the_bit(seed):
    rng = np.random.default_rng(seed)
    _, F, _ = _signal(rng, n=int(rng.integers(1, 300)))
    for width in (1, 3, 7, 31):
        got, want = moving_mean(F, width), _slow_moving_mean(F, width)
        np.testing.assert_array_equal(got, want)
        assert np.array_equal(np.signbit(got), np.signbit(want))
    assert np.signbit(running_mean(np.array([-0.0, -0.0]), 1)[0])


@pytest.mark.parametrize("seed", range(20))
def test_the_areas_of_a_difference_are_numpys_to_the_bit(seed):
    rng = np.random.default_rng(seed)
    t, F, _ = _signal(rng)
    d = F - np.roll(F, int(rng.integers(0, 9)))
    d[rng.random(d.size) < 0.05] = 0.0  # ends on zero, and a sign that does not change
    h = np.diff(t)
    assert _int_abs(h, d) == _slow_int_abs(h, d)


def test_the_areas_of_a_difference_in_closed_form():
    # two triangles where the sign changes at the middle; a trapezoid where it does not
    np.testing.assert_array_equal(abs_areas(np.array([1.0]), np.array([1.0, -1.0])), [0.5])
    np.testing.assert_array_equal(abs_areas(np.array([2.0]), np.array([1.0, 3.0])), [4.0])
    # a zero crossing at a quarter of the step: (1/4 * 3 + 3/4 * 9) / 2 = 3.75
    assert abs_areas(np.array([1.0]), np.array([-3.0, 9.0]))[0] == pytest.approx(3.75)


@pytest.mark.parametrize("seed", range(20))
def test_the_widened_windows_are_numpys(seed):
    rng = np.random.default_rng(seed)
    t = np.sort(rng.uniform(0.0, 1.0, 300))
    a = np.sort(rng.uniform(-0.2, 1.0, 2 * int(rng.integers(0, 4))))
    iv = a.reshape(-1, 2)
    for pad in (0.0, 0.01):
        np.testing.assert_array_equal(
            in_widened_intervals(t, iv, pad, 1.0), _slow_in_widened(t, iv, pad, 1.0)
        )


@pytest.mark.parametrize("seed", range(10))
def test_the_bin_means_are_numpys_to_the_bit(seed):
    rng = np.random.default_rng(seed)
    n, k = int(rng.integers(1, 500)), int(rng.integers(1, 60))
    bins = np.sort(rng.integers(0, k, n))
    bins = np.unique(bins, return_inverse=True)[1].astype(np.int64)  # no empty bin
    counts = np.bincount(bins)
    values = rng.standard_normal(n) * 10.0 ** rng.integers(-3, 6)
    want = np.bincount(bins, weights=values, minlength=counts.size) / counts
    np.testing.assert_array_equal(bin_means(bins, values, counts), want)


def test_each_loop_is_compiled_once_for_read_only_and_writeable_arrays():
    """A memoised (read-only) array and a fresh one take the same compiled version: a
    user's first command compiles nothing that `make install` did not."""
    from discovery.numerics import sampled

    x = np.linspace(0.0, 1.0, 20)
    ro = x.copy()
    ro.setflags(write=False)
    bins, counts = np.zeros(20, dtype=np.int64), np.array([20])
    for a in (x, ro):
        sampled.running_mean(a, 3)
        sampled.threshold_runs(a, a, 0.5, 3, -1.0, 0.0)
        sampled.abs_areas(np.diff(a), a)
        sampled.in_widened(a, np.array([[0.1, 0.2]]), 0.0, 1.0)
        sampled.bin_means(bins, a, counts)
    for name in sampled.__all__:
        assert len(getattr(sampled, name).signatures) == 1, name


def test_the_criteria_interpolation_is_compiled_once():
    """The compiled interpolation takes read-only and writeable signals and queries alike
    (a memoised signal compiled a second and third version at a user's first command)."""
    from discovery.numerics.piecewise import _values, periodic_values

    t, F = np.array([0.0, 0.5, 0.5, 1.0]), np.array([0.0, 1.0, 2.0, 0.0])
    ro_t, ro_q = t.copy(), np.linspace(0.0, 2.0, 9)
    ro_t.setflags(write=False)
    ro_q.setflags(write=False)
    a = periodic_values(t, F, 1.0, np.linspace(0.0, 2.0, 9), "left")
    b = periodic_values(ro_t, F, 1.0, ro_q, np.ones(9, dtype=bool))
    np.testing.assert_array_equal(a, b)
    assert len(_values.signatures) == 1
