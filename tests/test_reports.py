"""Reports: LaTeX from a run's summary, compiled to PDF and read back as a reader would.

The PDFs are checked through ``pdftotext`` (the model, the criteria, the verdict, the
figures' own text) and their page count; injection attempts go through every user-text
path. Where TeX is not installed the PDF tests are skipped, except when
``VIDI_REQUIRE_TEX=1`` (CI sets it): then a missing TeX fails them.
"""

import json
import os
import shutil
import subprocess

import pytest

from discovery.cli import main
from reports.document import compile_tex, report
from reports.texenv import Tex, escape, num

HAVE_TEX = shutil.which("latexmk") is not None and shutil.which("pdftotext") is not None


def _need_tex():
    if not HAVE_TEX:
        if os.environ.get("VIDI_REQUIRE_TEX"):
            pytest.fail(
                "TeX Live is required here (VIDI_REQUIRE_TEX=1) but latexmk or pdftotext is missing"
            )
        pytest.skip("needs TeX Live (latexmk) and poppler-utils (pdftotext)")


def _text(pdf):
    return subprocess.run(
        ["pdftotext", "-layout", str(pdf), "-"],
        capture_output=True,
        text=True,
        timeout=60,
        check=True,
    ).stdout


def test_escape_every_special_character():
    assert escape("z^1.5*zd_2 & 5% #x $ {a} ~ \\") == (
        r"z\textasciicircum{}1.5*zd\_2 \& 5\% \#x \$ \{a\} \textasciitilde{} "
        r"\textbackslash{}"
    )
    assert escape("a\nb\x07c\u4e2d") == "a b?c?"  # no line breaks, controls or CJK reach TeX
    assert escape(Tex(r"\zeta")) == r"\zeta" and escape(None) == "--"


def test_numbers_as_math():
    assert num(2.06e8) == r"$2.06\cdot 10^{8}$" and num(0.0466) == "$0.0466$"
    assert num(9.996e7) == r"$1.00\cdot 10^{8}$"  # the rounding carries into the exponent
    assert num(float("nan")) == "--" and num(None) == "--" and num(12.5) == "$12.5$"


def test_without_tex_the_source_is_written_and_the_packages_named(tmp_path, monkeypatch):
    import reports.document as doc

    tex = tmp_path / "m.tex"
    tex.write_text("\\documentclass{article}\\begin{document}x\\end{document}\n")
    monkeypatch.setattr(doc.shutil, "which", lambda name: None)
    pdf, why = compile_tex(tex)
    assert pdf is None and "apt-get install latexmk texlive-latex-recommended" in why
    assert tex.exists() and not (tmp_path / "m.pdf").exists()


def test_a_latex_error_keeps_the_log_and_names_the_error(tmp_path):
    _need_tex()
    tex = tmp_path / "bad.tex"
    tex.write_text("\\documentclass{article}\\begin{document}\\undefinedmacro\\end{document}\n")
    pdf, why = compile_tex(tex, timeout=120)
    assert pdf is None and "Undefined control sequence" in why
    assert (tmp_path / "bad.log").exists() and not (tmp_path / "bad.pdf").exists()
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".vidi-tex-")]


def test_tex_cannot_read_outside_or_run_commands(tmp_path):
    """Defence in depth, should raw TeX ever reach a document: no file outside the compile
    directory is read (openin_any=p) and no shell command runs (-no-shell-escape)."""
    _need_tex()
    tex = tmp_path / "evil.tex"
    tex.write_text(
        "\\documentclass{article}\\begin{document}\\immediate\\write18{touch "
        f"{tmp_path}/pwned}}\\input{{/etc/passwd}}\\end{{document}}\n"
    )
    pdf, why = compile_tex(tex, timeout=120)
    assert not (tmp_path / "pwned").exists()
    if pdf is not None:
        assert "root:" not in _text(pdf)
    else:
        assert "no PDF: LaTeX failed" in why


@pytest.fixture(scope="module")
def runs(tmp_path_factory):
    """One small run of every kind, on a record whose name tries TeX injection."""
    d = tmp_path_factory.mktemp("runs")
    cwd = os.getcwd()
    os.chdir(d)
    try:
        rec = "r_\\input{etc-passwd}_$x$.csv"
        assert (
            main(["simulate", "--periods", "12", "--noise", "0.01", "--seed", "2", "--out", rec])
            == 0
        )
        scen = d / "evil.toml"
        scen.write_text(
            'name = "\\\\write18{touch pwned} & 100% #1"\n[machine]\nm1 = 1.0e4\n'
            "m2 = 1.0e4\nk1 = 2.75e7\nc1 = 1.0e5\nA = 5.0e5\nfrequency = 25.0\n"
            '[law]\ntext = "2.06e8*z + 1.28e7*zd"\n'
        )
        law = "2.06e8*z + 1.28e7*zd"
        cmds = {
            "verify": ["verify", "--scenario", str(scen), "--data", rec, "--law", law],
            "fit": ["fit", "--data", rec, "--no-refine", "--intervals", "0"],
            "identify": [
                "identify",
                "--data",
                rec,
                "--start",
                "1.8e8*z + 1.1e7*zd",
                "--max-simulations",
                "40",
            ],
            "landscape": ["landscape", "--grid", "3x3", "--workers", "1"],
        }
        for kind, argv in cmds.items():
            assert main([*argv, "--out", kind]) == 0, kind
        assert main(["ueda", "simulate", "--periods", "120", "--out", "U.csv"]) == 0
        assert (
            main(
                [
                    "ueda",
                    "discover",
                    "--data",
                    "U.csv",
                    "--model",
                    "negres",
                    "--model-periods",
                    "400",
                    "--resamples",
                    "40",
                    "--out",
                    "ueda",
                ]
            )
            == 0
        )
    finally:
        os.chdir(cwd)
    return d


@pytest.mark.parametrize(
    "kind, needles",
    [
        (
            "verify",
            [
                "Verification of a contact law",
                "Verdict",
                "consistent",
                "noise floor",
                "write18",
                "100% #1",
            ],
        ),
        (
            "fit",
            [
                "Discovery of a contact law",
                "The discovered law",
                "Selection",
                "certified",
                "Verdict",
                "r_\\input{etc-passwd}_$x$.csv",
            ],
        ),
        ("identify", ["Identification of a contact law", "simulations", "Verdict"]),
        ("landscape", ["Criteria landscape", "Minima", "Noise floor"]),
        ("ueda", ["Ueda", "Verification by simulation", "energy distance"]),
    ],
)
def test_a_report_of_every_kind_reads_right(runs, kind, needles, capsys):
    _need_tex()
    run = runs / kind
    assert main(["report", str(run)]) == 0
    printed = capsys.readouterr().out
    assert "report.pdf" in printed and "pages" in printed
    pdf = run / "report.pdf"
    text = _text(pdf)
    for needle in needles:
        assert needle in text, (kind, needle)
    pages = int(
        subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, check=True)
        .stdout.split("Pages:")[1]
        .split()[0]
    )
    assert pages >= (3 if kind in ("fit", "verify") else 2), pages
    assert "Provenance" in text and "sha256" in text
    # the figures are embedded: their own axis text is in the PDF's text
    assert "Figure 1" in text
    # nothing was read or run by injection, and the report files are vidi's now
    assert "root:" not in text and not (runs / "pwned").exists()
    listed = json.loads((run / ".vidi-manifest.json").read_text())["files"]
    assert {"report.tex", "report.pdf"} <= set(listed)
    assert not [p for p in run.iterdir() if p.name.startswith(".vidi-tex-")]


def test_the_fit_report_is_at_least_three_pages_with_model_criteria_figures(runs):
    _need_tex()
    r = report(runs / "fit")
    assert r.pages >= 3 and len(r.figures) == 3
    text = _text(r.pdf)
    for needle in (
        "Conclusions",
        "data support the terms",
        "criterion",
        "I2",
        "Library, constraints and certificate",
        "Figures",
    ):
        assert needle in text, needle
    s = json.loads((runs / "fit" / "summary.json").read_text())
    assert s["selected"]["latex"] in (runs / "fit" / "report.tex").read_text()


def test_snippets_and_refusals(runs, capsys):
    fit = runs / "fit"
    assert main(["report", str(fit), "--snippet", "model"]) == 0
    snippet = (fit / "snippet-model.tex").read_text()
    assert snippet.count("\\begin{equation}") == 1 and "\\documentclass" not in snippet
    assert main(["report", str(fit), "--snippet", "criteria"]) == 0
    assert "noise floor" in (fit / "snippet-criteria.tex").read_text()
    assert main(["report", str(runs / "landscape"), "--snippet", "model"]) == 2
    assert main(["report", str(runs / "nothere")]) == 2
    assert main(["report", str(runs / "U.csv")]) == 2
    # a report.tex the user wrote into a run directory is never replaced
    mine = runs / "identify-copy"
    shutil.copytree(runs / "identify", mine)
    man = json.loads((mine / ".vidi-manifest.json").read_text())
    man["files"] = [f for f in man["files"] if not f.startswith("report.")]
    (mine / ".vidi-manifest.json").write_text(json.dumps(man))
    (mine / "report.tex").write_text("my own notes\n")
    assert main(["report", str(mine), "--no-pdf"]) == 2
    assert (mine / "report.tex").read_text() == "my own notes\n"
    err = capsys.readouterr().err
    assert err.count("vidi: error:") == 4 and "Traceback" not in err
    assert "was not written by vidi" in err


def test_fit_writes_model_tex_from_the_template(runs):
    tex = (runs / "fit" / "model.tex").read_text()
    assert "\\documentclass" in tex and "Records." in tex
    assert "r\\_\\textbackslash{}input\\{etc-passwd\\}\\_\\$x\\$.csv" in tex


def test_user_text_in_figures_is_not_read_as_mathtext(tmp_path):
    """A record name holding '$...$' is drawn as it is: matplotlib's mathtext would fail on
    a broken formula and end the run."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from reports.vibroimpact.figures import plain

    name = r"r$\frac{1}{0$_x.csv"
    fig, ax = plt.subplots()
    ax.set_title(plain(name))
    fig.savefig(tmp_path / "ok.png")
    plt.close(fig)
    fig, ax = plt.subplots()
    ax.set_title(name)
    with pytest.raises(ValueError):
        fig.savefig(tmp_path / "broken.png")
    plt.close(fig)


def test_study_report_states_recovery_coverage_and_figures(tmp_path):
    """A study's report: the design, the pooled table per method, the per-cell table and the
    four figures, compiled to a PDF."""
    _need_tex()
    from discovery import study
    from discovery.report import report

    cfg = {
        "name": "tiny & 100%",
        "seeds": 1,
        "factors": {
            "force_noise": [0.01, 0.02],
            "periods": [4],
            "library": ["z, zd, z^2"],
            "selection": ["best-subset", "l1-path"],
            "refine": [False],
        },
    }
    out = tmp_path / "s"
    study(cfg, out, workers=1)
    r = report(out)
    text = _text(r.pdf)
    assert "Model-term selection study: tiny & 100%" in text
    for words in (
        "Per selection method",
        "best-subset",
        "l1-path",
        "force_noise",
        "recovered",
        "Records were made by the independent scipy path",
    ):
        assert words in text, words
    tex = r.tex.read_text()
    for fig in ("recovery_noise.pdf", "recovery_map.pdf", "coverage.pdf", "inclusion.pdf"):
        assert fig in tex
