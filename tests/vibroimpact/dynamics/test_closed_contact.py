"""The kernel's contact in closed form for a linear law (``Tolerances(contact="closed")``,
the default) against the integrator's steps (``contact="integrate"``, the cross-check path,
at a tighter tolerance so that its own error stays below the comparison's) on every regime
of the suite, random machines and random starts inside a contact, against the scipy
reference path, the sensitivities along the start's states through it, and the switch
itself (laws and runs it leaves to the integrator)."""

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.vibroimpact.dynamics.kernel import codes as K
from discovery.vibroimpact.dynamics.kernel.contact_modes import _contact_eig_scaled, _contact_matrix
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
_PD_LAW = "1448000000*z + 9927000*zd"
# the paper's contact is critically damped at c = 2 sqrt(k m) = 2.03e6 (m = 5000 kg reduced)
PAPER_K = "2.06e8*z"

# regime -> (scenario, law, periods from the scenario's start)
REGIMES = {
    "P1 paper": (PAPER, PAPER.law.to_text(), 10),
    "slow P1 (multiplier -0.985, long transient)": (_PD, _PD_LAW, 40),
    "P2 (just past the doubling)": (_PD.replace(A=231045.9099917681 * 1.03), _PD_LAW, 20),
    "P4 subharmonic": (_P4, "81100000*z + 4910000*zd", 20),
    "short contacts (stiff law)": (_SHORT, "3.37e9*z + 8.15e6*zd", 20),
    "long contacts (sticking)": (PAPER.replace(A=2.2e5), PAPER.law.to_text(), 10),
    "long contacts (soft law)": (PAPER, "2e7*z + 1e6*zd", 10),
    "chatter: re-contacts within 1 % of a period": (
        LIGHT.replace(m2=1000.0),
        "2e9*z + 1.41e5*zd",
        8,
    ),
    "undamped contact (c = 0)": (PAPER, PAPER_K, 10),
    "near-critically damped contact": (PAPER, PAPER_K + " + 2.03e6*zd", 10),
    "strongly damped contact": (PAPER, PAPER_K + " + 1e8*zd", 10),
    "unloading damping (release, clipped)": (PAPER, PAPER.law.to_text() + "; unloading: 6e6*zd", 8),
    "undamped frame (c1 = 0)": (PAPER.replace(c1=0.0), PAPER.law.to_text(), 10),
    "frame without a spring (k1 = 0)": (PAPER.replace(k1=0.0), PAPER.law.to_text(), 10),
}


def _run(sc, law, n, contact, rtol=1e-10, y0=None, t0=0.0, **kw):
    te = np.linspace(t0, t0 + n * sc.period, 200 * n + 1)
    tol = Tolerances(rtol=rtol, contact=contact)
    return simulate(
        sc,
        law,
        (t0, t0 + n * sc.period),
        y0=y0,
        t_eval=te,
        tolerances=tol,
        max_events=100_000,
        **kw,
    )


def _far(te, event_t, T, gap=1e-4):
    far = np.ones(te.size, dtype=bool)
    for e in event_t:
        far &= np.abs(te - e) > gap * T
    return far


def _scale(sc):
    x, v = sc.scales()
    return np.array([x, v, x, v])[:, None]


def _agree(a, b, sc, dt_tol, dy_tol, df_tol):
    """The same events in the same order, event times within ``dt_tol`` of the period, the
    states within ``dy_tol`` of the scales and the force within ``df_tol`` of its peak away
    from the events; the largest differences."""
    T = sc.period
    assert [EVENT_NAMES[k] for k in a.event_kind] == [EVENT_NAMES[k] for k in b.event_kind]
    dt = np.max(np.abs(a.event_t - b.event_t)) / T
    far = _far(a.t, np.concatenate([a.event_t, b.event_t]), T)
    dy = np.max(np.abs(a.y[:, far] - b.y[:, far]) / _scale(sc))
    df = np.max(np.abs(a.force[far] - b.force[far])) / np.max(np.abs(b.force))
    assert dt < dt_tol and dy < dy_tol and df < df_tol, (dt, dy, df)
    return dt, dy, df


# the comparison's limits where the integrator's own error at rtol 1e-13 dominates: event
# times [T], states [scales] and force [peak] (measured 4.0e-11, 9.8e-9, 4.7e-9 with the short
# contacts; 6.3e-10, 1.3e-7, 3.5e-8 with the chatter, whose re-contacts amplify the error: as
# the integrator's tolerance tightens from 1e-11 to 1e-13 its event times close in on the
# closed form's tenfold at each step); elsewhere 1e-10, 1e-9, 1e-9
LIMITS = {
    "short contacts (stiff law)": (1e-9, 1e-7, 5e-8),
    "chatter: re-contacts within 1 % of a period": (5e-9, 1e-6, 3e-7),
}


@pytest.mark.parametrize("name", list(REGIMES))
def test_closed_form_contact_agrees_with_the_integrator(name):
    """Both paths at rtol 1e-13 (the steps a closed-form run still takes, the flights of a
    frame without a spring and the clipped phases, as accurate as the integrator path's)."""
    sc, text, n = REGIMES[name]
    law = ForceLaw.parse(text)
    a = _run(sc, law, n, "closed", rtol=1e-13)
    b = _run(sc, law, n, "integrate", rtol=1e-13)
    assert np.sum(a.event_kind == K.EV_ONSET) >= 5
    # measured <= 2e-12 T, 1.1e-11 of the scales, 1.2e-11 of the force's peak (the frame
    # without a spring: 1.9e-12 T, 1.1e-10, 1.0e-10); LIMITS above
    _agree(a, b, sc, *LIMITS.get(name, (1e-10, 1e-9, 1e-9)))
    # the contacts are not stepped (the flights neither but with k1 = 0)
    assert a.n_steps < (0.1 if sc.k1 > 0 else 0.5) * b.n_steps
    inside = (a.mode == K.LOAD) | (a.mode == K.UNLOAD)
    assert np.any(inside)
    np.testing.assert_array_equal(a.mode[inside], b.mode[inside])


@pytest.mark.parametrize(
    "name",
    [
        "P1 paper",
        "P4 subharmonic",
        "short contacts (stiff law)",
        "long contacts (sticking)",
        "undamped contact (c = 0)",
        "strongly damped contact",
        "unloading damping (release, clipped)",
    ],
)
def test_closed_form_contact_agrees_with_the_scipy_reference(name):
    sc, text, n = REGIMES[name]
    law = ForceLaw.parse(text)
    n = min(n, 10)
    T = sc.period
    te = np.linspace(0.0, n * T, 200 * n + 1)
    tr = _run(sc, law, n, "closed")
    ref = reference_simulate(sc, law, (0.0, n * T), t_eval=te, rtol=1e-12, max_events=100_000)
    kinds = [k for _, k, _ in ref["events"]]
    assert [EVENT_NAMES[k] for k in tr.event_kind] == kinds
    ref_t = np.array([t for t, _, _ in ref["events"]])
    # measured <= 1.0e-10 T (the clipped phases, integrated at rtol 1e-10), 4.3e-11 T the
    # short contacts, 1.4e-11 T elsewhere
    assert np.max(np.abs(tr.event_t - ref_t)) < 1e-9 * T
    far = _far(te, tr.event_t, T)
    # measured <= 2.5e-9 of the scales (the short contacts), 4.1e-10 elsewhere
    assert np.max(np.abs(tr.y[:, far] - ref["y"][:, far]) / _scale(sc)) < 1e-8


@pytest.mark.parametrize("name", ["P1 paper", "slow P1 (multiplier -0.985, long transient)"])
def test_steady_states_agree(name):
    sc, text, _ = REGIMES[name]
    law = ForceLaw.parse(text)
    a = steady_state(sc, law, tolerances=Tolerances(contact="closed"))
    b = steady_state(sc, law, tolerances=Tolerances(contact="integrate"))
    assert a.regime == b.regime and a.impacts == b.impacts
    pm = StroboscopicMap(sc, law)
    # measured <= 2.8e-9, within the solver's residuals (4.5e-10 and 4.8e-9 on the slow
    # orbit); the multipliers: 8.2e-9
    assert np.max(np.abs(a.y0 - b.y0) / pm.scale) < 1e-7
    ma, mb = np.sort_complex(a.multipliers), np.sort_complex(b.multipliers)
    assert np.max(np.abs(ma - mb)) < 1e-7


def _random_machine(rng):
    """A machine and linear law drawn over wide ranges: the frame's natural frequency from
    0.2 to 5 times the drive's, frame damping from 0.1 % to 50 % of critical (or none), the
    contact 1 to 300 times as stiff as the supports, its damping 5 % to 3 times critical."""
    m1 = 10 ** rng.uniform(3, 4.5)
    m2 = m1 * 10 ** rng.uniform(-1.3, 0.5)
    f = rng.uniform(5, 50)
    k1 = m1 * (2 * np.pi * f * 10 ** rng.uniform(-0.7, 0.7)) ** 2
    c1 = 2 * np.sqrt(k1 * m1) * 10 ** rng.uniform(-3, -0.3) * (rng.random() > 0.15)
    A = m1 * 9.81 * 10 ** rng.uniform(0.3, 1.5)
    k = k1 * 10 ** rng.uniform(0, 2.5)
    c = 2 * np.sqrt(k * m1 * m2 / (m1 + m2)) * 10 ** rng.uniform(-1.3, 0.5)
    sc = Scenario(m1=m1, m2=m2, k1=k1, c1=c1, A=A, frequency=f)
    return sc, ForceLaw.parse(f"{float(k)!r}*z + {float(c)!r}*zd")


def test_random_machines():
    rng = np.random.default_rng(31)
    onsets = 0
    for _ in range(20):
        sc, law = _random_machine(rng)
        a = _run(sc, law, 6, "closed")
        b = _run(sc, law, 6, "integrate", rtol=1e-13)
        # measured <= 9.5e-11 T, 2.8e-8 of the scales, 5.6e-9 of the force's peak
        _agree(a, b, sc, 1e-9, 3e-7, 5e-8)
        onsets += np.sum(a.event_kind == K.EV_ONSET)
    assert onsets >= 100  # 157


def test_the_first_event_from_random_starts_inside_a_contact():
    """Random machines started at random states inside a loading or an unloading phase (a
    penetration up to a few times the static one, rates of either sign): the first event
    against the integrator's at a tight tolerance with steps of 1e-4 period, so that no
    brief excursion across a switching surface escapes its probes."""
    rng = np.random.default_rng(32)
    kinds = set()
    for _ in range(30):
        sc, law = _random_machine(rng)
        x, v = sc.scales()
        w1 = rng.normal(0.0, x)
        y0 = np.array([w1, rng.normal(0.0, v), w1 - x * 10 ** rng.uniform(-3, 0.5), 0.0])
        y0[3] = y0[1] - v * rng.normal(0.0, 1.0)
        T = sc.period
        a = simulate(sc, law, (0.0, 2 * T), y0=y0, max_events=1, tolerances=Tolerances(rtol=1e-10))
        tol = Tolerances(rtol=1e-12, contact="integrate", hmax_fraction=1e-4)
        b = simulate(sc, law, (0.0, 2 * T), y0=y0, max_events=1, tolerances=tol)
        assert a.event_kind[0] == b.event_kind[0]
        assert abs(a.event_t[0] - b.event_t[0]) < 1e-12 * T  # measured <= 6.4e-15 T
        kinds.add(int(a.event_kind[0]))
    assert {K.EV_UNLOAD, K.EV_LOSS, K.EV_RELOAD} <= kinds  # 18, 11, 1


def test_the_first_events_from_starts_near_the_switching_surfaces():
    """Random machines started inside a contact a hair from its surfaces (a penetration or a
    rate down to 1e-10 of the scales, of either sign for the rate): the first three events
    against the integrator's with steps of 1e-4 period (the start's hair handling and the
    grazes that follow)."""
    rng = np.random.default_rng(33)
    kinds = set()
    for it in range(60):
        sc, law = _random_machine(rng)
        x, v = sc.scales()
        w1 = rng.normal(0.0, x)
        near = it % 3
        z0 = x * 10 ** (rng.uniform(-10, -2) if near == 0 else rng.uniform(-3, 0))
        rate = 10 ** rng.uniform(-10, -2) if near else rng.uniform(0.1, 1)
        zd0 = v * rng.choice([-1.0, 1.0]) * rate
        y0 = np.array([w1, rng.normal(0.0, v), w1 - z0, 0.0])
        y0[3] = y0[1] - zd0
        T = sc.period
        a = simulate(sc, law, (0.0, 2 * T), y0=y0, max_events=3, tolerances=Tolerances(rtol=1e-10))
        tol = Tolerances(rtol=1e-12, contact="integrate", hmax_fraction=1e-4)
        b = simulate(sc, law, (0.0, 2 * T), y0=y0, max_events=3, tolerances=tol)
        n = min(3, a.event_t.size)
        assert n and list(a.event_kind[:n]) == list(b.event_kind[:n])
        assert np.max(np.abs(a.event_t[:n] - b.event_t[:n])) < 1e-11 * T  # measured 2.5e-13 T
        kinds.add(tuple(int(k) for k in a.event_kind[:2]))
    # unload then loss, loss then onset, reload then unload, unload then reload, a lone loss
    assert len(kinds) >= 4


def test_the_contact_modes_eigenvalues_against_lapack():
    """The kernel's eigen-decomposition of a contact mode (the quartic's roots by
    Aberth-Ehrlich, null vectors of the 2x2 quadratic pencil) against numpy's on random
    machines and laws over wide ranges (springless and undamped frames and contacts too):
    every pair passes the kernel's residual check, and where the eigenvectors are
    well-conditioned the eigenvalues agree with LAPACK's."""
    rng = np.random.default_rng(34)
    worst, checked = 0.0, 0
    for _ in range(400):
        m1 = 10 ** rng.uniform(0, 5)
        m2 = m1 * 10 ** rng.uniform(-2, 1)
        k1 = m1 * 10 ** rng.uniform(0, 6) * (rng.random() > 0.1)
        c1 = 2 * np.sqrt(max(k1, 1.0) * m1) * 10 ** rng.uniform(-4, 1) * (rng.random() > 0.1)
        k = max(k1, m1) * 10 ** rng.uniform(-1, 4)
        c = 2 * np.sqrt(k * m1 * m2 / (m1 + m2)) * 10 ** rng.uniform(-3, 1.5) * (rng.random() > 0.1)
        p = np.zeros(K.N_PARAMS)
        p[:7] = m1, m2, k1, c1, 1.0, 10.0, 9.81
        dsc = np.array([1e-3, 1e-1, 1e-3, 1e-1])
        Ms = np.empty((4, 4), dtype=complex)
        _contact_matrix(p, k, c, dsc, Ms)
        lam, Vs = np.empty(4, dtype=complex), np.empty((4, 4), dtype=complex)
        assert _contact_eig_scaled(p, k, c, dsc, Ms, lam, Vs)
        ref, V = np.linalg.eig(Ms)
        if np.linalg.cond(V) > 1e4:
            continue  # near a defective pair: LAPACK's own error grows (the kernel integrates)
        scale = np.max(np.abs(ref))
        err = max(np.min(np.abs(lam - r)) for r in ref) / scale
        worst = max(worst, err)
        checked += 1
    assert checked > 300 and worst < 1e-12  # measured 1.6e-14 of |lambda|max over 368


@pytest.mark.parametrize("phase", [K.LOAD, K.UNLOAD])
def test_a_start_inside_a_phase(phase):
    """A run started at an output sample inside a loading or an unloading phase continues as
    the run it was taken from (the start's mode resolved from the state)."""
    sc, law = PAPER, PAPER.law
    a = _run(sc, law, 4, "closed")
    k = np.flatnonzero(a.mode == phase)[3]
    t0 = a.t[k]
    b = _run(sc, law, 2, "closed", y0=a.y[:, k], t0=t0)
    later = a.event_t > t0
    n = b.event_t.size
    np.testing.assert_array_equal(b.event_kind, a.event_kind[later][:n])
    # measured 2.1e-15 T; against the integrator: 7.6e-13 T, 1.0e-12, 1.0e-12
    assert np.max(np.abs(b.event_t - a.event_t[later][:n])) < 1e-13 * sc.period
    c = _run(sc, law, 2, "integrate", rtol=1e-12, y0=a.y[:, k], t0=t0)
    _agree(b, c, sc, 1e-10, 1e-10, 1e-10)


def test_the_switch():
    with pytest.raises(InputError, match="contact"):
        Tolerances(contact="exact")
    assert Tolerances().as_dict()["contact"] == "closed"
    sc, law, n = PAPER, PAPER.law, 4
    # free_flight="integrate" keeps the whole old path: the contact integrated too
    tol = Tolerances(rtol=1e-10, free_flight="integrate")
    tol2 = Tolerances(rtol=1e-10, free_flight="integrate", contact="integrate")
    te = np.linspace(0.0, n * sc.period, 101)
    a = simulate(sc, law, (0.0, n * sc.period), t_eval=te, tolerances=tol)
    b = simulate(sc, law, (0.0, n * sc.period), t_eval=te, tolerances=tol2)
    np.testing.assert_array_equal(a.y, b.y)
    assert a.n_steps == b.n_steps


@pytest.mark.parametrize(
    "sc, text",
    [
        (LIGHT, LIGHT.law.to_text()),  # Hunt-Crossley: not linear
        (PAPER, PAPER.law.to_text() + "; set: 0.3"),  # permanent set
        (PAPER.replace(mass_loss=0.01), PAPER.law.to_text()),
        (PAPER.replace(k3=2e12), PAPER.law.to_text()),
        (PAPER, "2.06e8*z + 1.28e7*zd + 5e10*z*zd"),
    ],
)
def test_what_the_closed_form_leaves_to_the_integrator(sc, text):
    """A law or machine with something else acting during the contact: the same steps on
    both contact paths."""
    law = ForceLaw.parse(text)
    a, b = _run(sc, law, 3, "closed"), _run(sc, law, 3, "integrate")
    np.testing.assert_array_equal(a.y, b.y)
    assert a.n_steps == b.n_steps


@pytest.mark.parametrize(
    "text, limits",
    [
        # measured 1.3e-13, 5.4e-12, 6.9e-13, 5.0e-13 T; against central differences 9.3e-9
        (PAPER.law.to_text(), (1e-10, 1e-9, 1e-10, 1e-10)),
        # release and clipped phases (integrated at rtol 1e-10 on the closed-form path):
        # measured 9.1e-13, 7.5e-10, 7.9e-11, 3.5e-12 T
        (PAPER.law.to_text() + "; unloading: 6e6*zd", (1e-10, 1e-8, 1e-9, 1e-10)),
    ],
)
def test_sensitivities_through_closed_form_contacts(text, limits):
    """The start's states and the law's coefficients: the state moves by the contact's
    transition matrix, a coefficient's column gains the response to its force term (in
    modal form).  Two flights and two contacts against the integrator path at rtol 1e-12
    (the state's, the force's and the penetration's derivatives at the outputs, the events'
    time derivatives, relative to the scales, the force's peak and the period) and against
    central differences."""
    sc, T = PAPER, PAPER.period
    law = ForceLaw.parse(text)
    tol = Tolerances(rtol=1e-10)
    y0 = simulate(sc, law, (0.0, 5 * T), tolerances=tol).y_final
    span = (5 * T, 7 * T)
    te = np.linspace(*span, 401)
    a = simulate(sc, law, span, y0=y0, t_eval=te, tolerances=tol, sensitivities="all")
    tol_b = Tolerances(rtol=1e-12, contact="integrate")
    b = simulate(sc, law, span, y0=y0, t_eval=te, tolerances=tol_b, sensitivities="all")
    assert a.n_steps < 50 < 1000 < b.n_steps  # 7 (40 with the clipped phases) and 1938
    s4 = _scale(sc)[:, 0]
    coef = np.array(law.coefficients + law.unloading_coefficients)
    size = np.concatenate([s4, coef])
    rel = lambda S: S * size[None, :] / s4[:, None]  # noqa: E731
    lim_s, lim_f, lim_z, lim_t = limits
    assert np.max(np.abs(rel(a.sensitivity) - rel(b.sensitivity))) < lim_s
    far = _far(te, a.event_t, T)
    peak = np.max(np.abs(b.force))
    dF = (a.force_sensitivity - b.force_sensitivity)[:, far] * size[:, None]
    dz = (a.penetration_sensitivity - b.penetration_sensitivity)[:, far] * size[:, None]
    assert np.max(np.abs(dF)) < lim_f * peak
    assert np.max(np.abs(dz)) < lim_z * s4[0]
    dtau = (a.event_time_sensitivity - b.event_time_sensitivity) * size[None, :]
    assert np.max(np.abs(dtau)) < lim_t * T
    if law.unloading:
        return
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
    # measured 9.3e-9 (the differences' own error, the integrator path's alike)
    assert np.max(np.abs(rel(a.sensitivity) - rel(np.array(dy).T))) < 1e-7


def test_sensitivities_on_random_machines():
    """The start's states and the law's coefficients through two periods of random machines
    (some never touch: no events) against the integrator path at rtol 1e-12, relative to the
    sensitivities' size; the events' time derivatives relative to each event's largest (a
    reload close to a graze has derivatives of 1e4 periods per scale)."""
    rng = np.random.default_rng(35)
    worst = np.zeros(3)
    for _ in range(25):
        sc, law = _random_machine(rng)
        T = sc.period
        y0 = simulate(sc, law, (0, 3 * T), tolerances=Tolerances(rtol=1e-10)).y_final
        span = (3 * T, 5 * T)
        te = np.linspace(*span, 201)
        kw = dict(y0=y0, t_eval=te, sensitivities="all", max_events=1000)
        a = simulate(sc, law, span, tolerances=Tolerances(rtol=1e-10), **kw)
        b = simulate(sc, law, span, tolerances=Tolerances(rtol=1e-12, contact="integrate"), **kw)
        assert list(a.event_kind) == list(b.event_kind)
        s4 = _scale(sc)[:, 0]
        size = np.concatenate([s4, law.coefficients])
        rel = lambda S: S * size[None, :] / s4[:, None]  # noqa: E731, B023
        mag = max(np.max(np.abs(rel(b.sensitivity))), 1.0)
        dS = np.max(np.abs(rel(a.sensitivity) - rel(b.sensitivity))) / mag
        far = _far(te, a.event_t, T)
        dz = (a.penetration_sensitivity - b.penetration_sensitivity)[:, far] * size[:, None]
        dz = np.max(np.abs(dz)) / s4[0] / mag
        dtau = 0.0
        if a.event_t.size:
            ta, tb = a.event_time_sensitivity * size, b.event_time_sensitivity * size
            dtau = np.max(np.max(np.abs(ta - tb), axis=1) / np.max(np.abs(tb), axis=1))
        worst = np.maximum(worst, [dS, dz, dtau])
    # measured 6.9e-11, 2.9e-10, 6.7e-9
    assert worst[0] < 1e-9 and worst[1] < 5e-9 and worst[2] < 1e-7, worst


def test_a_frame_without_a_spring_integrates_its_contacts_coefficient_sensitivities():
    """With ``k1 = 0`` a contact mode has a zero eigenvalue: a run with the coefficients'
    columns takes the integrator's steps in its contacts (one with the state's alone keeps
    the closed form), against the integrator path throughout."""
    sc = PAPER.replace(k1=0.0)
    law, T = PAPER.law, PAPER.period
    span = (0.0, 10 * T)
    a = simulate(sc, law, span, tolerances=Tolerances(rtol=1e-12), sensitivities="all")
    assert np.sum(a.event_kind == K.EV_ONSET) >= 5
    tol_b = Tolerances(rtol=1e-12, contact="integrate")
    b = simulate(sc, law, span, tolerances=tol_b, sensitivities="all")
    np.testing.assert_array_equal(a.sensitivity, b.sensitivity)
    c = simulate(sc, law, span, tolerances=Tolerances(rtol=1e-12), sensitivities="state")
    d = simulate(sc, law, span, tolerances=tol_b, sensitivities="state")
    assert c.n_steps < d.n_steps
    s4 = _scale(sc)[:, 0]
    # measured 1.5e-11 (entries up to 13.7)
    assert np.max(np.abs(c.sensitivity - d.sensitivity) * s4[None, :] / s4[:, None]) < 1e-9


@pytest.mark.parametrize("c1", [0.0, 20.0, 100.0, 2000.0])  # undamped to overdamped frames
def test_frames_from_undamped_to_overdamped(c1):
    """tests/vibroimpact/dynamics/test_free_flight.py's machines (critical damping at
    c1 = 20), whose contacts are short and stiff: the closed-form run against the integrator
    path at rtol 1e-13 (at rtol 1e-10 its own error in these contacts reaches 7e-7 T)."""
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
    a, b = _run(sc, law, 6, "closed"), _run(sc, law, 6, "integrate", rtol=1e-13)
    assert np.sum(a.event_kind == K.EV_ONSET) >= 3
    # measured <= 2.6e-9 T, 2.9e-9 of the scales, 4.7e-9 of the force's peak
    _agree(a, b, sc, 1e-8, 1e-7, 1e-7)


@pytest.mark.parametrize("name", list(REGIMES))
def test_a_map_sets_the_contact_modes_up_once(name):
    """A stroboscopic map sets the contact modes' closed form up when it is made (the
    kernel's ``modes``) and keeps them: every run, one period at a time or many from one
    call (``strobe``), gives the same bits as a run that sets them up afresh, and the
    storage says whether a mode has the closed form."""
    sc, text, _ = REGIMES[name]
    law = ForceLaw.parse(text)
    smap = StroboscopicMap(sc, law)
    assert smap._modes[3][0] == 1.0  # linear laws: a mode has the closed form
    y = sc.initial_state()
    for k in range(4):
        kept = smap.advance(y, 1, t0=k * sc.period)
        fresh = simulate(sc, law, (k * sc.period, (k + 1) * sc.period), y0=y).y_final
        np.testing.assert_array_equal(kept, fresh)
        y = kept
    points = [sc.initial_state()]
    for _ in range(4):  # each period from t = 0, as the map's strobe points
        points.append(simulate(sc, law, (0.0, sc.period), y0=points[-1]).y_final)
    np.testing.assert_array_equal(smap.strobe(points[0], 4), points)
    assert smap.n_calls == 8 and smap.n_periods == 8
    nonlinear = StroboscopicMap(sc, ForceLaw.parse(text + " + 1e9*z*zd"))
    assert nonlinear._modes[3][0] == 2.0
