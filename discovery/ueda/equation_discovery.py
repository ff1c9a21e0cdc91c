"""Equation discovery for Ueda's forced oscillators from a record with known forcing.

From a noisy, uniformly sampled record ``x(t)`` and the known forcing ``B cos(nu t)``,
:func:`discover` recovers ``x'' = sum_j c_j theta_j(x, x') + c_u B cos(nu t)`` over the
polynomial library ``theta = x^i x'^j`` (``i + j <= 3``, 10 terms) by sequentially
thresholded least squares (STLSQ, on columns scaled to unit RMS) in the weak form
(:mod:`discovery.ueda.weak_form`: test windows of half-width a quarter period by default,
at least 7 samples; only the terms in ``x'^2, x x'^2, x'^3`` use an estimated velocity,
Savitzky-Golay, a quintic over a quarter period).  The forcing is a known input: its
coefficient is fitted and reported (it should be 1) or fixed at 1 (``fit_forcing=False``).
Standard errors come from a bootstrap over blocks of consecutive windows
(``block_periods`` forcing periods each): the overlapping windows make rows correlated, so
the plain least-squares covariance is too small (it is reported too).

The discovered equation is verified by simulation with :func:`verify`
(:mod:`discovery.ueda.verification`).

The names of the modules this workflow is built from stay importable from here:
:mod:`.polynomial` (:class:`ForcedPolynomial`, :data:`TERMS`), :mod:`.record`
(:func:`simulate_record`, :func:`read_record_csv`, :func:`record_strobe_points`,
:func:`classify_record`), :mod:`.weak_form` (:func:`weak_system`, :func:`stlsq`),
:mod:`.strobe_resampling` (:func:`energy_distance`, :func:`strobe_block_length`) and
:mod:`.verification` (:func:`verify`, :class:`Verification`).
"""

import time
from dataclasses import dataclass, field

import numpy as np

from .._api._printing import generic_lines, readable
from .._api._result import Result
from .._api._settings import Settings, option, takes
from .._api._validate import Array, Real, params
from ..errors import InputError
from .polynomial import FORCING, MONOMIALS, TERMS, ForcedPolynomial
from .record import (
    check_forcing,
    classify_record,
    read_record_csv,
    record_strobe_points,
    simulate_record,
    smooth,
)
from .strobe_resampling import energy_distance, strobe_block_length
from .verification import Verification, verify
from .weak_form import stlsq, stlsq_gram, weak_system, window_half_width

__all__ = [
    "TERMS",
    "MONOMIALS",
    "FORCING",
    "ForcedPolynomial",
    "Discovery",
    "Verification",
    "discover",
    "verify",
    "simulate_record",
    "energy_distance",
    "record_strobe_points",
    "classify_record",
    "read_record_csv",
    "weak_system",
    "stlsq",
    "strobe_block_length",
]


@readable
@dataclass(frozen=True, eq=False)
class Discovery(Result):
    """A discovered equation with its uncertainty.

    Attributes
    ----------
    model : ForcedPolynomial
        The equation (simulable).
    terms : tuple of str
        The selected library terms (the forcing is always in the equation).
    coefficients, standard_errors, ols_standard_errors : dict
        ``{term: value}`` for the selected terms and ``FORCING`` (its coefficient, 1
        when fixed, with standard error 0).  ``standard_errors``: block bootstrap;
        ``ols_standard_errors``: least-squares covariance on the selected support
        (optimistic: the windows overlap).
    residual_rms : float
        RMS of the weak-form residual relative to the RMS of ``b``.
    n_windows, n_blocks : int
    settings : dict
        ``threshold``, ``half_width`` (samples), ``order``, ``fit_forcing``,
        ``bootstrap``, ``block_periods``, ``samples_per_period``, ``noise_sd`` (estimated
        from the filter's residual), ``velocity``.
    bootstrap_support : dict
        ``{term: fraction}``: how often STLSQ selects each term on bootstrap resamples.
    """

    KIND = "ueda-discover"
    _LOAD = {
        "model": lambda d: None,
        "terms": lambda d: tuple(d["terms"]),
        "settings": lambda d: d.get("discovery_settings", d.get("settings")),
    }

    model: ForcedPolynomial
    terms: tuple
    coefficients: dict
    standard_errors: dict
    ols_standard_errors: dict
    residual_rms: float
    n_windows: int
    n_blocks: int
    settings: dict
    bootstrap_support: dict
    seconds: float
    smoothed: object = field(repr=False, default=None)

    @property
    def sympy(self):
        return self.model.sympy()

    @property
    def latex(self):
        return self.model.latex()

    def as_dict(self, settings_key="settings"):
        """The document's keys; ``settings_key`` names the discovery's settings (the
        command line keeps ``settings`` for its options)."""
        return {
            "terms": list(self.terms),
            "coefficients": self.coefficients,
            "standard_errors": self.standard_errors,
            "ols_standard_errors": self.ols_standard_errors,
            "equation": self.model.text(),
            "latex": self.latex,
            "residual_rms": self.residual_rms,
            "n_windows": self.n_windows,
            "n_blocks": self.n_blocks,
            "bootstrap_support": self.bootstrap_support,
            settings_key: self.settings,
            "seconds": self.seconds,
        }

    def _lines(self):
        return generic_lines(self)


@dataclass(frozen=True)
class _WeakSystem:
    """The weak-form regression of one record, ``b`` scaled to unit RMS.

    ``G``: ndarray of shape (n_windows, n_columns); ``bn = b / sb``; ``keep``: the columns
    STLSQ never drops (the fitted forcing's); ``centres``: the windows' centre times."""

    G: np.ndarray
    bn: np.ndarray
    sb: float
    keep: np.ndarray
    centres: np.ndarray


@dataclass(frozen=True)
class _Bootstrap:
    """The block bootstrap's settings: ``resamples`` over blocks of windows spanning
    ``block_span`` time, STLSQ at ``threshold`` on each resample (selection frequency)."""

    resamples: int
    block_span: float
    threshold: float
    seed: int


def _block_bootstrap(system, sup, ols_se, boot):
    """Standard errors by a block bootstrap (``boot``, a :class:`_Bootstrap`): blocks of
    consecutive windows spanning ``boot.block_span`` time; the normal equations of each
    block are summed over a resample of blocks.  Returns ``(standard errors, selection
    frequency per term, number of blocks, whether it ran)``; with fewer than 4 blocks (or
    no resamples) the least-squares standard errors ``ols_se``."""
    G, bn, centres = system.G, system.bn, system.centres
    block = np.floor((centres - centres[0]) / boot.block_span).astype(int)
    n_blocks = int(block.max()) + 1
    chosen = np.zeros(G.shape[1])
    if not (bool(boot.resamples) and n_blocks >= 4):
        return ols_se, chosen, n_blocks, False
    A_k = np.array([G[block == k].T @ G[block == k] for k in range(n_blocks)])
    c_k = np.array([G[block == k].T @ bn[block == k] for k in range(n_blocks)])
    n_k = np.bincount(block, minlength=n_blocks)
    rng = np.random.default_rng(boot.seed)
    out = []
    ix = np.ix_(sup, sup)
    for _ in range(int(boot.resamples)):
        pick = np.bincount(rng.integers(0, n_blocks, n_blocks), minlength=n_blocks)
        A = np.tensordot(pick, A_k, axes=1)
        cc = pick @ c_k
        out.append(np.linalg.lstsq(A[ix], cc[sup], rcond=None)[0] * system.sb)
        chosen += stlsq_gram(A, cc, int(pick @ n_k), threshold=boot.threshold, keep=system.keep)[1]
    return np.array(out).std(axis=0, ddof=1), chosen / int(boot.resamples), n_blocks, True


@dataclass(frozen=True, repr=False)
class UedaDiscoverSettings(Settings):
    """The options of :func:`discover` (each is also a keyword of it; see its parameters)."""

    threshold: float = option(0.02, Real(0))
    half_width: object = option(None, (None, Real(2, integer=True)))
    order: int = option(4, Real(2, integer=True))
    fit_forcing: bool = option(True)
    bootstrap: int = option(200, Real(0, integer=True))
    block_periods: int = option(4, Real(1, integer=True))
    seed: int = option(0, Real(0, integer=True))


@takes(UedaDiscoverSettings)
@params(t=Array(1), x=Array(1), B=Real(), nu=Real(0, open_low=True))
def discover(t, x, B, nu, *, settings=None, **options):
    """Recover ``x'' = f(x, x') + B cos(nu t)`` from a record (see the module docstring).

    Parameters
    ----------
    t, x : array
        Uniformly sampled record (at least 64 samples, preferably >= 50 periods).
    B, nu : float
        The known forcing ``B cos(nu t)``.
    settings : UedaDiscoverSettings, optional
        The options below in one object; keywords override its fields.
    threshold : float
        STLSQ threshold on coefficients of unit-RMS columns (relative to the RMS of ``b``).
    half_width : int, optional
        Test-window half width in samples (default a quarter period, at least 7).
    order : int
        Test function ``(1 - s^2)^order`` (>= 2).
    fit_forcing : bool
        Fit the forcing's coefficient (reported, should be 1) or fix it at 1.
    bootstrap : int
        Bootstrap resamples of blocks of ``block_periods`` periods (0: no bootstrap; the
        standard errors are then the least-squares ones).
    seed : int

    Returns
    -------
    Discovery
    """
    s = UedaDiscoverSettings.of("discover", settings, options)
    t0 = time.perf_counter()
    t, x, spp = check_forcing(t, x, B, nu)
    T = 2 * np.pi / nu
    hs = window_half_width(t.size, spp, s.half_width)
    sm = smooth(t, x, spp)
    G, b, centres = weak_system(t, x, sm.v, B, nu, half_width=hs, order=int(s.order))
    nt = len(MONOMIALS)
    if not s.fit_forcing:
        b = b - G[:, nt]
        G = G[:, :nt]
    keep = np.zeros(G.shape[1], bool)
    if s.fit_forcing:
        keep[nt] = True
    sb = float(np.sqrt(np.mean(b**2))) or 1.0
    bn = b / sb
    c, sup = stlsq_gram(G.T @ G, G.T @ bn, G.shape[0], threshold=s.threshold, keep=keep)
    c = c * sb
    if not sup[:nt].any():
        raise InputError(
            "no library term was selected; lower the threshold or check the record and the forcing"
        )
    Gs = G[:, sup]
    r = b - G @ c
    n_rows, p = Gs.shape
    sigma2 = float(r @ r) / max(1, n_rows - p)
    ols_se = np.sqrt(np.diag(sigma2 * np.linalg.pinv(Gs.T @ Gs)))
    names = [TERMS[k] if k < nt else FORCING for k in range(G.shape[1])]
    sel = np.flatnonzero(sup)
    se, chosen, n_blocks, do_boot = _block_bootstrap(
        _WeakSystem(G, bn, sb, keep, centres),
        sup,
        ols_se,
        _Bootstrap(s.bootstrap, s.block_periods * T, s.threshold, s.seed),
    )
    coef = dict(zip([names[k] for k in sel], map(float, c[sel]), strict=True))
    ses = dict(zip([names[k] for k in sel], map(float, se), strict=True))
    oses = dict(zip([names[k] for k in sel], map(float, ols_se), strict=True))
    if not s.fit_forcing:
        coef[FORCING], ses[FORCING], oses[FORCING] = 1.0, 0.0, 0.0
    model = ForcedPolynomial(tuple(c[:nt]), B, nu, coef[FORCING])
    recorded = {
        "threshold": s.threshold,
        "half_width": hs,
        "order": int(s.order),
        "fit_forcing": bool(s.fit_forcing),
        "bootstrap": int(s.bootstrap) if do_boot else 0,
        "block_periods": s.block_periods,
        "samples_per_period": float(spp),
        "periods": float((t[-1] - t[0]) / T),
        "noise_sd": sm.noise_sd,
        "noise_fraction_of_range": sm.noise_sd / float(np.ptp(sm.x)),
        "velocity": f"Savitzky-Golay (window {sm.window}, order 5), only in the "
        "x'^2, x x'^2, x'^3 columns",
        "method": "weak-form STLSQ, test functions (1 - s^2)^order",
    }
    return Discovery(
        model=model,
        terms=tuple(names[k] for k in sel if k < nt),
        coefficients=coef,
        standard_errors=ses,
        ols_standard_errors=oses,
        residual_rms=float(np.sqrt(np.mean(r**2) / np.mean(b**2))),
        n_windows=int(n_rows),
        n_blocks=n_blocks,
        settings=recorded,
        bootstrap_support=({names[k]: float(chosen[k]) for k in range(nt)} if do_boot else {}),
        seconds=time.perf_counter() - t0,
        smoothed=sm,
    )
