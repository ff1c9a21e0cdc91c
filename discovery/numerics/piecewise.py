"""Values of a periodic piecewise-linear signal at query times, compiled.

The signal is given by its knots ``t`` (sorted, from 0 to the period ``W``; a repeated time
is a jump) and values ``F``; a query ``tq`` is taken modulo ``W``, and at a jump the
``side`` limit is returned.  One binary search per query: the criteria evaluate both
impulses of every comparison this way, thousands of times in a fit.
"""

import numpy as np
from numba import njit, types

from ._compiled_types import readonly

# compiled once, for read-only C arrays (:func:`._compiled_types.readonly`)
_F1 = readonly(types.float64)
_B1 = readonly(types.boolean)

__all__ = ["periodic_values"]


@njit(types.void(_F1, _F1, types.float64, _F1, _B1, types.float64[::1]), cache=True)
def _values(t, F, W, tq, lefts, out):
    """``out[k]``: the signal at ``tq[k]``, the left limit where ``lefts[k]`` (one flag for
    every query, or one for all)."""
    last = t.shape[0] - 2
    one = lefts.shape[0] == 1
    n = t.shape[0]
    q_prev, lo_prev = np.inf, 0
    for k in range(tq.shape[0]):
        left = lefts[0] if one else lefts[k]
        x = tq[k]
        q = np.mod(x, W)
        if left and q == 0.0 and x > 0.0:
            q = W
        # i: the last knot with t[i] <= q (right) or t[i] < q (left), within [0, last]:
        # lo, the first knot not before q, by halving [lo, hi); sorted queries (the
        # criteria's common grid) start from the last answer (back over knots equal to
        # it, a jump's, when the side changes) and double their steps forward first
        lo, hi = 0, n
        if q >= q_prev:
            lo = lo_prev
            while lo > 0 and not (t[lo - 1] < q or (not left and t[lo - 1] == q)):
                lo -= 1
            hi, step = lo, 1
            while hi < n and (t[hi] < q or (not left and t[hi] == q)):
                lo = hi + 1
                hi = lo + step
                step *= 2
            hi = min(hi, n)
        while lo < hi:
            mid = (lo + hi) // 2
            if t[mid] < q or (not left and t[mid] == q):
                lo = mid + 1
            else:
                hi = mid
        q_prev, lo_prev = q, lo
        i = min(max(lo - 1, 0), last)
        t0, t1 = t[i], t[i + 1]
        if t1 > t0:
            w = min(max((q - t0) / (t1 - t0), 0.0), 1.0)
        else:
            w = 1.0 if left else 0.0
        out[k] = F[i] + w * (F[i + 1] - F[i])


def periodic_values(t, F, W, tq, side="right"):
    """The signal at ``tq`` (any shape; a scalar gives a scalar), ``side`` the limit taken
    where it jumps: ``"right"`` or ``"left"`` for every query, or a boolean array of
    ``tq``'s shape, true where the left limit is wanted."""
    q = np.asarray(tq, dtype=float)
    out = np.empty(q.size)
    t, F = np.ascontiguousarray(t, dtype=float), np.ascontiguousarray(F, dtype=float)
    if isinstance(side, str):
        lefts = np.array([side == "left"])
    else:
        lefts = np.ascontiguousarray(side, dtype=np.bool_).ravel()
        if lefts.size != q.size:
            raise ValueError("one side flag per query time is needed")
    _values(t, F, float(W), np.ascontiguousarray(q).ravel(), lefts, out)
    return out.reshape(q.shape) if q.ndim else out[0]
