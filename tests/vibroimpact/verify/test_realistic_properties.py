"""Properties of verification on realistic records, as success rates (issue 6, section 5).

Records: :func:`realistic.reference_record` of cases drawn by
:func:`realistic.draw_case` (scipy reference path from rest, 15 steady periods at
20 kHz, 1 % force noise and 0.2 % of each motion channel's range).  Laws verified with
:func:`discovery.vibroimpact.verify.evaluate` (see :func:`realistic.verification_trials`):

* the true law is consistent with its record in >= 95 % of the records;
* a wrong law (one real term dropped, or one coefficient off by 30 %: see
  :func:`realistic.wrong_laws`) is inconsistent in >= 95 % of the trials where its
  difference is *detectable*: against the noise-free record of the same case its I2
  exceeds the consistency limit ``2 x noise floor + 0.005`` (the floor the
  verification computed on the noisy record, under that law), or it has another
  period there, or no stable periodic orbit with contact.  A difference the rule
  cannot see even without noise is no test of the rule.

The slow tests use a fixed set of seeds (4 cases per category, two noise realisations
each: 32 records; about 1.5 minutes); ``tests/realistic_survey.py --properties`` runs
the same on more cases and prints the rates (README, "Tests on realistic records").
Below them, regression tests for the defects the survey found.
"""

import numpy as np
import pytest

from discovery import ForceLaw, Scenario
from discovery.vibroimpact.data.contact_edges import _edges, _merge_unseparated
from discovery.vibroimpact.data.impulse import impulse_from_samples
from discovery.vibroimpact.verify import CONSISTENCY_FACTOR, CONSISTENCY_SLACK, Reference, evaluate
from tests import realistic as R

RATE = 0.95
NOISE_SEEDS = (0, 1)
# fixed cases: the quickest to draw in the 25-seed survey (0.5-3.3 s each), all kinds
SEEDS = {
    "p1": (2, 4, 12, 13),
    "p1-slow": (0, 10, 14, 17),
    "subharmonic": (0, 5, 8, 21),
    "short-contact": (4, 9, 15, 18),
}


def _trials(category):
    out = []
    for seed in SEEDS[category]:
        case = R.draw_case(category, seed)
        for ns in NOISE_SEEDS:
            out += [(seed, ns, tr) for tr in R.verification_trials(case, ns)]
    return out


def _rates(rows):
    true = [tr for *_, tr in rows if tr.label == "true"]
    det = [tr for *_, tr in rows if tr.label != "true" and tr.detectable]
    return (
        sum(tr.consistent for tr in true),
        len(true),
        sum(not tr.consistent for tr in det),
        len(det),
    )


def _failures(rows):
    return [
        f"seed {s} noise {n} {tr.label}: {tr.verdict}"
        for s, n, tr in rows
        if (tr.label == "true" and not tr.consistent)
        or (tr.label != "true" and tr.detectable and tr.consistent)
    ]


@pytest.fixture(scope="module")
def all_trials():
    return {cat: _trials(cat) for cat in SEEDS}


@pytest.mark.slow
@pytest.mark.parametrize("category", list(SEEDS))
def test_rates_per_category(all_trials, category):
    rows = all_trials[category]
    ok, n, caught, n_det = _rates(rows)
    msg = (
        f"{category}: true law consistent {ok}/{n}, wrong law inconsistent {caught}/{n_det}"
        f" detectable; failures: {_failures(rows)}"
    )
    assert n == len(SEEDS[category]) * len(NOISE_SEEDS)
    # per category the sets are small: at most one miss of each property
    assert n - ok <= 1, msg
    assert n_det - caught <= 1 and n_det >= 5, msg


@pytest.mark.slow
def test_rates_overall(all_trials):
    rows = [r for cat in SEEDS for r in all_trials[cat]]
    ok, n, caught, n_det = _rates(rows)
    msg = (
        f"true law consistent {ok}/{n} = {ok / n:.3f}, wrong law inconsistent "
        f"{caught}/{n_det} = {caught / n_det:.3f} of the detectable; failures: "
        f"{_failures(rows)}"
    )
    assert ok / n >= RATE, msg
    assert caught / n_det >= RATE, msg


# ----------------------------------------------------------------- quick checks
def test_wrong_laws():
    law = ForceLaw.parse("1e8*z + 2e6*zd + 3e9*z*zd")
    wrong = dict(R.wrong_laws(law))
    assert list(wrong) == [
        "drop z",
        "drop zd",
        "drop z*zd",
        "z x1.3",
        "z x0.7",
        "zd x1.3",
        "zd x0.7",
        "z*zd x1.3",
        "z*zd x0.7",
    ]
    assert wrong["drop zd"].as_dict() == {"z": 1e8, "z*zd": 3e9}
    assert wrong["zd x0.7"].as_dict()["zd"] == pytest.approx(1.4e6)
    # a one-term law has no term to drop
    assert [lab for lab, _ in R.wrong_laws(ForceLaw.parse("1e8*z"))] == ["z x1.3", "z x0.7"]


def test_trials_on_a_fast_case():
    """One case end to end (about 3 s): the true law is consistent, every detectable
    wrong law inconsistent, and detectability is the rule applied to the noise-free
    difference."""
    case = R.draw_case("p1", 2)
    trials = R.verification_trials(case, 0)
    true, wrong = trials[0], trials[1:]
    assert true.label == "true" and true.detectable is None
    assert true.consistent, true.verdict
    assert len(wrong) == 6
    for tr in wrong:
        if tr.status == "ok" and tr.regime == "P1":
            limit = CONSISTENCY_FACTOR * tr.floor_i2 + CONSISTENCY_SLACK
            assert tr.detectable == (tr.i2_clean > limit)
        if tr.detectable:
            assert not tr.consistent, f"{tr.label}: {tr.verdict}"


def test_generator_rejects_orbits_that_do_not_settle():
    """A record still settling is not a steady record: every category needs the
    slowest mode to decay to 1e-4 within the longest transient (|mu| < 0.985).  The
    survey met a short-contact P1 orbit with multiplier 0.997 whose record, still
    alternating after 600 periods, was (rightly) read as P2."""

    class SS:
        n_periods, impacts = 1, 1

    for cat in R.CATEGORIES:
        assert not R._accepts(cat, SS, 0.99)
    assert R._accepts("p1-slow", SS, 0.97)
    assert R.transient_periods(R.MAX_MULTIPLIER - 1e-6) <= R.TRANSIENT_MAX
    assert R.MAX_MULTIPLIER**R.TRANSIENT_MAX < 1.5 * R.TRANSIENT_DECAY


# ------------------------------------------- regressions found by the survey
_DIP = Scenario(m1=12800.0, m2=2700.0, k1=120000000.0, c1=74500.0, A=209000.0, frequency=35.0)
_DIP_LAW = ForceLaw.parse("140000000000*z^1.5 + 14100000000000*z^1.5*zd")  # p1-slow seed 4


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_a_force_dip_within_the_noise_of_the_threshold_is_one_contact(seed):
    """The contact's force dips to 0.95 of the threshold for 0.3 ms (a near-loss): with
    noise the averaged cycle showed one contact or two depending on the draw, and the
    true law (always two when seen without noise) failed the 'same number of contacts'
    test on one record in two.  A gap now has to go clearly (3 noise) below the
    threshold."""
    sc, law = _DIP, _DIP_LAW
    rec = R.reference_record((sc, law), transient=273, seed=seed)
    ref = Reference.from_measurement(rec, sc)
    ev = evaluate(sc, law, ref)
    assert ref.impacts == 1 and ev.impacts == {"measured": 1, "simulated": 1}
    assert ev.consistent, ev.verdict


def test_gap_closed_only_within_the_noise_of_the_threshold():
    t = np.arange(60) * 1e-4
    thr, noise = 100.0, 10.0
    for level, runs in ((thr - 2 * noise, 1), (thr - 4 * noise, 2), (0.0, 2)):
        F = np.zeros_like(t)
        F[10:25] = 1000.0
        F[25:35] = level  # a 10-sample dip, longer than the debounce length (3)
        F[35:50] = 1000.0
        assert len(_edges(t, F, thr, 3, noise=noise)) == runs, level
        # without noise only the length decides (noise-free records unchanged)
        assert len(_edges(t, F, thr, 3)) == 2


def test_contact_shorter_than_the_debounce_length_is_found():
    """A strong contact of 8 samples (0.4 ms, 0.8 % of a 50 ms period, below the 1 %
    debounce length) was dropped as threshold flicker: 'no contact found'."""
    T, fs = 0.05, 20000.0
    t = np.arange(int(12 * T * fs)) / fs
    F = np.zeros_like(t)
    for k in range(12):
        tt = t - (0.3 + k) * T
        m = (tt >= 0) & (tt < 4e-4)
        F[m] = 1e6 * np.sin(np.pi * tt[m] / 4e-4)
    F += np.random.default_rng(0).normal(0, 1e3, t.size)
    imp = impulse_from_samples(t, F, T)
    assert imp.n_periods == 1 and len(imp.support) == 1
    assert imp.peak == pytest.approx(1e6, rel=0.05)
    # (the support of a noisy cycle is found after a moving average over 1 % of a
    # period, 11 samples here, which widens so short a pulse: measured and simulated alike)
    assert 4e-4 - 2 / fs < imp.contact_time < 4e-4 + 0.01 * T + 2 / fs


_NEAR_LOSS = Scenario(m1=3640.0, m2=1900.0, k1=7730000.0, c1=8670.0, A=65900.0, frequency=18.4)
_NEAR_LOSS_LAW = ForceLaw.parse("812000000*z + 1690000*zd")  # p1-slow seed 17


@pytest.mark.slow
@pytest.mark.parametrize("seed", [0, 1])
def test_a_near_loss_within_a_contact_is_not_a_new_impact(seed):
    """A 25 ms contact whose force falls from 270 kN to 4 kN (below the 14 kN threshold)
    for 1.5 ms while the bodies stay pressed (zeta 3e-6 m, within its noise) and rises
    again: the second run of force, the larger in impulse, was taken for the main
    impact, the cycle started inside the contact and the true law scored I2 = 0.99,
    'measured 2 contacts, simulated 1'.  Without separation it is one contact."""
    sc, law = _NEAR_LOSS, _NEAR_LOSS_LAW
    rec = R.reference_record((sc, law), transient=193, seed=seed)
    ref = Reference.from_measurement(rec, sc)
    assert ref.impacts == 1 and len((ref.cycle or ref.impulse).onsets) == 1
    ev = evaluate(sc, law, ref)
    assert ev.criteria["I2"] < 0.03
    assert ev.consistent, ev.verdict


def test_runs_merge_only_without_separation():
    t = np.arange(100) * 1e-4
    runs = [(t[10], t[30], 10), (t[40], t[60], 40), (t[80], t[90], 80)]
    zeta = np.full(t.size, 1e-5)
    zeta[30:40] = 2e-7  # a near-loss: zeta stays >= 0
    zeta[60:80] = -5e-5  # a flight: clearly separated
    rng = np.random.default_rng(0)
    noisy = zeta + rng.normal(0, 1e-6, t.size)
    for z in (zeta, noisy):
        out = _merge_unseparated(t, z, runs)
        assert [(a, b) for a, b, _ in out] == [(t[10], t[60]), (t[80], t[90])]
        assert out[0][2] == 10
