"""Loops over sampled signals, compiled: the contact edges' running mean and threshold runs,
the criteria's areas of a piecewise-linear difference and their contact windows, a fold's
bin means.

Each is the same arithmetic, in the same order, as the numpy expression it replaces (so
every result is the same to the last bit: the contact edges decide samples at a threshold,
where a last-bit change once moved a survey record's final refit), made in one compiled
loop instead of ten array operations: on a fit's cycle-by-cycle evaluation these made a
third of each cycle's time (a cycle's run is 30 us), most of it numpy's per-call cost on
arrays of a few hundred samples.  Sums over a whole array stay with numpy (its pairwise
summation), the callers' part.
"""

import numpy as np
from numba import njit, types

from ._compiled_types import readonly

# each loop compiled once, for read-only C arrays (:func:`._compiled_types.readonly`);
# callers pass contiguous arrays of these types
_F1 = readonly(types.float64)
_F2 = readonly(types.float64, 2)
_I1 = readonly(types.int64)

__all__ = ["running_mean", "threshold_runs", "abs_areas", "in_widened", "bin_means"]


@njit(types.float64[::1](_F1, types.int64), cache=True)
def running_mean(x, width):
    """The mean of ``x`` over ``width`` samples centred on each (``width`` odd), the ends
    padded with the end values: the first window summed in order, then the running sum of
    the entering less the leaving sample, divided by ``width`` (numpy's ``cumsum`` of the
    same terms)."""
    n, h = x.shape[0], width // 2
    p = np.empty(n + 2 * h)
    p[:h] = x[0]
    p[h : h + n] = x
    p[h + n :] = x[n - 1]
    acc = p[0]  # (not 0.0 + p[0]: a -0.0 stays one)
    for i in range(1, width):
        acc += p[i]
    out = np.empty(n)
    out[0] = acc / width
    for i in range(1, n):
        acc += p[width + i - 1] - p[i - 1]
        out[i] = acc / width
    return out


@njit(cache=True)
def _above_runs(F, thr, min_len, noise):
    """The runs ``[start, end)`` of samples above ``thr``, a gap closed when shorter than
    ``min_len`` or not going below ``thr - 3 noise`` (with ``noise > 0``), then the runs
    kept that last ``min_len`` samples, or 3 and peak at ``3 thr`` or more: rows of an
    (r, 2) integer array."""
    n = F.shape[0]
    runs = np.empty((n // 2 + 1, 2), dtype=np.int64)
    r = 0
    i = 0
    while i < n:
        if not F[i] > thr:
            i += 1
            continue
        s = i
        while i < n and F[i] > thr:
            i += 1
        if r > 0 and s - runs[r - 1, 1] < min_len:
            runs[r - 1, 1] = i
            continue
        if r > 0 and noise > 0:
            low = F[runs[r - 1, 1]]  # the gap's least value (a NaN, as numpy's min)
            for k in range(runs[r - 1, 1] + 1, s):
                if F[k] < low or F[k] != F[k]:
                    low = F[k]
            if low > thr - 3.0 * noise:
                runs[r - 1, 1] = i
                continue
        runs[r, 0], runs[r, 1] = s, i
        r += 1
    keep = np.empty((r, 2), dtype=np.int64)
    m = 0
    for j in range(r):
        a, b = runs[j, 0], runs[j, 1]
        ok = b - a >= min_len
        if not ok and b - a >= 3:
            top = F[a]
            for k in range(a + 1, b):
                if F[k] > top:
                    top = F[k]
            ok = top >= 3.0 * thr
        if ok:
            keep[m, 0], keep[m, 1] = a, b
            m += 1
    return keep[:m]


@njit(cache=True)
def _clip(x, lo, hi):
    """``min(max(x, lo), hi)`` as Python's builtins take it (a NaN ``x`` stays)."""
    v = lo if lo > x else x
    return hi if hi < v else v


@njit(
    types.float64[:, ::1](_F1, _F1, types.float64, types.int64, types.float64, types.float64),
    cache=True,
)
def threshold_runs(t, F, thr, min_len, max_extrap, noise):
    """Sub-sample ``(onset, loss, first sample)`` rows of the runs where ``F > thr`` (see
    :func:`_above_runs` for the gaps closed and the runs kept), the runs touching either end
    left out; an edge steeper than ``3 noise`` a sample extrapolated along its slope to zero
    force by at most ``max_extrap`` samples (none with ``max_extrap < 0``), else cut at the
    threshold; runs whose extrapolated edges meet are one.  An (r, 3) float array."""
    runs = _above_runs(F, thr, min_len, noise)
    n = F.shape[0]
    extrap = max_extrap >= 0.0
    out = np.empty((runs.shape[0], 3))
    m = 0
    for j in range(runs.shape[0]):
        s, e = runs[j, 0], runs[j, 1]
        if s == 0 or e >= n:
            continue  # incomplete at the record's ends
        f0, f1 = F[s - 1], F[s]
        steep = extrap and f1 - f0 > 3.0 * noise
        lo = -max_extrap if steep else 0.0
        frac = ((0.0 if steep else thr) - f0) / (f1 - f0) if f1 > f0 else 1.0
        t_on = t[s - 1] + _clip(frac, lo, 1.0) * (t[s] - t[s - 1])
        g0, g1 = F[e - 1], F[e]
        steep = extrap and g0 - g1 > 3.0 * noise
        hi = 1.0 + max_extrap if steep else 1.0
        frac = ((0.0 if steep else thr) - g0) / (g1 - g0) if g1 < g0 else 0.0
        t_off = t[e - 1] + _clip(frac, 0.0, hi) * (t[e] - t[e - 1])
        if m > 0 and t_on <= out[m - 1, 1]:  # extrapolated edges met: one contact
            if t_off > out[m - 1, 1]:
                out[m - 1, 1] = t_off
        else:
            out[m, 0], out[m, 1], out[m, 2] = t_on, t_off, s
            m += 1
    return out[:m]


@njit(types.float64[::1](_F1, _F1), cache=True)
def abs_areas(h, d):
    """``h_i`` times the exact integral of ``|d|`` over step ``i`` (``d`` linear between its
    values, ``h`` the steps): the mean of the two ends' magnitudes where they do not change
    sign, else ``(a^2 + b^2) / 2 (|a| + |b|)``; their sum is the integral of ``|d|``."""
    n = h.shape[0]
    out = np.empty(n)
    for i in range(n):
        a, b = d[i], d[i + 1]
        total = abs(a) + abs(b)
        if a * b >= 0:
            out[i] = h[i] * (0.5 * total)
        else:
            out[i] = h[i] * (0.5 * (a * a + b * b) / total)
    return out


@njit(types.boolean[::1](_F1, _F2, types.float64, types.float64), cache=True)
def in_widened(t, iv, pad, length):
    """Whether each of the sorted times ``t`` lies in one of the intervals ``iv`` (rows
    ``(a, b)``) widened by ``pad`` on each side, the intervals repeated at ``-length`` and
    ``+length``: two binary searches an interval and shift, then one pass."""
    n = t.shape[0]
    marks = np.zeros(n + 1, dtype=np.int64)
    for i in range(iv.shape[0]):
        for s in (-length, 0.0, length):
            start = np.searchsorted(t, (iv[i, 0] - pad) + s, side="left")
            end = np.searchsorted(t, (iv[i, 1] + pad) + s, side="right")
            if start < end:
                marks[start] += 1
                marks[end] -= 1
    out = np.empty(n, dtype=np.bool_)
    acc = 0
    for k in range(n):
        acc += marks[k]
        out[k] = acc > 0
    return out


@njit(types.float64[::1](_I1, _F1, _I1), cache=True)
def bin_means(bins, values, counts):
    """The mean of ``values`` in each bin (``bins[i]`` the bin of sample ``i``, ``counts``
    the samples per bin): each bin's sum in sample order, as numpy's weighted ``bincount``
    adds them, divided by its count."""
    k = counts.shape[0]
    sums = np.zeros(k)
    for i in range(bins.shape[0]):
        sums[bins[i]] += values[i]
    out = np.empty(k)
    for j in range(k):
        out[j] = sums[j] / counts[j]
    return out
