"""Least-squares fits of Ueda's equation on a fixed support in the weak form, and the
score test of an omitted effect: the statistics of the missing-effect workflow
(:func:`discovery.ueda.explain`).

A fit on the support ``S`` takes the weak-form residual ``r = b - G_S c``.  The score
(Lagrange-multiplier) test of an effect: ``z`` its weak-form column made orthogonal to the
current columns, ``LM = (z^T r)^2 / V``, where ``V`` estimates ``Var(z^T r)`` under "the
effect is absent" from the residual itself (heteroskedasticity- and
autocorrelation-consistent, Newey-West with Bartlett weights over twice the lag at which
the overlapping test windows stop sharing samples: the rows are correlated, so the plain
``n R^2`` would be too large); ``LM ~ chi^2(1)``.  The standard errors of a fit come from
the same sandwich.
"""

from dataclasses import dataclass

import numpy as np
from scipy.stats import chi2

from ..numerics.test_functions import test_function
from .polynomial import FORCING, MONOMIALS, TERMS, ForcedPolynomial
from .weak_form import weak_system

__all__ = ["WeakSettings", "Fit", "WeakFits", "hac"]


@dataclass(frozen=True)
class WeakSettings:
    """The weak form's test windows (``half_width`` samples, ``(1 - s^2)^order``) and
    whether the forcing's coefficient is fitted (else fixed at 1)."""

    half_width: int
    order: int
    fit_forcing: bool


def hac(U, lag):
    """Newey-West estimate of ``Var(sum_i U_i)`` (rows ``U_i``, Bartlett weights)."""
    U = U.reshape(U.shape[0], -1)
    V = U.T @ U
    for k in range(1, min(lag, U.shape[0] - 1) + 1):
        C = U[k:].T @ U[:-k]
        V += (1.0 - k / (lag + 1.0)) * (C + C.T)
    return V


@dataclass(frozen=True)
class Fit:
    """A least-squares fit on the columns ``cols`` of ``G``: coefficients, standard
    errors, the weak-form residual ``r`` and the equation."""

    cols: tuple  # column indices of G (library terms, then the forcing's)
    coef: np.ndarray
    se: np.ndarray
    r: np.ndarray
    model: ForcedPolynomial


class WeakFits:
    """The weak-form system of one record and least-squares fits on given supports.

    ``t, x``: the record; ``smoothed``: its :class:`~discovery.ueda.record.Smoothed`
    (velocity and noise sd); ``B, nu``: the forcing; ``settings``: a
    :class:`WeakSettings`.
    """

    def __init__(self, t, x, smoothed, *, B, nu, settings):
        self.B, self.nu = B, nu
        dt = float(t[1] - t[0])
        self.hs = int(settings.half_width)
        order, fit_forcing = settings.order, settings.fit_forcing
        G, b, self.centres = weak_system(t, x, smoothed.v, B, nu, half_width=self.hs, order=order)
        self.nt = len(MONOMIALS)
        self.fit_forcing = bool(fit_forcing)
        self.b = b if fit_forcing else b - G[:, self.nt]
        self.G = G
        self.stride = max(1, self.hs // 2)
        # rows share samples up to (2 hs) / stride rows apart; twice that for Bartlett
        self.lag = 2 * int(np.ceil(2 * self.hs / self.stride))
        self.b_rms = float(np.sqrt(np.mean(self.b**2))) or 1.0
        # the residual's floor: b's part from white measurement noise of sd noise_sd
        _, _, ddphi = test_function(self.hs, order)
        w = np.full(ddphi.size, dt)
        w[0] = w[-1] = dt / 2
        H = self.hs * dt
        self.noise_rms = float(smoothed.noise_sd * np.linalg.norm(w * ddphi / H**2))

    def fit(self, terms):
        cols = tuple(TERMS.index(n) for n in terms) + ((self.nt,) if self.fit_forcing else ())
        if cols:
            X = self.G[:, cols]
            s = np.sqrt(np.mean(X**2, axis=0))
            s[s == 0] = 1.0
            Xs = X / s
            cs = np.linalg.lstsq(Xs, self.b, rcond=None)[0]
            r = self.b - Xs @ cs
            A = np.linalg.pinv(Xs.T @ Xs)
            cov = A @ hac(Xs * r[:, None], self.lag) @ A
            coef, se = cs / s, np.sqrt(np.maximum(np.diag(cov), 0.0)) / s
        else:
            coef, se, r = np.zeros(0), np.zeros(0), self.b.copy()
        c = np.zeros(self.nt)
        forcing = 1.0
        for j, v in zip(cols, coef, strict=True):
            if j < self.nt:
                c[j] = v
            else:
                forcing = float(v)
        return Fit(cols, coef, se, r, ForcedPolynomial(tuple(c), self.B, self.nu, forcing))

    def score(self, fit, eff):
        """The robust LM test of adding ``eff``'s terms to ``fit``."""
        k = [TERMS.index(n) for n in eff.terms]
        Z = self.G[:, k]
        if fit.cols:
            Q, _ = np.linalg.qr(self.G[:, fit.cols])
            Z = Z - Q @ (Q.T @ Z)
        zz = np.einsum("ij,ij->j", Z, Z)
        if np.any(zz <= 1e-24 * max(float(self.b @ self.b), 1e-300)):
            return {
                "effect": eff.id,
                "terms": list(eff.terms),
                "lm": 0.0,
                "p": 1.0,
                "share": 0.0,
                "direction": dict.fromkeys(eff.terms, 0.0),
                "note": "its columns are absorbed by the current terms",
            }
        s = Z.T @ fit.r
        V = hac(Z * fit.r[:, None], self.lag)
        lm = float(s @ np.linalg.pinv(V) @ s) if np.all(np.diag(V) > 0) else 0.0
        direction = np.linalg.lstsq(Z, fit.r, rcond=None)[0]
        share = float((fit.r @ (Z @ direction)) / max(float(fit.r @ fit.r), 1e-300))
        return {
            "effect": eff.id,
            "terms": list(eff.terms),
            "lm": lm,
            "p": float(chi2.sf(lm, len(k))),
            "share": share,
            "direction": {n: float(d) for n, d in zip(eff.terms, direction, strict=True)},
        }

    def residual_rms(self, fit):
        return float(np.sqrt(np.mean(fit.r**2))) / self.b_rms

    def parameters(self, fit, terms):
        return {
            n: {
                "value": float(fit.coef[fit.cols.index(TERMS.index(n))]),
                "stderr": float(fit.se[fit.cols.index(TERMS.index(n))]),
            }
            for n in terms
        }

    def coefficients(self, fit):
        names = [TERMS[j] if j < self.nt else FORCING for j in fit.cols]
        coef = dict(zip(names, map(float, fit.coef), strict=True))
        se = dict(zip(names, map(float, fit.se), strict=True))
        if not self.fit_forcing:
            coef[FORCING], se[FORCING] = 1.0, 0.0
        return coef, se
