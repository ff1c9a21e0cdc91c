"""Impulses from simulated orbits and from sampled records."""

import dataclasses

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.vibroimpact.data.impulse import Impulse, estimate_noise, impulse_from_samples
from discovery.vibroimpact.dynamics.kernel import codes as K
from discovery.vibroimpact.dynamics.law_response import impulse_from_steady_state
from discovery.vibroimpact.dynamics.simulation import simulate
from discovery.vibroimpact.verify.criteria import evaluate_criteria

FS = 20_000.0  # sampling rate of the synthetic records [Hz]
DT = 1.0 / FS
N_REC = 10  # periods per record


# ------------------------------------------------------------------- exact impulse


def _orbit(sc, ss, n=1, t_eval=None):
    return simulate(sc, sc.law, (ss.t0, ss.t0 + n * sc.period), y0=ss.y0, t_eval=t_eval)


def test_exact_impulse_structure(paper, paper_ss, paper_impulse):
    imp = paper_impulse
    T = paper.period
    assert imp.n_periods == 1 and imp.duration == T
    assert imp.t[0] == 0.0 and imp.t[-1] == pytest.approx(T, abs=1e-15)
    assert np.all(np.diff(imp.t) >= 0)
    assert np.all(imp.F >= 0)
    tr = _orbit(paper, paper_ss)
    on = tr.event_t[tr.event_kind == K.EV_ONSET]
    loss = tr.event_t[tr.event_kind == K.EV_LOSS]
    assert len(on) == 1 and len(loss) == 1
    # onset and contact time equal the orbit's events (rel 1e-9: re-integration from the
    # located onset at rtol 1e-9)
    assert imp.onset == pytest.approx(on[0], abs=1e-9 * T)
    assert imp.support.shape == (1, 2) and imp.support[0, 0] == 0.0
    # (the window [t0, t0 + T] may start inside a contact: the loss then precedes the onset)
    assert imp.contact_time == pytest.approx((loss[0] - on[0]) % T, rel=1e-7)
    # F(0+) is the viscous jump c * dzeta at the onset (zeta = 0); F(0-) = F(T-) = 0
    y = tr.event_y[tr.event_kind == K.EV_ONSET][0]
    assert imp.F[0] == pytest.approx(1.28e7 * (y[1] - y[3]), rel=1e-7)
    assert imp.F[-1] == 0.0
    assert imp.peak == imp.F[0]
    # one-sided evaluation at the onset jump
    assert imp.evaluate(0.0) == imp.F[0]
    assert imp.evaluate(T, side="left") == 0.0
    assert imp.evaluate(T) == imp.F[0]  # periodic
    # inside the support the force is the law on the orbit: compare at a few times
    te = imp.onset + np.array([0.1, 0.3, 0.6]) * imp.contact_time
    tr2 = simulate(paper, paper.law, (paper_ss.t0, paper_ss.t0 + 2 * T), y0=paper_ss.y0, t_eval=te)
    # rel 1e-3: linear interpolation on h = T/2000 = 2e-5 s of a force decaying with a
    # time constant ~0.45 ms errs by up to h^2 |F''| / 8 ~ 2.5e-4 F (measured 8.4e-5)
    np.testing.assert_allclose(imp.evaluate(te - imp.onset), tr2.force, rtol=1e-3)


def test_exact_impulse_light_has_no_jump(light, light_ss):
    imp = impulse_from_steady_state(light, light.law, light_ss)
    # z^1.5 law: F(0+) ~ 0 (relative to the peak; the onset state has zeta ~ 1e-15)
    assert abs(imp.F[0]) < 1e-9 * imp.peak
    assert imp.contact_time > 0 and imp.n_periods == 1


def test_exact_impulse_needs_periodic_state(paper, paper_ss):
    bad = dataclasses.replace(paper_ss, regime="nonperiodic", n_periods=0)
    with pytest.raises(InputError, match="periodic"):
        impulse_from_steady_state(paper, paper.law, bad)


def test_impulse_evaluate_limits_and_periodic_support():
    imp = Impulse(
        t=np.array([0, 0.3, 0.3, 1.0]),
        F=np.array([2.0, 2.0, 0.0, 0.0]),
        duration=1.0,
        support=np.array([[0.0, 0.3]]),
        n_periods=1,
        onset=0.0,
    )
    assert imp.evaluate(0.3) == 0.0 and imp.evaluate(0.3, side="left") == 2.0
    np.testing.assert_array_equal(imp.evaluate([0.1, 1.1, 2.35, 5.0]), [2.0, 2.0, 0.0, 2.0])
    np.testing.assert_array_equal(imp.periodic_support(3.0), [[0, 0.3], [1, 1.3], [2, 2.3]])
    with pytest.raises(ValueError):
        imp.periodic_support(2.5)


def _values_numpy(t, F, W, tq, side):
    """The independent slow path: numpy's searchsorted over all queries at once."""
    tq = np.asarray(tq, dtype=float)
    q = np.mod(tq, W)
    if side == "left":
        q = np.where((q == 0) & (tq > 0), W, q)
    i = np.clip(np.searchsorted(t, q, side) - 1, 0, len(t) - 2)
    t0, t1 = t[i], t[i + 1]
    at_jump = 1.0 if side == "left" else 0.0
    w = np.where(t1 > t0, (q - t0) / np.where(t1 > t0, t1 - t0, 1.0), at_jump)
    return F[i] + np.clip(w, 0.0, 1.0) * (F[i + 1] - F[i])


def test_impulse_values_match_the_numpy_path(paper_impulse):
    """The compiled values against numpy's vectorised search: random knots with jumps
    (at the origin and inside), queries on the knots, at multiples of the period, negative,
    unsorted, and a scalar; both limits."""
    rng = np.random.default_rng(11)
    W = 0.04
    t = np.sort(rng.uniform(0.0, W, 60))
    t = np.concatenate([[0.0, 0.0], np.sort(np.concatenate([t, t[::7]])), [W]])
    F = rng.uniform(0.0, 1e6, t.size)
    cases = [(Impulse(t=t, F=F, duration=W, support=np.zeros((0, 2)), n_periods=1, onset=0.0))]
    cases.append(paper_impulse)
    for imp in cases:
        tq = np.concatenate(
            [
                rng.uniform(-2 * imp.duration, 3 * imp.duration, 500),
                imp.t,
                imp.t + imp.duration,
                np.arange(-2, 4) * imp.duration,
            ]
        )
        for side in ("right", "left"):
            want = _values_numpy(imp.t, imp.F, imp.duration, tq, side)
            np.testing.assert_array_equal(imp.evaluate(tq, side), want)
            np.testing.assert_array_equal(
                imp.evaluate(tq.reshape(-1, 2), side), want.reshape(-1, 2)
            )
            x = float(tq[3])
            got = imp.evaluate(x, side)
            assert np.ndim(got) == 0 and got == _values_numpy(imp.t, imp.F, imp.duration, x, side)


# ------------------------------------------------------------------ sampled records


@pytest.fixture(scope="module")
def paper_record(paper, paper_ss):
    """Ten periods of the paper steady state sampled at 20 kHz."""
    te = paper_ss.t0 + np.arange(int(round(N_REC * paper.period * FS))) * DT
    return _orbit(paper, paper_ss, N_REC, te)


def _complete_cycles(true_onsets, t_end, W):
    return int(np.sum(true_onsets + W <= t_end))


def test_samples_clean_record(paper, paper_record):
    tr = paper_record
    imp = impulse_from_samples(tr.t, tr.force, paper.period)
    true_on = tr.event_t[tr.event_kind == K.EV_ONSET]
    assert imp.n_periods == 1 and imp.duration == paper.period
    # onset within one sample of a true onset (a jump can only be located to a sample)
    assert np.min(np.abs(true_on - imp.onset)) <= DT
    assert imp.noise == 0.0  # a noise-free simulated record
    # every complete cycle is averaged (see the report: a tie in the main-impact search can
    # drop the first one, so one fewer is tolerated)
    full = _complete_cycles(true_on, tr.t[-1], paper.period)
    assert full - 1 <= imp.n_cycles <= full


def test_samples_contact_time_within_two_samples(paper, paper_record, paper_impulse):
    imp = impulse_from_samples(paper_record.t, paper_record.force, paper.period)
    assert abs(imp.contact_time - paper_impulse.contact_time) <= 2 * DT


def _shifted(imp, d):
    """The exact impulse delayed by d (its onset jump moves to t = d)."""
    t = np.concatenate([[0.0], imp.t + d])
    F = np.concatenate([[0.0], imp.F])
    keep = t < imp.duration
    return Impulse(
        t=np.append(t[keep], imp.duration),
        F=np.append(F[keep], 0.0),
        duration=imp.duration,
        support=imp.support + d,
        n_periods=1,
        onset=0.0,
    )


def test_samples_close_to_exact_impulse(paper, paper_record, paper_impulse):
    imp = impulse_from_samples(paper_record.t, paper_record.force, paper.period)
    vals = evaluate_criteria(paper_impulse, imp)
    # the onset of a force jump is only known to within one sample, and this impulse
    # decays by 10x within 20 samples, so a sub-sample misalignment alone costs several
    # percent of I2 (measured 7.3%). Bound: no worse than the exact impulse against
    # itself delayed by one full sample (16%).
    bound = evaluate_criteria(paper_impulse, _shifted(paper_impulse, DT))["I2"]
    assert vals["I2"] < bound
    assert vals["I2"] < 0.1


def test_samples_onset_from_zeta(paper, paper_record, paper_impulse):
    """With positions recorded, the onset is the up-crossing of zeta: sub-sample accurate."""
    tr = paper_record
    imp = impulse_from_samples(tr.t, tr.force, paper.period, zeta=tr.zeta)
    true_on = tr.event_t[tr.event_kind == K.EV_ONSET]
    # quadratic free-flight extrapolation, O(dt^3): measured 1.3e-5 samples; 1e-3 samples
    assert np.min(np.abs(true_on - imp.onset)) < 1e-3 * DT
    # with the onset right, the force jump lines up: measured I2 = 0.1%, I1 = 0.17%
    vals = evaluate_criteria(paper_impulse, imp)
    assert vals["I2"] < 0.02 and vals["I1"] < 0.02


def test_samples_close_to_exact_impulse_without_jump(light, light_ss):
    """No force jump at onset ('light'): the sampled impulse matches closely."""
    te = light_ss.t0 + np.arange(int(round(N_REC * light.period * FS))) * DT
    tr = _orbit(light, light_ss, N_REC, te)
    imp = impulse_from_samples(tr.t, tr.force, light.period)
    exact = impulse_from_steady_state(light, light.law, light_ss)
    true_on = tr.event_t[tr.event_kind == K.EV_ONSET]
    assert np.min(np.abs(true_on - imp.onset)) <= DT
    assert imp.n_periods == 1
    # measured I2 = 0.2%, I3 = 0.3%: 2% leaves room for sub-sample onset error
    vals = evaluate_criteria(exact, imp)
    assert vals["I2"] < 0.02 and vals["I3"] < 0.02


def test_samples_noisy_record(paper, paper_record, paper_impulse):
    tr = paper_record
    sigma = 0.01 * np.max(tr.force)
    F = tr.force + np.random.default_rng(7).normal(0.0, sigma, tr.force.size)
    imp = impulse_from_samples(tr.t, F, paper.period)
    # MAD of first differences on ~8000 samples: measured 3% off; 20% is the brief's bound
    assert imp.noise == pytest.approx(sigma, rel=0.2)
    # the support threshold is that of the averaged cycle: 5 sigma / sqrt(cycles)
    # (here still above 1e-3 of the peak)
    assert imp.threshold == pytest.approx(5 * imp.noise / np.sqrt(imp.n_cycles), rel=1e-12)
    assert imp.n_periods == 1
    true_on = tr.event_t[tr.event_kind == K.EV_ONSET]
    assert np.min(np.abs(true_on - imp.onset)) <= DT  # the jump is 100 sigma high
    full = _complete_cycles(true_on, tr.t[-1], paper.period)
    assert full - 1 <= imp.n_cycles <= full
    # averaging over ~9 cycles: the peak region (well above the noise) matches the exact
    # impulse to within the one-sample onset effect (I1 measured 7.5%)
    assert evaluate_criteria(paper_impulse, imp, names=["I1"])["I1"] < 0.15


@pytest.mark.parametrize("sigma", [0.01, 1.0, 100.0])
def test_estimate_noise(sigma):
    rng = np.random.default_rng(3)
    t = np.linspace(0, 1, 20_001)
    smooth = 50 * sigma * np.sin(2 * np.pi * 3 * t)  # slow signal, much larger than noise
    est = estimate_noise(smooth + rng.normal(0, sigma, t.size))
    # 20k samples: the MAD estimator's standard error is ~1%; 5% margin
    assert est == pytest.approx(sigma, rel=0.05)
    assert estimate_noise([1.0]) == 0.0


def test_record_without_contact_raises(paper):
    t = np.arange(8000) * DT
    with pytest.raises(InputError, match="no contact"):
        impulse_from_samples(t, np.zeros_like(t), paper.period)
    noise = np.random.default_rng(1).normal(0, 1.0, t.size)
    with pytest.raises(InputError, match="no contact"):
        impulse_from_samples(t, noise, paper.period)


def test_record_shorter_than_a_cycle_raises(paper, paper_record):
    tr = paper_record
    on = tr.event_t[tr.event_kind == K.EV_ONSET][0]
    keep = tr.t < on + 0.5 * paper.period
    with pytest.raises(InputError, match="shorter than one cycle"):
        impulse_from_samples(tr.t[keep], tr.force[keep], paper.period)


def _pulse_train(amplitudes, T=0.04, width=0.1, offset=0.3173, n=12):
    """Half-sine pulses of width*T starting at (k + offset) T, amplitude amplitudes[k % m]."""
    t = np.arange(int(round(n * T * FS))) * DT
    F = np.zeros_like(t)
    onsets = []
    for k in range(n):
        t0 = (k + offset) * T
        onsets.append(t0)
        m = (t >= t0) & (t <= t0 + width * T)
        F[m] = amplitudes[k % len(amplitudes)] * np.sin(np.pi * (t[m] - t0) / (width * T))
    return t, F, np.array(onsets)


def test_samples_detect_p2_cycle():
    T = 0.04
    t, F, onsets = _pulse_train([1.0e6, 0.5e6], T=T)
    imp = impulse_from_samples(t, F, T)
    assert imp.n_periods == 2 and imp.duration == pytest.approx(2 * T, rel=1e-15)
    # the cycle starts at the larger impact
    k = int(np.argmin(np.abs(onsets - imp.onset)))
    assert k % 2 == 0 and abs(onsets[k] - imp.onset) <= DT
    # two contacts per cycle, each 0.1 T long (within a sample at each edge)
    assert imp.support.shape == (2, 2)
    np.testing.assert_allclose(imp.support[:, 1] - imp.support[:, 0], 0.1 * T, atol=2 * DT)
    assert imp.support[1, 0] == pytest.approx(T, abs=2 * DT)
    # peaks of the averaged cycle (sampling of a half-sine: within 1% of the amplitude)
    assert imp.peak == pytest.approx(1.0e6, rel=1e-2)
    assert np.max(imp.evaluate(np.linspace(T, 1.2 * T, 801))) == pytest.approx(0.5e6, rel=1e-2)
    # forcing n_periods=1 is honoured
    assert impulse_from_samples(t, F, T, n_periods=1).n_periods == 1


def test_samples_equal_pulses_are_p1():
    T = 0.04
    t, F, onsets = _pulse_train([1.0e6], T=T)
    imp = impulse_from_samples(t, F, T)
    assert imp.n_periods == 1
    assert np.min(np.abs(onsets - imp.onset)) <= DT
    full = int(np.sum(onsets + T <= t[-1]))
    assert full - 1 <= imp.n_cycles <= full


def test_contacts_too_short_for_the_sampling_rate_are_named_so(paper):
    """Contacts of two samples, one every drive period (survey draw 76's noisier record: a
    contact resolved in 1-2 samples at 20 kHz) are no noise spikes: the message says they
    are too short for the rate and which rate resolves them; spikes at random times are
    still read as noise."""
    from discovery.vibroimpact.data.measurement import no_contact_message

    n = int(round(N_REC * paper.period * FS))
    t = np.arange(n) * DT
    F = np.random.default_rng(2).normal(0.0, 1e3, n)
    every = int(round(paper.period * FS))
    for k in range(every // 3, n - 2, every):
        F[k : k + 2] = 5e6  # a contact of two samples each period
    msg = no_contact_message(t, F, paper.period)
    assert "recur with the drive period" in msg and "too short for this sampling rate" in msg
    need = int(0.01 * paper.period * FS)
    assert f"needs {need}" in msg and f"record at {FS * need / 2:.3g} Hz" in msg
    spikes = np.random.default_rng(3).normal(0.0, 1e3, n)
    spikes[np.random.default_rng(4).choice(n, 12, replace=False)] = 5e6
    msg = no_contact_message(t, spikes, paper.period)
    assert "look like noise spikes" in msg and "do not recur" in msg
