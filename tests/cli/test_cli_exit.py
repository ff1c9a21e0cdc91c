"""``vidi`` as the process's entry point ends without the interpreter's teardown
(``discovery.cli._finish``): what the run wrote and printed is all there, the exit handlers
ran, its code is the run's, and a thread the interpreter would wait for is waited for."""

import json
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

# the entry point as the console script calls it, with an exit handler and, on request, a
# non-daemon thread that writes a file after the run has ended
_ENTRY = """
import atexit, sys, threading, time
from pathlib import Path
work = Path(sys.argv[1])
atexit.register(lambda: (work / "atexit.txt").write_text("ran"))
if sys.argv[2] == "thread":
    def late():
        time.sleep(1.0)
        (work / "thread.txt").write_text("done")
    threading.Thread(target=late).start()
sys.argv = ["vidi"] + sys.argv[3:]
from discovery.cli import main
sys.exit(main())
"""


def _entry(tmp_path, thread, *words):
    return subprocess.run(
        [sys.executable, "-c", _ENTRY, str(tmp_path), thread, *words],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )


def test_a_run_ends_with_its_outputs_its_lines_and_its_exit_handlers(tmp_path):
    out = tmp_path / "rec.csv"
    words = ["simulate", "--scenario", "paper", "--periods", "3", "--out", str(out)]
    run = _entry(tmp_path, "none", *words)
    assert run.returncode == 0, run.stderr
    assert "rec.csv" in run.stdout  # the last printed line reached the pipe
    rows = out.read_text().splitlines()
    assert rows[0].startswith("t,F") and len(rows) > 100
    summary = json.loads((tmp_path / "rec.summary.json").read_text())
    assert summary["command"] == "simulate"
    assert (tmp_path / "atexit.txt").read_text() == "ran"


def test_bad_input_keeps_its_code_and_line(tmp_path):
    run = _entry(tmp_path, "none", "simulate", "--periods", "-3", "--out", str(tmp_path / "x"))
    assert run.returncode == 2
    assert run.stderr.count("\n") == 1 and "--periods" in run.stderr
    assert (tmp_path / "atexit.txt").read_text() == "ran"


def test_a_thread_still_running_is_waited_for(tmp_path):
    words = ["simulate", "--scenario", "paper", "--periods", "2", "--out", str(tmp_path / "r.csv")]
    run = _entry(tmp_path, "thread", *words)
    assert run.returncode == 0, run.stderr
    assert (tmp_path / "thread.txt").read_text() == "done"
    assert (tmp_path / "atexit.txt").read_text() == "ran"


def test_a_profiled_run_leaves_its_profile(tmp_path):
    """``python -m cProfile -o`` writes its file after the script returns: a watched run
    ends as usual."""
    script = tmp_path / "entry.py"
    script.write_text(_ENTRY)
    words = ["simulate", "--scenario", "paper", "--periods", "2", "--out", str(tmp_path / "r.csv")]
    prof = tmp_path / "run.prof"
    run = subprocess.run(
        [sys.executable, "-m", "cProfile", "-o", str(prof), str(script), str(tmp_path), "none"]
        + words,
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
        check=False,
    )
    assert run.returncode == 0, run.stderr
    assert prof.stat().st_size > 0
