"""Verification against records made by the independent scipy path with realistic noise.

Every record here comes from :func:`discovery.vibroimpact.dynamics.reference.reference_simulate`
(not the compiled kernel), from rest, through a transient, with noise relative to
each channel's own range: so the penetration ``w1 - w2`` is noisy.
"""

import numpy as np
import pytest

from discovery import ForceLaw, Measurement, Scenario, load_scenario, simulate
from discovery.vibroimpact.data.impulse import estimate_noise
from discovery.vibroimpact.dynamics.law_response import response
from discovery.vibroimpact.dynamics.reference import reference_simulate
from discovery.vibroimpact.verify import Reference, evaluate, verify


def _record(
    sc,
    law,
    *,
    periods=15,
    transient=60,
    fs=20000.0,
    force_noise=0.01,
    motion_noise=0.002,
    seed=0,
    velocities=True,
):
    T = sc.period
    t = transient * T + np.arange(int(periods * T * fs)) / fs
    r = reference_simulate(sc, law, (0.0, t[-1]), t_eval=t, rtol=1e-9)
    rng = np.random.default_rng(seed)
    F = r["force"] + rng.normal(0.0, force_noise * np.max(np.abs(r["force"])), t.size)
    ch = {}
    for k, name in enumerate(("w1", "v1", "w2", "v2")):
        ch[name] = r["y"][k] + rng.normal(0.0, motion_noise * np.ptp(r["y"][k]), t.size)
    if not velocities:
        del ch["v1"], ch["v2"]
    return Measurement(t, F, ch, source="reference")


@pytest.fixture(scope="module")
def light():
    return load_scenario("light")


@pytest.fixture(scope="module")
def light_record(light):
    return _record(light, light.law, seed=3)


def test_true_law_consistent_wrong_law_not(light, light_record):
    ok = verify(light, light_record, light.law, check_default_start=False)
    assert ok.consistent, ok.verdict
    assert ok.evaluation.regime == {"measured": "P1", "simulated": "P1"}
    # stiffness 30 % off, damping 30 % off: both far outside the noise
    for coefs in ([2.6e10, 5e11], [2e10, 3.5e11]):
        bad = verify(
            light, light_record, light.law.with_coefficients(coefs), check_default_start=False
        )
        assert not bad.consistent
        assert bad.criteria["I2"] > 5 * bad.noise_floor["I2"]


def test_noise_floor_is_the_spread_of_the_true_law(light):
    # over independent noise draws the true law's I2 scatters around its floor
    rows = []
    for seed in range(4):
        v = verify(
            light, _record(light, light.law, seed=10 + seed), light.law, check_default_start=False
        )
        rows.append((v.criteria["I2"], v.noise_floor["I2"]))
    i2, fl = np.array(rows).T
    assert np.all(i2 < 2 * fl + 0.005)
    assert 0.3 < np.mean(i2) / np.mean(fl) < 2.0


def test_verify_starts_from_the_measured_state(light, light_record):
    ref = Reference.from_measurement(light_record, light)
    assert ref.start is not None
    # the state comes from the record's first free flight, fitted by the exact free motion:
    # it predicts the recorded positions to their noise level
    assert ref.span is not None and ref.span.state.method == "free-flight fit"
    t = light_record.t
    assert t[0] <= ref.start_time <= t[-1]  # the last block's start (the latest cycles)
    tr = simulate(
        light,
        light.law,
        (ref.start_time, ref.start_time + 0.5 * light.period),
        y0=ref.start,
        t_eval=t[(t >= ref.start_time) & (t <= ref.start_time + 0.5 * light.period)],
    )
    sel = (t >= ref.start_time) & (t <= ref.start_time + 0.5 * light.period)
    for k, name in ((0, "w1"), (2, "w2")):
        ch = light_record.channels[name]
        rms = float(np.sqrt(np.mean((tr.y[k] - ch[sel]) ** 2)))
        assert rms < 1.3 * estimate_noise(ch, order=3)  # the sensor noise, no model error
    # the measured state is on the orbit: a short transient suffices
    ev = evaluate(light, light.law, ref, transient=2)
    assert ev.status == "ok" and ev.consistent


def test_time_offset_shifts_the_drive_clock(light, light_record):
    # the same record with t shifted by 0.3 T is verified with --time-offset 0.3 T
    off = 0.3 * light.period
    shifted = Measurement(light_record.t - off, light_record.F, light_record.channels)
    good = verify(light, shifted, light.law, time_offset=off, check_default_start=False)
    assert good.consistent
    assert good.reference.start_time == pytest.approx(
        Reference.from_measurement(light_record, light).start_time
    )


_SUB = Scenario(
    m1=7240.8062456432735,
    m2=5459.453320705147,
    k1=170863194.34024045,
    c1=69692.89930199806,
    A=256308.8049041235,
    frequency=33.232564136106916,
)
_SUB_LAW = ForceLaw.parse("1318000000*z + 23170000*zd")


@pytest.mark.slow
def test_subharmonic_with_several_impacts_is_aligned():
    # a P4 orbit with 3 impacts: t* must be the same impact in both (issue case 2)
    ss = response(_SUB, _SUB_LAW).steady
    assert ss.regime == "P4" and ss.impacts == 3
    rec = _record(_SUB, _SUB_LAW, periods=16, seed=1)
    v = verify(_SUB, rec, _SUB_LAW, check_default_start=False)
    assert v.evaluation.regime == {"measured": "P4", "simulated": "P4"}
    assert v.consistent, v.verdict
    # without positions (the force alone) the impacts are aligned: each other impact taken
    # as t* matches far worse than the one chosen
    from discovery.vibroimpact.verify.criteria import evaluate_criteria

    v = verify(
        _SUB,
        Reference.from_measurement(rec, _SUB, use_state=False),
        _SUB_LAW,
        check_default_start=False,
    )
    assert v.consistent, v.verdict
    exact = v.evaluation.aligned
    E = v.reference.impulse
    others = [
        evaluate_criteria(E, exact.rotated(o).resampled_like(E))["I2"] for o in exact.onsets[1:]
    ]
    assert len(others) == 2 and min(others) > 2 * v.criteria["I2"]


_PD = Scenario(
    m1=4770.989046559852,
    m2=5430.940884957566,
    k1=161209836.32495606,
    c1=343759.5619373554,
    A=231045.9099917681 * 1.01,
    frequency=37.287324033370695,
)
_PD_LAW = ForceLaw.parse("1448000000*z + 9927000*zd")


@pytest.mark.slow
def test_slow_p1_record_is_read_as_p1():
    # Floquet multiplier -0.985: after a short transient the record still alternates a
    # little from period to period; it is P1 and the true law is consistent with it
    rec = _record(_PD, _PD_LAW, periods=15, transient=600, seed=2)
    v = verify(_PD, rec, _PD_LAW, check_default_start=False)
    assert v.evaluation.regime == {"measured": "P1", "simulated": "P1"}
    assert v.consistent, v.verdict


def test_regime_mismatch_is_inconsistent(light, light_record):
    # the P4 machine's law against a P1 record of another machine: never consistent
    ref = Reference.from_measurement(light_record, light)
    ev = evaluate(light, ForceLaw.parse("2e10*z^1.5"), ref)
    assert not ev.consistent


def test_an_undefined_noise_floor_never_makes_a_law_consistent(light, light_record):
    """When no bootstrap replicate finds the contacts the floor is infinite; the rule must
    not then accept any criterion value."""
    import dataclasses

    class _NoFloor(Reference):
        def floor_for(self, stand_in, **kwargs):
            inf = {n: float("inf") for n in ("I0", "I1", "I2", "I3", "I4")}
            return {"mean": inf, "q95": dict(inf), "n_boot": 0, "seed": 0}

    ref = Reference.from_measurement(light_record, light, n_boot=4)
    ev = evaluate(
        light,
        light.law,
        _NoFloor(**{f.name: getattr(ref, f.name) for f in dataclasses.fields(ref)}),
    )
    assert ev.status == "ok" and ev.criteria
    assert not ev.consistent and "could not be estimated" in ev.verdict


def test_a_record_of_another_drive_frequency_is_refused_up_front(light_record):
    """A 20 Hz record against the 25 Hz paper scenario: its force repeats every 1.25 drive
    periods, which no machine at 25 Hz does; refused before any simulation."""
    from discovery.errors import InputError

    with pytest.raises(InputError, match=r"repeats every .* 20 Hz rather than 25 Hz"):
        Reference.from_measurement(light_record, load_scenario("paper"))


def test_a_transient_verdict_names_the_law_s_trajectory_not_the_record():
    """When the law's trajectory from the measured state has not settled over the span, the
    verdict says so of the law's trajectory (the record is what was measured)."""
    from discovery.vibroimpact.verify.notes import transient_notes

    (note,) = transient_notes(False, False, 0.611, {"measured": "P1", "simulated": "P1"}, None)
    assert note.startswith("the law's trajectory from the measured state has not settled")
    assert "record is still in a transient" not in note and "0.611" in note
    (note,) = transient_notes(True, False, 0.3, {"measured": "P1", "simulated": "P2"}, None)
    assert "record reads P1, but this law's trajectory" in note
    assert "record is still in a transient" not in note


def test_a_verdict_without_i5_states_why(light, light_record, monkeypatch):
    """A record with positions whose span cannot be simulated from a measured free flight
    is compared with the law's steady orbit: the verdict says so (it said "the record has
    no positions, or no free flight", though the record had positions)."""
    from discovery.vibroimpact.verify import reference

    why = "no free flight of the record ends before its first compared cycle"

    def no_span(*args, **kwargs):
        kwargs["why"].append(why)

    monkeypatch.setattr(reference, "record_span", no_span)
    ref = Reference.from_measurement(light_record, light, n_boot=4)
    assert ref.span is None and ref.noise["zeta"] is not None and ref.no_span == why
    ev = evaluate(light, light.law, ref)
    assert ev.comparison == "steady orbit"
    assert (
        "I5 (the penetration) not checked: the record was compared with the law's steady "
        f"orbit, where the penetration is not compared ({why})"
    ) in ev.verdict
    assert "no positions" not in ev.verdict
    # without positions the verdict says just that
    ch = {k: v for k, v in light_record.channels.items() if k not in ("w1", "w2", "v1", "v2")}
    bare = Measurement(light_record.t, light_record.F, ch, source="force only")
    ref = Reference.from_measurement(bare, light, n_boot=4)
    assert ref.no_span == "the record has no positions"
    verdict = evaluate(light, light.law, ref).verdict
    assert verdict.endswith("I5 (the penetration) not checked: the record has no positions")


def test_a_run_up_whose_first_cycle_begins_inside_its_first_flight_keeps_its_span():
    """The demo's low-amplitude record (scipy path, from rest): its first whole cycle began
    inside the first free flight, so no flight ended before the first block and the whole
    record fell back to the law's steady orbit (no I5).  The compared cycles now begin after
    the first flight ends; a record that already had its span keeps the same blocks."""
    from discovery import synthesize
    from discovery.vibroimpact.verify.trajectory import record_span

    law = ForceLaw.parse("2.06e8*z + 4e6*zd; unloading: 4e6*zd")
    base = dict(m1=1.0e4, m2=1.0e4, k1=2.75e7, c1=1.0e5, frequency=25.0)
    low = Scenario(name="grid-low", A=3.5e5, law=law, **base)
    rec = synthesize(low, law, periods=30, noise=0.01, seed=2, from_rest=True, integrator="scipy")
    ref = Reference.from_measurement(rec, low, n_boot=4)
    assert ref.span is not None and ref.span.n_cycles >= 25
    ends = []
    span = record_span(rec, low, ref.impulse, why=ends)
    assert span is not None and not ends
    # every block starts after a flight that ended before it
    assert all(b.state is not None for b in span.blocks)
    ev = evaluate(low, law, ref)
    assert ev.comparison != "steady orbit" and "I5" in ev.criteria


def test_a_block_of_a_record_that_sheds_mass_starts_with_the_mass_left():
    """Compared over its span, each block of a record whose moulding sheds mass at each
    impact is simulated with the mass after the record's impacts before it: the true law
    and loss are consistent with a noisy scipy-path record (the scenario's mass the one at
    the record's start), the law without the loss is not, and each block counts the
    record's impacts before it."""
    from tests import realistic as R

    paper = load_scenario("paper")
    lossy = paper.replace(mass_loss=0.005)
    rec = R.reference_record((lossy, paper.law), periods=30, transient=5, seed=2)
    m2 = reference_simulate(lossy, paper.law, (0.0, 5 * paper.period))["m2_final"]
    start = lossy.replace(m2=m2)
    ref = Reference.from_measurement(rec, start, n_boot=8, seed=0)
    before = [b.impacts_before for b in ref.span.blocks]
    assert before == sorted(before) and before[-1] >= 20
    ev = evaluate(start, paper.law, ref)
    assert ev.consistent, ev.verdict
    assert not evaluate(start.replace(mass_loss=0.0), paper.law, ref).consistent


def test_a_replicate_block_without_contact_leaves_the_floor_to_the_other_blocks(
    light, light_record, monkeypatch
):
    """A short contact averaged over a transient block's few cycles can vanish from a
    bootstrap replicate (survey draw 35: a 2-cycle block of every replicate).  That block
    has no criteria.  Where every replicate lost a block, the floor is over the blocks each
    shows (weighted by their cycles), not undefined (which made every law inconsistent);
    with no block left it is undefined; where some replicates are complete, theirs."""
    from discovery.vibroimpact.verify import span_floor as SF

    ref = Reference.from_measurement(light_record, light, n_boot=4)
    assert ref.span is not None and len(ref.span.blocks) > 1
    ev = evaluate(light, light.law, ref)
    base = ev.noise_floor
    assert np.isfinite(base["I2"]) and ev.consistent
    run = SF.simulated_motion

    def hidden(blocks):
        def motion(*args, starts=None, **kwargs):
            hist, zs = run(*args, starts=starts, **kwargs)
            if starts is not None:  # a replicate's draw: these blocks' contacts gone
                hist = [0.0 * h if i in blocks else h for i, h in enumerate(hist)]
            return hist, zs

        return motion

    stand_in = [s for _, s in ev.blocks]  # the law's folded blocks from the measured states
    monkeypatch.setattr(SF, "simulated_motion", hidden({0}))
    fl = ref.floor_for(stand_in, scenario=light, law=light.law)
    assert fl["n_boot"] == 4 and np.isfinite(fl["mean"]["I2"])
    assert fl["mean"]["I2"] != base["I2"]  # the first block's share is out
    # one replicate without the first block's contact, three complete: the floor is the
    # complete replicates' (a replicate that lost a block is a draw that left the record)
    calls = []

    def first_hidden(*args, starts=None, **kwargs):
        hist, zs = run(*args, starts=starts, **kwargs)
        if starts is not None:
            calls.append(1)
            if len(calls) == 1:
                hist = [0.0 * h if i == 0 else h for i, h in enumerate(hist)]
        return hist, zs

    monkeypatch.setattr(SF, "simulated_motion", first_hidden)
    three = ref.floor_for(stand_in, scenario=light, law=light.law)
    assert three["n_boot"] == 3 and np.isfinite(three["mean"]["I2"])
    monkeypatch.setattr(SF, "simulated_motion", hidden(set(range(len(ref.span.blocks)))))
    none = ref.floor_for(stand_in, scenario=light, law=light.law)
    assert none["n_boot"] == 0 and none["mean"]["I2"] == float("inf")


def test_a_floor_that_would_pass_a_law_without_force_decides_nothing():
    """A law without force scores I2 = 1.  Where the law's own replicates score so far
    from its force that the I2 limit reaches 1 (survey draw 39: floor 0.97), every law
    with a contact would pass: the limit is undefined, the law not consistent, and the
    verdict says why."""
    from discovery.vibroimpact.verify.consistency import consistency_limits
    from discovery.vibroimpact.verify.evaluation import _verdict

    assert np.isfinite(consistency_limits({"I2": 0.49, "I4": 0.3})["I2"])
    lim = consistency_limits({"I2": 0.5, "I4": 0.3})
    assert lim["I2"] == float("inf") and np.isfinite(lim["I4"])
    same = {"measured": "P1", "simulated": "P1"}
    text = _verdict(
        False,
        same,
        {"measured": 1, "simulated": 1},
        {"I2": 0.6, "I4": 0.1},
        {"I2": 0.5, "I4": 0.3},
        lim=lim,
    )
    assert "would pass a law without force" in text and "cannot test it" in text
