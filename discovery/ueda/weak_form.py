"""The weak form of ``x'' = sum_j c_j x^i x'^j + c_u B cos(nu t)`` and its sparse
regression (STLSQ).

For smooth test functions ``phi_k`` (``(1 - s^2)^order`` on windows of ``2 half_width + 1``
samples), ``int phi_k x'' dt = int phi_k'' x dt`` needs no second derivative of the data,
and every term linear in ``x'`` is integrated by parts (``int phi x^i x' dt = -int phi'
x^(i+1) / (i+1) dt``), so only the terms in ``x'^2, x x'^2, x'^3`` use an estimated
velocity.  Differentiating the record twice instead (Savitzky-Golay) biases the duffing
coefficients by 10-30 % and misses its damping even without noise (the filter smooths over
the fast internal oscillation); the weak form is exact to quadrature.
"""

import numpy as np

from ..errors import InputError
from ..numerics.test_functions import test_function
from .polynomial import MONOMIALS

__all__ = ["window_half_width", "weak_system", "stlsq_gram", "stlsq"]


def weak_system(t, x, v, B, nu, *, half_width, order=4, stride=None):
    """The weak-form regression ``G c = b`` (rows: test windows).

    ``b_k = int phi_k'' x dt``; column ``j`` is ``int phi_k theta_j dt`` (terms linear in
    ``x'`` by parts: no velocity; ``v`` enters only the terms in ``x'^2, x x'^2, x'^3``);
    the last column is ``int phi_k B cos(nu t) dt``.  Trapezoidal quadrature (exact to
    high order: ``phi`` vanishes with its derivatives at the window's ends).

    Parameters
    ----------
    t, x, v : ndarray of shape (n_samples,)
        The record: uniform times, position and (estimated) velocity.
    B, nu : float
        The forcing's amplitude and angular frequency.
    half_width : int
        The test windows' half width in samples (:func:`window_half_width`).
    order : int
        The test functions' order (``(1 - s^2)^order``).
    stride : int, optional
        Samples between window centres (default ``max(1, half_width // 2)``).

    Returns
    -------
    G : ndarray of shape (n_windows, n_terms + 1)
    b : ndarray of shape (n_windows,)
    centres : ndarray of shape (n_windows,)
        The windows' centre times.
    """
    hs = int(half_width)
    dt = float(t[1] - t[0])
    H = hs * dt
    phi, dphi, ddphi = test_function(hs, order)
    dphi, ddphi = dphi / H, ddphi / H**2
    w = np.full(phi.size, dt)
    w[0] = w[-1] = dt / 2
    stride = max(1, hs // 2) if stride is None else int(stride)
    centres = np.arange(hs, t.size - hs, stride)
    idx = centres[:, None] + np.arange(-hs, hs + 1)[None, :]
    X, V = x[idx], v[idx]
    u = B * np.cos(nu * t[idx])
    cols = []
    for i, j in MONOMIALS:
        if j == 0:
            cols.append((X**i) @ (w * phi))
        elif j == 1:
            cols.append(-(X ** (i + 1)) @ (w * dphi) / (i + 1))
        else:
            cols.append((X**i * V**j) @ (w * phi))
    cols.append(u @ (w * phi))
    return np.column_stack(cols), X @ (w * ddphi), t[centres]


def window_half_width(n_samples, samples_per_period, half_width=None):
    """The test windows' half width in samples: ``half_width``, by default a quarter
    forcing period and at least 7 (with 5, 11 samples per window, the quadrature of
    ``phi''`` biases the forcing's coefficient by -0.8 % at 20 samples per period).  A
    window must fit four times into the record's ``n_samples``."""
    hs = max(7, int(round(samples_per_period / 4))) if half_width is None else int(half_width)
    if 2 * hs + 1 > n_samples // 4:
        raise InputError(
            f"the record ({n_samples} samples) is too short for test windows of "
            f"{2 * hs + 1} samples; record more periods"
        )
    return hs


def stlsq_gram(A, c, n, *, threshold, keep, max_iter=25):
    """STLSQ from the normal equations ``A = G^T G``, ``c = G^T b`` of ``n`` rows
    (columns scaled to unit RMS, ``b`` too).

    Parameters
    ----------
    A : ndarray of shape (n_terms, n_terms)
    c : ndarray of shape (n_terms,)
    n : int
        Rows of ``G``.
    threshold : float
        Scaled coefficients below it are dropped.
    keep : ndarray of bool, shape (n_terms,)
        Columns never dropped.
    max_iter : int
        Thresholding rounds at most.

    Returns
    -------
    coefficients : ndarray of shape (n_terms,)
        In the units of ``A`` and ``c``.
    support : ndarray of bool, shape (n_terms,)
    """
    s = np.sqrt(np.maximum(np.diag(A), 0.0) / n)
    s[s == 0] = 1.0
    An = A / np.outer(s, s)
    cn = c / s
    sup = np.ones(A.shape[0], bool)
    for _ in range(max_iter):
        x = np.zeros(A.shape[0])
        x[sup] = np.linalg.lstsq(An[np.ix_(sup, sup)], cn[sup], rcond=None)[0]
        new = sup & ((np.abs(x) >= threshold) | keep)
        if np.array_equal(new, sup):
            break
        sup = new
    x = np.zeros(A.shape[0])
    if sup.any():
        x[sup] = np.linalg.lstsq(An[np.ix_(sup, sup)], cn[sup], rcond=None)[0]
    return x / s, sup


def stlsq(G, b, threshold, keep=None, max_iter=25):
    """Sequentially thresholded least squares on columns scaled to unit RMS (and ``b``
    too): terms whose scaled coefficient is below ``threshold`` are dropped, the rest
    refitted, until the support stops changing.  ``keep``: columns never dropped.
    Returns ``(coefficients, support)`` in the original units."""
    G, b = np.asarray(G, float), np.asarray(b, float)
    sb = float(np.sqrt(np.mean(b**2))) or 1.0
    keep = np.zeros(G.shape[1], bool) if keep is None else np.asarray(keep, bool)
    x, sup = stlsq_gram(
        G.T @ G, G.T @ (b / sb), G.shape[0], threshold=threshold, keep=keep, max_iter=max_iter
    )
    return x * sb, sup
