"""The energy-distance test of strobe points: the distance, and how the record's points are
resampled so that the noise floor and the test are alike under the null hypothesis.

A record's ``n`` strobe points are one orbit segment: consecutive points are correlated
over a few periods, so resampling must keep blocks of consecutive points together
(:func:`strobe_block_length`, :class:`FloorScheme`, :func:`energy_resamples`; the reasons
and the measured rates are in :func:`discovery.ueda.verification.verify`).
"""

from dataclasses import dataclass

import numpy as np

from ..errors import InputError

__all__ = [
    "energy_distance",
    "strobe_block_length",
    "FloorScheme",
    "floor_scheme",
    "energy_resamples",
]


def energy_distance(a, b):
    """The energy distance ``2 E|A - B| - E|A - A'| - E|B - B'|`` (V-statistics) between
    two point sets in the plane (rows)."""
    from scipy.spatial.distance import cdist

    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(2 * cdist(a, b).mean() - cdist(a, a).mean() - cdist(b, b).mean())


def strobe_block_length(points, *, max_lag=None, run=5, min_block=4, max_block=None):
    """Block length (in forcing periods) for resampling a sequence of strobe points
    without breaking its serial correlation: ``(block, lag)``.

    ``lag`` is the decorrelation lag: the first lag after which the autocorrelations of
    the standardised features ``x, x', x^2, x'^2, x x'`` all stay inside
    ``+-2 sqrt(log10(n) / n)`` for ``run`` consecutive lags (Politis and White's rule,
    2004, for the flat-top lag window); ``block = clip(2 lag, min_block, max_block)``
    (``max_block`` default ``n // 8``: at least 8 blocks, 4 per half).
    """
    s = np.asarray(points, float)
    n = len(s)
    sd = s.std(axis=0)
    sd[sd == 0] = 1.0
    z = (s - s.mean(axis=0)) / sd
    feats = np.column_stack([z, z**2, z[:, :1] * z[:, 1:2]])
    feats = feats - feats.mean(axis=0)
    var = (feats**2).mean(axis=0)
    feats = feats[:, var > 1e-12 * max(float(var.max()), 1e-300)]
    max_lag = max(1, min(n // 4, 50) if max_lag is None else int(max_lag))
    lag = max_lag
    if feats.shape[1]:
        f = feats / np.sqrt((feats**2).mean(axis=0))
        rho = np.array(
            [np.abs((f[:-k] * f[k:]).sum(axis=0) / n).max() for k in range(1, max_lag + 1)]
        )
        small = rho < 2.0 * np.sqrt(np.log10(max(n, 10)) / n)
        for k in range(max_lag):
            if small[k : k + run].all() and k + run <= max_lag:
                lag = k  # lags k+1 .. k+run are insignificant
                break
    else:  # constant points (a fixed point without noise): no correlation to respect
        lag = 0
    hi = max(1, n // 8 if max_block is None else int(max_block))
    return int(min(max(2 * lag, int(min_block)), hi)), int(lag)


def _block_halves(n, L, rng):
    """Two disjoint halves of ``range(n)`` made of contiguous blocks of ``L`` (a random
    circular offset for the block grid, the blocks shuffled between the halves)."""
    idx = np.roll(np.arange(n), -int(rng.integers(L)))
    nb = n // L
    blocks = idx[: nb * L].reshape(nb, L)
    p = rng.permutation(nb)
    return blocks[p[: nb // 2]].ravel(), blocks[p[nb // 2 :]].ravel()


def _block_sample(N, size, L, rng):
    """``size`` indices into a sequence of ``N`` made of contiguous blocks of ``L``."""
    L = max(1, min(L, N))
    nb = -(-size // L)
    starts = rng.choice(N - L + 1, nb, replace=nb > N - L + 1)
    return (starts[:, None] + np.arange(L)).ravel()[:size]


@dataclass(frozen=True)
class FloorScheme:
    """How the record's strobe points are halved for the noise floor.

    Attributes
    ----------
    method : str
        ``"blocks"`` (halves made of contiguous blocks) or ``"halves"`` (random points).
    block : int
        Block length in strobe points (forcing periods); 1 for ``"halves"``.
    lag : int or None
        The record's decorrelation lag (:func:`strobe_block_length`), None unless
        estimated.
    """

    method: str
    block: int
    lag: object = None


def floor_scheme(rs, floor, block_periods):
    """The :class:`FloorScheme` of the record's strobe points ``rs`` for ``floor``
    (``"blocks"`` or ``"halves"``) and ``block_periods`` (None: estimated from ``rs``)."""
    n = len(rs)
    if floor == "halves":
        return FloorScheme(floor, 1, None)
    if block_periods is None:
        return FloorScheme(floor, *strobe_block_length(rs))
    L = int(block_periods)
    if L > n // 4:
        raise InputError(
            f"block_periods must be 1 .. {n // 4} (a quarter of the record's "
            f"{n} strobe points), got {block_periods}"
        )
    return FloorScheme(floor, L, None)


def energy_resamples(rs, ms, scheme, resamples, seed):
    """Energy distances of the record's half against its other half (the floor) and
    against the model's strobe points ``ms`` (the test), one pair per resample, the halves
    drawn by ``scheme`` (a :class:`FloorScheme`): ``(floor, test)`` arrays."""
    floor, L = scheme.method, scheme.block
    n = len(rs)
    scale = rs.std(axis=0)
    scale[scale == 0] = 1.0
    R, M = rs / scale, ms / scale
    rng = np.random.default_rng(seed)
    h = n // 2
    floor_s, test = np.empty(int(resamples)), np.empty(int(resamples))
    for k in range(int(resamples)):
        if floor == "halves":
            perm = rng.permutation(n)
            r1, r2 = R[perm[:h]], R[perm[h:]]
            m = M[rng.choice(len(M), n - h, replace=False)]
        else:
            i1, i2 = _block_halves(n, L, rng)
            r1, r2 = R[i1], R[i2]
            m = M[_block_sample(len(M), len(i2), L, rng)]
        floor_s[k] = energy_distance(r1, r2)
        test[k] = energy_distance(r1, m)
    return floor_s, test
