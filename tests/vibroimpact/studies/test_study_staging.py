"""A study is staged like every other result: interrupted, killed or failing it leaves an
earlier directory exactly as it was; run files are checked; manifests are claims to check."""

import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest

from discovery.cli import main
from discovery.errors import InputError, VidiError
from discovery.vibroimpact.studies import study

VIDI = [sys.executable, "-c", "import sys; from discovery.cli import main; sys.exit(main())"]

# one cell, a short record, a two-term library: a run takes a fraction of a second
TINY = {
    "name": "tiny",
    "seeds": 1,
    "factors": {
        "law": ["2.06e8*z + 1.28e7*zd"],
        "force_noise": [0.01],
        "periods": [4],
        "library": ["z, zd"],
        "selection": ["best-subset"],
        "refine": [False],
    },
}
LONG = """name = "long"
seeds = 60
[factors]
law = ["2.06e8*z + 1.28e7*zd"]
force_noise = [0.01]
periods = [4]
library = ["z, zd"]
selection = ["best-subset"]
refine = [false]
"""


def _snapshot(d):
    """Every file below ``d`` with its bytes (hidden ones included)."""
    d = Path(d)
    return {str(p.relative_to(d)): p.read_bytes() for p in sorted(d.rglob("*")) if p.is_file()}


def _verify_result(d):
    """An earlier `vidi verify` result with a user's file beside it (cells.csv, a name a
    study writes)."""
    d.mkdir()
    (d / ".vidi-manifest.json").write_text(
        json.dumps({"command": "verify", "files": ["summary.json", "verify.png"]})
    )
    (d / "summary.json").write_text('{"command": "verify"}')
    (d / "verify.png").write_bytes(b"png")
    (d / "cells.csv").write_text("the user's own table\n")
    return _snapshot(d)


def _work(out):
    return out.parent / f".{out.name}.vidi-study"


def _sigint_as_in_a_terminal():
    """A child's Ctrl-C as in a terminal: a suite started as a background job passes SIGINT
    ignored to its children, and Python then installs no KeyboardInterrupt handler."""
    signal.signal(signal.SIGINT, signal.SIG_DFL)


def _start(tmp_path, out, *extra):
    cfg = tmp_path / "long.toml"
    cfg.write_text(LONG)
    cmd = [*VIDI, "study", "--config", str(cfg), "--out", str(out), "--workers", "1"]
    cmd += ["--no-figures", "--quiet", *extra]
    # Ctrl-C as in a terminal, also when the suite runs as a background job (SIGINT ignored)
    proc = subprocess.Popen(
        cmd,
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        cwd=tmp_path,
        preexec_fn=_sigint_as_in_a_terminal,
    )
    runs = _work(out) / "runs"
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and proc.poll() is None:
        if runs.is_dir() and len(list(runs.glob("*.json"))) >= 2:
            break
        time.sleep(0.05)
    assert proc.poll() is None, proc.stderr.read()
    return proc, cmd


def test_an_interrupted_api_study_says_what_was_kept_and_how_to_go_on(tmp_path):
    """Ctrl-C in ``study()``: the traceback's last line names the kept runs and the call
    that continues; the next call runs only the rest."""
    cfg = {**TINY, "seeds": 3}

    def stop_after_one(stage, done, total):
        if done >= 1:
            raise KeyboardInterrupt

    with pytest.raises(KeyboardInterrupt) as info:
        study(cfg, tmp_path / "s", workers=1, progress=stop_after_one)
    (note,) = info.value.__notes__
    assert note.startswith("study: 1 finished run(s) of 3 kept in ")
    assert "call study() again with the same config and out to continue" in note
    assert "nothing was written to" in note
    assert study(cfg, tmp_path / "s", workers=1, progress=False).executed == 2


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGKILL])
def test_a_stopped_study_leaves_an_earlier_result_exactly_as_it_was(tmp_path, sig):
    out = tmp_path / "res"
    before = _verify_result(out)
    proc, cmd = _start(tmp_path, out, "--overwrite")
    proc.send_signal(sig)
    _, err = proc.communicate(timeout=60)
    assert _snapshot(out) == before  # not relabelled a study, nothing added or lost
    kept = len(list((_work(out) / "runs").glob("*.json")))
    assert kept >= 2
    if sig == signal.SIGINT:
        assert proc.returncode == 130
        line = err.strip()
        assert "\n" not in line and "Traceback" not in line, err
        assert f"{kept} finished run(s) of 60 kept in" in line
        assert "run the same command again to continue" in line and "is unchanged" in line
    # the next `vidi verify`-like run there is still possible: the directory is verify's
    with open(out / ".vidi-manifest.json") as fh:
        assert json.load(fh)["command"] == "verify"


def test_a_resumed_study_replaces_the_earlier_result_keeping_the_users_files(tmp_path):
    out = tmp_path / "res"
    _verify_result(out)
    proc, cmd = _start(tmp_path, out, "--overwrite")
    proc.send_signal(signal.SIGINT)
    proc.communicate(timeout=60)
    kept = len(list((_work(out) / "runs").glob("*.json")))
    done = subprocess.run(
        [*cmd, "--max-runs", "1"], capture_output=True, text=True, timeout=120, cwd=tmp_path
    )
    assert done.returncode == 0, done.stderr
    names = sorted(p.name for p in out.iterdir())
    assert "verify.png" not in names and (out / "cells.csv.kept").read_text().startswith("the")
    assert json.loads((out / ".vidi-manifest.json").read_text())["command"] == "study"
    assert len(list((out / "runs").glob("*.json"))) == kept + 1
    assert sorted(p.name for p in tmp_path.iterdir()) == ["long.toml", "res"]


def test_a_second_study_into_a_finished_one_is_refused_unless_overwrite(tmp_path, capsys):
    out = tmp_path / "s"
    study(TINY, out, workers=1, figures=False)
    (out / "notes.txt").write_text("mine")
    (out / "runs" / "mine.txt").write_text("mine too")
    first = _snapshot(out)
    again = study(TINY, out, workers=1, figures=False)  # the same study: continued
    assert again.executed == 0 and again.reused == 1
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "runs" / "mine.txt").read_text() == "mine too"
    other = {**TINY, "seeds": 2}
    with pytest.raises(InputError, match="finished study of other cells"):
        study(other, out, workers=1, figures=False)
    assert _snapshot(out).keys() == first.keys()
    cfg = tmp_path / "other.toml"
    cfg.write_text(LONG.replace("seeds = 60", "seeds = 2"))
    argv = ["study", "--config", str(cfg), "--out", str(out), "--workers", "1", "--no-figures"]
    assert main([*argv, "--quiet"]) == 2
    assert "--overwrite" in capsys.readouterr().err
    assert main([*argv, "--quiet", "--overwrite"]) == 0
    capsys.readouterr()
    cfgj = json.loads((out / "config.json").read_text())
    assert len(cfgj["seeds"]) == 2 and len(list((out / "runs").glob("*.json"))) == 2
    assert (out / "notes.txt").read_text() == "mine"
    assert (out / "runs" / "mine.txt").read_text() == "mine too"


def test_a_failed_study_leaves_no_directory(tmp_path, capsys):
    cfg = tmp_path / "s.toml"
    cfg.write_text(LONG)
    out = tmp_path / "new" / "s"
    code = main(["study", "--config", str(cfg), "--out", str(out), "--scheduler", "foo"])
    assert code == 2
    err = capsys.readouterr().err.strip()
    assert "cannot reach the Dask scheduler" in err and "\n" not in err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["s.toml"]


def test_a_copied_or_broken_run_file_is_named_and_run_again(tmp_path, capsys):
    out = tmp_path / "s"
    two = {**TINY, "seeds": 2}
    first = study(two, out, workers=1, figures=False)
    a, b = sorted((out / "runs").glob("*.json"))
    b.write_bytes(a.read_bytes())  # another run's file under this run's name
    again = study(two, out, workers=1, figures=False)
    err = capsys.readouterr().err
    assert b.name in err and "not its file name" in err
    assert again.executed == 1 and again.reused == 1
    assert json.loads(b.read_text())["key"] == b.stem
    assert again.cells == first.cells or [c["runs"] for c in again.cells] == [2]
    b.write_text(json.dumps({"key": b.stem, "cell": "x"}))  # parses, but is no run
    again = study(two, out, workers=1, figures=False)
    assert "wrong type" in capsys.readouterr().err and again.executed == 1


def test_study_progress_must_be_callable(tmp_path):
    with pytest.raises(VidiError, match="progress"):
        study(TINY, tmp_path / "s", workers=1, progress=5)
    assert not (tmp_path / "s").exists()


# -------------------------------------------------------------------------- manifests
@pytest.mark.parametrize("files", ["5", '"summary.json"', '{"a": 1}', "[5]"])
def test_a_malformed_manifest_is_one_line(tmp_path, capsys, files):
    out = tmp_path / "res"
    out.mkdir()
    (out / "summary.json").write_text('{"command": "steady"}')
    (out / ".vidi-manifest.json").write_text('{"command": "steady", "files": ' + files + "}")
    before = _snapshot(out)
    assert main(["steady", "--out", str(out)]) == 2
    err = capsys.readouterr().err.strip()
    assert "not a vidi manifest" in err and "\n" not in err
    assert _snapshot(out) == before
    assert main(["report", str(out), "--no-pdf"]) == 2  # vidi report checks it too
    err = capsys.readouterr().err.strip()
    assert "not a vidi manifest" in err and "\n" not in err
    assert _snapshot(out) == before


def test_a_manifest_that_is_a_list_is_one_line(tmp_path, capsys):
    out = tmp_path / "res"
    out.mkdir()
    (out / ".vidi-manifest.json").write_text('["summary.json"]')
    assert main(["steady", "--out", str(out)]) == 2
    assert "not a vidi manifest" in capsys.readouterr().err


def test_names_no_command_writes_are_kept_whatever_the_manifest_says(tmp_path, capsys):
    out = tmp_path / "res"
    assert main(["steady", "--out", str(out)]) == 0
    (out / "lab_notes.txt").write_text("notes")
    (out / "mydata").mkdir()
    (out / "mydata" / "a.csv").write_text("1,2\n")
    man = json.loads((out / ".vidi-manifest.json").read_text())
    man["files"] += ["lab_notes.txt", "mydata/", "mydata", "mydata/a.csv"]
    (out / ".vidi-manifest.json").write_text(json.dumps(man))
    assert main(["steady", "--out", str(out)]) == 0
    capsys.readouterr()
    assert (out / "lab_notes.txt").read_text() == "notes"
    assert (out / "mydata" / "a.csv").read_text() == "1,2\n"


def test_a_users_own_summary_is_not_a_vidi_result(tmp_path, capsys):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "summary.json").write_text('{"my": "numbers"}')
    assert main(["steady", "--out", str(out)]) == 2
    assert "not an earlier vidi result" in capsys.readouterr().err
    assert json.loads((out / "summary.json").read_text()) == {"my": "numbers"}


def test_a_very_long_out_is_not_echoed_whole(tmp_path, capsys):
    long = str(tmp_path / ("x" * 250) / ("y" * 250) / ("z" * 4000))
    assert main(["steady", "--out", long]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and len(err) < 600 and " ... " in err


def test_the_users_file_inside_a_study_folder_survives_verify_overwrite(tmp_path, capsys):
    out = tmp_path / "s"
    study(TINY, out, workers=1, figures=False)
    (out / "runs" / "mine.txt").write_text("mine")
    assert main(["steady", "--out", str(out), "--overwrite"]) == 0
    capsys.readouterr()
    assert (out / "runs" / "mine.txt").read_text() == "mine"
    assert json.loads((out / ".vidi-manifest.json").read_text())["command"] == "steady"
    assert not list((out / "runs").glob("*.json"))
    assert os.path.exists(out / "summary.json")


@pytest.mark.slow
def test_ctrl_c_of_a_dask_study_is_one_line(tmp_path):
    """Ctrl-C at a terminal reaches the whole process group: the workers of the local
    cluster start with SIGINT ignored, so only vidi's one line is printed."""
    pytest.importorskip("distributed")
    out = tmp_path / "dask"
    cfg = tmp_path / "long.toml"
    cfg.write_text(LONG)
    cmd = [*VIDI, "study", "--config", str(cfg), "--out", str(out), "--scheduler", "local"]
    proc = subprocess.Popen(
        [*cmd, "--workers", "2", "--no-figures", "--quiet"],
        stdout=subprocess.DEVNULL,
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,
        preexec_fn=_sigint_as_in_a_terminal,
    )
    runs = _work(out) / "runs"
    deadline = time.monotonic() + 180
    while time.monotonic() < deadline and proc.poll() is None:
        if runs.is_dir() and len(list(runs.glob("*.json"))) >= 2:
            break
        time.sleep(0.1)
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130
    assert len(err.strip().splitlines()) == 1, err
    assert "kept in" in err and not out.exists()


def test_two_studies_into_one_directory_at_once_are_refused(tmp_path):
    import fcntl

    out = tmp_path / "s"
    work = _work(out)
    work.mkdir()
    with open(work / ".lock", "w") as fh:
        fcntl.flock(fh, fcntl.LOCK_EX | fcntl.LOCK_NB)  # another study holds it
        with pytest.raises(InputError, match="another study is writing"):
            study(TINY, out, workers=1, figures=False)
    assert not out.exists()


def test_an_older_manifest_listing_runs_whole_keeps_the_users_file_in_it(tmp_path, capsys):
    out = tmp_path / "old"
    (out / "runs").mkdir(parents=True)
    (out / "runs" / "0123abcd.json").write_text("{}")
    (out / "runs" / "mine.txt").write_text("mine")
    (out / "summary.json").write_text('{"command": "steady"}')
    man = {"command": "steady", "files": ["runs", "summary.json"]}
    (out / ".vidi-manifest.json").write_text(json.dumps(man))
    assert main(["steady", "--out", str(out)]) == 0
    capsys.readouterr()
    assert (out / "runs" / "mine.txt").read_text() == "mine"
    assert not (out / "runs" / "0123abcd.json").exists()
