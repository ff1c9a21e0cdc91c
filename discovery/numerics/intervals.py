"""Sorted times against intervals: which times a set of widened, cyclic intervals holds."""

import numpy as np

__all__ = ["in_widened_intervals"]


def in_widened_intervals(t, iv, pad, length):
    """Whether each of the sorted times ``t`` lies in one of the intervals ``iv`` (rows
    ``(a, b)``) widened by ``pad`` on each side, the intervals repeated at ``-length`` and
    ``+length`` (a cyclic signal): ``a - pad + s <= t <= b + pad + s`` for a shift ``s`` in
    ``(-length, 0, length)``, by two binary searches an interval instead of a pass over
    ``t`` each."""
    from .sampled import in_widened  # (numba: not at import, the --help path reads this)

    t = np.ascontiguousarray(t, dtype=float)
    iv = np.ascontiguousarray(np.reshape(iv, (-1, 2)), dtype=float)
    return in_widened(t, iv, float(pad), float(length))
