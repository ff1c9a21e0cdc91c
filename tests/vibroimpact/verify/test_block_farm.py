"""A block farm shares out a record's blocks and answers the same bits as one process: the
evaluations (with their noise floor), the exact Jacobians and identify's fit; a failing law
fails the same way; a model it cannot send is evaluated here; the farm answers only in the
process that made it, and leaves no worker behind."""

import dataclasses
import multiprocessing
import os

import numpy as np
import pytest

from discovery import ForceLaw, load_scenario
from discovery.vibroimpact.fit.identification import identify
from discovery.vibroimpact.verify import Reference, evaluate
from discovery.vibroimpact.verify import block_farm as BF
from discovery.vibroimpact.verify import trajectory as TR
from tests.realistic import reference_record

TRUTH = ForceLaw.parse("2.06e8*z + 0.9e7*zd + 2e10*z*zd")


@pytest.fixture(scope="module")
def record():
    sc = load_scenario("paper")
    m = reference_record((sc.with_law(TRUTH), TRUTH), periods=12, seed=3, check=False)
    return sc, Reference.from_measurement(m, sc)


def _same(a, b):
    """Two evaluations agree bit for bit (criteria, floor, verdict, folded blocks,
    penetrations)."""
    assert a.status == b.status and a.verdict == b.verdict
    assert a.criteria == b.criteria and a.noise_floor == b.noise_floor
    assert a.consistent == b.consistent
    for (_, s1), (_, s2) in zip(a.blocks, b.blocks, strict=True):
        assert np.array_equal(s1.t, s2.t) and np.array_equal(s1.F, s2.F)
    for z1, z2 in zip(a.penetration, b.penetration, strict=True):
        assert np.array_equal(z1, z2)


def _fresh(f):
    TR.MEMO.clear()
    return f()


def test_evaluations_are_the_same_bits_on_a_farm(record):
    sc, ref = record
    law = ForceLaw.parse("2.1e8*z + 1.0e7*zd")
    short = ref.shortened()
    assert len(short.span.blocks) > 3
    here = [_fresh(lambda r=r: evaluate(sc, law, r, floor=True)) for r in (ref, short)]
    with BF.shared_blocks([ref], 3) as farm:
        assert farm is not None and farm.holds(ref.span) and farm.holds(short.span)
        there = [_fresh(lambda r=r: evaluate(sc, law, r, floor=True)) for r in (ref, short)]
        windowed = _fresh(lambda: evaluate(sc, law, short, floor=False, objective=("I2",)))
    for a, b in zip(here, there, strict=True):
        _same(a, b)
    _same(_fresh(lambda: evaluate(sc, law, short, floor=False, objective=("I2",))), windowed)


def test_sensitivities_are_the_same_bits_on_a_farm(record):
    sc, ref = record
    law = ForceLaw.parse("2.1e8*z + 1.0e7*zd")
    span = ref.shortened().span
    here = _fresh(lambda: TR.history_sensitivities(sc, law, span))
    here_z = TR.penetration_sensitivities(sc, law, span)
    with BF.shared_blocks([ref], 2):
        there = _fresh(lambda: TR.history_sensitivities(sc, law, span))
        there_z = TR.penetration_sensitivities(sc, law, span)
    for a, b in zip(here + here_z, there + there_z, strict=True):
        assert np.array_equal(a, b)


def test_a_failing_law_fails_the_same_way(record):
    sc, ref = record
    soft = ForceLaw.parse("1e3*z + 1e2*zd")  # the moulding sinks into the frame
    here = _fresh(lambda: evaluate(sc, soft, ref, floor=False))
    with BF.shared_blocks([ref], 2):
        there = _fresh(lambda: evaluate(sc, soft, ref, floor=False))
    assert here.status == there.status != "ok"
    assert here.verdict == there.verdict and "sinks" in here.verdict


def test_a_model_that_cannot_be_sent_is_evaluated_here(record):
    sc, ref = record
    law = ForceLaw.parse("2.1e8*z + 1.0e7*zd")

    def observe(impulse):  # a closure: not picklable
        return impulse

    here = _fresh(lambda: evaluate(sc, law, ref, floor=False, observe=observe))
    with BF.shared_blocks([ref], 2):
        there = _fresh(lambda: evaluate(sc, law, ref, floor=False, observe=observe))
    _same(here, there)


def test_identify_on_a_farm_is_the_same_fit(record):
    sc, ref = record
    start = ForceLaw.parse("1.8e8*z + 1.2e7*zd + 1e10*z*zd")
    kw = {"max_simulations": 40, "check": False}
    one = _fresh(lambda: identify(sc, ref, start, workers=1, **kw))
    two = _fresh(lambda: identify(sc, ref, start, workers=2, **kw))
    assert one.law == two.law and one.value == two.value
    assert one.n_simulations == two.n_simulations
    assert one.standard_errors == two.standard_errors


def test_the_farm_answers_only_where_it_was_made(record):
    sc, ref = record
    other = Reference.from_measurement(
        reference_record((sc.with_law(TRUTH), TRUTH), periods=8, seed=4, check=False), sc
    )
    with BF.shared_blocks([ref], 2) as farm:
        assert BF.farm_for(ref.span) is farm
        assert BF.farm_for(other.span) is None  # not one of its records
        pid = os.fork()
        if pid == 0:  # a forked worker of a pool does its blocks itself
            os._exit(0 if BF.farm_for(ref.span) is None else 1)
        _, status = os.waitpid(pid, 0)
        assert os.waitstatus_to_exitcode(status) == 0
    assert BF.farm_for(ref.span) is None
    with BF.shared_blocks([ref], 1) as farm:
        assert farm is None


def test_no_worker_is_left_behind(record):
    sc, ref = record
    with BF.shared_blocks([ref], 3):
        assert len(multiprocessing.active_children()) >= 2
    assert not [p for p in multiprocessing.active_children() if p.name.startswith("Process")]


def _interrupt(reference, k):
    if os.getpid() == _interrupt.parent:
        raise KeyboardInterrupt
    return k


def test_an_interrupted_farm_closes(record):
    sc, ref = record
    _interrupt.parent = os.getpid()
    with BF.shared_blocks([ref], 2) as farm:
        with pytest.raises(KeyboardInterrupt):
            farm.map(_interrupt, ref.span, ())
        assert not farm.holds(ref.span)  # closed: its answers would be out of step
        assert BF.farm_for(ref.span) is None


def test_the_named_contact_models_on_a_farm_are_the_same_fits():
    """``fit_contact_models(workers=2)``: each fit's blocks and the bootstrap's refits in
    parallel, the same fits as on one process."""
    from discovery.vibroimpact.fit.contact_fit import fit_contact_models

    sc = load_scenario("paper")
    m = reference_record((sc, sc.law), periods=8, seed=5, check=False)
    kw = {"models": ("kelvin-voigt", "hertz-damper"), "max_simulations": 40, "n_boot": 5}
    one = _fresh(lambda: fit_contact_models(sc, m, workers=1, **kw))
    two = _fresh(lambda: fit_contact_models(sc, m, workers=2, **kw))
    assert [dataclasses.asdict(f) for f in one.fits] == [dataclasses.asdict(f) for f in two.fits]
    assert one.selected == two.selected


def _unsendable_in_workers(reference, k):
    """An answer a worker cannot send (a lambda), a plain one here."""
    if os.getpid() != _interrupt.parent:
        return lambda: k
    return k


def test_answers_a_worker_cannot_send_are_made_here(record):
    sc, ref = record
    _interrupt.parent = os.getpid()
    n = len(ref.span.blocks)
    with BF.shared_blocks([ref], 2) as farm:
        assert farm.map(_unsendable_in_workers, ref.span, ()) == list(range(n))
        assert farm.holds(ref.span)  # still in step: it goes on sharing out


def test_a_lost_worker_leaves_the_work_here(record):
    sc, ref = record
    law = ForceLaw.parse("2.1e8*z + 1.0e7*zd")
    here = _fresh(lambda: evaluate(sc, law, ref, floor=True))
    with BF.shared_blocks([ref], 2) as farm:
        farm._procs[0].kill()
        farm._procs[0].join()
        there = _fresh(lambda: evaluate(sc, law, ref, floor=True))
        assert not farm.holds(ref.span)  # closed: the blocks are done here
        _same(here, there)


def _farm_in_a_daemon(ref, out):
    with BF.shared_blocks([ref], 2) as farm:
        out.put(farm is None)


def test_a_daemonic_process_opens_no_farm(record):
    """A worker of someone else's pool (daemonic: it may not have children) fits alone."""
    sc, ref = record
    ctx = multiprocessing.get_context("fork")
    out = ctx.Queue()
    p = ctx.Process(target=_farm_in_a_daemon, args=(ref, out), daemon=True)
    p.start()
    assert out.get(timeout=60) is True
    p.join(timeout=10)
