"""Atomic output directories, output checks, stale staging, provenance, file modes and
worker processes that die with their parent (discovery._files._io, discovery.numerics._workers)."""

import hashlib
import json
import os
import re
import signal
import subprocess
import sys
import textwrap
import threading
import time
from pathlib import Path

import pytest

from discovery._files import _io
from discovery._files._io import OutputDir, atomic_write_text, check_output, clean_stale, provenance
from discovery.errors import InputError

ROOT = Path(__file__).resolve().parent.parent
LINUX = sys.platform.startswith("linux")


@pytest.fixture
def umask022():
    old = os.umask(0o022)
    yield
    os.umask(old)


def _write_set(target, run_id, names=("summary.json", "a.csv", "b.png")):
    with OutputDir(target) as out:
        for n in names:
            out.path(n).write_text(f"{run_id}\n")


def _snapshot(d):
    """The result files (the manifest aside: it is checked on its own)."""
    return {p.name: p.read_text() for p in sorted(Path(d).iterdir()) if p.name != _io.MANIFEST}


# ----------------------------------------------------------------------------- OutputDir
def test_new_and_replaced_result_sets(tmp_path, umask022):
    target = tmp_path / "res"
    _write_set(target, 1, ("summary.json", "old_only.csv"))
    assert _snapshot(target) == {"old_only.csv": "1\n", "summary.json": "1\n"}
    assert (target.stat().st_mode & 0o777) == 0o755
    assert (os.stat(target / "summary.json").st_mode & 0o777) == 0o644
    _write_set(target, 2)
    # replaced as a whole: a file of the earlier set that the new one lacks is gone
    assert _snapshot(target) == {"a.csv": "2\n", "b.png": "2\n", "summary.json": "2\n"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res"]


def test_fallback_without_exchange(tmp_path, monkeypatch):
    monkeypatch.setattr(_io, "_exchange", lambda a, b: False)
    target = tmp_path / "res"
    _write_set(target, 1)
    _write_set(target, 2)
    assert set(_snapshot(target).values()) == {"2\n"}
    assert sorted(p.name for p in tmp_path.iterdir()) == ["res"]


def test_failure_keeps_earlier_result_and_leaves_nothing(tmp_path):
    target = tmp_path / "a" / "b" / "res"
    with pytest.raises(RuntimeError), OutputDir(target) as out:
        out.write_json("summary.json", {"x": 1})
        raise RuntimeError("boom")
    assert not (tmp_path / "a").exists()  # parents made for the failed run are removed
    _write_set(target, 1)
    before = _snapshot(target)
    for exc in (RuntimeError, KeyboardInterrupt):
        with pytest.raises(exc), OutputDir(target) as out:
            out.path("summary.json").write_text("new")
            raise exc()
        assert _snapshot(target) == before
    assert sorted(p.name for p in target.parent.iterdir()) == ["res"]


def test_a_symlinked_target_is_refused_and_left_alone(tmp_path):
    """Results never replace through a link: the directory it points to may hold the
    user's files."""
    real = tmp_path / "real"
    _write_set(real, 1)
    (real / "lab_notes.txt").write_text("mine")
    link = tmp_path / "latest"
    link.symlink_to(real)
    with pytest.raises(InputError, match="symbolic link"):
        _write_set(link, 2)
    assert link.is_symlink() and _snapshot(real) == {
        "a.csv": "1\n",
        "b.png": "1\n",
        "lab_notes.txt": "mine",
        "summary.json": "1\n",
    }


@pytest.mark.skipif(not LINUX, reason="readers by directory fd")
def test_reader_never_sees_a_mixed_set(tmp_path):
    """A reader that opens the directory, then its files, never mixes two sets: the
    writer replaces the directory as a whole (the old scheme moved files one by one into
    the target, so a reader saw new files beside old ones).  A reader that holds the old
    directory may see its files disappear while it is removed, never replaced."""
    target = tmp_path / "res"
    names = ("summary.json", "a.csv", "b.png", "c.pdf")
    _write_set(target, 0, names)
    stop = threading.Event()
    bad, seen, complete = [], set(), [0]

    def reader():
        while not stop.is_set():
            try:
                fd = os.open(target, os.O_RDONLY | os.O_DIRECTORY)
            except FileNotFoundError:
                continue  # the fallback's window: absent, never mixed
            try:
                listing = sorted(n for n in os.listdir(fd) if n != _io.MANIFEST)
                vals = set()
                for n in listing:
                    try:
                        with open(n, opener=lambda p, f, fd=fd: os.open(p, f, dir_fd=fd)) as fh:
                            vals.add(fh.read())
                    except FileNotFoundError:
                        pass  # the old set is being removed
            finally:
                os.close(fd)
            if not set(listing) <= set(names) or len(vals) > 1:
                bad.append((listing, vals))
            complete[0] += listing == sorted(names) and len(vals) == 1
            seen.update(vals)

    th = threading.Thread(target=reader)
    th.start()
    try:
        for i in range(1, 150):
            _write_set(target, i, names)
    finally:
        stop.set()
        th.join()
    assert not bad, bad[:3]
    assert len(seen) > 1 and complete[0] > 0


# ------------------------------------------------------------------------ check_output
def test_check_output_refusals(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    data = tmp_path / "d.csv"
    data.write_text("t,F\n")
    (tmp_path / "afile").write_text("x")
    notours = tmp_path / "mine"
    notours.mkdir()
    (notours / "notes.txt").write_text("keep me")
    withsub = tmp_path / "withsub"
    (withsub / "landscape").mkdir(parents=True)
    (withsub / "summary.json").write_text("{}")
    cases = [
        ("", "--out is empty"),
        ("   ", "--out is empty"),
        (str(data), "is the input file"),
        ("afile", "is an existing file"),
        (".", "is the current directory or above it"),
        (str(tmp_path.parent), "is the current directory or above it"),
        ("mine", "not an earlier vidi result (it holds notes.txt)"),
        ("withsub", "not an earlier vidi result (it holds landscape)"),
        ("afile/sub", "is a file, not a directory"),
    ]
    if LINUX:
        cases.append(("/proc/self/x", "cannot write in '/proc/self'"))
    for path, needle in cases:
        with pytest.raises(InputError) as exc:
            check_output(path, [data])
        assert needle in str(exc.value), (path, str(exc.value))
    holder = tmp_path / "holder"
    holder.mkdir()
    inner = holder / "d.csv"
    inner.write_text("t,F\n")
    (holder / "summary.json").write_text("{}")
    with pytest.raises(InputError, match="holds the input file"):
        check_output(holder, [inner])
    with pytest.raises(InputError, match="is a directory; give a file name"):
        check_output(tmp_path, kind="file")
    # accepted: new (with missing parents), empty, an earlier result
    (tmp_path / "empty").mkdir()
    (tmp_path / "prev").mkdir()
    (tmp_path / "prev" / "summary.json").write_text("{}")
    (tmp_path / "prev" / "fig.png").write_bytes(b"png")
    # a summary.json that names no command is the user's own file, not a vidi result
    with pytest.raises(InputError, match="not an earlier vidi result"):
        check_output("prev", [data])
    (tmp_path / "prev" / "summary.json").write_text('{"command": "landscape"}')
    monkeypatch.setitem(_io._RUN, "command", "landscape")  # whatever ran before in-process
    for ok in ("new/deeper/res", "empty", "prev"):
        assert check_output(ok, [data]) == Path(ok)
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "afile",
        "d.csv",
        "empty",
        "holder",
        "mine",
        "prev",
        "withsub",
    ]
    assert (notours / "notes.txt").read_text() == "keep me"


def test_output_dir_refuses_before_touching(tmp_path):
    f = tmp_path / "afile"
    f.write_text("x")
    with pytest.raises(InputError, match="existing file"), OutputDir(f):
        pass
    assert f.read_text() == "x"


# ------------------------------------------------------------------------ stale staging
def _dead_pid():
    p = subprocess.Popen([sys.executable, "-c", "pass"])
    p.wait()
    return p.pid


def test_clean_stale_removes_dead_runs_only(tmp_path):
    target = tmp_path / "res"
    _write_set(target, 1)
    dead = _dead_pid()
    stale = tmp_path / f".res.vidi-staging.{dead}-123.abcd"
    (stale / "x").mkdir(parents=True)
    live = tmp_path / f".res.vidi-staging.{os.getpid()}-{_io._proc_start(os.getpid())}.beef"
    live.mkdir()
    other = tmp_path / f".other.vidi-staging.{dead}-123.abcd"  # another target's
    other.mkdir()
    lookalike = tmp_path / ".res.something"  # not ours
    lookalike.mkdir()
    assert clean_stale(target) == [stale]
    assert live.exists() and other.exists() and lookalike.exists() and not stale.exists()


def test_clean_stale_restores_an_aside_result(tmp_path):
    target = tmp_path / "res"
    _write_set(target, 1)
    aside = tmp_path / f".res.vidi-old.{_dead_pid()}-7.cafe"
    os.rename(target, aside)  # a kill between the two renames of the fallback
    clean_stale(target)
    assert set(_snapshot(target).values()) == {"1\n"} and not aside.exists()


_WRITER = textwrap.dedent("""
    import sys, time
    from discovery._files._io import OutputDir
    target, mode = sys.argv[1], sys.argv[2]
    print("ready", flush=True)
    i = 0
    while True:
        i += 1
        with OutputDir(target) as out:
            for n in ("summary.json", "a.csv", "b.png", "c.pdf"):
                out.path(n).write_text(str(i))
            if mode == "hang":
                print("staged", flush=True)
                time.sleep(60)
""")


def test_sigkill_leaves_staging_that_the_next_run_removes(tmp_path):
    target = tmp_path / "res"
    _write_set(target, "earlier")
    p = subprocess.Popen(
        [sys.executable, "-c", _WRITER, str(target), "hang"],
        stdout=subprocess.PIPE,
        text=True,
        cwd=ROOT,
    )
    assert p.stdout.readline().strip() == "ready"
    assert p.stdout.readline().strip() == "staged"
    p.kill()
    p.wait()
    p.stdout.close()
    assert any(".vidi-staging." in q.name for q in tmp_path.iterdir())
    assert set(_snapshot(target).values()) == {"earlier\n"}
    _write_set(target, "next")
    assert sorted(q.name for q in tmp_path.iterdir()) == ["res"]
    assert set(_snapshot(target).values()) == {"next\n"}


@pytest.mark.slow
@pytest.mark.parametrize("exchange", [True, False])
def test_sigkill_at_random_moments_never_mixes(tmp_path, exchange):
    """A writer replacing the set in a loop is killed at random moments: the target is
    always one complete set, and the next run leaves no staging behind."""
    target = tmp_path / "res"
    script = (
        _WRITER
        if exchange
        else ("import discovery._files._io as m; m._exchange = lambda a, b: False\n" + _WRITER)
    )
    _write_set(target, "earlier", ("summary.json", "a.csv", "b.png", "c.pdf"))
    rng = __import__("random").Random(7)
    for _ in range(3):
        p = subprocess.Popen(
            [sys.executable, "-c", script, str(target), "loop"],
            stdout=subprocess.PIPE,
            text=True,
            cwd=ROOT,
        )
        assert p.stdout.readline().strip() == "ready"
        time.sleep(0.05 + rng.random() * 0.3)  # hundreds of commits
        p.send_signal(signal.SIGKILL)
        p.wait()
        p.stdout.close()
        clean_stale(target)
        assert target.is_dir()
        snap = _snapshot(target)
        assert sorted(snap) == ["a.csv", "b.png", "c.pdf", "summary.json"]
        assert len(set(snap.values())) == 1
    assert sorted(q.name for q in tmp_path.iterdir()) == ["res"]


# -------------------------------------------------------------------- provenance, modes
def test_provenance_versions_git_and_inputs(tmp_path):
    data = tmp_path / "d.csv"
    data.write_bytes(b"t,F\n0,1\n")
    p = provenance(
        {"seed": 1, "f": print},
        inputs={"data": data, "scenario": "paper", "missing": tmp_path / "nope"},
    )
    for name in ("scikit-learn", "clarabel", "osqp", "cvxpy", "numpy"):
        assert p["versions"][name], name
    assert p["settings"] == {"seed": 1}
    assert p["inputs"]["data"]["sha256"] == hashlib.sha256(b"t,F\n0,1\n").hexdigest()
    assert p["inputs"]["data"]["bytes"] == 8
    assert p["inputs"]["scenario"]["path"] == "builtin:paper"
    assert re.fullmatch(r"[0-9a-f]{64}", p["inputs"]["scenario"]["sha256"])
    assert p["inputs"]["missing"]["sha256"] is None
    if (ROOT / ".git").exists():
        assert re.fullmatch(r"[0-9a-f]{40}", p["git"]["commit"])
        assert p["git"]["dirty"] in (True, False)
    json.dumps(p)


def test_git_state_outside_a_checkout(tmp_path):
    assert _io.git_state(tmp_path) == (None, None)


def test_atomic_write_text_mode_follows_umask(tmp_path):
    old = os.umask(0o027)
    try:
        atomic_write_text(tmp_path / "a.txt", "x")
        assert (os.stat(tmp_path / "a.txt").st_mode & 0o777) == 0o640
        os.umask(0o022)
        atomic_write_text(tmp_path / "a.txt", "y")
        assert (os.stat(tmp_path / "a.txt").st_mode & 0o777) == 0o644
    finally:
        os.umask(old)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.txt"]


def test_atomic_write_removes_stale_temporaries(tmp_path):
    stale = tmp_path / f".a.txt.vidi-tmp.{_dead_pid()}-5.abcd"
    stale.write_text("half")
    live = tmp_path / f".a.txt.vidi-tmp.{os.getpid()}-{_io._proc_start(os.getpid())}.beef"
    live.write_text("mine")
    atomic_write_text(tmp_path / "a.txt", "x")
    assert sorted(p.name for p in tmp_path.iterdir()) == [live.name, "a.txt"]


# ------------------------------------------------------------------------------ workers
_POOL = textwrap.dedent("""
    import sys, time
    from concurrent.futures import ProcessPoolExecutor
    from multiprocessing import get_context
    from discovery.numerics._workers import worker_initializer

    def work(x):
        time.sleep(120)

    def init(tag):
        assert tag == "ok"

    kw = worker_initializer(init, ("ok",)) if sys.argv[1] == "guarded" else {}
    pool = ProcessPoolExecutor(2, mp_context=get_context("fork"), **kw)
    futs = [pool.submit(work, i) for i in range(2)]
    time.sleep(1.0)
    print(" ".join(str(p) for p in pool._processes), flush=True)
    time.sleep(120)
""")


def _running(pid):
    try:
        with open(f"/proc/{pid}/stat") as fh:
            return fh.read().rsplit(")", 1)[1].split()[0] not in ("Z", "X")
    except OSError:
        return False


@pytest.mark.skipif(not LINUX, reason="PR_SET_PDEATHSIG is Linux")
def test_workers_die_with_their_parent():
    p = subprocess.Popen(
        [sys.executable, "-c", _POOL, "guarded"], stdout=subprocess.PIPE, text=True, cwd=ROOT
    )
    workers = [int(w) for w in p.stdout.readline().split()]
    p.stdout.close()
    assert len(workers) == 2 and all(_running(w) for w in workers)
    p.kill()
    p.wait()
    deadline = time.time() + 10
    while time.time() < deadline and any(_running(w) for w in workers):
        time.sleep(0.05)
    assert not any(_running(w) for w in workers)


@pytest.mark.skipif(not LINUX, reason="/proc")
def test_die_with_parent_in_this_process_is_harmless():
    # run in a child so the signal dispositions of the test process are untouched
    code = (
        "import os, signal\nfrom discovery.numerics._workers import die_with_parent\n"
        "print(die_with_parent(), signal.getsignal(signal.SIGINT) is signal.SIG_IGN)"
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True
    ).stdout.split()
    assert out == ["prctl", "True"]


# ------------------------------------------------- ownership: nothing a user owns is lost
def test_user_files_in_an_earlier_result_are_kept(tmp_path):
    target = tmp_path / "res"
    _write_set(target, 1, ("summary.json", "old_only.csv"))
    (target / "lab_notes.txt").write_text("mine")
    (target / "record2.csv").write_text("t,F\n")
    _write_set(target, 2)
    assert _snapshot(target) == {
        "a.csv": "2\n",
        "b.png": "2\n",
        "summary.json": "2\n",
        "lab_notes.txt": "mine",
        "record2.csv": "t,F\n",
    }
    manifest = json.loads((target / _io.MANIFEST).read_text())
    assert manifest["files"] == ["a.csv", "b.png", "summary.json"]


def test_a_file_dropped_in_during_the_run_is_kept(tmp_path):
    target = tmp_path / "res"
    _write_set(target, 1)
    with OutputDir(target) as out:
        for n in ("summary.json", "a.csv", "notes.txt"):
            out.path(n).write_text("2\n")
        (target / "dropped.txt").write_text("during")  # the user, while the run goes on
        (target / "notes.txt").write_text("user's")  # a name the new result also uses
    snap = _snapshot(target)
    assert snap["dropped.txt"] == "during" and snap["notes.txt"] == "2\n"
    assert snap["notes.txt.kept"] == "user's"


def test_another_commands_result_is_refused_unless_overwrite(tmp_path):
    target = tmp_path / "res"
    _io.set_run("verify")
    try:
        _write_set(target, 1)
        (target / "notes.txt").write_text("mine")
        _io.set_run("explain")
        with pytest.raises(InputError, match="holds the results of `vidi verify`"):
            check_output(target)
        _io.set_run("explain", overwrite=True)
        check_output(target)
        _write_set(target, 2)
        assert json.loads((target / _io.MANIFEST).read_text())["command"] == "explain"
        assert (target / "notes.txt").read_text() == "mine"
    finally:
        _io.set_run(None)


@pytest.mark.skipif(not LINUX, reason="mkfifo and /dev/null")
@pytest.mark.parametrize("kind", ["fifo", "device", "symlink", "foreign"])
def test_file_targets_that_are_not_ours_are_refused(tmp_path, kind):
    target = tmp_path / "D.csv"
    if kind == "fifo":
        os.mkfifo(target)
    elif kind == "device":
        target = Path("/dev/null")
    elif kind == "symlink":
        (tmp_path / "real.csv").write_text("x")
        target.symlink_to(tmp_path / "real.csv")
    else:
        target.write_text("a user's file")
    _io.set_run("simulate")
    try:
        with pytest.raises(InputError):
            check_output(target, kind="file")
    finally:
        _io.set_run(None)
    if kind == "foreign":
        assert target.read_text() == "a user's file"


def test_a_device_or_a_huge_file_is_no_summary_or_scenario(tmp_path):
    """Issue 53: discovery.load('/dev/zero') and a scenario naming /dev/zero read until
    memory ran out."""
    import discovery
    from discovery.errors import InputError

    with pytest.raises(InputError, match="not a regular file"):
        discovery.load("/dev/zero")
    with pytest.raises(InputError, match="not a regular file"):
        discovery.load_scenario("/dev/zero")
    big = tmp_path / "big.toml"
    big.write_bytes(b"#" * (2**20 + 1))
    with pytest.raises(InputError, match="over 1 MB"):
        discovery.load_scenario(big)
