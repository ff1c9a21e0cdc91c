"""Verification of a discovered equation by simulation: its attractor against the record's.

The equation (a :class:`~discovery.ueda.polynomial.ForcedPolynomial`) is integrated from the
record's state at its first strobe time (:func:`~discovery.ueda.polynomial.simulate_model`);
its stroboscopic points are compared with the record's by an energy distance against a
noise floor from halves of the record's own points
(:mod:`discovery.ueda.strobe_resampling`); its regime against the record's regime
classified from its strobe points (:func:`~discovery.ueda.record.classify_record`), with
the largest Lyapunov exponent (variational equations, batch-means error) for a chaotic
record.
"""

import time
from dataclasses import dataclass, field

import numpy as np

from .._api._printing import generic_lines, readable
from .._api._settings import Settings, option, takes
from .._api._validate import Array, Choice, Real, params
from ..errors import InputError, IntegrationError
from ..numerics.tolerances import Tolerances
from .polynomial import ForcedPolynomial, simulate_model
from .record import Smoothed, check_forcing, classify_record, record_strobe_points, smooth
from .regimes import classify_points
from .strobe_resampling import energy_resamples, floor_scheme

__all__ = ["Verification", "verify"]


@readable
@dataclass(frozen=True)
class Verification:
    """The discovered equation's attractor against the record's.

    Attributes
    ----------
    energy_distance : float
        Median over ``resamples`` of the energy distance between a half of the record's
        strobe points and as many of the model's (coordinates scaled by the record's
        standard deviations); with ``floor_method == "blocks"`` (the default) both are
        made of contiguous blocks of ``floor_block_periods`` strobe points (see
        :func:`verify`), with ``"halves"`` they are random points.
    floor_q95, floor_median : float
        Quantiles of the noise floor: the energy distance between the two halves of the
        record's own strobe points (same resamples, same kind of halves).
    energy_consistent : bool
        ``energy_distance <= floor_q95``.
    regime_record, regime_model : str
    regime_agrees : bool
        The same regime (``P<n>`` with the same ``n``, beat or chaotic); for a chaotic
        record the model's exponent must also be positive (above ``max(0.01, 3 se)``).
    consistent : bool
        ``energy_consistent and regime_agrees``.
    lyapunov : dict
        The model's largest exponent ``value``, ``stderr``, ``second``.
    diverged : str or None
        Why the model could not be simulated (then ``consistent`` is False).
    model_strobe, record_strobe : ndarray
    floor_samples, test_samples : ndarray
        The resampled floor and record-vs-model distances.
    floor_method : str
        ``"blocks"`` (block halves, the default) or ``"halves"`` (random halves).
    floor_block_periods : int
        Block length in forcing periods (strobe points); 1 for ``"halves"``.
    floor_correlation_lag : int or None
        The record's decorrelation lag in periods (:func:`strobe_block_length`), None
        when the block length was given.
    """

    energy_distance: float
    floor_q95: float
    floor_median: float
    energy_consistent: bool
    regime_record: str
    regime_model: str
    regime_agrees: bool
    consistent: bool
    lyapunov: dict
    diverged: object
    n_record_points: int
    n_model_points: int
    record_evidence: dict
    model_evidence: dict
    resamples: int
    seconds: float
    record_strobe: np.ndarray = field(repr=False)
    model_strobe: np.ndarray = field(repr=False)
    floor_samples: np.ndarray = field(repr=False, default=None)
    test_samples: np.ndarray = field(repr=False, default=None)
    floor_method: str = "halves"
    floor_block_periods: int = 1
    floor_correlation_lag: object = None

    def as_dict(self):
        return {
            "energy_distance": self.energy_distance,
            "floor_q95": self.floor_q95,
            "floor_median": self.floor_median,
            "energy_consistent": self.energy_consistent,
            "consistent": self.consistent,
            "regime_record": self.regime_record,
            "regime_model": self.regime_model,
            "regime_agrees": self.regime_agrees,
            "lyapunov": self.lyapunov,
            "diverged": self.diverged,
            "n_record_points": self.n_record_points,
            "n_model_points": self.n_model_points,
            "record_evidence": self.record_evidence,
            "model_evidence": self.model_evidence,
            "resamples": self.resamples,
            "floor_method": self.floor_method,
            "floor_block_periods": self.floor_block_periods,
            "floor_correlation_lag": self.floor_correlation_lag,
            "rule": (
                f"energy distance (median over halves of the record made of "
                f"{self.floor_block_periods}-period blocks vs as many model points "
                f"in such blocks) <= the 95 % quantile of the distance between the "
                f"record's own block halves, and the same regime"
                if self.floor_method == "blocks"
                else "energy distance (median over random halves of the record vs as "
                "many model points) <= the 95 % quantile of the distance between "
                "the record's own random halves, and the same regime"
            ),
            "seconds": self.seconds,
        }

    def _lines(self):
        return generic_lines(self)


def _regime_match(rec, mod, lyap):
    if rec.kind in ("P1", "Pn"):
        return rec.regime == mod.regime
    if rec.kind == "chaotic":
        return mod.kind == "chaotic" and lyap.value > max(0.01, 3 * lyap.stderr)
    return mod.kind == "beat"


@dataclass(frozen=True, repr=False)
class UedaVerifySettings(Settings):
    """The options of :func:`verify` (each is also a keyword of it; see its docstring)."""

    transient: int = option(200, Real(0, integer=True))
    periods: int = option(2000, Real(1, integer=True))
    resamples: int = option(200, Real(0, integer=True))
    seed: int = option(0, Real(0, integer=True))
    tolerances: object = option(None, (Tolerances, None))
    floor: str = option("blocks", Choice("blocks", "halves"))
    block_periods: object = option(None, (None, Real(1, integer=True)))


@takes(UedaVerifySettings)
@params(model=ForcedPolynomial, t=Array(1), x=Array(1), smoothed=(None, Smoothed))
def verify(model, t, x, *, smoothed=None, settings=None, **options):
    """Verify ``model`` (a :class:`ForcedPolynomial`) against the record ``(t, x)`` by
    simulation (see :class:`Verification`).

    The model starts from the record's smoothed state at its first strobe time, runs
    ``transient`` periods, then ``periods`` more with the variational equations (its
    strobe points and exponents).

    The energy-distance test.  The record's ``n`` strobe points are one orbit segment:
    consecutive points are correlated over a few periods (in x' the negres points
    alternate, lag-2 autocorrelation -0.45; duffing's x stays correlated, +0.1 to lag
    ~8), so a segment departs from the invariant measure by more (duffing) or less
    (negres) than ``n`` independent points would.  The floor must therefore be made of
    halves that keep that correlation: ``floor="blocks"`` (the default) cuts the record
    into contiguous blocks of ``L`` periods (``block_periods``, default
    :func:`strobe_block_length`: twice the record's own decorrelation lag, at least 4, at
    most ``n // 8``; a random circular offset of the block grid), and shuffles the
    blocks between two halves: the floor is the distance between the halves, the test
    the distance between one half and as many model points drawn as blocks of ``L``
    consecutive model periods.  Floor and test are then alike under the null hypothesis
    (a half of one correlated segment against a half's worth of an independent
    correlated segment).  Random halves (``floor="halves"``) interleave in time and share
    the segment's departure: their floor is the independent-points one, too tight for
    duffing (its truth is rejected more often than the level says) and too loose for
    negres.  The whole record is not compared with the whole simulation under a floor
    rescaled by the sample sizes: the rescaling assumes Gaussian fluctuations, and
    duffing's are heavy-tailed.  What neither floor can see: a segment atypical on the
    scale of the whole record, and differences smaller than the false-alarm rate allows on
    the record's length (duffing with ``k`` x0.8 or ``B`` x0.95 on 200 periods).  The
    rates behind these rules are in the CHANGELOG (Ueda: verification).

    ``smoothed``: the record's smoothing (:func:`~discovery.ueda.record.smooth`), if made.
    ``settings`` (a :class:`UedaVerifySettings`) holds the options ``transient``,
    ``periods``, ``resamples``, ``seed``, ``tolerances``, ``floor`` and ``block_periods``
    in one object; keywords override its fields.
    """
    s = UedaVerifySettings.of("verify", settings, options)
    t_start = time.perf_counter()
    t, x, spp = check_forcing(t, x, model.B, model.nu)
    sm = smooth(t, x, spp) if smoothed is None else smoothed
    rs, ts = record_strobe_points(t, x, model.nu, sm)
    if len(rs) < 20:
        raise InputError(f"the record has {len(rs)} strobe points; need at least 20 periods")
    scheme = floor_scheme(rs, s.floor, s.block_periods)
    reg_rec = classify_record(rs, sm.noise_sd)
    record = {
        "regime_record": reg_rec.regime,
        "n_record_points": len(rs),
        "record_evidence": reg_rec.as_dict(),
        "resamples": int(s.resamples),
        "record_strobe": rs,
        "floor_method": s.floor,
        "floor_block_periods": scheme.block,
        "floor_correlation_lag": scheme.lag,
    }
    try:
        ms, lyap = simulate_model(
            model,
            rs[0],
            ts[0],
            transient=s.transient,
            periods=s.periods,
            tolerances=s.tolerances or Tolerances(rtol=1e-8),
        )
    except IntegrationError as exc:
        return _diverged(record, str(exc), time.perf_counter() - t_start)
    reg_mod = classify_points(ms, model.scales(), lyap.value, lyap.stderr)
    floor_s, test = energy_resamples(rs, ms, scheme, s.resamples, s.seed)
    ed, q95 = float(np.median(test)), float(np.quantile(floor_s, 0.95))
    agrees = _regime_match(reg_rec, reg_mod, lyap)
    e_ok = bool(ed <= q95)
    return Verification(
        **record,
        energy_distance=ed,
        floor_q95=q95,
        floor_median=float(np.median(floor_s)),
        energy_consistent=e_ok,
        regime_model=reg_mod.regime,
        regime_agrees=bool(agrees),
        consistent=bool(e_ok and agrees),
        lyapunov={
            "value": lyap.value,
            "stderr": lyap.stderr,
            "second": lyap.second,
            "n_periods": lyap.n_periods,
            "units": "per unit time",
        },
        diverged=None,
        n_model_points=len(ms),
        model_evidence=reg_mod.as_dict(),
        seconds=time.perf_counter() - t_start,
        model_strobe=ms,
        floor_samples=floor_s,
        test_samples=test,
    )


def _diverged(record, why, seconds):
    """The verification of a model that could not be simulated: not consistent."""
    return Verification(
        **record,
        energy_distance=float("inf"),
        floor_q95=float("nan"),
        floor_median=float("nan"),
        energy_consistent=False,
        regime_model="diverged",
        regime_agrees=False,
        consistent=False,
        lyapunov={},
        diverged=why,
        n_model_points=0,
        model_evidence={},
        seconds=seconds,
        model_strobe=np.empty((0, 2)),
    )
