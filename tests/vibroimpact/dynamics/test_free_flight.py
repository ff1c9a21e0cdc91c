"""The kernel's free flight in closed form (``Tolerances(free_flight="closed")``, the
default) against the integrator's steps throughout (``"integrate"``, the cross-check path)
on every regime of the suite and every catalogue effect that acts in the simulation, against
the scipy reference path, against central differences for the sensitivities, and in the
hard cases of the onset search (grazes and near misses below the integrator's probes)."""

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.vibroimpact.dynamics.kernel import codes as K
from discovery.vibroimpact.dynamics.reference import reference_simulate
from discovery.vibroimpact.dynamics.simulation import EVENT_NAMES, Tolerances, simulate
from discovery.vibroimpact.dynamics.steady_states import StroboscopicMap, steady_state
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import Scenario, load_scenario

PAPER, LIGHT = load_scenario("paper"), load_scenario("light")
_P4 = Scenario(m1=10800.0, m2=5960.0, k1=216000000.0, c1=96300.0, A=393000.0, frequency=13.7)
_PD = Scenario(  # tests/vibroimpact/dynamics/test_steady_state.py
    m1=4770.989046559852,
    m2=5430.940884957566,
    k1=161209836.32495606,
    c1=343759.5619373554,
    A=231045.9099917681 * 1.01,
    frequency=37.287324033370695,
)
_SHORT = Scenario(m1=4390.0, m2=3270.0, k1=21900000.0, c1=73600.0, A=142000.0, frequency=16.6)

# regime -> (scenario, law, periods from the scenario's start)
REGIMES = {
    "P1 paper": (PAPER, PAPER.law.to_text(), 10),
    "P1 light (Hunt-Crossley)": (LIGHT, LIGHT.law.to_text(), 10),
    "slow P1 (multiplier -0.985)": (_PD, "1448000000*z + 9927000*zd", 20),
    "P2 (just past the doubling)": (
        _PD.replace(A=231045.9099917681 * 1.03),
        "1448000000*z + 9927000*zd",
        20,
    ),
    "P4 subharmonic": (_P4, "81100000*z + 4910000*zd", 20),
    "short contact": (_SHORT, "3370000000*z + 8150000*zd + 78700000000*z*zd", 20),
    "chatter: re-contacts, riding the frame": (LIGHT, "2.3e10*z^1.5 + 5.5e11*z^1.5*zd", 60),
    "sticking (long contacts)": (PAPER.replace(A=2.2e5), PAPER.law.to_text(), 10),
    "adhesive law (release, resume)": (PAPER, "2.06e8*z - 1e10*z^2 + 1.28e7*zd", 8),
    # the catalogue's effects that act in the simulation
    "penetration_velocity_coupling": (PAPER, "2.06e8*z + 1.28e7*zd + 5e10*z*zd", 8),
    "hertzian_stiffening": (PAPER, "2.06e8*z + 1.28e7*zd + 5e9*z^1.5", 8),
    "unloading_damping": (PAPER, "2.06e8*z + 1.28e7*zd; unloading: 6e6*zd", 8),
    "permanent_set": (PAPER, "2.06e8*z + 1.28e7*zd; set: 0.35", 8),
    "set, damping and coupling": (
        PAPER,
        "2.06e8*z + 5e10*z*zd + 4e6*zd; unloading: 3e6*zd; set: 0.2",
        8,
    ),
    "mass_loss": (PAPER.replace(mass_loss=0.01), PAPER.law.to_text(), 8),
    # no closed form for the frame: the integrator's steps on both paths
    "support_nonlinearity (k3)": (PAPER.replace(k3=2e12), PAPER.law.to_text(), 8),
}


def _run(sc, law, n, free_flight, rtol=1e-10, contact="closed", **kw):
    te = np.linspace(0.0, n * sc.period, 200 * n + 1)
    tol = Tolerances(rtol=rtol, free_flight=free_flight, contact=contact)
    return simulate(sc, law, (0.0, n * sc.period), t_eval=te, tolerances=tol, **kw)


def _far(te, event_t, T, gap=1e-4):
    far = np.ones(te.size, dtype=bool)
    for e in event_t:
        far &= np.abs(te - e) > gap * T
    return far


@pytest.mark.parametrize("name", list(REGIMES))
def test_closed_form_flight_agrees_with_the_integrator(name):
    sc, text, n = REGIMES[name]
    law = ForceLaw.parse(text)
    a, b = _run(sc, law, n, "closed"), _run(sc, law, n, "integrate")
    T = sc.period
    # the same events in the same order
    assert [EVENT_NAMES[k] for k in a.event_kind] == [EVENT_NAMES[k] for k in b.event_kind]
    assert np.sum(a.event_kind == K.EV_ONSET) >= 5
    # event times: measured <= 1.5e-9 T (the integrator path's error at rtol 1e-10; the
    # re-contact case, 2.2e-10 T elsewhere)
    assert np.max(np.abs(a.event_t - b.event_t)) < 1e-8 * T
    # states and force away from the events: measured <= 2.5e-8 of the scales, 2.3e-8 of
    # the force's peak (the adhesive law)
    far = _far(a.t, np.concatenate([a.event_t, b.event_t]), T)
    x, v = sc.scales()
    scale = np.array([x, v, x, v])[:, None]
    # measured <= 1.7e-6 (undamped: the frame near resonance grows to 7x the scale; the
    # closed form is then within 2.8e-7 of the scipy path at rtol 1e-12, the integrator
    # path within 2.0e-6), 1.7e-7 critically damped, 5e-10 overdamped
    assert np.max(np.abs(a.y[:, far] - b.y[:, far]) / scale) < 1e-5
    peak = np.max(np.abs(b.force))
    assert np.max(np.abs(a.force[far] - b.force[far])) < 2e-7 * peak
    # the flights are not stepped: fewer steps (the same ones with supports' cubic term)
    if sc.k3 == 0:
        assert a.n_steps < b.n_steps
    else:
        np.testing.assert_array_equal(a.y, b.y)
        assert a.n_steps == b.n_steps


@pytest.mark.parametrize(
    "name",
    # (not the re-contact case: scipy steps over its brief dip,
    # tests/vibroimpact/dynamics/test_kernel_events.py)
    ["P1 paper", "P4 subharmonic", "permanent_set", "sticking (long contacts)", "short contact"],
)
def test_closed_form_flight_agrees_with_the_scipy_reference(name):
    sc, text, n = REGIMES[name]
    law = ForceLaw.parse(text)
    n = min(n, 10)
    T = sc.period
    te = np.linspace(0.0, n * T, 200 * n + 1)
    tr = _run(sc, law, n, "closed")
    ref = reference_simulate(sc, law, (0.0, n * T), t_eval=te, rtol=1e-10, max_events=100_000)
    onsets = [t for t, k, _ in ref["events"] if k == "onset"]
    np.testing.assert_allclose(
        tr.event_t[tr.event_kind == K.EV_ONSET], onsets, rtol=0, atol=1e-8 * T
    )
    far = _far(te, tr.event_t, T)
    x, v = sc.scales()
    scale = np.array([x, v, x, v])[:, None]
    # measured <= 1.1e-7 of the scales (the short contact; the integrator path: 1.2e-7),
    # <= 1.1e-8 on the others; onsets <= 6.4e-10 T
    assert np.max(np.abs(tr.y[:, far] - ref["y"][:, far]) / scale) < 5e-7


@pytest.mark.parametrize(
    "name", ["P1 paper", "P4 subharmonic", "short contact", "sticking (long contacts)"]
)
def test_evenly_spaced_samples_equal_the_closed_form_at_each_sample(name):
    """A record's evenly spaced samples advance through a flight, and through a contact in
    closed form, by the phase's semigroup; each equals the closed form evaluated at that
    sample alone (the first sample of a run is always evaluated directly): states, force,
    and the force's and the penetration's derivatives."""
    sc, text, n = REGIMES[name]
    law = ForceLaw.parse(text)
    n = min(n, 6)
    T = sc.period
    # a record's sample times: 20 kHz from an offset, as a long record's late part
    te = 3.7 * T + np.arange(int(n * T * 20000)) / 20000.0
    span = (te[0] - 0.3 * T, te[-1] + 1e-9)
    kw = dict(sensitivities="coefficients", control_sensitivities=False)
    whole = simulate(sc, law, span, t_eval=te, **kw)
    free = np.flatnonzero(whole.mode == 0)
    contact = np.flatnonzero(whole.mode != 0)
    assert free.size > 0.2 * te.size and contact.size > 20
    x, v = sc.scales()
    scale = np.array([x, v, x, v])
    dF, dz = whole.force_sensitivity, whole.penetration_sensitivity
    dF_scale, dz_scale = np.max(np.abs(dF), axis=1), np.max(np.abs(dz), axis=1)
    peak = np.max(np.abs(whole.force))
    worst = np.zeros(4)
    for k in np.concatenate(
        [free[:: max(1, free.size // 30)], contact[:: max(1, contact.size // 30)]]
    ):
        one = simulate(sc, law, span, t_eval=te[k : k + 1], **kw)
        assert one.mode[0] == whole.mode[k]
        worst = np.maximum(
            worst,
            [
                np.max(np.abs(one.y[:, 0] - whole.y[:, k]) / scale),
                abs(one.force[0] - whole.force[k]) / peak,
                np.max(np.abs(one.force_sensitivity[:, 0] - dF[:, k]) / dF_scale),
                np.max(np.abs(one.penetration_sensitivity[:, 0] - dz[:, k]) / dz_scale),
            ],
        )
    # measured <= 1.7e-12 of the scales (the samples' own rounding: their times carry
    # about 1e-16 s of it), 1.1e-13 of the force's peak and 4.8e-13 of the derivatives'
    # largest; the kernel's tolerance is 1e-9
    assert np.all(worst < 1e-10)


@pytest.mark.parametrize("name", ["P1 paper", "slow P1 (multiplier -0.985)", "P4 subharmonic"])
def test_steady_states_agree(name):
    sc, text, _ = REGIMES[name]
    law = ForceLaw.parse(text)
    a = steady_state(sc, law, tolerances=Tolerances(free_flight="closed"))
    b = steady_state(sc, law, tolerances=Tolerances(free_flight="integrate"))
    assert a.regime == b.regime and a.impacts == b.impacts
    pm = StroboscopicMap(sc, law)
    # measured <= 1.6e-8 and 9e-9
    assert np.max(np.abs(a.y0 - b.y0) / pm.scale) < 1e-6
    ma, mb = np.sort_complex(a.multipliers), np.sort_complex(b.multipliers)
    assert np.max(np.abs(ma - mb)) < 1e-6


def test_sensitivities_agree_and_match_central_differences():
    """Through two flights and two contacts: the state and coefficient sensitivities of the
    closed-form path against the integrator path's and against central differences."""
    sc, law = PAPER, PAPER.law
    tol, T = Tolerances(rtol=1e-10), sc.period
    y0 = simulate(sc, law, (0.0, 5 * T), tolerances=tol).y_final
    span = (5 * T, 7 * T)
    a = simulate(sc, law, span, y0=y0, tolerances=tol, sensitivities="all")
    b = simulate(
        sc,
        law,
        span,
        y0=y0,
        tolerances=Tolerances(rtol=1e-10, free_flight="integrate"),
        sensitivities="all",
    )
    x, v = sc.scales()
    s4 = np.array([x, v, x, v])
    coef = np.array(law.coefficients)
    size = np.concatenate([s4, coef])
    rel = lambda S: S * size[None, :] / s4[:, None]  # noqa: E731
    # measured 1.3e-10 between the paths
    assert np.max(np.abs(rel(a.sensitivity) - rel(b.sensitivity))) < 1e-6
    dy = []
    for j in range(size.size):
        ends = []
        for sign in (1.0, -1.0):
            y, c = y0.copy(), coef.copy()
            if j < 4:
                y[j] += sign * 1e-6 * size[j]
            else:
                c[j - 4] += sign * 1e-6 * size[j]
            ends.append(simulate(sc, law.with_coefficients(c), span, y0=y, tolerances=tol).y_final)
        dy.append((ends[0] - ends[1]) / (2e-6 * size[j]))
    # measured 4.6e-8 on both paths (the differences' own error)
    assert np.max(np.abs(rel(a.sensitivity) - rel(np.array(dy).T))) < 1e-5
    np.testing.assert_allclose(
        a.event_time_sensitivity, b.event_time_sensitivity, atol=1e-7 * T
    )  # 4.6e-9 T


def test_exact_monodromy_matches_central_differences_on_the_closed_form_path():
    ss = steady_state(PAPER, PAPER.law)
    pm = StroboscopicMap(PAPER, PAPER.law)
    J = pm.jacobian(ss.y0)
    Jfd = np.empty((4, 4))
    for j in range(4):
        d = 1e-6 * pm.scale[j]
        yp, ym = ss.y0.copy(), ss.y0.copy()
        yp[j] += d
        ym[j] -= d
        Jfd[:, j] = (pm.advance(yp) - pm.advance(ym)) / (2 * d)
    err = np.abs(J - Jfd) * pm.scale[None, :] / pm.scale[:, None]
    assert err.max() < 1e-5  # measured 2.2e-8


# ------------------------------------------------------------------ the onset search
AMP, OMEGA = 1.0e-3, 10 * np.pi


def _graze(depth, shift=0.0, g=0.0, c1=0.0):
    """The frame oscillates on its spring (no drive), the moulding floats at ``AMP - depth``
    (no gravity): ``zeta`` peaks at ``+depth`` (a graze) or stays ``-depth`` short of the
    surface (a near miss) once a cycle (tests/vibroimpact/dynamics/test_kernel_events.py)."""
    return Scenario(
        m1=1.0,
        m2=1.0,
        k1=OMEGA**2,
        c1=c1,
        A=0.0,
        frequency=20.0,
        g=g,
        initial=(
            -AMP * np.cos(OMEGA * shift),
            AMP * OMEGA * np.sin(OMEGA * shift),
            AMP - depth,
            0.0,
        ),
    )


@pytest.mark.parametrize("depth", [1e-9, 1e-12, 1e-14])
@pytest.mark.parametrize("shift", [0.0, 1.3e-4, 3.7e-4])
def test_a_graze_far_below_any_step_is_found(depth, shift):
    sc = _graze(depth, shift)
    tr = simulate(sc, ForceLaw.parse("1e6*z"), (0.0, 0.15))
    assert list(tr.event_kind) == [K.EV_ONSET, K.EV_UNLOAD, K.EV_LOSS]
    t_on = (np.pi - np.arccos(1.0 - depth / AMP)) / OMEGA - shift
    closing = OMEGA * np.sqrt(2 * AMP * depth - depth**2)
    # the zeta error at the crossing: measured <= 3e-19 m (8 to 23 intervals a flight)
    assert abs(tr.event_t[0] - t_on) * closing < 1e-15


@pytest.mark.parametrize("miss", [1e-9, 1e-12])
def test_a_near_miss_is_not_a_contact(miss):
    sc = _graze(-miss)
    tr = simulate(sc, ForceLaw.parse("1e6*z"), (0.0, 0.5))
    assert tr.success and tr.event_t.size == 0
    assert tr.n_steps <= 2  # one flight (and no steps)


def test_the_first_root_is_found():
    """A fast frame (20 Hz on its spring, lightly damped) under a falling moulding: ``zeta``
    touches zero briefly at its first peaks before it crosses for good; the onset is the
    first crossing of the integrator path's dense output sampled every 1e-7 s."""
    sc = Scenario(
        m1=1.0,
        m2=1.0,
        k1=(40 * np.pi) ** 2,
        c1=0.3,
        A=0.0,
        frequency=1.0,
        g=9.81,
        initial=(0.0, 0.2, 1.05e-3, 0.0),
    )
    law = ForceLaw.parse("1e8*z")
    tr = simulate(sc, law, (0.0, 0.2), max_events=1)
    t = np.arange(0.0, tr.event_t[0] + 1e-4, 1e-7)
    probe = simulate(
        sc,
        law,
        (0.0, t[-1]),
        t_eval=t,
        max_events=1,
        tolerances=Tolerances(rtol=1e-12, free_flight="integrate", hmax_fraction=1e-4),
    )
    first = probe.event_t[0]
    assert abs(tr.event_t[0] - first) < 1e-9
    assert tr.event_t[0] <= t[np.argmax(probe.zeta > 0)]


def test_free_flight_option_is_validated():
    with pytest.raises(InputError, match="free_flight"):
        Tolerances(free_flight="exact")
    assert Tolerances().as_dict()["free_flight"] == "closed"


@pytest.mark.parametrize("c1", [0.0, 20.0, 100.0, 2000.0])  # undamped to overdamped frames
def test_frames_from_undamped_to_overdamped(c1):
    """Critical damping is c1 = 20 here; a long flight of an overdamped frame takes the
    transition matrix's exponential form (``r s > 1``)."""
    sc = Scenario(
        m1=1.0,
        m2=0.5,
        k1=100.0,
        c1=c1,
        A=30.0,
        frequency=2.0,
        g=9.81,
        initial=(0.0, 0.0, 0.01, 3.0),
    )
    law = ForceLaw.parse("1e6*z + 50*zd")
    # the flights alone: the same integrated contacts on both paths (this stiff law's
    # closed-form contacts are checked in tests/vibroimpact/dynamics/test_closed_contact.py)
    a = _run(sc, law, 6, "closed", contact="integrate")
    b = _run(sc, law, 6, "integrate")
    assert [EVENT_NAMES[k] for k in a.event_kind] == [EVENT_NAMES[k] for k in b.event_kind]
    assert np.sum(a.event_kind == K.EV_ONSET) >= 3
    assert np.max(np.abs(a.event_t - b.event_t)) < 1e-8 * sc.period
    far = _far(a.t, np.concatenate([a.event_t, b.event_t]), sc.period)
    x, v = sc.scales()
    scale = np.array([x, v, x, v])[:, None]
    # measured <= 1.7e-6 (undamped: the frame near resonance grows to 7x the scale; the
    # closed form is then within 2.8e-7 of the scipy path at rtol 1e-12, the integrator
    # path within 2.0e-6), 1.7e-7 critically damped, 5e-10 overdamped
    assert np.max(np.abs(a.y[:, far] - b.y[:, far]) / scale) < 1e-5


def test_first_onset_against_brute_force_sampling_of_the_exact_flight():
    """Random machines and states: the kernel's first onset against the first positive
    sample of the exact penetration on a grid of 2e5 points (the record-span state fit's own
    closed form, :mod:`discovery.vibroimpact.verify.state`, an independent implementation):
    no crossing is missed and none is invented (within one period)."""
    from discovery.vibroimpact.verify.state import _frame_basis, _frame_particular

    rng = np.random.default_rng(30)
    law = ForceLaw.parse("1e9*z")
    checked = missed = 0
    for _ in range(60):
        m1 = 10 ** rng.uniform(2, 4)
        f = rng.uniform(5, 50)
        k1 = m1 * (2 * np.pi * f * rng.uniform(0.2, 3.0)) ** 2
        c1 = 2 * np.sqrt(k1 * m1) * 10 ** rng.uniform(-3, 0.5)
        A = m1 * 9.81 * rng.uniform(0.0, 5.0)
        sc0 = Scenario(m1=m1, m2=m1, k1=k1, c1=c1, A=A, frequency=f)
        x, v = sc0.scales()
        w1, v1 = rng.normal(0, x), rng.normal(0, v)
        gap = x * 10 ** rng.uniform(-6, 1.5)
        y0 = (w1, v1, w1 + gap, rng.normal(0, v))  # the moulding ``gap`` above the frame
        sc = sc0.replace(initial=y0)
        t1 = 1.0 / f
        tr = simulate(sc, law, (0.0, t1), max_events=1, throw=False)
        s = np.linspace(0.0, t1, 200_001)
        ws, P, Q, w = _frame_particular(sc)

        def xp(tt, ws=ws, P=P, Q=Q, w=w):
            sn, cs = np.sin(w * tt), np.cos(w * tt)
            return np.stack([ws + P * sn + Q * cs, w * (P * cs - Q * sn)])

        u = np.einsum(
            "nij,j->ni", _frame_basis(sc, s), np.array(y0[:2]) - xp(np.array([0.0]))[:, 0]
        )
        zeta = xp(s)[0] + u[:, 0] - (y0[2] + y0[3] * s - 0.5 * sc.g * s * s)
        pos = np.flatnonzero(zeta > 1e-12 * x)
        onset = tr.event_t[0] if tr.event_t.size and tr.event_kind[0] == K.EV_ONSET else None
        if pos.size:
            # the onset is at or before the first positive sample, and after the last
            # sample before it (unless the grid itself missed an earlier brief contact)
            assert onset is not None and onset <= s[pos[0]] + 1e-12
            assert onset >= s[pos[0] - 1] - 1e-12 or np.interp(onset, s, zeta) > -1e-9 * x
            checked += 1
        elif onset is not None:
            # a contact the grid did not see: a graze, between samples
            near = np.abs(s - onset) < 2 * (s[1] - s[0])
            assert np.max(zeta[near]) > -1e-9 * x
        else:
            missed += 1
    assert checked >= 20 and missed >= 5  # 46 crossings, 14 flights without one


def test_a_contact_offset_moves_only_the_recorded_state():
    """The catalogue's contact offset shifts the recorded moulding against the model's
    (:meth:`Scenario.model_state`); the kernel's flights are the model's, so the closed form
    covers it: both paths agree, and the onset is where the recorded penetration reaches
    the offset."""
    sc = PAPER.replace(offset=1.5e-3)
    y_rec = np.array([0.0, 0.05, 0.0, 0.3])  # recorded penetration 0, below the offset
    y0 = sc.model_state(y_rec)
    T = sc.period
    a, b = (
        simulate(sc, sc.law, (0.0, 3 * T), y0=y0, tolerances=Tolerances(free_flight=ff))
        for ff in ("closed", "integrate")
    )
    assert a.event_kind[0] == K.EV_ONSET and list(a.event_kind) == list(b.event_kind)
    assert np.max(np.abs(a.event_t - b.event_t)) < 1e-8 * T
    zeta_on = a.event_y[0, 0] - a.event_y[0, 2]
    assert sc.recorded_penetration(zeta_on) == pytest.approx(1.5e-3, abs=1e-15)
