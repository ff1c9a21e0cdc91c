"""Periodic orbits of laws with contact memory (Flores, Lankarani-Nikravesh): the regime and
the Floquet multipliers agree with long runs from rest.

A law scaled by each impact's approach velocity carries that velocity through a contact,
so where a strobe point falls inside a contact the period map's state holds it too
(:class:`~discovery.vibroimpact.dynamics.memory_map.MemoryMap`).  Each expectation here
is measured independently of the shooting: the strobe points of a plain run from rest (the
kernel's own period-by-period integration, which carries the memory exactly), their
recurrence and their contraction per period onto the orbit.  The machines are random draws
of ``tests/realistic.py``'s machines with a memory law (``tests/survey_memory_orbits.py``)
written out, so the test does not depend on the generator's ranges.
"""

import numpy as np
import pytest

from discovery.numerics.shooting import recurrence
from discovery.vibroimpact.dynamics.memory_map import MemoryMap
from discovery.vibroimpact.dynamics.steady_states import StroboscopicMap, steady_state
from discovery.vibroimpact.model.contact_models import parse_law
from discovery.vibroimpact.model.scenario import Scenario, load_scenario


def _machine(m1, m2, k1, c1, A, f):
    return Scenario(m1=m1, m2=m2, k1=k1, c1=c1, A=A, frequency=f, name="drawn")


def _contraction(scenario, law, ss, periods):
    """The long run from rest: its strobe points' contraction per orbit onto the steady
    orbit (a log-linear fit where the distance is between 100 times its final floor and
    1e-3), and the distance at the end."""
    pm = StroboscopicMap(scenario, law)
    pts = pm.strobe(scenario.initial_state(), periods)
    pm.zeta_max, pm.impact_v0 = ss.zeta_max0, ss.impact_v0
    orbit = pm.strobe(ss.y0, ss.n_periods)[:-1]
    d = np.array([min(np.max(np.abs(p - q) / pm.scale) for q in orbit) for p in pts])
    dd = d[:: ss.n_periods]
    floor = max(1e-9, 100 * dd[-1])
    last = int(np.nonzero(dd > floor)[0][-1])
    k = np.arange(last + 1)
    keep = (dd[: last + 1] > floor) & (dd[: last + 1] < 1e-3)
    rate = float(np.exp(np.polyfit(k[keep], np.log(dd[: last + 1][keep]), 1)[0]))
    return rate, float(d[-1])


def test_the_paper_machines_flores_law_is_the_p1_a_long_run_settles_on():
    """Issue 48: reported P3 (max multiplier 0.8907) where a run from rest settles on a P1."""
    sc = load_scenario("paper")
    law = parse_law("flores: k=8e8, n=1.25, e=0.5")
    ss = steady_state(sc, law)
    assert ss.regime == "P1" and ss.impacts == 1
    rate, end = _contraction(sc, law, ss, 1000)
    assert end < 1e-7
    # measured 0.9631 from the run against 0.9621 from the map
    assert float(np.max(np.abs(ss.multipliers))) == pytest.approx(rate, abs=0.005)


def test_a_strobe_point_inside_a_contact_carries_the_impact_velocity():
    """A P2 whose strobe point lies inside a contact: the impact velocity is part of the
    state there, and the multipliers agree with the run's contraction."""
    sc = _machine(10300.0, 14400.0, 3.28e8, 6.35e5, 6.09e5, 14.7)
    law = parse_law("flores: k=3.165e+09, n=1.52, e=0.326")
    ss = steady_state(sc, law)
    assert ss.regime == "P2" and ss.y0[0] - ss.y0[2] > 0 and ss.impact_v0 > 0
    rate, end = _contraction(sc, law, ss, 400)
    assert end < 1e-8
    # measured 0.160 from the run against 0.154 from the map
    assert float(np.max(np.abs(ss.multipliers))) == pytest.approx(rate, abs=0.02)
    # the memory moves the next strobe point: its column of the Jacobian is not zero
    mm = MemoryMap(StroboscopicMap(sc, law))
    z = np.concatenate([ss.y0, [ss.zeta_max0, ss.impact_v0]])
    J = mm.jacobian(z, 2)
    assert np.max(np.abs(J[:4, 5]) * mm.scale[5] / mm.scale[:4]) > 1e-3
    # and the orbit closes with its memory
    assert np.max(np.abs(mm.advance(z, 2) - z) / mm.scale) < 1e-6


def test_out_of_contact_the_memory_does_not_move_the_map():
    sc = _machine(19500.0, 9410.0, 8.1e8, 1.57e6, 7.67e5, 16.7)
    law = parse_law("flores: k=3.453e+08, n=1.12, e=0.573")
    ss = steady_state(sc, law)
    assert ss.regime == "P1" and ss.y0[0] - ss.y0[2] < 0  # the strobe point is in flight
    mm = MemoryMap(StroboscopicMap(sc, law))
    J = mm.jacobian(np.concatenate([ss.y0, [ss.zeta_max0, ss.impact_v0]]))
    assert np.all(J[:4, 4:] == 0.0)


def test_a_contact_that_never_ends_keeps_its_memory_and_is_periodic():
    """The moulding lands once and never leaves the grid: the impact velocity is then a
    constant of the motion (its multiplier exactly 1), not a reason to call the motion
    nonperiodic; the run's strobe points recur after one period."""
    sc = _machine(4350.0, 1310.0, 8.23e8, 6.5e5, 7.59e4, 39.4)
    law = parse_law("flores: k=1.431e+12, n=1.57, e=0.489")
    ss = steady_state(sc, law)
    pm = StroboscopicMap(sc, law)
    pts = pm.strobe(sc.initial_state(), 200)
    assert recurrence(pts[-20:], pm.scale, 1)[1] < 1e-10
    assert ss.regime == "P1" and ss.impacts == 0
    assert float(np.max(np.abs(ss.multipliers))) < 1.0


def test_an_orbit_the_motion_does_not_reach_is_not_its_steady_state():
    """The moulding dropped from a fifth of the motion's scale above its resting place: the
    motion stays chaotic; Newton from the transient's end converges to a stable P4 that
    coexists with it.  That orbit is not what the motion reaches, so the search reports no
    periodic steady state (it had reported P4).  (From rest the machine's first contact
    begins without an approach velocity; since that contact is divided by the machine's
    floor, the search from rest meets no such orbit: which one a chaotic transient meets is
    decided by its start.)"""
    sc = _machine(3940.0, 5610.0, 5.23e7, 1.35e5, 1.21e5, 32.4)
    law = parse_law("flores: k=7.063e+09, n=1.52, e=0.878")
    y0 = sc.initial_state()
    y0[2] += 0.2 * sc.scales()[0]  # in flight above the frame
    ss = steady_state(sc, law, y_start=y0)
    assert ss.regime == "nonperiodic"
    tried = [t for a in ss.evidence["attempts"] for t in a["tried"]]
    assert any(t.get("stable") and t.get("reached") is False for t in tried)
    pm = StroboscopicMap(sc, law)
    pts = pm.strobe(y0, 600)
    assert min(recurrence(pts[-40:], pm.scale, 8).values()) > 1e-2
