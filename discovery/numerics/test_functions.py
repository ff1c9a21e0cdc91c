"""Compact test functions of the weak form, shared by both systems' weak-form fits.

``phi(s) = (1 - s^2)^order`` on ``s in [-1, 1]`` vanishes with its first ``order - 1``
derivatives at both ends, so ``int phi x'' dt = int phi'' x dt = -int phi' x' dt`` over a
window moves every derivative of the data onto the test function: no record is
differentiated.
"""

import numpy as np

__all__ = ["test_function", "window_weights"]


def test_function(hs, order):
    """The test function ``phi = (1 - s^2)^order`` on ``2 hs + 1`` samples of ``s`` in
    ``[-1, 1]``, and its first and second derivatives in ``s``: ``(phi, dphi, ddphi)``."""
    s = np.linspace(-1.0, 1.0, 2 * hs + 1)
    q = 1.0 - s * s
    phi = q**order
    dphi = -2.0 * order * s * q ** (order - 1)
    ddphi = -2.0 * order * q ** (order - 1) + 4.0 * order * (order - 1) * s * s * q ** (order - 2)
    return phi, dphi, ddphi


def window_weights(hs, order, dt):
    """Quadrature weights of one window of ``2 hs + 1`` samples spaced ``dt`` [s]: the
    trapezoidal weights times ``phi``, ``d phi / dt`` and ``d^2 phi / dt^2`` (ndarrays of
    shape (2 hs + 1,)), so that ``x[window] @ w_phi`` is ``int phi x dt``."""
    phi, dphi, ddphi = test_function(hs, order)
    H = hs * dt
    w = np.full(phi.size, dt)
    w[0] = w[-1] = dt / 2
    return w * phi, w * dphi / H, w * ddphi / H**2
