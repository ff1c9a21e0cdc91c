"""Reports are pure functions of results: LaTeX escaping and a compiled model.tex."""

import shutil
import subprocess

import pytest

from reports.latex import _esc


def test_escape_every_special_character():
    assert _esc("z^1.5*zd_2 & 5% #x $ {a} ~ \\") == (
        r"z\textasciicircum{}1.5*zd\_2 \& 5\% \#x \$ \{a\} \textasciitilde{} \textbackslash{}")


@pytest.mark.slow
@pytest.mark.skipif(shutil.which("latexmk") is None, reason="needs TeX Live (latexmk)")
def test_model_tex_compiles(tmp_path):
    from discovery.cli import main

    csv = tmp_path / "d.csv"
    assert main(["simulate", "--periods", "12", "--from-rest", "--law",
                 "2e10*z^1.5 + 5e11*z^1.5*zd", "--scenario", "light", "--out", str(csv)]) == 0
    out = tmp_path / "fit"
    assert main(["fit", "--scenario", "light", "--data", str(csv), "--library", "poly:2+hc",
                 "--out", str(out)]) == 0
    run = subprocess.run(["latexmk", "-pdf", "-interaction=nonstopmode", "-quiet", "model.tex"],
                         cwd=out, capture_output=True, text=True, timeout=180)
    assert run.returncode == 0, run.stdout[-2000:]
    assert (out / "model.pdf").stat().st_size > 1000
