"""The machine's state from a record: a least-squares fit of the exact free-flight motion.

Between contacts the two bodies do not interact, and their motion is known in closed form
whatever the contact law is:

* the moulding falls freely, ``w2(t) = w2a + v2a s - g s^2 / 2`` with ``s = t - t_a``;
* the frame is a linear oscillator driven by ``A sin(w t)`` (supports without a cubic
  term), ``x(t) = x_p(t) + Phi(s) (x_a - x_p(t_a))`` with ``x = (w1, v1)``, ``x_p`` its
  periodic particular solution and ``Phi(s) = exp(M s)`` its transition matrix.

Fitted to every free-flight sample around ``t_a`` (positions and, when recorded,
velocities, each weighted by its own noise level), the state at ``t_a`` is known far
better than from a local polynomial: the penetration ``zeta = w1 - w2``, a small
difference of two large noisy motions, is then predicted at the next impact to a small
fraction of a sample's motion.  The fit's covariance goes with it, so the noise floor can
include the state's own uncertainty.  Supports with a cubic term (``k3 > 0``) fall back to
a local quadratic for the frame.
"""

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..data.noise import estimate_noise

__all__ = ["StateEstimate", "free_flight_runs", "free_flight_state"]


@dataclass(frozen=True)
class StateEstimate:
    """A measured state and how well it is known.

    Attributes
    ----------
    y : ndarray of shape (4,)
        ``w1 [m], v1 [m/s], w2 [m], v2 [m/s]`` at ``t``.
    cov : ndarray of shape (4, 4)
        Covariance of ``y`` from the fit (noise levels estimated from the record).
    t : float
        Drive-clock time [s].
    n_samples : int
        Free-flight samples fitted.
    method : str
        ``"free-flight fit"`` or ``"local quadratic"``.
    """

    y: np.ndarray
    cov: np.ndarray
    t: float
    n_samples: int
    method: str

    @cached_property
    def factor(self):
        """``L`` with ``L L^T = cov`` (the square roots of the variances where the
        covariance is not positive definite)."""
        try:
            return np.linalg.cholesky(self.cov + 1e-30 * np.eye(4))
        except np.linalg.LinAlgError:
            return np.diag(np.sqrt(np.clip(np.diag(self.cov), 0.0, None)))

    def draw(self, rng):
        """A state drawn from the fit's distribution (four standard normals from ``rng``)."""
        return self.y + self.factor @ rng.standard_normal(4)


def free_flight_runs(t, F, zeta, period, *, min_fraction=0.08):
    """Index ranges ``[a, b)`` of the record's free flights: ``zeta`` clearly negative (by
    five times its noise) and no force above the contact threshold, lasting at least
    ``min_fraction`` of a period."""
    sz = estimate_noise(zeta, order=3)
    sf = estimate_noise(F)
    thr = max(5.0 * sf, 1e-3 * float(np.max(F)))
    free = (zeta < -5.0 * sz) & (F <= thr)
    dt = float(np.median(np.diff(t)))
    need = max(8, int(min_fraction * period / dt))
    edges = np.flatnonzero(np.diff(np.concatenate([[0], free.astype(np.int8), [0]])))
    runs = [(int(a), int(b)) for a, b in zip(edges[::2], edges[1::2], strict=True)]
    # a flight is shortened by a few samples at each end: the contact force decays and the
    # bodies separate over a sample or two
    trim = 2
    return [(a + trim, b - trim) for a, b in runs if b - a - 2 * trim >= need]


def _frame_particular(scenario):
    """Periodic particular solution of the frame's free motion: ``w_s + P sin + Q cos``."""
    m1, c1, k1, A, g = scenario.m1, scenario.c1, scenario.k1, scenario.A, scenario.g
    w = 2.0 * np.pi * scenario.frequency
    a, b = k1 - m1 * w * w, c1 * w
    # m1 w'' + c1 w' + k1 w = -A sin(w t) - m1 g
    P, Q = np.linalg.solve(np.array([[a, -b], [b, a]]), np.array([-A, 0.0]))
    return -m1 * g / k1, P, Q, w


def _frame_basis(scenario, s):
    """``Phi(s)`` of ``(w1, v1)`` for every ``s``: ndarray of shape (n, 2, 2)."""
    m1, c1, k1 = scenario.m1, scenario.c1, scenario.k1
    M = np.array([[0.0, 1.0], [-k1 / m1, -c1 / m1]])
    lam, V = np.linalg.eig(M)
    Vi = np.linalg.inv(V)
    E = np.exp(np.outer(s, lam))  # (n, 2)
    return np.real(np.einsum("ij,nj,jk->nik", V, E, Vi))


def _wls(A, y, sigma):
    """Weighted least squares: solution and covariance (``sigma`` per row)."""
    Aw, yw = A / sigma[:, None], y / sigma
    x, *_ = np.linalg.lstsq(Aw, yw, rcond=None)
    cov = np.linalg.pinv(Aw.T @ Aw)
    return x, cov


def free_flight_state(measurement, scenario, run, t_a, *, time_offset=0.0):
    """The state at drive-clock time ``t_a`` from the free flight ``run`` (sample range).

    Parameters
    ----------
    measurement : Measurement
        With ``w1, w2`` (``v1, v2`` used when recorded).
    scenario : Scenario
    run : (int, int)
        Sample range ``[a, b)`` of one free flight (:func:`free_flight_runs`).
    t_a : float
        Drive-clock time [s] of the state, inside the flight.
    time_offset : float
        Drive-clock time of the record's ``t = 0``.

    Returns
    -------
    StateEstimate
    """
    ch = measurement.channels
    a, b = run
    td = measurement.t[a:b] + time_offset
    s = td - t_a
    y = np.zeros(4)
    cov = np.zeros((4, 4))
    noise = {
        k: max(estimate_noise(ch[k], order=3), 1e-300) for k in ch if k in ("w1", "v1", "w2", "v2")
    }
    # the moulding: a parabola of known curvature
    rows, obs, sig = (
        [np.stack([np.ones_like(s), s], 1)],
        [ch["w2"][a:b] + 0.5 * scenario.g * s * s],
        [np.full(s.size, noise["w2"])],
    )
    if "v2" in ch:
        rows.append(np.stack([np.zeros_like(s), np.ones_like(s)], 1))
        obs.append(ch["v2"][a:b] + scenario.g * s)
        sig.append(np.full(s.size, noise["v2"]))
    x2, c2 = _wls(np.concatenate(rows), np.concatenate(obs), np.concatenate(sig))
    y[2:], cov[2:, 2:] = x2, c2
    method = "free-flight fit"
    if getattr(scenario, "k3", 0.0) == 0.0:
        ws, P, Q, w = _frame_particular(scenario)

        def xp(tt):
            return np.stack(
                [
                    ws + P * np.sin(w * tt) + Q * np.cos(w * tt),
                    w * (P * np.cos(w * tt) - Q * np.sin(w * tt)),
                ]
            )

        Phi = _frame_basis(scenario, s)
        xp_t = xp(td)
        rows, obs, sig = [Phi[:, 0, :]], [ch["w1"][a:b] - xp_t[0]], [np.full(s.size, noise["w1"])]
        if "v1" in ch:
            rows.append(Phi[:, 1, :])
            obs.append(ch["v1"][a:b] - xp_t[1])
            sig.append(np.full(s.size, noise["v1"]))
        u, cu = _wls(np.concatenate(rows), np.concatenate(obs), np.concatenate(sig))
        y[:2] = u + xp(np.array([t_a]))[:, 0]
        cov[:2, :2] = cu
    else:
        # cubic supports: a local quadratic over the flight (no closed form)
        sel = np.abs(s) <= 0.02 / scenario.frequency
        sel = sel if sel.sum() >= 5 else np.ones_like(s, dtype=bool)
        A = np.stack([np.ones(sel.sum()), s[sel], s[sel] ** 2], 1)
        cw, ccw = _wls(A, ch["w1"][a:b][sel], np.full(sel.sum(), noise["w1"]))
        y[0], y[1] = cw[0], cw[1]
        cov[:2, :2] = ccw[:2, :2]
        if "v1" in ch:
            cv, ccv = _wls(A, ch["v1"][a:b][sel], np.full(sel.sum(), noise["v1"]))
            y[1], cov[1, 1] = cv[0], ccv[0, 0]
        method = "free-flight fit (moulding), local quadratic (frame: cubic supports)"
    return StateEstimate(y=y, cov=cov, t=float(t_a), n_samples=int(b - a), method=method)
