"""Figures drawn by a process forked when a command starts (``discovery._files._drawer``):
the same files as drawn in the command, waited for by the output directory, drawn again by
the command where the drawer did not write them, at once outside an output directory."""

import os
import re
import signal
import time
from pathlib import Path

import numpy as np
import pytest

from discovery._files import _handoff
from discovery._files._drawer import Drawer, drawing
from discovery._files._io import OutputDir

pytestmark = pytest.mark.skipif(not _handoff.in_parallel(), reason="one core or no fork here")

SQUARE = "_test_square"  # a name of `reports`, as the commands' figures are (fixture below)


def _square(stem, here=None, *, fail=False, slow=False, extra=None):
    """A small figure with mathtext as ``stem.png``/``.pdf``; in a process other than
    ``here`` (a pid) it raises (``fail``) or first sleeps 5 s (``slow``)."""
    from reports._mpl import save, subplots

    if here is not None and os.getpid() != here:
        if slow:
            time.sleep(5.0)
        if fail:
            raise RuntimeError("drawn in the wrong process")
    fig, ax = subplots(figsize=(3.0, 2.0), layout="constrained")
    x = np.linspace(0.0, 1.0, 40)
    ax.plot(x, x**2, label=r"$\dot{\zeta}_{+}$")
    ax.set_xlabel(r"penetration $\zeta$ [mm]")
    ax.legend()
    save(fig, stem)


@pytest.fixture(autouse=True)
def _square_in_reports(monkeypatch):
    """``reports._test_square``: set before each drawer is forked, so it has it too."""
    import reports

    monkeypatch.setattr(reports, SQUARE, _square, raising=False)


def _pdf_body(path):
    return re.sub(rb"/CreationDate \(.*?\)", b"", Path(path).read_bytes())


def test_a_figure_the_drawer_draws_is_the_figure_drawn_here(tmp_path):
    _square(str(tmp_path / "here"))
    with drawing([SQUARE], ["reports._mpl"]) as drawer, OutputDir(tmp_path / "out") as out:
        assert isinstance(drawer, Drawer)
        stem = str(out.path("fig"))
        drawer.draw(stem, SQUARE, stem)
        assert {out.path("fig.png"), out.path("fig.pdf")} <= set(_handoff._PENDING)
    assert drawer.answers == {0: True}  # the drawer wrote both files
    out_dir = tmp_path / "out"
    assert (out_dir / "fig.png").read_bytes() == (tmp_path / "here.png").read_bytes()
    assert _pdf_body(out_dir / "fig.pdf") == _pdf_body(tmp_path / "here.pdf")
    assert "fig.pdf" in (out_dir / ".vidi-manifest.json").read_text()
    assert not _handoff._PENDING


def test_a_figure_the_drawer_fails_is_drawn_by_the_command(tmp_path):
    with drawing() as drawer, OutputDir(tmp_path / "out") as out:
        stem = str(out.path("fig"))
        drawer.draw(stem, SQUARE, stem, os.getpid(), fail=True)
    assert drawer.answers == {0: False}
    assert (tmp_path / "out" / "fig.png").stat().st_size > 0
    assert (tmp_path / "out" / "fig.pdf").stat().st_size > 0


def test_a_dead_drawers_figures_are_drawn_by_the_command(tmp_path):
    with drawing() as drawer, OutputDir(tmp_path / "out") as out:
        first, second = str(out.path("a")), str(out.path("b"))
        drawer.draw(first, SQUARE, first, os.getpid(), slow=True)
        os.kill(drawer.pid, signal.SIGKILL)
        drawer.draw(second, SQUARE, second)  # sent to a dead drawer, or drawn here at once
    for name in ("a.png", "a.pdf", "b.png", "b.pdf"):
        assert (tmp_path / "out" / name).stat().st_size > 0


def _slow_print(stem):
    """A figure whose PDF takes its printing child a second and a half."""
    from discovery.outputs import hand_off

    def pdf():
        time.sleep(1.5)
        Path(f"{stem}.pdf").write_bytes(b"%PDF-1.4 slow\n")

    Path(f"{stem}.png").write_bytes(b"png")
    hand_off(f"{stem}.pdf", pdf)


def test_the_drawer_draws_the_next_figure_while_a_pdf_is_printing(tmp_path, monkeypatch):
    """The drawer does not wait for a figure's PDF before it draws the next figure: the
    second figure, sent right after a figure whose print takes 1.5 s, is drawn and answered
    first; both figures' files are in place when the output directory closes."""
    import reports

    monkeypatch.setattr(reports, "_test_slow_print", _slow_print, raising=False)
    with drawing() as drawer, OutputDir(tmp_path / "out") as out:
        slow, fast = str(out.path("slow")), str(out.path("fast"))
        drawer.draw(slow, "_test_slow_print", slow)
        drawer.draw(fast, SQUARE, fast)
        assert drawer.answered(1)
        assert 0 not in drawer.answers  # the slow figure's PDF still printing
    assert list(drawer.answers) == [1, 0] and all(drawer.answers.values())
    assert (tmp_path / "out" / "slow.pdf").read_bytes() == b"%PDF-1.4 slow\n"
    for name in ("slow.png", "fast.png", "fast.pdf"):
        assert (tmp_path / "out" / name).stat().st_size > 0


def _meet(stem, mine, theirs):
    """A figure drawn only while the figure that marks ``theirs`` is drawn too: it marks
    ``mine`` (its pid and its parent's) and waits for ``theirs`` (10 s at most)."""
    Path(mine).write_text(f"{os.getpid()} {os.getppid()}")
    deadline = time.monotonic() + 10.0
    while not Path(theirs).exists():
        if time.monotonic() > deadline:
            raise RuntimeError("drawn alone")
        time.sleep(0.01)
    _square(stem)


def test_the_drawer_draws_figures_side_by_side(tmp_path, monkeypatch):
    """Two figures, each of which is drawn only while the other is: the drawer draws them
    at once, each in a child of its own, and both are answered as written."""
    import reports

    monkeypatch.setattr(reports, "_test_meet", _meet, raising=False)
    marks = [tmp_path / "a.mark", tmp_path / "b.mark"]
    with drawing() as drawer, OutputDir(tmp_path / "out") as out:
        for name, mine, theirs in (("a", *marks), ("b", *marks[::-1])):
            stem = str(out.path(name))
            drawer.draw(stem, "_test_meet", stem, str(mine), str(theirs))
    assert drawer.answers == {0: True, 1: True}
    (a, pa), (b, pb) = (map(int, m.read_text().split()) for m in marks)
    assert a != b and pa == pb == drawer.pid
    for name in ("a.png", "a.pdf", "b.png", "b.pdf"):
        assert (tmp_path / "out" / name).stat().st_size > 0


def test_outside_an_output_directory_or_unpicklable_a_figure_is_drawn_at_once(tmp_path):
    with drawing() as drawer:
        stem = str(tmp_path / "loose")
        drawer.draw(stem, SQUARE, stem)
        assert Path(f"{stem}.png").exists() and not _handoff._PENDING
        with OutputDir(tmp_path / "out") as out:
            stem = str(out.path("fig"))
            drawer.draw(stem, SQUARE, stem, extra=lambda: None)  # a lambda: no pickle
            assert out.path("fig.png").exists()  # (its PDF a child's of this process)
    assert drawer.sent == 0 and (tmp_path / "out" / "fig.pdf").exists()


def test_a_failed_run_stops_the_drawer_and_leaves_the_target(tmp_path):
    target = tmp_path / "out"
    with pytest.raises(RuntimeError), drawing() as drawer, OutputDir(target) as out:
        stem = str(out.path("fig"))
        drawer.draw(stem, SQUARE, stem, os.getpid(), slow=True)
        raise RuntimeError("the run failed")
    assert drawer.dead and not target.exists() and not _handoff._PENDING
    assert not list(tmp_path.iterdir())  # no staging directory left


@pytest.fixture(scope="module")
def records(tmp_path_factory):
    """``{"vibro": the README quickstart's kind of record (12 periods of the paper's machine,
    1 % noise), "ueda": a record of the negative-resistance oscillator}``."""
    from discovery.cli import main

    d = tmp_path_factory.mktemp("rec")
    words = ["simulate", "--scenario", "paper", "--periods", "12", "--noise", "0.01"]
    assert main([*words, "--seed", "1", "--out", str(d / "d.csv")]) == 0
    assert main(["ueda", "simulate", "--periods", "60", "--out", str(d / "u.csv")]) == 0
    return {"vibro": d / "d.csv", "ueda": d / "u.csv"}


#: the commands that draw their figures at their end: their words ("{vibro}", "{ueda}": a
#: record of the fixture) and the figures' stems
FIGURES_AT_THE_END = {
    "calibrate": (["calibrate", "--data", "{vibro}"], ["calibrate"]),
    "identify": (
        ["identify", "--data", "{vibro}", "--start", "1.5e8*z + 1e7*zd", "--intervals", "0"],
        ["identification"],
    ),
    "landscape": (["landscape", "--data", "{vibro}", "--grid", "5x5"], ["landscape"]),
    "advise": (
        ["advise", "--data", "{vibro}", "--law", "2.06e8*z + 1.28e7*zd"]
        + ["--law", "2.0e8*z + 1.28e7*zd + 1e10*z*zd", "--amplitude", "4e5:5e5"]
        + ["--frequency", "24:26", "--grid", "2x2"],
        ["advise_map"],
    ),
    "ueda-attractor": (
        ["ueda", "attractor", "--periods", "200", "--basins", "4"],
        ["attractor", "basins"],
    ),
    "ueda-discover": (["ueda", "discover", "--data", "{ueda}", "--model", "negres"], ["discover"]),
}


@pytest.mark.parametrize("command", sorted(FIGURES_AT_THE_END))
def test_a_command_s_figures_are_drawn_by_its_drawer(records, tmp_path, monkeypatch, command):
    """calibrate, identify, landscape, advise and the Ueda commands send their figures to
    the drawer forked when they start (as verify, fit and explain do), which writes both
    files of each."""
    from discovery.cli import main

    sent, answered = [], []
    draw, wait = Drawer.draw, Drawer.answered

    def spy_draw(self, stem, name, *args, **kwargs):
        sent.append(name)
        return draw(self, stem, name, *args, **kwargs)

    def spy_wait(self, job):
        answered.append(wait(self, job))
        return answered[-1]

    monkeypatch.setattr(Drawer, "draw", spy_draw)
    monkeypatch.setattr(Drawer, "answered", spy_wait)
    words, stems = FIGURES_AT_THE_END[command]
    words = [w.format(**records) for w in words]
    out = tmp_path / "out"
    assert main([*words, "--out", str(out)]) == 0
    assert len(sent) == len(stems) and all(n.endswith("_figure") for n in sent)
    assert answered and all(answered)
    for stem in stems:
        for suffix in (".png", ".pdf"):
            assert (out / f"{stem}{suffix}").stat().st_size > 0
