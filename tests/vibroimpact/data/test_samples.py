"""Contact samples for the regression (discovery.vibroimpact.data.samples) and CSV records with
a2."""

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.vibroimpact.data.impulse import impulse_from_samples
from discovery.vibroimpact.data.measurement import Measurement
from discovery.vibroimpact.data.samples import contact_samples
from discovery.vibroimpact.dynamics.synthetic import synthesize


@pytest.fixture(scope="module")
def rec(paper, paper_ss):
    """20 steady periods of law (11), noise-free, with velocities."""
    return synthesize(paper, paper.law, periods=20, ss=paper_ss)


@pytest.fixture(scope="module")
def rec_light(light, light_ss):
    return synthesize(light, light.law, periods=20, ss=light_ss)


def _episodes(zeta):
    c = zeta > 0
    return int(np.sum(np.diff(c.astype(int)) == 1) + c[0])


@pytest.mark.parametrize("which", ["rec", "rec_light"])
def test_only_contact_samples_and_one_impact_per_contact(which, request):
    m = request.getfixturevalue(which)
    cs = contact_samples(m)
    assert cs.derivative == "velocities"
    assert np.all(cs.zeta > 0)
    # the samples are exactly the record's samples with zeta above the floor
    zeta = m.zeta
    sel = np.isin(m.t, m.t[zeta > 0])
    assert len(cs) <= int(sel.sum())
    # every contact episode of the record is one impact, numbered 0, 1, 2, ...
    assert cs.n_impacts == _episodes(zeta)
    assert np.array_equal(np.unique(cs.impact), np.arange(cs.n_impacts))
    assert np.all(np.diff(cs.impact) >= 0)  # in time order
    # F is the recorded force at those samples; noise-free: force > 0 in contact
    assert np.all(cs.F > 0)
    assert cs.X.shape == (len(cs), 2)
    np.testing.assert_array_equal(cs.X[:, 0], cs.zeta)
    np.testing.assert_array_equal(cs.weight, np.ones(len(cs)))


def test_samples_of_each_impact_are_contiguous_in_contact(rec):
    cs = contact_samples(rec)
    t_in = np.flatnonzero(np.isin(rec.t, rec.t[rec.zeta > 0]))
    # one impact never spans a free-flight gap: its samples are consecutive indices of the
    # record up to samples dropped at the edges (zeta below the floor)
    idx = np.flatnonzero(np.isin(rec.zeta, cs.zeta))
    for k in range(cs.n_impacts):
        ii = idx[cs.impact == k]
        assert np.all(np.diff(ii) == 1)
    assert t_in.size >= idx.size


def _positions_only(m):
    return Measurement(m.t, m.F, {k: v for k, v in m.channels.items() if k in ("w1", "w2")})


@pytest.mark.parametrize(
    "which, tol_savgol, tol_sindy",
    [
        # paper: law (11) has a force jump at onset, so the acceleration jumps and a local cubic
        # over 7 samples is off near the onset by ~ dt * jump; measured max 0.28 % (savgol) and
        # 1.2 % (pysindy) of max dzeta; tolerances ~3x the measured values.
        ("rec", 0.01, 0.035),
        # light: Hunt-Crossley, no force jump, smooth zeta; measured 3e-5 and 2e-4.
        ("rec_light", 1e-4, 1e-3),
    ],
)
def test_dzeta_from_positions_agrees_with_velocities(which, tol_savgol, tol_sindy, request):
    m = request.getfixturevalue(which)
    ref = contact_samples(m)
    scale = float(np.max(np.abs(ref.dzeta)))
    for derivative, tol in (("savgol", tol_savgol), ("pysindy", tol_sindy)):
        cs = contact_samples(_positions_only(m), derivative=derivative)
        assert cs.derivative == derivative
        np.testing.assert_array_equal(cs.zeta, ref.zeta)  # same samples selected
        err = np.abs(cs.dzeta - ref.dzeta) / scale
        assert err.max() < tol, (derivative, err.max())
        # away from the onset kink the cubic is near exact: median well below 1e-4
        assert np.median(err) < 1e-4, (derivative, np.median(err))


def test_default_derivative_without_velocities_is_savgol(rec):
    assert contact_samples(_positions_only(rec)).derivative == "savgol"


def test_savgol_with_velocities_recorded_is_used_when_asked(rec):
    cs = contact_samples(rec, derivative="savgol")
    assert cs.derivative == "savgol"


@pytest.mark.parametrize("keep", [("w1",), ("w2",), ()])
def test_missing_positions_raise(rec, keep):
    m = Measurement(rec.t, rec.F, {k: rec.channels[k] for k in keep})
    with pytest.raises(InputError, match="w1 and w2"):
        contact_samples(m)


@pytest.mark.parametrize(
    "kwargs", [dict(derivative="spline"), dict(window=6), dict(window=3), dict(weights="equal")]
)
def test_bad_options_raise(rec, kwargs):
    with pytest.raises(InputError):
        contact_samples(rec, **kwargs)


def test_velocities_requested_but_absent_raise(rec):
    with pytest.raises(InputError, match="v1 and v2"):
        contact_samples(_positions_only(rec), derivative="velocities")


def test_no_contact_raises(rec):
    far = {k: v.copy() for k, v in rec.channels.items()}
    far["w2"] = far["w2"] + 1.0  # moulding lifted by 1 m: zeta < 0 everywhere
    with pytest.raises(InputError, match="fewer than 10 contact samples"):
        contact_samples(Measurement(rec.t, rec.F, far))


def test_per_impact_weights_equal_total_per_impact(paper):
    # a run-up record: impacts of very different durations
    m = synthesize(paper, paper.law, periods=10, from_rest=True)
    cs = contact_samples(m, weights="per-impact")
    totals = np.bincount(cs.impact, weights=cs.weight)
    counts = np.bincount(cs.impact)
    assert counts.min() < counts.max()  # the check below is not trivial
    # equal totals up to float summation error
    np.testing.assert_allclose(totals, totals[0], rtol=1e-12)
    # weights have mean 1 (scale of the residual sum of squares unchanged)
    assert cs.weight.mean() == pytest.approx(1.0, rel=1e-12)


def test_pysindy_derivative_goes_through_the_public_call(rec, monkeypatch):
    # pysindy 2.x's public differentiation API is calling the object, sfd(x, t)
    from pysindy.differentiation import SmoothedFiniteDifference

    calls = []
    public = SmoothedFiniteDifference.__call__

    def spy(self, x, t=1):
        calls.append(np.shape(x))
        return public(self, x, t)

    monkeypatch.setattr(SmoothedFiniteDifference, "__call__", spy)
    cs = contact_samples(_positions_only(rec), derivative="pysindy")
    assert calls == [(rec.t.size, 1)]
    assert cs.derivative == "pysindy"


# ------------------------------------------------------------ average_cycles


def _cycle_start_and_length(m, period):
    imp = impulse_from_samples(m.t, m.F, period, zeta=m.zeta)
    dt = m.t[1] - m.t[0]
    return int(np.searchsorted(m.t, imp.onset - dt)), int(round(imp.duration / dt)), imp


def _reshape_like_law(F, a, n, e):
    """``F`` with a zero-sum wiggle of ``e`` max F inside the contact of samples a..a+n: the
    impulse (integral) is unchanged, the shape is not."""
    F = F.copy()
    seg = F[a : a + n]
    on = np.flatnonzero(seg > 1e-3 * F.max())[1:-1]
    d = e * F.max() * np.sin(4 * np.pi * np.arange(on.size) / on.size)
    seg[on] += d - d.mean()
    return F


def test_average_cycles_of_a_steady_record(rec, paper):
    i0, n, imp = _cycle_start_and_length(rec, paper.period)
    cs = contact_samples(rec, average_cycles=True, period=paper.period)
    k = (rec.t.size - i0) // n
    assert imp.n_cycles == k == 19
    avg = cs.weight > 1
    assert set(np.unique(cs.weight)) == {1.0, float(k)}
    # the averaged samples are the sample-wise mean of the k whole cycles
    mean = {
        name: a[i0 : i0 + k * n].reshape(k, n).mean(axis=0)
        for name, a in (("zeta", rec.zeta), ("F", rec.F))
    }
    sel = np.isin(mean["zeta"], cs.zeta[avg])
    assert sel.sum() == avg.sum()
    np.testing.assert_array_equal(cs.F[avg], mean["F"][sel])
    # every recorded contact sample counted once
    assert cs.weight.sum() == len(contact_samples(rec))


def test_average_cycles_leaves_out_a_deviating_cycle(rec, paper):
    i0, n, _ = _cycle_start_and_length(rec, paper.period)
    clean = contact_samples(rec, average_cycles=True, period=paper.period)
    bad = 7
    F = _reshape_like_law(rec.F, i0 + bad * n, n, 0.02)
    m = Measurement(rec.t, F, rec.channels)
    imp = impulse_from_samples(m.t, F, paper.period, zeta=m.zeta)
    # the premise: the impulse averages 18 cycles, not contiguous (cycle 7 is left out)
    assert imp.n_cycles == 18 and imp.onset == pytest.approx(rec.t[i0 + 1], abs=rec.t[1])
    cs = contact_samples(m, average_cycles=True, period=paper.period)
    assert set(np.unique(cs.weight)) == {1.0, 18.0}
    # the average is that of the 18 steady cycles: the clean cycle to rounding (with the
    # deviating cycle in it, it would be off by 0.02 / 18 ~ 1e-3 of the peak)
    np.testing.assert_allclose(
        cs.F[cs.weight > 1], clean.F[clean.weight > 1], rtol=0, atol=1e-9 * rec.F.max()
    )
    # the deviating cycle stays in as recorded (weight 1), its wiggle included
    sl = slice(i0 + bad * n, i0 + (bad + 1) * n)
    raw = cs.weight == 1
    in_bad = np.isin(cs.zeta[raw], m.zeta[sl])
    assert in_bad.sum() > 10
    np.testing.assert_array_equal(
        cs.F[raw][in_bad], F[sl][np.isin(m.zeta[sl], cs.zeta[raw][in_bad])]
    )
    # total weight: every recorded contact sample counted once
    assert cs.weight.sum() == pytest.approx(clean.weight.sum(), rel=1e-12)


# ------------------------------------------------------------------ CSV with a2


def _write(path, cols):
    names = list(cols)
    rows = np.column_stack([cols[n] for n in names])
    with open(path, "w") as f:
        f.write(",".join(names) + "\n")
        for r in rows:
            f.write(",".join(repr(float(v)) for v in r) + "\n")


def test_csv_with_a2_forms_force_from_equation_of_motion(paper, rec, tmp_path):
    # a2 from the moulding's equation of motion m2 a2 = F - m2 g: loading must invert it
    a2 = rec.F / paper.m2 - paper.g
    p = tmp_path / "a2.csv"
    _write(p, {"t": rec.t, "a2": a2, "w1": rec.channels["w1"], "w2": rec.channels["w2"]})
    m = Measurement.from_csv(p, scenario=paper)
    # repr() round-trips exactly; the two float operations cost a few ulps of max F
    np.testing.assert_allclose(m.F, rec.F, rtol=0, atol=1e-9 * rec.F.max())
    assert any("m2 (a2 + g)" in n for n in m.notes)
    cs = contact_samples(m)
    assert len(cs) == len(contact_samples(rec))


def test_csv_a2_sign_convention_matches_simulated_motion(paper, rec, tmp_path):
    # independent of the formula: a2 = dv2/dt by central differences of the simulated v2
    a2 = np.gradient(rec.channels["v2"], rec.t)
    p = tmp_path / "a2.csv"
    _write(p, {"t": rec.t, "a2": a2})
    m = Measurement.from_csv(p, scenario=paper)
    # compare where the force is smooth (away from the jumps at onset and release):
    # central differences are O(dt^2) there; 1 % of the peak force is ample (the wrong
    # sign of g would be off by 2 m2 g, i.e. >> 1 %)
    smooth = np.ones(rec.t.size, bool)
    jumps = np.flatnonzero(np.abs(np.diff(rec.F)) > 0.05 * rec.F.max())
    for j in jumps:
        smooth[max(j - 2, 0) : j + 3] = False
    smooth[[0, -1]] = False
    err = np.abs(m.F - rec.F)[smooth].max() / rec.F.max()
    assert err < 0.01, err
    assert 2 * paper.m2 * paper.g > 0.01 * rec.F.max()  # the sign check above has teeth


def test_csv_with_a2_without_scenario_raises(rec, tmp_path):
    p = tmp_path / "a2.csv"
    _write(p, {"t": rec.t[:10], "a2": np.zeros(10)})
    with pytest.raises(InputError, match="a2 but no F"):
        Measurement.from_csv(p)


@pytest.mark.parametrize("width", [1, 3, 7, 31])
def test_the_edge_smoothing_is_scipys_moving_mean(width):
    """The contact edges' smoothing (``moving_mean``) is scipy's ``uniform_filter1d`` with
    the ends held, to the last bit, on noisy impulse trains of several lengths."""
    from scipy.ndimage import uniform_filter1d

    from discovery.vibroimpact.data.contact_edges import moving_mean

    rng = np.random.default_rng(width)
    for n in (width, 500, 4001):
        x = np.maximum(0.0, np.sin(np.linspace(0, 20, n))) * 1e6 + rng.normal(0, 1e4, n)
        np.testing.assert_array_equal(
            moving_mean(x, width), uniform_filter1d(x, width, mode="nearest")
        )


def _offset_record(fs, delta0, jump, seed):
    """40 contacts a period ``T`` apart, each starting at a random time within its sample
    interval where the penetration (a free flight crossing ``delta0`` at 0.3 m/s, 3 um of
    noise) reaches ``delta0``; the force jumps there (``jump``) or rises from zero."""
    rng = np.random.default_rng(seed)
    T, v, a, tc = 0.04, 0.3, 9.81, 0.004
    t = np.arange(0.0, 41 * T, 1.0 / fs)
    onsets = (np.arange(40) + 0.5) * T + rng.uniform(0, 1.0 / fs, 40)
    zeta, F = np.full(t.size, -1e-3), np.zeros(t.size)
    for t_k in onsets:
        w = (t > t_k - 0.4 * T) & (t < t_k + 0.5 * T)
        s = t[w] - t_k
        zeta[w] = delta0 + v * s - 0.5 * a * s**2
        c = (t >= t_k) & (t < t_k + tc)
        F[c] = (5e4 if jump else 0.0) + 2e7 * (t[c] - t_k)
    return t, F, zeta + rng.normal(0.0, 3e-6, t.size), T


@pytest.mark.parametrize("fs", [10e3, 20e3, 80e3])
@pytest.mark.parametrize("jump", [True, False])
def test_the_onset_penetration_reads_a_contact_offset_without_a_sample_bias(fs, jump):
    """The closed form: the recorded penetration at each force onset is the offset.  Read at
    the first sample above the force's threshold it would be ``v dt / 2`` high on average
    (7.5 um at 20 kHz); the reading is within 1.5 um at every rate."""
    from discovery.vibroimpact.data.contact_edges import onset_penetrations

    t, F, zeta, T = _offset_record(fs, 5e-5, jump, seed=int(fs) + jump)
    reads = onset_penetrations(t, F, zeta, T)
    assert reads.size == 40
    assert np.median(reads) == pytest.approx(5e-5, abs=1.5e-6)
    at_sample = [zeta[np.searchsorted(t, t_k)] for t_k in t[np.flatnonzero(np.diff(F > 0)) + 1]]
    if fs <= 20e3:  # the first sample in contact: biased by about half a sample's motion
        assert np.median(at_sample) - 5e-5 > 3e-6
