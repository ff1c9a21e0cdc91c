"""Files of a staged result written by forked children (``discovery._files._handoff``): the
output directory waits for them, writes again what a failed child left, kills them when the
run fails; outside an output directory a write is done at once; a figure's files are the
same either way."""

import os
import re
import time
from pathlib import Path

import numpy as np
import pytest

from discovery._files import _handoff
from discovery._files._io import OutputDir

pytestmark = pytest.mark.skipif(not _handoff.in_parallel(), reason="one core or no fork here")


def _writer(path, *, fail_in_child=False, sleep=0.0):
    """A write of ``path`` that records the pid that wrote it (and fails in a child)."""
    parent = os.getpid()

    def fn():
        time.sleep(sleep)
        if fail_in_child and os.getpid() != parent:
            raise RuntimeError("a child's write failed")
        Path(path).write_text(str(os.getpid()))

    return fn


def test_a_write_in_an_output_directory_is_a_childs_and_is_waited_for(tmp_path):
    with OutputDir(tmp_path / "out") as out:
        _handoff.write(out.path("slow.txt"), _writer(out.path("slow.txt"), sleep=0.3))
        assert out.path("slow.txt") in {p for p in _handoff._PENDING}
    written = (tmp_path / "out" / "slow.txt").read_text()
    assert int(written) != os.getpid()  # a child wrote it
    assert not _handoff._PENDING
    assert "slow.txt" in (tmp_path / "out" / ".vidi-manifest.json").read_text()


def test_a_write_outside_an_output_directory_is_done_at_once(tmp_path):
    f = tmp_path / "now.txt"
    _handoff.write(f, _writer(f))
    assert int(f.read_text()) == os.getpid() and not _handoff._PENDING


def test_a_failed_childs_file_is_written_by_the_parent(tmp_path):
    with OutputDir(tmp_path / "out") as out:
        _handoff.write(out.path("f.txt"), _writer(out.path("f.txt"), fail_in_child=True))
    assert int((tmp_path / "out" / "f.txt").read_text()) == os.getpid()


def test_finish_waits_for_the_files_a_reader_needs(tmp_path):
    with OutputDir(tmp_path / "out") as out:
        _handoff.write(out.path("a.txt"), _writer(out.path("a.txt"), sleep=0.3))
        assert not out.path("a.txt").exists()
        _handoff.finish([out.path("a.txt")])
        assert out.path("a.txt").exists() and not _handoff._PENDING


def test_a_reader_in_another_thread_finds_the_file_there(tmp_path):
    """LaTeX's thread (``vidi fit``) waits for the figure it reads while this thread hands
    off the next ones."""
    from concurrent.futures import ThreadPoolExecutor

    with OutputDir(tmp_path / "out") as out, ThreadPoolExecutor(1) as reader:
        _handoff.write(out.path("a.txt"), _writer(out.path("a.txt"), sleep=0.3))

        def read():
            _handoff.finish([out.path("a.txt")])
            return out.path("a.txt").read_text()

        seen = reader.submit(read)
        for k in range(3):
            _handoff.write(out.path(f"b{k}.txt"), _writer(out.path(f"b{k}.txt")))
        assert int(seen.result()) != os.getpid()
    assert sorted(p.name for p in (tmp_path / "out").glob("*.txt")) == [
        "a.txt",
        "b0.txt",
        "b1.txt",
        "b2.txt",
    ]


def test_a_failed_run_kills_its_children_and_leaves_the_target(tmp_path):
    (tmp_path / "out").mkdir()
    with pytest.raises(KeyError), OutputDir(tmp_path / "out") as out:
        _handoff.write(out.path("late.txt"), _writer(out.path("late.txt"), sleep=30.0))
        (pid,) = [child.pid for child, _ in _handoff._PENDING.values()]
        raise KeyError("the run failed")
    assert not _handoff._PENDING
    with pytest.raises(ChildProcessError):  # reaped, not a zombie left behind
        os.waitpid(pid, os.WNOHANG)
    assert list((tmp_path / "out").iterdir()) == []
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".out")]


def test_one_core_writes_at_once(tmp_path, monkeypatch):
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0})
    with OutputDir(tmp_path / "out") as out:
        _handoff.write(out.path("x.txt"), _writer(out.path("x.txt")))
        assert int(out.path("x.txt").read_text()) == os.getpid()


def _figure():
    from matplotlib.figure import Figure

    fig = Figure(figsize=(4.0, 3.0), layout="constrained")
    ax = fig.subplots()
    x = np.linspace(0.0, 1.0, 50)
    ax.plot(x, x**2, label=r"$\dot{\zeta}_{+}$")
    ax.set_xlabel(r"penetration $\zeta$ [mm]")
    ax.set_title(r"$F = k \zeta^{3/2}$")
    ax.legend(loc="best")
    return fig


def _pdf_body(path):
    return re.sub(rb"/CreationDate \(.*?\)", b"", Path(path).read_bytes())


def test_a_figure_saved_by_a_child_is_the_figure_saved_at_once(tmp_path):
    """The PNG and the PDF (but its date) are the same bytes whether the PDF was printed by
    a forked child in an output directory or in this process, and a report's figure list
    sees the child's PDF."""
    from reports._mpl import save
    from reports.cells import _figures

    save(_figure(), str(tmp_path / "here"))
    with OutputDir(tmp_path / "out") as out:
        save(_figure(), str(out.path("fit_impulse")))
        assert out.path("fit_impulse.pdf") in _handoff._PENDING
        assert [f["file"] for f in _figures(out.stage, ["fit_impulse"])] == ["fit_impulse.pdf"]
    out_dir = tmp_path / "out"
    assert (out_dir / "fit_impulse.png").read_bytes() == (tmp_path / "here.png").read_bytes()
    assert _pdf_body(out_dir / "fit_impulse.pdf") == _pdf_body(tmp_path / "here.pdf")
