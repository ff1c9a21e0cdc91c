"""The noise level of a sampled signal (:func:`estimate_noise`)."""

import math

import numpy as np

__all__ = ["estimate_noise"]


def estimate_noise(x, order=1):
    """Robust noise standard deviation of a sampled signal (MAD of differences).

    Differences of order ``k`` cancel a smooth trend (a polynomial of degree < k)
    while white noise of variance ``s^2`` gives them variance ``C(2k, k) s^2``; the
    median absolute deviation makes the estimate robust to the few differences that
    straddle a jump.  Order 1 suits mostly-flat signals (a force record), order 3
    smooth ones (positions).
    """
    d = np.diff(np.asarray(x, dtype=float), n=order)
    if d.size < 2:
        return 0.0
    return float(
        1.4826 * np.median(np.abs(d - np.median(d))) / np.sqrt(math.comb(2 * order, order))
    )
