"""The README's examples run top to bottom exactly as written: the vibro-impact quickstart,
its `explain` step and its Python version, and Ueda's quickstart."""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from . import survey_readme

ROOT = Path(__file__).resolve().parent.parent


def _block(name="quickstart"):
    """The lines of the bash block between ``<!-- NAME -->`` and ``<!-- /NAME -->`` (the
    README survey times the same lines)."""
    return survey_readme.block(name)


def _python_quickstart():
    """The README's first Python block (the quickstart's Python version)."""
    return re.search(r"```python\n(.*?)```", (ROOT / "README.md").read_text(), re.S).group(1)


def _run(lines, cwd, env):
    vidi = Path(sys.executable).with_name("vidi")
    assert vidi.exists(), "the vidi entry point is not installed beside this Python"
    for line in lines:
        argv = shlex.split(line)
        assert argv[0] == "vidi", line
        run = subprocess.run(
            [str(vidi), *argv[1:]],
            cwd=cwd,
            capture_output=True,
            text=True,
            timeout=600,
            env=env,
        )
        assert run.returncode == 0, (line, run.stderr[-2000:])
        assert "Traceback" not in run.stderr


def test_the_quickstart_runs_as_written(tmp_path):
    env = dict(os.environ)
    if not (shutil.which("latexmk") or env.get("VIDI_REQUIRE_TEX")):
        pytest.skip("needs TeX Live for the report step")
    _run(_block("quickstart"), tmp_path, env)
    assert (tmp_path / "D.csv").exists() and (tmp_path / "out" / "fit" / "report.pdf").exists()
    assert "consistent" in (tmp_path / "out" / "verify" / "summary.json").read_text()
    _run(_block("quickstart-explain"), tmp_path, env)
    assert (tmp_path / "out" / "explain" / "summary.json").exists()
    run = subprocess.run(
        [sys.executable, "-c", _python_quickstart()],
        cwd=tmp_path,
        capture_output=True,
        text=True,
        timeout=600,
        env=env,
    )
    assert run.returncode == 0, run.stderr[-2000:]
    assert run.stdout.strip()


def test_the_ueda_quickstart_runs_as_written(tmp_path):
    _run(_block("quickstart-ueda"), tmp_path, dict(os.environ))
    assert (tmp_path / "U.csv").exists()
    assert "consistent" in (tmp_path / "out" / "ueda" / "summary.json").read_text()
    assert (tmp_path / "out" / "ueda-explain" / "summary.json").exists()
    assert (tmp_path / "out" / "egg" / "summary.json").exists()


def test_the_python_quickstart_names_real_functions():
    import discovery as d

    for name in re.findall(r"\bd\.([A-Za-z_]+)", _python_quickstart()):
        assert hasattr(d, name), name
