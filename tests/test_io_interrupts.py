"""Interruptions of a command: Ctrl-C (SIGINT) exits 130 and SIGTERM 143 with one line,
no traceback, earlier results intact and no staging left; after SIGKILL the next run
removes the staging directory the killed one left."""

import contextlib
import json
import os
import signal
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pytest

from discovery.cli import main

ROOT = Path(__file__).resolve().parent.parent


def _restore_sigint():
    """A child's Ctrl-C as in a terminal: a suite started as a background job (``make test
    &``, some CI runners) passes SIGINT ignored to its children, and Python then installs
    no KeyboardInterrupt handler."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


# `vidi steady --out DIR`, held inside the output stage (the staging directory exists):
# the result is written into the open stage (``Result.write_into``)
_CHILD = textwrap.dedent("""
    import sys, time
    import discovery._api._result as R
    real = R.Result.write_into
    def slow(*a, **k):
        print("staged", flush=True)
        time.sleep(120)
        return real(*a, **k)
    R.Result.write_into = slow
    from discovery.cli import main
    sys.exit(main(["steady", "--out", sys.argv[1]]))
""")


def _wait_staged(p):
    for line in p.stdout:  # steady prints its result, then enters the output stage
        if line.strip() == "staged":
            return
    raise AssertionError("the child ended before staging its output")


EARLIER = {"command": "steady", "earlier": True}


@pytest.fixture
def earlier(tmp_path):
    out = tmp_path / "res"
    out.mkdir()
    # an earlier result (a summary.json naming the command that wrote it)
    (out / "summary.json").write_text('{"command": "steady", "earlier": true}\n')
    (out / "figure.png").write_bytes(b"old figure")
    return out


def _intact(out):
    assert json.loads((out / "summary.json").read_text()) == EARLIER
    assert (out / "figure.png").read_bytes() == b"old figure"
    assert sorted(p.name for p in out.parent.iterdir()) == ["res"]


def test_keyboard_interrupt_in_process(earlier, monkeypatch, capsys):
    import discovery.cli.steady as st

    def interrupt(*a, **k):
        raise KeyboardInterrupt

    monkeypatch.setattr(st, "provenance_of", interrupt)
    assert main(["steady", "--out", str(earlier)]) == 130
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("vidi: error: interrupted (Ctrl-C)")
    _intact(earlier)


@pytest.mark.parametrize(
    ("sig", "code", "word"),
    [(signal.SIGINT, 130, "interrupted"), (signal.SIGTERM, 143, "terminated")],
)
def test_signal_exits_with_one_line(earlier, sig, code, word):
    p = subprocess.Popen(
        [sys.executable, "-c", _CHILD, str(earlier)],
        cwd=ROOT,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        preexec_fn=_restore_sigint,
    )
    _wait_staged(p)
    assert any(".vidi-staging." in q.name for q in earlier.parent.iterdir())
    p.send_signal(sig)
    out, err = p.communicate(timeout=60)
    assert p.returncode == code, err
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"vidi: error: {word}"), err
    assert "Traceback" not in err
    _intact(earlier)


# a Ctrl-C that lands in a callback Python cannot propagate from (as an import lock's
# weakref callback, during the imports): printed as "Exception ignored" and lost, the run
# went on; vidi's entry point gives it back to the main thread
_LOST = textwrap.dedent("""
    import sys, time, weakref
    import discovery._api._result as R
    real = R.Result.write_into
    def lost(*a, **k):
        class Held: pass
        h = Held()
        def cb(_):
            raise KeyboardInterrupt
        r = weakref.ref(h, cb)
        del h  # the callback raises: an unraisable interrupt
        time.sleep(5)
        return real(*a, **k)
    R.Result.write_into = lost
    from discovery.cli import main
    sys.argv = ["vidi", "steady", "--out", sys.argv[1]]
    sys.exit(main())
""")


def _stops_with_one_line(script, earlier):
    """``script`` run as a child on ``earlier``: exit 130, the interrupt's one line, the
    earlier results intact."""
    p = subprocess.run(
        [sys.executable, "-c", script, str(earlier)],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=120,
        preexec_fn=_restore_sigint,
    )
    assert p.returncode == 130, p.stderr
    assert p.stderr.splitlines() == [
        "vidi: error: interrupted (Ctrl-C); partial outputs were removed, earlier results "
        "are unchanged"
    ], p.stderr
    _intact(earlier)


def test_interrupt_in_an_unraisable_callback_still_stops_the_run(earlier):
    _stops_with_one_line(_LOST, earlier)


# `vidi steady` interrupted while it holds an object the interrupt left half built (as
# llvmlite's, when Ctrl-C cuts a first run's compilation short): its ``__del__`` fails when
# the run's frames are freed, one held directly and one in a reference cycle (freed by the
# collector, later)
_HALF = textwrap.dedent("""
    import sys
    import discovery.cli.steady as st
    class Half:
        def __del__(self):
            del self._as_parameter_
    def compiled(*a, **k):
        held, cycle = Half(), Half()
        cycle.me = cycle
        raise KeyboardInterrupt
    st.provenance_of = compiled
    from discovery.cli import main
    sys.argv = ["vidi", "steady", "--out", sys.argv[1]]
    sys.exit(main())
""")


def test_what_an_interrupt_left_half_built_is_freed_without_a_traceback(earlier):
    _stops_with_one_line(_HALF, earlier)


def test_a_failing_clean_up_outside_an_interrupt_is_still_reported(monkeypatch):
    """The quiet hook is for a stopped run only: before it, a failing ``__del__`` reaches
    the previous hook."""
    import discovery.cli as cli

    seen = []
    hook = cli._Unraisable(seen.append)
    monkeypatch.setattr(sys, "unraisablehook", hook)

    class Half:
        def __del__(self):
            del self._as_parameter_

    Half()
    assert [type(u.exc_value) for u in seen] == [AttributeError]
    hook.stopped = True
    Half()
    assert len(seen) == 1


def test_sigkill_then_next_run_cleans_up(earlier, capsys):
    p = subprocess.Popen(
        [sys.executable, "-c", _CHILD, str(earlier)], cwd=ROOT, stdout=subprocess.PIPE, text=True
    )
    _wait_staged(p)
    p.kill()
    p.wait()
    p.stdout.close()
    left = [q for q in earlier.parent.iterdir() if ".vidi-staging." in q.name]
    assert len(left) == 1
    assert json.loads((earlier / "summary.json").read_text()) == EARLIER
    assert main(["steady", "--out", str(earlier)]) == 0
    capsys.readouterr()
    assert sorted(q.name for q in earlier.parent.iterdir()) == ["res"]
    # an earlier result without a manifest (older vidi): what the new result does not
    # replace is kept, since nothing says it was vidi's
    assert sorted(q.name for q in earlier.iterdir()) == [
        ".vidi-manifest.json",
        "figure.png",
        "summary.json",
    ]
    assert json.loads((earlier / "summary.json").read_text())["command"] == "steady"


def test_interrupt_reraised_by_compiled_code_is_an_interrupt(earlier, monkeypatch, capsys):
    """numba re-raises a Ctrl-C inside compiled code as ``SystemError`` with the interrupt
    as its cause: still 130 and the interrupt line, not an internal error."""
    import discovery.cli.steady as st

    def compiled(*a, **k):
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as exc:
            raise SystemError("CPUDispatcher returned a result with an exception set") from exc

    monkeypatch.setattr(st, "provenance_of", compiled)
    assert main(["steady", "--out", str(earlier)]) == 130
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("vidi: error: interrupted (Ctrl-C)")
    _intact(earlier)


@pytest.mark.parametrize("delay", [0.3, 2.0, 4.0, 7.0])
def test_ctrl_c_to_the_process_group_during_identify(tmp_path, delay):
    """Ctrl-C in a terminal reaches the whole process group, at any moment of a run:
    during the imports, the simulations, the bootstrap; the exit is 130 with one line (or 0
    when the run had already finished), never an internal error or a traceback."""
    from discovery import ForceLaw, load_scenario, synthesize

    rec = synthesize(
        load_scenario("paper"), ForceLaw.parse("2e8*z + 1e7*zd"), periods=8, noise=0.01, seed=1
    )
    rec.to_csv(tmp_path / "R.csv")
    entry = "import sys; from discovery.cli import main; sys.exit(main())"
    p = subprocess.Popen(
        [
            sys.executable,
            "-c",
            entry,
            "identify",
            "--scenario",
            "paper",
            "--data",
            "R.csv",
            "--start",
            "1.5e8*z + 8e6*zd",
            "--intervals",
            "10",
            "--out",
            "I",
        ],
        cwd=tmp_path,
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=_restore_sigint,
    )
    time.sleep(delay)
    with contextlib.suppress(ProcessLookupError):
        os.killpg(p.pid, signal.SIGINT)
    out, err = p.communicate(timeout=300)
    assert p.returncode in (130, 0), (p.returncode, err)
    assert "Traceback" not in err and "internal error" not in err, err
    if p.returncode == 130:
        lines = [ln for ln in err.splitlines() if not ln.endswith(" ...")]  # progress lines
        assert lines == [
            "vidi: error: interrupted (Ctrl-C); partial outputs were "
            "removed, earlier results are unchanged"
        ], err
        assert not (tmp_path / "I").exists()
        assert not [q for q in tmp_path.iterdir() if ".vidi-staging." in q.name]


def test_out_of_memory_is_one_line_once_the_memory_is_freed(earlier, monkeypatch, capfd):
    """A MemoryError is reported after the handlers have left the frames that hold the
    memory (formatting a message inside them raised a second MemoryError), from a line
    built in advance; earlier results stay."""
    import discovery.cli.steady as st

    def exhaust(*a, **k):
        hog = [bytearray(1 << 20)]  # noqa: F841  (a frame holding memory)
        raise MemoryError

    monkeypatch.setattr(st, "provenance_of", exhaust)
    assert main(["steady", "--out", str(earlier)]) == 2
    err = capfd.readouterr().err
    assert err.splitlines() == [
        "vidi: error: not enough memory for this run; reduce its size "
        "(--fs, --periods, --grid) and try again"
    ], err
    _intact(earlier)
