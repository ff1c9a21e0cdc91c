"""Sorted times against intervals: which times a set of widened, cyclic intervals holds."""

import numpy as np

__all__ = ["in_widened_intervals"]


def in_widened_intervals(t, iv, pad, length):
    """Whether each of the sorted times ``t`` lies in one of the intervals ``iv`` (rows
    ``(a, b)``) widened by ``pad`` on each side, the intervals repeated at ``-length`` and
    ``+length`` (a cyclic signal): ``a - pad + s <= t <= b + pad + s`` for a shift ``s`` in
    ``(-length, 0, length)``, by two binary searches an interval instead of a pass over
    ``t`` each."""
    t = np.asarray(t, dtype=float)
    iv = np.asarray(iv, dtype=float).reshape(-1, 2)
    shifts = np.array([-length, 0.0, length])
    lo = ((iv[:, :1] - pad) + shifts).ravel()  # the same arithmetic as the inequalities
    hi = ((iv[:, 1:] + pad) + shifts).ravel()
    start = np.searchsorted(t, lo, "left")
    end = np.searchsorted(t, hi, "right")
    keep = start < end
    n = t.size + 1
    marks = np.bincount(start[keep], minlength=n) - np.bincount(end[keep], minlength=n)
    return np.cumsum(marks[:-1]) > 0
