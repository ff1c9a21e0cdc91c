"""The bootstrap's replicates of the machine's fit (:func:`~.estimate._fit`), all at once.

A replicate takes each window ``c`` times (its cycles are drawn with replacement); its least
squares is that of the windows taken once, each row weighted by ``sqrt(c)`` (``c = 0``: the
row drops out).  So the blocks are built once and every replicate carries its rows' weights.
Each replicate's rows ``[X | y]`` of a block are then replaced by the ``R`` of their QR
(``P + 1`` rows, one stacked QR for all replicates): an orthogonal map of the rows, it keeps
every least squares and inner product of the block's columns, so the alternation's solves
and scale steps run on these few rows.  Each solve is a stacked QR too, its columns scaled
to unit norm as :func:`~.estimate._solve` scales them, the right-hand side and the held
columns carried as extra columns of the factored matrix (their part of ``R`` is ``Q^T`` of
them): the momentum balance is factored once, and each round is a triangular solve.

A replicate whose solve is near singular (:data:`RCOND`), or whose scale is not finite or
is zero at a round's start, is marked: the caller fits it alone (:func:`~.estimate._fit`),
which keeps its meaning whatever ``lstsq`` makes of it.
"""

import numpy as np

#: a solve whose scaled columns' smallest singular value is below this share of their
#: largest is left to the replicate's own fit (numpy's ``lstsq`` cuts at about 1e-13)
RCOND = 1e-10


def _compressed(Xy, counts):
    """Each replicate's rows ``sqrt(counts) [X | y]`` (``Xy``: ``(m, P + 1)``, ``counts``:
    ``(B, m)``) as the ``R`` of their QR, zero rows added to ``P + 1``: ``(X, y)``,
    ``(B, P + 1, P)`` and ``(B, P + 1)``."""
    k = Xy.shape[1]
    T = np.linalg.qr(np.sqrt(counts)[:, :, None] * Xy, mode="r")
    if T.shape[1] < k:
        T = np.concatenate([T, np.zeros((T.shape[0], k - T.shape[1], k))], axis=1)
    return T[:, :, :-1], T[:, :, -1]


def _factored(A, extra):
    """The QR of each replicate's ``A`` (``(B, m, n)``, ``m >= n``, its columns scaled to
    unit norm) and ``Q^T extra`` (``(B, m, k)``): ``(R, z, scale, ok)``; ``ok`` is false
    where ``A`` is near singular (:data:`RCOND`) or not finite, and ``R`` there is the
    identity."""
    B, _, n = A.shape
    eye = np.broadcast_to(np.eye(n), (B, n, n))
    scale = np.sqrt(np.einsum("bij,bij->bj", A, A))
    scale[scale == 0] = 1.0
    full = np.linalg.qr(np.concatenate([A / scale[:, None, :], extra], axis=2), mode="r")
    R, z = full[:, :n, :n], full[:, :n, n:]
    ok = np.isfinite(full[:, :n]).all(axis=(1, 2))
    R = np.where(ok[:, None, None], R, eye)
    if n:
        s = np.linalg.svd(R, compute_uv=False)
        ok &= s[:, -1] > RCOND * s[:, 0]
        R = np.where(ok[:, None, None], R, eye)
    return R, z, scale, ok


def _back(factored, free, fixed):
    """Each replicate's solution from its :func:`_factored` ``A`` (the ``free`` columns)
    with the extra columns ``y`` then the held ones: the held at ``fixed`` (``(B, P)``)."""
    R, z, scale, _ = factored
    rhs = z[:, :, 0] - np.einsum("bnk,bk->bn", z[:, :, 1:], fixed[:, ~free])
    theta = np.array(fixed, dtype=float)
    theta[:, free] = np.linalg.solve(R, rhs[:, :, None])[:, :, 0] / scale
    return theta


def _factor(X, y, free):
    """:func:`_factored` of the least squares of ``y`` on the ``free`` columns of ``X``,
    the others to be held (:func:`_back`)."""
    return _factored(X[:, :, free], np.concatenate([y[:, :, None], X[:, :, ~free]], axis=2))


def _scale_step(part, lag_column, rest, scale):
    """:func:`~.estimate._scale_step` of each replicate: ``(scale, tau, ok)``."""
    if lag_column is None:
        den = np.einsum("bm,bm->b", part, part)
        num = np.einsum("bm,bm->b", part, rest)
        return np.where(den > 0, num / np.where(den > 0, den, 1.0), scale), 0.0, True
    factored = _factored(np.stack([part, lag_column], axis=2), rest[:, :, None])
    sol = _back(factored, np.ones(2, bool), np.zeros((part.shape[0], 2)))
    return sol[:, 0], sol[:, 1], factored[3]


def _ratio_free(free, lag):
    """The columns the momentum balance fits: the free ones but ``m1`` (the ratios' 1) and
    ``tau`` (the balance holds no force)."""
    out = free.copy()
    out[0] = False
    if lag:
        out[-1] = False
    return out


def fits(blocks, counts, held, weights, *, rounds, lag=False):
    """Every replicate's :func:`~.estimate._fit` with the full fit's ``weights``.

    Parameters
    ----------
    blocks : tuple
        The frame's, the moulding's and the balance's ``(X, y)`` on every window
        (:func:`~.estimate._blocks` with ``pick=None``; with ``lag``, with its column, see
        :func:`~.estimate._with_lag_column`).
    counts : tuple of ndarray
        How often each replicate takes each row: ``(force, balance)``, ``(B, rows)``
        each, ``force`` the rows of the frame's block (the moulding's are the same windows).
    held : ndarray
        The held values, NaN where free (with ``lag``, ``tau`` last, free).
    weights : sequence of float
        The frame's and the moulding's weights.
    rounds : int
        The rounds of the alternation (:data:`~.estimate.ROUNDS`).
    lag : bool
        Whether the last column is a force sensor's time constant.

    Returns
    -------
    theta : ndarray
        ``(B, P)``, ``tau`` last with ``lag``.
    ok : ndarray of bool
        False where the replicate is left to :func:`~.estimate._fit` (:data:`RCOND`, a
        scale not finite or zero).
    """
    (Xf, yf), (Xm, ym), (Xb, yb) = blocks
    force = np.vstack(
        [weights[0] * np.column_stack([Xf, yf]), weights[1] * np.column_stack([Xm, ym])]
    )
    X, y = _compressed(force, np.hstack([counts[0], counts[0]]))
    free = np.isnan(held)
    fixed = np.broadcast_to(np.where(free, 0.0, held), (X.shape[0], held.size))
    first = _factor(X, y, free)
    theta, ok = _back(first, free, fixed), first[3].copy()
    balance = _factor(*_compressed(np.column_stack([Xb, yb]), counts[1]), _ratio_free(free, lag))
    ok &= balance[3]
    return _rounds(theta, ok, (X, y, balance), held, (rounds, lag))


def _rounds(theta, ok, system, held, how):
    """The rounds of :func:`~.estimate._fit`'s alternation from the first ``theta``, on
    the weighted force equations ``X, y`` and the factored ``balance`` (``system``);
    ``how``: ``(rounds, lag)``.  Returns ``(theta, ok)``."""
    rounds, lag = how
    X, y, balance = system
    free = np.isnan(held)
    ratio_free = _ratio_free(free, lag)
    scaled = free.copy()
    if lag:
        scaled[-1] = False  # tau is no ratio to m1
    rest = y - X[:, :, ~free] @ held[~free]
    tau = theta[:, -1] if lag else 0.0
    for _ in range(rounds):
        scale = theta[:, 0]
        ok &= np.isfinite(scale) & (scale != 0)
        scale = np.where(ok, scale, 1.0)
        ratios = np.where(free, 0.0, held / scale[:, None])
        ratios[:, 0] = 1.0
        if lag:
            ratios[:, -1] = 0.0
        rho = _back(balance, ratio_free, ratios)
        if free[0]:
            part = np.einsum("bmp,bp->bm", X[:, :, scaled], rho[:, scaled])
            scale, tau, step_ok = _scale_step(part, X[:, :, -1] if lag else None, rest, scale)
            ok &= step_ok
        theta = np.where(free, scale[:, None] * rho, held)
        if lag:
            theta[:, -1] = tau
    return theta, ok
