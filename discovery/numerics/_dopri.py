"""Shared Dormand–Prince 5(4) building blocks, compiled, for every system's integrator.

The method (stages, solution, error estimate, dense output and step-size control) does
not depend on the system; only the right-hand side does.  Each system's integrator
(:mod:`discovery.vibroimpact.dynamics.kernel` for the two-body vibro-impact machine,
:mod:`discovery.ueda._kernel` for Ueda's oscillators) is a loop that calls these
functions and its own right-hand side::

    D = blocks(n)                                    (n: the state size)
    K[0] = f(t, y)                                   (FSAL: reused from the last step)
    for s in 1..5:  D.stage(s, y, h, K, ytmp);  K[s] = f(t + C[s] h, ytmp)
    D.combine(y, h, K, ynew);                        K[6] = f(t + h, ynew)
    err = D.error_norm(y, ynew, K, h, rtol, atol)
    h  *= step_factor(err)                           (accepted or rejected)
    D.dense(y, K, h, theta, out)                     (output / events inside the step)

Why building blocks and not a factory closing over the right-hand side: numba caches a
module-level function on disk, but a jitted closure over a jitted right-hand side (and
a jitted function taking one as an argument) is compiled again in every new process and
adds a cache entry each time (numba 0.68: ``NUMBA_DEBUG_CACHE`` shows a new ``.nbc`` per
start, about 1 s of compilation each).  The blocks are closures over the state size only
and are inlined by numba (``inline="always"``) into the system's module-level
``@njit(cache=True)`` integrator, which numba caches.  The blocks fix the order of the
floating-point operations: changing it changes every result in its last bits.

Caveat (numba's): a cached integrator is invalidated only when the *content* of its own
source file changes (numba 0.68 stamps sources by a content hash; touching does not
help).  The vibro-impact kernel checks this file and its own modules itself
(:func:`discovery._startup._compile.refresh`); after editing this file, delete the ``__pycache__``
directory of ``discovery/ueda`` so that Ueda's integrators are recompiled with the new
blocks.

``K`` has shape ``(7, n)``.  Coefficients are in :mod:`discovery.numerics._tableau`
(checked against scipy's RK45 tables by the tests).
"""

from typing import NamedTuple

import numpy as np
from numba import njit

from ._tableau import A as _A
from ._tableau import B as _B
from ._tableau import C
from ._tableau import E as _E
from ._tableau import P as _P
from .status import BLOW_UP, OK, STEP_BUDGET, STEP_UNDERFLOW

__all__ = [
    "C",
    "SAFETY",
    "MIN_FACTOR",
    "MAX_FACTOR",
    "Blocks",
    "blocks",
    "dense_weights",
    "step_factor",
    "ORDER",
]

SAFETY, MIN_FACTOR, MAX_FACTOR = 0.9, 0.2, 10.0
ORDER = 5  # the error estimate is of order 4: factors use err^(-1/5)


class Blocks(NamedTuple):
    """The compiled building blocks for one state size (see :func:`blocks`)."""

    n: object
    stage: object
    combine: object
    dense: object
    error_norm: object


@njit(inline="always")
def dense_weights(theta):
    """The weights ``(w0, w2, w3, w4, w5, w6)`` of the stages in Shampine's continuous
    extension at ``t + theta h`` (stage 1's is 0)."""
    t2 = theta * theta
    t3 = t2 * theta
    t4 = t3 * theta
    return (
        _P[0, 0] * theta + _P[0, 1] * t2 + _P[0, 2] * t3 + _P[0, 3] * t4,
        _P[2, 1] * t2 + _P[2, 2] * t3 + _P[2, 3] * t4,
        _P[3, 1] * t2 + _P[3, 2] * t3 + _P[3, 3] * t4,
        _P[4, 1] * t2 + _P[4, 2] * t3 + _P[4, 3] * t4,
        _P[5, 1] * t2 + _P[5, 2] * t3 + _P[5, 3] * t4,
        _P[6, 1] * t2 + _P[6, 2] * t3 + _P[6, 3] * t4,
    )


def _build(n):
    """The building blocks for states of size ``n`` (a compile-time constant: numba
    unrolls the loops over the state; with ``y.shape[0]`` as the bound the vibro-impact
    integrator runs 5-20 % slower)."""
    nf = float(n)

    @njit(inline="always")
    def stage(s, y, h, K, ytmp):
        """Stage state ``ytmp = y + h sum_{i<s} A[s, i] K[i]`` (``1 <= s <= 5``)."""
        for j in range(n):
            acc = 0.0
            for i in range(s):
                acc += _A[s, i] * K[i, j]
            ytmp[j] = y[j] + h * acc

    @njit(inline="always")
    def combine(y, h, K, ynew):
        """Fifth-order solution ``ynew = y + h sum_i B[i] K[i]`` over the six stages."""
        for j in range(n):
            acc = 0.0
            for i in range(6):
                acc += _B[i] * K[i, j]
            ynew[j] = y[j] + h * acc

    @njit(inline="always")
    def dense(y, K, h, theta, out):
        """Shampine's continuous extension at ``t + theta h`` (``0 <= theta <= 1``)."""
        w0, w2, w3, w4, w5, w6 = dense_weights(theta)
        for j in range(n):
            out[j] = y[j] + h * (
                w0 * K[0, j]
                + w2 * K[2, j]
                + w3 * K[3, j]
                + w4 * K[4, j]
                + w5 * K[5, j]
                + w6 * K[6, j]
            )

    @njit(inline="always")
    def error_norm(y, ynew, K, h, rtol, atol):
        """RMS of the embedded error estimate scaled by ``atol[j] + rtol max(|y|, |ynew|)``
        (the norm of scipy's RK45); a step is accepted when it is ``<= 1``."""
        s = 0.0
        for j in range(n):
            e = 0.0
            for i in range(7):
                e += _E[i] * K[i, j]
            sc = atol[j] + rtol * max(abs(y[j]), abs(ynew[j]))
            r = h * e / sc
            s += r * r
        return np.sqrt(s / nf)

    return Blocks(n, stage, combine, dense, error_norm)


_BUILT = {}


def blocks(n):
    """:class:`Blocks` for a state of size ``n`` (built once per size and process).

    Use them from a module-level ``@njit(cache=True)`` integrator: they are inlined
    into it, so the integrator is cached on disk as usual (a closure that is itself the
    cached function is not: see the module docstring)."""
    n = int(n)
    if n not in _BUILT:
        _BUILT[n] = _build(n)
    return _BUILT[n]


@njit(cache=True, inline="always")
def step_factor(err):
    """Factor on the step size after a step with error norm ``err`` (accepted when
    ``err <= 1``: grow by at most ``MAX_FACTOR``; rejected: shrink by at most
    ``MIN_FACTOR``)."""
    if err > 1.0:
        return max(MIN_FACTOR, SAFETY * err**-0.2)
    return min(MAX_FACTOR, max(MIN_FACTOR, SAFETY * max(err, 1e-10) ** -0.2))


def make_smooth_advance(rhs, n, n_out):
    """An adaptive DP5(4) advance for a *smooth* system (no events), for inlining.

    Parameters
    ----------
    rhs : numba function ``rhs(t, y, p, out)``
        The system's right-hand side (``p`` its parameter array), ``@njit``.
    n : int
        State size.
    n_out : int
        Leading state components written to the dense output.

    Returns
    -------
    numba function
        ``advance(t, y, t_end, h, p, ctl, n_steps, work, samples, k_eval)`` -> ``(status,
        t, h, k_eval, n_steps)``: steps from ``t`` to exactly ``t_end`` (the last step is
        cut to land on it; ``y`` is updated in place and ``K[0]`` must hold ``f(t, y)`` on
        entry and holds ``f(t_end, y)`` on return), writing the dense output at
        ``t_eval[k_eval:]`` up to ``t_end`` into ``out_eval[:n_out, k]``.  ``h`` is the
        step size to try first (returned for the next call); ``n_steps`` the steps the run
        took before (returned with this call's added).  The arguments come in bundles, as
        the vibro-impact kernel's: ``ctl`` ``(rtol, atol, hmax, max_steps)``, the step
        control (``max_steps`` the run's budget, ``n_steps`` included); ``work`` ``(K,
        ytmp, ynew)``, the work arrays; ``samples`` ``(t_eval, out_eval)``.  Inline it (it is
        ``inline="always"``) into a module-level ``@njit(cache=True)`` integrator: a
        closure over ``rhs`` inlined there is cached on disk with it, while a closure that
        is itself the compiled entry point is compiled again in every process.
    """
    D = blocks(n)
    stage, combine, dense, error_norm = D.stage, D.combine, D.dense, D.error_norm

    @njit(inline="always")
    def advance(t, y, t_end, h, p, ctl, n_steps, work, samples, k_eval):
        rtol, atol, hmax, max_steps = ctl
        K, ytmp, ynew = work
        t_eval, out_eval = samples
        status = OK
        n_eval = t_eval.shape[0]
        while t < t_end:
            if n_steps >= max_steps:
                status = STEP_BUDGET
                break
            h = min(h, hmax)
            # the step that would end within 1 % of t_end ends on it (stretched or cut),
            # so no sliver of a step is left before t_end
            last = 1.01 * h >= t_end - t
            if last:
                h_try = t_end - t
            else:
                h_try = h
            if h_try < 1e-14 * max(1.0, abs(t)) and not last:
                status = STEP_UNDERFLOW
                break
            for s in range(1, 6):
                stage(s, y, h_try, K, ytmp)
                rhs(t + C[s] * h_try, ytmp, p, K[s])
            combine(y, h_try, K, ynew)
            t_new = t_end if last else t + h_try
            rhs(t_new, ynew, p, K[6])
            n_steps += 1
            err = error_norm(y, ynew, K, h_try, rtol, atol)
            if not np.isfinite(err):
                h = h_try * MIN_FACTOR
                if h < 1e-14 * max(1.0, abs(t)):
                    status = BLOW_UP
                    break
                continue
            if err > 1.0:
                h = h_try * step_factor(err)
                continue
            while k_eval < n_eval and t_eval[k_eval] <= t_new:
                theta = (t_eval[k_eval] - t) / h_try
                dense(y, K, h_try, min(max(theta, 0.0), 1.0), ytmp)
                for j in range(n_out):
                    out_eval[j, k_eval] = ytmp[j]
                k_eval += 1
            for j in range(n):
                y[j] = ynew[j]
                K[0, j] = K[6, j]
            t = t_new
            fac = step_factor(err)
            if last and h_try < h:
                # a step cut to land on t_end says little about the step size: keep it
                # (smaller if even the cut step was near the tolerance)
                if fac < 1.0:
                    h = h * fac
            else:
                h = h_try * fac
        return status, t, h, k_eval, n_steps

    return advance


def make_segments(rhs, n, n_out):
    """The pieces every driver of a smooth system repeats, for inlining (see
    :func:`make_smooth_advance`).

    Returns
    -------
    start : numba function
        ``start(t, y, p)`` -> the work arrays ``W`` (stages, trial states, an empty dense
        output) with ``f(t, y)`` in ``W[0][0]``, as ``advance`` needs on entry.
    advance : numba function
        The advance of :func:`make_smooth_advance` (for a driver with dense output,
        ``W[:3]`` its work arrays).
    to : numba function
        ``to(t, y, t_end, h, p, ctl, n_steps, W)`` -> ``(status, t, h, n_steps)``:
        ``advance`` to ``t_end`` without dense output (``ctl`` and ``n_steps`` as for
        ``advance``).  ``W[0][0]`` must hold ``f(t, y)`` on entry, as for ``advance``.
    """
    advance = make_smooth_advance(rhs, n, n_out)

    @njit(inline="always")
    def start(t, y, p):
        W = np.empty((7, n)), np.empty(n), np.empty(n), np.empty(0), np.empty((n_out, 0))
        rhs(t, y, p, W[0][0])
        return W

    @njit(inline="always")
    def to(t, y, t_end, h, p, ctl, n_steps, W):
        K, ytmp, ynew, empty_t, empty_o = W
        status, t, h, _, n_steps = advance(
            t, y, t_end, h, p, ctl, n_steps, (K, ytmp, ynew), (empty_t, empty_o), 0
        )
        return status, t, h, n_steps

    return start, advance, to
