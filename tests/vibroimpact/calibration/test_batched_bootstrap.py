"""The calibration's bootstrap computed in one batch (``calibration/batched.py``) against
each replicate's own fit (``estimate._fit`` on its drawn rows), on a noisy record of the
paper's machine: the same numbers to rounding, with held parameters, the lag's column, both
kinds of windows, and the replicates the batch leaves to their own fit."""

from dataclasses import replace

import numpy as np
import pytest

from discovery import load_scenario
from discovery.vibroimpact.calibration import estimate as est
from discovery.vibroimpact.calibration.equations import machine_rows
from discovery.vibroimpact.calibration.sensor import with_lag
from tests.realistic import reference_record

#: replicates of the bootstrap (enough to draw every cycle many times)
N_BOOT = 40
#: relative tolerance: the batch is another order of the same sums
RTOL = 1e-9


@pytest.fixture(scope="module")
def rows():
    sc = load_scenario("paper")
    m = reference_record(
        (sc, sc.law), periods=20, fs=19310.0, force_noise=0.01, motion_noise=0.002, check=False
    )
    return [machine_rows(m, sc, 0.0)]


def _held(rows, fixed):
    return np.array([fixed.get(n, np.nan) for n in est.parameter_names(len(rows))])


def _one_by_one(rows, held, draws, force_on, lag):
    """The replicates as :func:`est._fit` gives them one at a time, and the full fit's
    weights: ``(theta, tau, weights)``."""
    _, weights, _ = est._fit(rows, held, force_on=force_on, lag=lag)
    fits = [est._fit(rows, held, pick, weights, force_on, lag=lag) for pick in draws]
    return np.array([f[0] for f in fits]), np.array([f[2] for f in fits]), weights


def _batched(monkeypatch, rows, held, draws, weights, *, force_on, lag):
    """:func:`est._boot_fits` and how many replicates it left to :func:`est._fit`."""
    alone = []
    fit = est._fit

    def counted(*args, **kw):
        alone.append(args[2])
        return fit(*args, **kw)

    monkeypatch.setattr(est, "_fit", counted)
    theta, tau = est._boot_fits(rows, held, draws, weights, force_on, lag=lag)
    monkeypatch.setattr(est, "_fit", fit)
    return theta, tau, len(alone)


#: the linear sheet's first estimate (k3 held at 0), one more parameter held, the scale held
HELD = ({"k3": 0.0}, {"k3": 0.0, "k1": 2.7e7}, {"k3": 0.0, "m1": 1.02e4})


@pytest.mark.parametrize("fixed", HELD)
@pytest.mark.parametrize("force_on", ["contacts", "even"])
@pytest.mark.parametrize("lag", [False, True])
def test_the_batch_is_each_replicate_s_own_fit(rows, fixed, force_on, lag, monkeypatch):
    """Every replicate's parameters (and lag) within 1e-9 of its own fit's, none of them
    left to that fit (the batch computes them all)."""
    held = _held(rows, fixed)
    draws = est.cycle_draws(rows, N_BOOT, 7)
    theta, tau, weights = _one_by_one(rows, held, draws, force_on, lag)
    got, got_tau, alone = _batched(
        monkeypatch, rows, held, draws, weights, force_on=force_on, lag=lag
    )
    assert alone == 0
    np.testing.assert_allclose(got, theta, rtol=RTOL, atol=0)
    np.testing.assert_allclose(got_tau, tau, rtol=RTOL, atol=0)


def test_a_free_k3_is_its_own_fit_s_to_its_rounding(rows, monkeypatch):
    """With ``k3`` free (the record's supports are linear: it is a few times its spread
    around 0), each parameter within 1e-8 of its largest value over the replicates: the
    per-replicate fit itself moves ``k3`` by 1e-9 of it when its rows come in another
    order (the others by 1e-14)."""
    held = _held(rows, {})
    draws = est.cycle_draws(rows, N_BOOT, 8)
    for lag in (False, True):
        theta, tau, weights = _one_by_one(rows, held, draws, "contacts", lag)
        got, got_tau, alone = _batched(
            monkeypatch, rows, held, draws, weights, force_on="contacts", lag=lag
        )
        assert alone == 0
        assert np.all(np.abs(got - theta) <= 1e-8 * np.abs(theta).max(axis=0))
        assert np.all(np.abs(got_tau - tau) <= 1e-8 * np.abs(tau).max())


@pytest.mark.parametrize("lagged", [False, True])
def test_the_intervals_and_the_lag_keep_their_numbers(rows, lagged):
    """``_bootstrapped`` (value, low, high) on both kinds of windows and ``force_lag`` on
    both, k1 held, against the percentiles of the one-by-one fits; ``lagged``: the rows of
    a sensor's force (the force's equations on the evenly spread windows either way)."""
    if lagged:
        rows = with_lag(rows, 2e-4)
    fixed = {"k3": 0.0, "k1": 2.7e7}
    held = _held(rows, fixed)
    draws = est.cycle_draws(rows, N_BOOT, 9)
    for force_on in ("contacts", "even"):
        value, low, high = est._bootstrapped(rows, held, draws, force_on)
        theta, _, _ = _one_by_one(rows, held, draws, force_on, False)
        ref_low, ref_high = np.nanpercentile(theta, [2.5, 97.5], axis=0)
        assert np.array_equal(value, est._fit(rows, held, force_on=force_on)[0])
        np.testing.assert_allclose(low, ref_low, rtol=RTOL, atol=0)
        np.testing.assert_allclose(high, ref_high, rtol=RTOL, atol=0)
        tau, tau_low, tau_high = est.force_lag(rows, fixed, draws, force_on)
        _, taus, _ = _one_by_one(rows, held, draws, force_on, True)
        ref = np.nanpercentile(taus, [2.5, 97.5])
        assert tau == est._fit(rows, held, force_on=force_on, lag=True)[2]
        np.testing.assert_allclose([tau_low, tau_high], ref, rtol=RTOL, atol=0)


#: the linear sheet's first estimate; every parameter held but the masses (few columns: a
#: replicate with few contacts' windows is still determined)
FEW_HELD = ({"k3": 0.0}, {"c1": 1e5, "k1": 2.75e7, "k3": 0.0, "A": 5e5})


@pytest.mark.parametrize("fixed", FEW_HELD)
def test_replicates_the_batch_cannot_do_are_fitted_alone(rows, fixed, monkeypatch):
    """Contacts' windows in only four cycles: a replicate that draws fewer than three puts
    the force's equations on the evenly spread windows, and with the masses alone free one
    with three is determined, with four columns free it is not; those go to their own fit,
    the rest stay in the batch, and every replicate is its own fit's (NaN where that is
    NaN)."""
    r = rows[0]
    idx = np.flatnonzero(r.anchored)
    cycles = r.cycle[idx]
    anchored = np.zeros_like(r.anchored)
    anchored[[idx[np.flatnonzero(cycles == c)[0]] for c in np.unique(cycles)[:4]]] = True
    few = [replace(r, anchored=anchored)]
    held = _held(few, fixed)
    draws = est.cycle_draws(few, N_BOOT, 10)
    other = est._row_counts(few, draws) @ anchored < est.MIN_ANCHORED
    assert 0 < other.sum() < N_BOOT
    theta, _, weights = _one_by_one(few, held, draws, "contacts", False)
    got, _, alone = _batched(monkeypatch, few, held, draws, weights, force_on="contacts", lag=False)
    assert other.sum() <= alone < N_BOOT
    np.testing.assert_allclose(got, theta, rtol=RTOL, atol=0, equal_nan=True)
