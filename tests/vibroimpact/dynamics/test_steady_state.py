"""Periodic steady states: stroboscopic map, Newton shooting, Floquet multipliers."""

import dataclasses

import numpy as np
import pytest

from discovery.errors import IntegrationError
from discovery.vibroimpact.dynamics.kernel import codes as K
from discovery.vibroimpact.dynamics.simulation import simulate
from discovery.vibroimpact.dynamics.steady_states import StroboscopicMap, steady_state
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import Scenario, load_scenario


def _rel(pm, a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)) / pm.scale))


def test_paper_is_p1_with_one_impact(paper, paper_ss):
    ss = paper_ss
    assert ss.regime == "P1" and ss.n_periods == 1 and ss.periodic
    assert ss.impacts == 1 and ss.impacts_per_period == 1.0
    assert np.all(np.abs(ss.multipliers) < 1.0)
    assert ss.residual < 1e-8  # the Newton tolerance (default tol=1e-8)
    # t0 is a whole number of periods (rel 1e-12: a product of integers and T)
    k = ss.t0 / paper.period
    assert k == pytest.approx(round(k), abs=1e-9) and round(k) > 0
    d = ss.as_dict()
    assert d["regime"] == "P1" and len(d["multipliers_abs"]) == 4


def test_paper_orbit_closes_after_one_period(paper, paper_ss):
    pm = StroboscopicMap(paper, paper.law)
    # the orbit closes to Newton's tolerance up to the 10x slack the divisor check allows;
    # 1e-7 of the motion's scale
    assert _rel(pm, pm.advance(paper_ss.y0, 1), paper_ss.y0) < 1e-7
    # the drive phase only depends on t mod T: starting at t0 = k T gives the same map
    # (differences only from roundoff of sin(omega t) at larger t: 1e-9 of scale)
    assert (
        _rel(pm, pm.advance(paper_ss.y0, 1, t0=paper_ss.t0), pm.advance(paper_ss.y0, 1, t0=0.0))
        < 1e-9
    )
    # and through simulate(): the public path gives the same point (same kernel, same steps)
    tr = simulate(paper, paper.law, (paper_ss.t0, paper_ss.t0 + paper.period), y0=paper_ss.y0)
    assert _rel(pm, tr.y_final, paper_ss.y0) < 1e-7
    assert np.sum(tr.event_kind == K.EV_ONSET) == 1


def test_reported_residual_is_that_of_the_reported_period(paper, paper_ss):
    pm = StroboscopicMap(paper, paper.law)
    # the docstring defines residual = max |Phi^n(y0) - y0| / scale, Phi the run Newton
    # took (with the variational equations); same computation, so 1% is generous
    fy, _ = pm.advance_jacobian(paper_ss.y0, paper_ss.n_periods)
    assert paper_ss.residual == pytest.approx(_rel(pm, fy, paper_ss.y0), rel=1e-2)
    # the plain run's steps differ within the integrator's tolerance
    assert _rel(pm, pm.advance(paper_ss.y0, paper_ss.n_periods), paper_ss.y0) < 1e-8


def test_light_is_p1(light, light_ss):
    assert light_ss.regime == "P1"
    assert light_ss.impacts == 1
    assert np.all(np.abs(light_ss.multipliers) < 1.0)
    pm = StroboscopicMap(light, light.law)
    assert _rel(pm, pm.advance(light_ss.y0), light_ss.y0) < 1e-7


def test_nonperiodic_case_reports_evidence():
    sc = Scenario(m1=5e3, m2=2e3, k1=1.2e7, c1=6e4, A=1e5, frequency=20.0)
    law = ForceLaw.parse("2.0e10*z^1.5 + 4e10*z^1.5*zd")
    ss = steady_state(sc, law)
    assert ss.regime == "nonperiodic" and ss.n_periods == 0 and not ss.periodic
    assert np.isnan(ss.impacts_per_period) and np.isnan(ss.residual)
    attempts = ss.evidence["attempts"]
    assert [a["phase"] for a in attempts] == ["transient", "long-transient"]
    for a in attempts:
        assert set(a["recurrence"]) == set(range(1, 9))
        # no period recurs: every strobe distance is far above the 1e-2 acceptance level
        assert min(a["recurrence"].values()) > 1e-2
        assert a["tried"] and not any(t["stable"] for t in a["tried"])
    assert ss.n_simulations > 0


def _decay_rate(pm, y0, n0=10, n1=50, seed=0):
    """Least-squares growth factor per period of a small perturbation of the orbit."""
    rng = np.random.default_rng(seed)
    y = y0 + 1e-4 * pm.scale * rng.standard_normal(4)
    d = []
    for _ in range(n1 + 1):
        d.append(_rel(pm, y, y0))
        y = pm.advance(y)
    k = np.arange(n0, n1 + 1)
    slope = np.polyfit(k, np.log(np.array(d)[n0:]), 1)[0]
    return float(np.exp(slope)), d


@pytest.mark.parametrize("which", ["paper", "light"])
def test_floquet_multipliers_match_perturbation_decay(which, request):
    sc = request.getfixturevalue(which)
    ss = request.getfixturevalue(f"{which}_ss")
    pm = StroboscopicMap(sc, sc.law)
    rho = float(np.max(np.abs(ss.multipliers)))
    rate, d = _decay_rate(pm, ss.y0)
    # the dominant pair is complex, so the norm wobbles around rho^k; measured within
    # 0.006 of rho over k = 10..50, 0.03 allows for the wobble
    assert rate == pytest.approx(rho, abs=0.03)
    # bound: after k periods the perturbation is within a constant times rho^k
    ks = np.arange(len(d))
    assert np.all(np.array(d) <= 20 * d[0] * rho**ks + 1e-10)


@pytest.mark.parametrize("which", ["paper", "light"])
def test_floquet_multipliers_match_central_differences(which, request):
    sc = request.getfixturevalue(which)
    ss = request.getfixturevalue(f"{which}_ss")
    pm = StroboscopicMap(sc, sc.law)
    J = np.empty((4, 4))
    for j in range(4):
        e = np.zeros(4)
        e[j] = 1e-5 * pm.scale[j]
        J[:, j] = (pm.advance(ss.y0 + e) - pm.advance(ss.y0 - e)) / (2 * e[j])
    ours = np.sort(np.abs(np.linalg.eigvals(J)))
    theirs = np.sort(np.abs(ss.multipliers))
    # forward (1e-6) vs central (1e-5) differences with rtol-1e-9 integration:
    # measured <= 1.4e-4 apart; 2e-3 absolute is the FD noise floor with margin
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=2e-3)


def test_stroboscopic_map_jacobian_shape_and_counters(paper, paper_ss):
    pm = StroboscopicMap(paper, paper.law)
    J = pm.jacobian(paper_ss.y0)
    assert J.shape == (4, 4) and np.all(np.isfinite(J))
    # exact: one run with the variational equations (finite differences took five)
    assert pm.n_calls == 1 and pm.n_exact == 1 and pm.n_steps > 0
    # P1 orbit: Phi^2 has the squared multipliers (the shooting's Jacobian is exact too;
    # 2e-3 kept from the finite-difference days)
    J2 = pm.jacobian(paper_ss.y0, n=2)
    np.testing.assert_allclose(
        np.sort(np.abs(np.linalg.eigvals(J2))),
        np.sort(np.abs(paper_ss.multipliers) ** 2),
        rtol=0,
        atol=2e-3,
    )


def test_t0_shift_gives_same_orbit(paper, paper_ss):
    """y_start on the orbit: the search returns (essentially) the same state."""
    ss2 = steady_state(paper, paper.law, y_start=paper_ss.y0)
    pm = StroboscopicMap(paper, paper.law)
    assert ss2.regime == "P1"
    # both within Newton tolerance (x10 slack) of the same stable orbit: 1e-6 of scale
    assert _rel(pm, ss2.y0, paper_ss.y0) < 1e-6


def test_advance_raises_on_runaway(paper):
    """A contact too soft to carry the moulding: it falls through the grid for good."""
    pm = StroboscopicMap(paper, ForceLaw.parse("1e-3*z"))
    # free fall for 800 s reaches |w2| = g t^2 / 2 ~ 3e6 m, beyond advance()'s runaway
    # guard (1e6 * velocity scale + 1e3 ~ 3.2e5): it must raise rather than return it
    with pytest.raises(IntegrationError, match="left the physical range"):
        pm.advance(paper.initial_state(), 20000)


def test_strobe_points_are_those_of_one_advance_a_period():
    """``strobe`` runs many periods in one call of the kernel, each as its own run: the
    points, the counters and a permanent set's contact memory are those of one
    ``advance`` a period, bit for bit; a runaway raises as ``advance`` does."""
    sc = Scenario(m1=4390.0, m2=3270.0, k1=21900000.0, c1=73600.0, A=142000.0, frequency=16.6)
    for text in ("1.4e8*z + 8.24e6*zd; set: 0.3", "1e10*z^1.5 + 1e7*zd", "3.37e9*z + 8.15e6*zd"):
        law = ForceLaw.parse(text)
        one, many = StroboscopicMap(sc, law), StroboscopicMap(sc, law)
        y = sc.initial_state()
        points = [y]
        for _ in range(12):
            points.append(one.advance(points[-1]))
        np.testing.assert_array_equal(many.strobe(y, 12), points)
        assert (many.n_calls, many.n_periods, many.n_steps) == (12, 12, one.n_steps)
        assert (many.zeta_max, many.impact_v0) == (one.zeta_max, one.impact_v0)
    pm = StroboscopicMap(sc, ForceLaw.parse("1e-3*z"))
    with pytest.raises(IntegrationError, match="left the physical range"):
        pm.strobe(sc.initial_state(), 20000)


def test_an_orbits_onsets_are_the_simulated_ones(paper, paper_ss):
    """The map counts an orbit's contact onsets from its own run: the count a simulation
    of the same periods gives, also where a period holds more events than the first
    guess of room (chatter); the count is not one of the search's evaluations."""
    light = load_scenario("light").replace(m2=1000.0)
    # the light machine's period from there holds 13 events: the count runs twice
    cases = [
        (paper, paper.law, paper_ss.y0, 1),
        (light, ForceLaw.parse("2e9*z + 1.41e5*zd"), 20, 2),
    ]
    for sc, law, start, runs in cases:
        pm = StroboscopicMap(sc, law)
        y = pm.advance(sc.initial_state(), start) if sc is light else start
        calls, periods = pm.n_calls, pm.n_periods
        tr = simulate(sc, law, (0.0, sc.period), y0=y)
        assert pm.onsets(y) == np.sum(tr.event_kind == K.EV_ONSET) > 0
        assert (pm.n_calls, pm.n_periods) == (calls, periods + runs)


# --- period detection near multipliers -1 (issue: a slow P1 orbit read as P2) -------------
_PD = Scenario(
    m1=4770.989046559852,
    m2=5430.940884957566,
    k1=161209836.32495606,
    c1=343759.5619373554,
    A=231045.9099917681 * 1.01,
    frequency=37.287324033370695,
)
_PD_LAW = ForceLaw.parse("1448000000*z + 9927000*zd")


def test_p1_with_multiplier_near_minus_one_is_not_read_as_p2():
    # largest multiplier -0.985: the strobe points alternate, so the recurrence suggests
    # n = 2; shooting at n = 2 with tol 1e-6 reaches an accuracy ~ tol / (1 - mu^2), far
    # above the former closure test 10 tol at n = 1 (which then kept "P2", 2 impacts)
    ss = steady_state(_PD, _PD_LAW, tol=1e-6)
    assert ss.regime == "P1" and ss.impacts == 1
    mu = ss.multipliers[np.argmax(np.abs(ss.multipliers))]
    assert -0.99 < mu.real < -0.98 and abs(mu.imag) < 1e-6


def test_p1_at_the_edge_of_period_doubling_is_p1():
    # multiplier -0.9999 (the period doubling is a whisker away): still one orbit, 2 impacts
    sc = Scenario(
        m1=13548.873878973951,
        m2=10237.086997075849,
        k1=201079328.34759715,
        c1=107030.21999360243,
        A=300137.0,
        frequency=12.074213096216956,
    )
    ss = steady_state(sc, ForceLaw.parse("182300000*z + 383000*zd + 893800000*z*zd"))
    assert ss.regime == "P1" and ss.impacts == 2
    assert np.max(np.abs(ss.multipliers)) > 0.999


def test_period_doubled_orbit_is_not_reduced():
    # just past the doubling the P1 orbit is unstable (multiplier < -1): P2 stays P2
    sc = dataclasses.replace(_PD, A=231045.9099917681 * 1.03)
    ss = steady_state(sc, _PD_LAW)
    assert ss.regime == "P2" and ss.impacts == 2
    pm = StroboscopicMap(sc, _PD_LAW)
    assert np.max(np.abs(pm.advance(ss.y0, 1) - ss.y0) / pm.scale) > 1e-3


def test_start_from_a_state_at_any_time():
    # the orbit reached from a state given mid-period (drive clock) is the same orbit
    paper = Scenario(m1=1e4, m2=1e4, k1=2.75e7, c1=1e5, A=5e5, frequency=25.0)
    law = ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    ref = steady_state(paper, law)
    t_mid = ref.t0 + 0.37 * paper.period
    tr = simulate(paper, law, (ref.t0, t_mid), y0=ref.y0)
    ss = steady_state(paper, law, y_start=tr.y_final, t_start=t_mid, transient=3)
    assert ss.regime == "P1"
    assert ss.t0 % paper.period == pytest.approx(0.0, abs=1e-12)
    np.testing.assert_allclose(ss.y0, ref.y0, rtol=0, atol=1e-7 * np.abs(ref.y0).max())
