"""Noise floor of the criteria: what the true law would score on a record this noisy.

A parametric bootstrap.  The record's averaged cycle ``F_E`` stands in for the true
force history; each replicate is a synthetic record of as many cycles as were
averaged, sampled at the record's rate with a random sub-sample phase, with white
force noise of the record's estimated level and, when the onsets came from the
penetration, a penetration signal crossing zero at every onset with the record's
impact velocity and penetration noise.  The replicate goes through the *same*
processing as the record (:func:`~discovery.vibroimpact.data.impulse.impulse_from_samples`: onsets,
averaging, thresholds, supports), is aligned with the stand-in in the same way
(:func:`~discovery.vibroimpact.verify.evaluation.align`) and compared with it by the same
criteria.  The mean over replicates is the floor; a model whose criteria are within
a small factor of it agrees with the record as well as the truth could.
"""

from dataclasses import dataclass

import numpy as np

from ..._api._settings import Settings, option, takes
from ..._api._validate import Real
from ...errors import InputError
from ..data.impulse import impulse_from_samples
from .criteria import CRITERIA, evaluate_criteria
from .evaluation import align

__all__ = ["noise_floor"]


def _sawtooth(t, onsets, velocity):
    """A penetration crossing zero upward at every onset with slope ``velocity``
    (linear between the midpoints of neighbouring onsets)."""
    mids = 0.5 * (onsets[1:] + onsets[:-1])
    k = np.searchsorted(mids, t)
    return velocity * (t - onsets[k])


@dataclass(frozen=True, repr=False)
class NoiseFloorSettings(Settings):
    """The bootstrap's options of :func:`noise_floor` (each is also a keyword of it)."""

    n_boot: int = option(16, Real(0, integer=True))
    seed: int = option(0, (None, Real(0, integer=True)))


@takes(NoiseFloorSettings)
def noise_floor(
    reference_impulse,
    period,
    dt,
    *,
    sigma_f,
    n_cycles,
    sigma_zeta=None,
    impact_velocity=None,
    settings=None,
    **options,
):
    """Expected criteria of the true law against a record with this noise.

    Parameters
    ----------
    reference_impulse : Impulse
        The record's averaged cycle ``F_E`` (the stand-in for the truth).
    period : float
        Drive period [s].
    dt : float
        The record's sample spacing [s].
    sigma_f : float
        Force noise standard deviation [N].
    n_cycles : int
        Cycles averaged in the record.
    sigma_zeta : float, optional
        Penetration noise [m]; ``None`` when the onsets came from the force alone.
    impact_velocity : float, optional
        Penetration rate at the onsets [m/s] (needed with ``sigma_zeta``).
    settings : NoiseFloorSettings, optional
        The options below in one object; keywords override its fields.
    n_boot : int
        Replicates (0: none, the floor infinite).
    seed : int
        Seed of ``numpy.random.default_rng``.

    Returns
    -------
    dict
        ``{"mean": {I0..I4}, "q95": {I0..I4}, "n_boot": n, "seed": seed}``.
    """
    s = NoiseFloorSettings.of("noise_floor", settings, options)
    E = reference_impulse
    rng = np.random.default_rng(s.seed)
    W = E.duration
    K = max(int(n_cycles), 1) + 1
    lead = 0.3 * period
    samples = {n: [] for n in CRITERIA}
    for _ in range(s.n_boot):
        t = rng.uniform(0.0, dt) + np.arange(int((lead + K * W + 0.5 * period) / dt)) * dt
        # the stand-in repeated: main onset of cycle c at lead + c W
        F = E.evaluate(t - lead) + rng.normal(0.0, sigma_f, t.size)
        zeta = None
        if sigma_zeta is not None and impact_velocity:
            ons = np.concatenate([lead + c * W + E.onsets for c in range(-1, K + 1)])
            zeta = _sawtooth(t, np.sort(ons), impact_velocity)
            zeta = zeta + rng.normal(0.0, sigma_zeta, t.size)
        try:
            rep = impulse_from_samples(t, F, period, zeta=zeta, n_periods=E.n_periods)
        except InputError:
            continue  # a replicate too noisy to find its contacts: the floor is high anyway
        # aligned like a record (every impact of the stand-in tried as t*): with several
        # impacts of similar size the replicate's main impact is either one
        crit = evaluate_criteria(rep, align(rep, E)[1])
        for n, v in crit.items():
            samples[n].append(v)
    if not samples["I2"]:
        return {
            "mean": {n: float("inf") for n in CRITERIA},
            "q95": {n: float("inf") for n in CRITERIA},
            "n_boot": 0,
            "seed": s.seed,
        }
    return {
        "mean": {n: float(np.mean(v)) for n, v in samples.items()},
        "q95": {n: float(np.quantile(v, 0.95)) for n, v in samples.items()},
        "sd": {n: float(np.std(v, ddof=1)) if len(v) > 1 else 0.0 for n, v in samples.items()},
        "n_boot": len(samples["I2"]),
        "seed": s.seed,
    }
