"""Values of a periodic piecewise-linear signal at query times, compiled.

The signal is given by its knots ``t`` (sorted, from 0 to the period ``W``; a repeated time
is a jump) and values ``F``; a query ``tq`` is taken modulo ``W``, and at a jump the
``side`` limit is returned.  One binary search per query: the criteria evaluate both
impulses of every comparison this way, thousands of times in a fit.
"""

import numpy as np
from numba import njit

__all__ = ["periodic_values"]


@njit(cache=True)
def _values(t, F, W, tq, left, out):
    last = t.shape[0] - 2
    for k in range(tq.shape[0]):
        x = tq[k]
        q = np.mod(x, W)
        if left and q == 0.0 and x > 0.0:
            q = W
        # i: the last knot with t[i] <= q (right) or t[i] < q (left), within [0, last]
        lo, hi = 0, t.shape[0]
        while lo < hi:
            mid = (lo + hi) // 2
            if t[mid] < q or (not left and t[mid] == q):
                lo = mid + 1
            else:
                hi = mid
        i = min(max(lo - 1, 0), last)
        t0, t1 = t[i], t[i + 1]
        if t1 > t0:
            w = min(max((q - t0) / (t1 - t0), 0.0), 1.0)
        else:
            w = 1.0 if left else 0.0
        out[k] = F[i] + w * (F[i + 1] - F[i])


def periodic_values(t, F, W, tq, side="right"):
    """The signal at ``tq`` (any shape; a scalar gives a scalar), ``side`` (``"right"`` or
    ``"left"``) the limit taken where it jumps."""
    q = np.asarray(tq, dtype=float)
    out = np.empty(q.size)
    t, F = np.ascontiguousarray(t, dtype=float), np.ascontiguousarray(F, dtype=float)
    _values(t, F, float(W), np.ascontiguousarray(q).ravel(), side == "left", out)
    return out.reshape(q.shape) if q.ndim else out[0]
