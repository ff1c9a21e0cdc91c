"""The README's quickstart runs top to bottom exactly as written."""

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent


def _quickstart():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"<!-- quickstart -->\s*```bash\n(.*?)```\s*<!-- /quickstart -->", text, re.S)
    assert block, "the README has no quickstart block"
    return [ln for ln in block.group(1).splitlines() if ln.strip()]


def test_the_quickstart_runs_as_written(tmp_path):
    vidi = Path(sys.executable).with_name("vidi")
    assert vidi.exists(), "the vidi entry point is not installed beside this Python"
    env = dict(os.environ)
    if not (shutil.which("latexmk") or env.get("VIDI_REQUIRE_TEX")):
        pytest.skip("needs TeX Live for the report step")
    for line in _quickstart():
        argv = shlex.split(line)
        assert argv[0] == "vidi", line
        run = subprocess.run(
            [str(vidi), *argv[1:]],
            cwd=tmp_path,
            capture_output=True,
            text=True,
            timeout=600,
            env=env,
        )
        assert run.returncode == 0, (line, run.stderr[-2000:])
        assert "Traceback" not in run.stderr
    assert (tmp_path / "D.csv").exists() and (tmp_path / "out" / "fit" / "report.pdf").exists()
    assert "consistent" in (tmp_path / "out" / "verify" / "summary.json").read_text()


def test_the_python_quickstart_names_real_functions():
    text = (ROOT / "README.md").read_text()
    block = re.search(r"```python\n(.*?)```", text, re.S).group(1)
    import discovery as d

    for name in re.findall(r"\bd\.([A-Za-z_]+)", block):
        assert hasattr(d, name), name
