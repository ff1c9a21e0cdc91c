"""The compiled event-driven integrator: tableau, closed forms, scipy reference, failures."""

import numpy as np
import pytest
from scipy.integrate._ivp.rk import RK45

from discovery.errors import InputError, IntegrationError, VidiError, VidiTypeError
from discovery.numerics import _tableau
from discovery.numerics.status import STEP_BUDGET
from discovery.vibroimpact.dynamics.kernel import codes as K
from discovery.vibroimpact.dynamics.reference import reference_simulate
from discovery.vibroimpact.dynamics.simulation import EVENT_NAMES, Tolerances, simulate
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import Scenario

# ------------------------------------------------------------------------ (a) tableau


@pytest.mark.parametrize("name", ["A", "B", "C", "E", "P"])
def test_tableau_matches_scipy_rk45(name):
    ours, theirs = getattr(_tableau, name), getattr(RK45, name)
    assert ours.shape == theirs.shape
    # 1 ulp-level: both are the same rationals evaluated in double precision
    np.testing.assert_allclose(ours, theirs, rtol=1e-15, atol=1e-16)


def test_tableau_order_conditions():
    # consistency: row sums of A equal C, weights sum to 1, error weights sum to 0
    np.testing.assert_allclose(_tableau.A.sum(axis=1), _tableau.C, rtol=0, atol=1e-14)
    assert _tableau.B.sum() == pytest.approx(1.0, abs=1e-15)
    assert _tableau.E.sum() == pytest.approx(0.0, abs=1e-15)


# ------------------------------------------------------ (b) closed form: wall impact

M, MU, KW, V0, GAP = 2.0, 1.0, 1.0e6, 1.0, 1.0e-3  # reduced mass mu = M/2; w0 = 1000 rad/s
W0 = np.sqrt(KW / MU)
TIGHT = Tolerances(rtol=1e-11, hmax_fraction=1e-3)


def _wall(law, g=9.81):
    sc = Scenario(m1=M, m2=M, k1=0, c1=0, A=0, frequency=1, g=g, initial=(0, 0, GAP, -V0))
    return simulate(sc, law, (0.0, 0.02), tolerances=TIGHT)


def _phi(xi):
    if xi < 1:
        return np.arccos(xi) / np.sqrt(1 - xi**2)
    if xi == 1:
        return 1.0
    return np.arccosh(xi) / np.sqrt(xi**2 - 1)


@pytest.mark.parametrize("xi", [0.05, 0.3, 0.999, 1.0, 1.5, 6.3])
def test_wall_impact_closed_form(xi):
    c = float(2 * xi * np.sqrt(KW * MU))
    tr = _wall(ForceLaw.parse(f"{KW!r}*z + {c!r}*zd"))
    assert tr.success
    assert list(tr.event_kind) == [K.EV_ONSET, K.EV_UNLOAD, K.EV_LOSS]
    dz = tr.event_y[:, 1] - tr.event_y[:, 3]
    zeta = tr.event_y[:, 0] - tr.event_y[:, 2]
    phi = _phi(xi)
    e_exact = np.exp(-xi * phi)
    # free flight: gravity cancels in zeta, so the onset is at gap / v0 with dzeta = v0
    # (rel 1e-12: a polynomial flight, exact for RK up to roundoff)
    assert tr.event_t[0] == pytest.approx(GAP / V0, rel=1e-12)
    assert dz[0] == pytest.approx(V0, rel=1e-12)
    # restitution and contact time: measured ~1e-11..1e-10 at rtol 1e-11; 5e-10 leaves margin
    assert -dz[2] / dz[0] == pytest.approx(e_exact, rel=5e-10)
    assert (tr.event_t[2] - tr.event_t[0]) * W0 == pytest.approx(phi + np.pi / 2, rel=5e-10)
    # loading phase ends at w0 t = phi with zeta_max = v0/w0 exp(-xi phi) (same tolerance)
    assert (tr.event_t[1] - tr.event_t[0]) * W0 == pytest.approx(phi, rel=5e-10)
    assert zeta[1] == pytest.approx(V0 / W0 * e_exact, rel=5e-10)


# --------------------------------------------------------- (d) energy balance


def test_elastic_impact_conserves_energy():
    tr = _wall(ForceLaw.parse(f"{KW!r}*z"), g=0.0)
    assert list(tr.event_kind) == [K.EV_ONSET, K.EV_UNLOAD, K.EV_LOSS]
    y_in, y_out = tr.event_y[0], tr.event_y[-1]
    ke = lambda y: 0.5 * M * (y[1] ** 2 + y[3] ** 2)  # noqa: E731
    # e = 1 and kinetic energy conserved: 1e-9 is ~10x the integrator's error at rtol 1e-11
    assert -(y_out[1] - y_out[3]) / (y_in[1] - y_in[3]) == pytest.approx(1.0, abs=1e-9)
    assert ke(y_out) == pytest.approx(ke(y_in), rel=1e-9)
    # momentum is conserved exactly by the equations (no external force): roundoff only
    assert M * (y_out[1] + y_out[3]) == pytest.approx(M * (y_in[1] + y_in[3]), abs=1e-12)
    # undamped half oscillation: contact time pi / w0
    assert (tr.event_t[-1] - tr.event_t[0]) * W0 == pytest.approx(np.pi, rel=5e-10)


# ------------------------------------------------------- (c) kernel vs scipy reference


def _normalised_reference_events(events, period):
    """The reference reports a spurious 'release' at the instant of contact loss when
    P(0, 0) = 0 (the kernel resolves that tie in favour of 'loss'); drop those."""
    out = []
    for i, (t, kind, _) in enumerate(events):
        nxt = events[i + 1] if i + 1 < len(events) else None
        if kind == "release" and nxt and nxt[1] == "loss" and abs(nxt[0] - t) < 1e-9 * period:
            continue
        out.append((t, kind))
    return out


def _compare_with_reference(sc, law, n_periods=10, max_events=100_000):
    T = sc.period
    te = np.linspace(0.0, n_periods * T, 200 * n_periods + 1)
    tr = simulate(sc, law, (0.0, n_periods * T), t_eval=te, tolerances=Tolerances(rtol=1e-10))
    ref = reference_simulate(
        sc, law, (0.0, n_periods * T), t_eval=te, rtol=1e-10, max_events=max_events
    )
    ours = [EVENT_NAMES[k] for k in tr.event_kind]
    theirs = _normalised_reference_events(ref["events"], T)
    assert ours == [k for _, k in theirs]
    # event times: measured ~1e-9 T at rtol 1e-10 over 10 periods; 1e-8 T leaves 10x margin
    dt = np.abs(tr.event_t - np.array([t for t, _ in theirs]))
    assert np.max(dt) < 1e-8 * T
    # states away from events (a state jumps in slope there, so a time error shows up)
    far = np.min(np.abs(te[:, None] - tr.event_t[None, :]), axis=1) > 1e-6 * T
    assert far.sum() > 0.9 * te.size
    x, v = sc.scales()
    scale = np.array([x, v, x, v])[:, None]
    # measured ~2e-8 of the motion's scale (two rtol-1e-10 integrators over 10 periods
    # of a system with multipliers ~0.9); 2e-7 leaves 10x margin
    assert np.max(np.abs(tr.y[:, far] - ref["y"][:, far]) / scale) < 2e-7
    return tr, ref


def test_kernel_matches_reference_paper(paper):
    tr, _ = _compare_with_reference(paper, paper.law)
    assert np.sum(tr.event_kind == K.EV_ONSET) >= 10  # the run really has impacts


def test_kernel_matches_reference_light(light):
    tr, _ = _compare_with_reference(light, light.law)
    assert np.sum(tr.event_kind == K.EV_ONSET) >= 9
    # no force jump at onset: the force right after each onset is ~0 (z^1.5 at z = 0)
    lims = tr.event_forces(light.law)
    onset = tr.event_kind == K.EV_ONSET
    assert np.all(np.abs(lims[onset, 1]) < 1e-6 * np.max(tr.force))


def test_kernel_matches_reference_negative_coefficient(paper):
    law = ForceLaw.parse("2e8*z - 3e10*z^2 + 1e7*zd")
    # equal event sequences (checked in the helper) imply release/resume agree too;
    # at these penetrations (< 6.7e-3 m) P stays positive, so there are none
    tr, _ = _compare_with_reference(paper, law)
    assert not ({K.EV_RELEASE, K.EV_RESUME} & set(tr.event_kind.tolist()))
    assert np.all(tr.force >= 0)
    assert np.all(law(tr.zeta, tr.dzeta) >= 0)


CLIPPING = "2e8*z - 1e12*z^2 + 1e7*zd"  # P(z, 0) < 0 for z > 2e-4 m: unloading is clipped


def test_clipping_law_kernel(paper):
    """A law whose polynomial turns adhesive during unloading: F is clipped to 0."""
    law = ForceLaw.parse(CLIPPING)
    T = paper.period
    te = np.linspace(0.0, 4 * T, 8001)
    tr = simulate(paper, law, (0.0, 4 * T), t_eval=te, tolerances=Tolerances(rtol=1e-10))
    kinds = set(tr.event_kind.tolist())
    assert K.EV_RELEASE in kinds and K.EV_RESUME in kinds
    assert np.all(tr.force >= 0)
    clipped = tr.mode == K.CLIPPED
    assert clipped.any() and np.all(tr.zeta[clipped] > 0)
    np.testing.assert_array_equal(tr.force[clipped], 0.0)
    # at a release the force is continuous (P passes through 0): left limit ~0
    lims = tr.event_forces(law)
    rel = tr.event_kind == K.EV_RELEASE
    assert np.all(np.abs(lims[rel, 0]) < 1e-6 * np.max(tr.force))
    _assert_force_is_law(tr, law, T)


def test_clipping_law_every_event_changes_mode(paper):
    law = ForceLaw.parse(CLIPPING)
    tr = simulate(paper, law, (0.0, 4 * paper.period), tolerances=Tolerances(rtol=1e-10))
    assert np.all(tr.event_modes[:, 0] != tr.event_modes[:, 1])


def test_clipping_law_reference_agrees(paper):
    law = ForceLaw.parse(CLIPPING)
    # the reference path once looped between modes at a loss followed by re-contact; it now
    # decides the mode from the motion, so a small event budget is enough
    _compare_with_reference(paper, law, n_periods=2, max_events=200)


def test_reference_force_output_is_the_law(paper):
    T = paper.period
    te = np.linspace(0.0, 2 * T, 801)
    ref = reference_simulate(paper, paper.law, (0.0, 2 * T), t_eval=te)
    zeta, dz = ref["y"][0] - ref["y"][2], ref["y"][1] - ref["y"][3]
    F = paper.law(zeta, dz)
    # loose: the modes at t_eval may lag an event; anything beyond 1% is not a lag
    assert np.max(np.abs(ref["force"] - F)) < 1e-2 * np.max(F)


# --------------------------------------------------------------- (f) force output


def _assert_force_is_law(tr, law, T):
    far = np.min(np.abs(tr.t[:, None] - tr.event_t[None, :]), axis=1) > 1e-6 * T
    F = law(tr.zeta, tr.dzeta)
    # same formula evaluated on the same state: only roundoff of the polynomial
    np.testing.assert_allclose(tr.force[far], F[far], rtol=0, atol=1e-12 * np.max(F))
    assert np.max(F) > 0


@pytest.mark.parametrize("which", ["paper", "light"])
def test_force_output_equals_law(which, request):
    sc = request.getfixturevalue(which)
    T = sc.period
    te = np.linspace(0.0, 5 * T, 5001)
    tr = simulate(sc, sc.law, (0.0, 5 * T), t_eval=te)
    assert tr.t.shape == te.shape and tr.y.shape == (4, te.size)
    assert tr.force.shape == tr.mode.shape == te.shape
    _assert_force_is_law(tr, sc.law, T)
    # mode codes agree with the state: free iff no penetration (away from events)
    far = np.min(np.abs(te[:, None] - tr.event_t[None, :]), axis=1) > 1e-6 * T
    assert np.all((tr.mode[far] == K.FREE) == (tr.zeta[far] <= 0))


def test_t_eval_endpoints_and_final_state(paper):
    T = paper.period
    te = np.array([0.0, 0.5 * T, T])
    tr = simulate(paper, paper.law, (0.0, T), t_eval=te)
    np.testing.assert_array_equal(tr.y[:, 0], paper.initial_state())
    assert tr.t_final == T
    # output at t1 is the final state (dense output at theta = 1 is the step end): roundoff
    x, v = paper.scales()
    np.testing.assert_allclose(tr.y[:, -1], tr.y_final, rtol=0, atol=1e-12 * max(x, v))


def test_split_integration_matches_single_run(paper):
    """Restarting from the final state and mode continues the same trajectory."""
    T = paper.period
    tol = Tolerances(rtol=1e-10)
    whole = simulate(paper, paper.law, (0.0, 4 * T), tolerances=tol)
    a = simulate(paper, paper.law, (0.0, 2 * T), tolerances=tol)
    b = simulate(paper, paper.law, (2 * T, 4 * T), y0=a.y_final, mode0=a.mode_final, tolerances=tol)
    x, v = paper.scales()
    scale = np.array([x, v, x, v])
    # different step sequences: agreement to ~rtol-level global error (1e-7 of scale)
    assert np.max(np.abs(b.y_final - whole.y_final) / scale) < 1e-7


def _runs_alike(a, b):
    for name in ("t", "y", "force", "mode", "event_t", "event_kind", "event_y", "y_final"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))


def test_runs_sharing_a_set_up_are_bitwise_those_set_up_alone(paper):
    """Runs of one law on one machine with one set of tolerances share the kernel's set-up
    (the contact modes' closed form made by the first): each is bitwise the run made with
    its own, from any start and in any order; another law, machine or tolerances object
    gets its own set-up."""
    from discovery.vibroimpact.dynamics import simulation as S

    T, law = paper.period, ForceLaw.parse("2e8*z + 1.2e7*zd")
    starts = [(0.0, None), (0.3 * T, simulate(paper, law, (0.0, 0.3 * T)).y_final)]
    te = np.linspace(0.3 * T, 2.3 * T, 50)
    tol = Tolerances.default()  # what a run without tolerances is set up with
    shared = [simulate(paper, law, (t0, 2.3 * T), y0=y0, t_eval=te) for t0, y0 in starts]
    assert S._RunSetup.of(paper, law, tol) is S._RunSetup.of(paper, law, tol)
    for (t0, y0), run in zip(starts, shared, strict=True):
        S._SETUPS.clear()  # a set-up of its own
        _runs_alike(simulate(paper, law, (t0, 2.3 * T), y0=y0, t_eval=te), run)
    other = ForceLaw.parse("2e8*z + 1.2e7*zd")  # equal, another object: its own set-up
    assert S._RunSetup.of(paper, other, tol) is not S._RunSetup.of(paper, law, tol)
    assert S._RunSetup.of(paper.scaled(1.01), law, tol) is not S._RunSetup.of(paper, law, tol)
    # the modes' closed form is set up once and then only read
    setup = S._RunSetup.of(paper, law, tol)
    made = [m.copy() for m in setup.modes]
    simulate(paper, law, (0.0, 2 * T))
    for a, b in zip(made, setup.modes, strict=True):
        np.testing.assert_array_equal(a, b)


# ---------------------------------------------------------------- (e) failures


def test_step_budget_exhausted(paper):
    tol = Tolerances(max_steps=5)
    tr = simulate(paper, paper.law, (0.0, paper.period), tolerances=tol, throw=False)
    assert tr.status == STEP_BUDGET and not tr.success
    assert "step budget" in tr.message
    assert tr.t_final < paper.period
    with pytest.raises(IntegrationError, match="step budget"):
        simulate(paper, paper.law, (0.0, paper.period), tolerances=tol)


def test_failed_run_keeps_only_reached_outputs(paper):
    te = np.linspace(0.0, paper.period, 11)
    tr = simulate(
        paper,
        paper.law,
        (0.0, paper.period),
        t_eval=te,
        tolerances=Tolerances(max_steps=5),
        throw=False,
    )
    assert np.all(tr.t <= tr.t_final) and tr.t.size < te.size
    assert tr.y.shape == (4, tr.t.size)


@pytest.mark.parametrize("span", [(1.0, 1.0), (1.0, 0.0), (0.0, np.nan), (0.0, np.inf)])
def test_invalid_t_span(paper, span):
    with pytest.raises(InputError, match="t_span"):
        simulate(paper, paper.law, span)


@pytest.mark.parametrize(
    "te",
    [[0.02, 0.01], [-1.0, 0.01], [0.0, 0.5], [0.0, 0.01, 0.03, 0.02], [0.0, np.nan, 0.02]],
)
def test_invalid_t_eval(paper, te):
    with pytest.raises(InputError, match="t_eval"):
        simulate(paper, paper.law, (0.0, 0.04), t_eval=te)


def test_t_eval_at_the_span_ends_and_repeated(paper):
    """Times on the span's ends (within 1e-12 s) and repeated times are valid."""
    te = [-1e-13, 0.0, 0.01, 0.01, 0.04 + 1e-13]
    tr = simulate(paper, paper.law, (0.0, 0.04), t_eval=te)
    assert tr.t.size == 5 and tr.force[2] == tr.force[3]


@pytest.mark.parametrize(
    "kw",
    [
        dict(rtol=0),
        dict(rtol=1),
        dict(atol_scale=0),
        dict(max_steps=0),
        dict(max_steps=2.5),
        dict(hmax_fraction=0),
        dict(hmax_fraction=1.5),
    ],
)
def test_invalid_tolerances(kw):
    with pytest.raises(VidiError) as info:  # a wrong value, or a float for an integer
        Tolerances(**kw)
    assert isinstance(info.value, InputError | VidiTypeError)
    with pytest.raises(VidiError):
        Tolerances(**kw)
