"""What a verification says: a failed simulation, the default start's note, a transient, the
contacts per cycle, and a law whose steady orbit has no contact force over the record's last
cycles."""

import pytest

from discovery import ForceLaw, load_scenario
from discovery.vibroimpact.dynamics.synthetic import synthesize
from discovery.vibroimpact.verify import Evaluation, Reference, evaluate, verify
from discovery.vibroimpact.verify.notes import contacts_note, transient_notes
from discovery.vibroimpact.verify.verdict import _default_start_note


@pytest.fixture(scope="module")
def paper():
    return load_scenario("paper")


@pytest.fixture(scope="module")
def quickstart(paper):
    """The README quickstart's record (``vidi simulate --scenario paper --periods 12 --noise
    0.01 --seed 1``)."""
    m = synthesize(paper, paper.law, periods=12, fs=20000.0, noise=0.01, seed=1)
    return Reference.from_measurement(m, paper)


def _ev(status, simulated, criteria=None, message="", comparison="record span"):
    return Evaluation(
        status,
        {"measured": "P1", "simulated": simulated},
        {"measured": 1, "simulated": None if status == "failed" else 1},
        criteria or {},
        {},
        False,
        "",
        message=message,
        comparison=comparison,
    )


def test_a_failed_simulation_is_inconsistent_with_its_message_and_no_none(paper, quickstart):
    """A law far too soft sinks the moulding into the frame: the verdict is "inconsistent"
    with the failure's message, the regime line has no Python None, and no coexisting
    attractors are claimed (a failure is no attractor)."""
    res = verify(paper, quickstart, ForceLaw.parse("z"))
    ev = res.evaluation
    assert ev.status == "failed" and not ev.criteria
    assert ev.verdict.startswith("inconsistent: the law's simulation failed: ")
    assert ev.message and ev.message in ev.verdict
    text = str(res)
    assert "None" not in text and "simulated none (the simulation failed)" in text
    assert "None" not in res.regime_line()
    assert not any("coexisting" in n or "attractor" in n for n in res.notes)


def test_the_default_start_note_claims_coexisting_attractors_only_when_they_differ():
    """Two nonperiodic motions, or a failure on either side, are no evidence of another
    attractor; a periodic regime against another one is."""
    nonperiodic = _ev("ok", "nonperiodic", {"I2": 1.2})
    assert _default_start_note(nonperiodic, _ev("nonperiodic", None)) == ""
    failed = _ev("failed", None, message="the step size underflowed")
    note = _default_start_note(_ev("ok", "P1", {"I2": 0.02}), failed)
    assert "attractor" not in note and "the step size underflowed" in note
    note = _default_start_note(failed, _ev("ok", "P1", {"I2": 0.5}))
    assert "attractor" not in note and "reaches P1" in note
    assert _default_start_note(failed, failed) == ""
    note = _default_start_note(_ev("ok", "P1", {"I2": 0.02}), _ev("ok", "P2", {"I2": 0.5}))
    assert note == (
        "from the scenario's initial state the law reaches another attractor (P2, I2 0.5) "
        "than from the measured state (P1): coexisting attractors"
    )
    note = _default_start_note(_ev("ok", "P1", {"I2": 0.02}), _ev("nonperiodic", None))
    assert "another attractor (nonperiodic)" in note and "inf" not in note


def test_a_transient_note_reads_as_a_sentence():
    (note,) = transient_notes(False, False, 0.611, {"measured": "P1", "simulated": "P1"}, None)
    assert note == (
        "the law's trajectory from the measured state has not settled by the record's end: "
        "over its last cycles it is I2 = 0.611 from the law's steady orbit; the law is judged "
        "against the record's own span"
    )
    (note,) = transient_notes(
        False, False, float("inf"), {"measured": "P1", "simulated": "P1"}, None
    )
    assert "inf" not in note and "contact force where the law's steady orbit has none" in note
    (note,) = transient_notes(True, False, None, {"measured": "P1", "simulated": "P2"}, None)
    assert note.startswith("the record reads P1, but this law's trajectory from the measured")
    assert "record is still in a transient" not in note


def test_the_contacts_note_states_one_thing():
    """The law's folded cycle and the record's counts differ, yet they are taken to agree:
    the note says why, without contradicting itself."""
    note = contacts_note(2, 1, 1)
    assert note.startswith("the law's folded cycle shows 2 contacts and the record 1 contact;")
    assert "the law's own records with the record's noise show the record's 1 contact" in note
    assert "the contact counts agree" in note and "where the record has" not in note
    note = contacts_note(2, 1, 2)
    assert "the record's folded cycle shows 2 contacts too" in note
    note = contacts_note(2, 1, 2, own=1)
    assert "the law's own motion has 1 contact" in note


def test_a_compared_law_is_never_reported_as_failed(paper, quickstart):
    """The quickstart's pure damper: its steady orbit has no contact force over the record's
    last cycles, which made I2 to that orbit undefined and the regime "failed (I2 is
    undefined ...)" next to criteria that were computed."""
    ev = evaluate(paper, ForceLaw.parse("4.3375945630e10*zd"), quickstart)
    assert ev.status == "ok" and ev.criteria["I2"] > 0.5
    assert not str(ev.regime["simulated"]).startswith("failed")
    assert "failed" not in ev.verdict and "undefined" not in ev.verdict
    assert ev.verdict.startswith("inconsistent")


def test_the_report_of_a_failed_simulation_says_so(paper, quickstart, tmp_path):
    """No "None", no empty criteria table, no conclusion pointing at a simulated curve that
    is not drawn."""
    from reports.document import report
    from reports.vibroimpact.verify_figures import verify_figure

    res = verify(paper, quickstart, ForceLaw.parse("z"))
    res.record_run({"command": "verify", "scenario": paper.as_dict(), "data": "D.csv"})
    res.save(tmp_path)
    verify_figure(res, str(tmp_path / "verify"))
    report(tmp_path, compile=False)
    tex = (tmp_path / "report.tex").read_text()
    assert "None" not in tex
    assert "the law's simulation failed (under law" in tex
    assert "criterion & value" not in tex  # no table with its header alone
    assert "departs from the measured" not in tex and "(red)" not in tex
    assert "The measured force alone" in tex
