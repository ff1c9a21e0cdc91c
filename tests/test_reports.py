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
    # vidi fit compiled it (and removed the auxiliary files)
    assert (out / "model.pdf").stat().st_size > 1000
    assert not list(out.glob("model.aux")) and not list(out.glob("model.fdb_latexmk"))
    run = subprocess.run(["pdftotext", "model.pdf", "-"], cwd=out, capture_output=True,
                         text=True, timeout=60) if shutil.which("pdftotext") else None
    if run is not None:
        assert "standard error" in run.stdout and "noise floor" in run.stdout


def test_compile_pdf_without_tex_says_how_to_get_it(tmp_path, monkeypatch):
    from reports import latex

    tex = tmp_path / "m.tex"
    tex.write_text("\\documentclass{article}\\begin{document}x\\end{document}\n")
    monkeypatch.setattr(latex.shutil, "which", lambda name: None)
    pdf, why = latex.compile_pdf(tex)
    assert pdf is None and "apt-get install latexmk" in why
    assert tex.exists() and not (tmp_path / "m.pdf").exists()


@pytest.mark.skipif(shutil.which("latexmk") is None, reason="needs TeX Live (latexmk)")
def test_compile_pdf_reports_a_latex_error(tmp_path):
    from reports.latex import compile_pdf

    tex = tmp_path / "bad.tex"
    tex.write_text("\\documentclass{article}\\begin{document}\\undefinedmacro\\end{document}\n")
    pdf, why = compile_pdf(tex, timeout=120)
    assert pdf is None and why.startswith("no PDF: LaTeX failed")
