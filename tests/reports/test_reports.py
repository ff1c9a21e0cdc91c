"""Reports: LaTeX from a run's summary, compiled to PDF and read back as a reader would.

The PDFs are checked through ``pdftotext`` (the model, the criteria, the verdict, the
figures' own text) and their page count; injection attempts go through every user-text
path. Where TeX is not installed the PDF tests are skipped, except when
``VIDI_REQUIRE_TEX=1`` (CI sets it): then a missing TeX fails them.
"""

import json
import os
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
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


def test_the_report_s_printout_names_each_file_once_with_the_right_article(tmp_path):
    from reports.document import Report

    tex, pdf = tmp_path / "report.tex", tmp_path / "report.pdf"
    text = str(Report(tex, pdf, f"wrote {pdf}", "ueda attractor", 4))
    assert text.splitlines()[0] == "report of a Ueda attractor run", text
    assert text.count(str(pdf)) == 1 and f"PDF: {pdf} (4 pages)" in text, text
    text = str(Report(tex, None, f"wrote {tex}; left out figure(s) x.pdf", "identify"))
    assert text.splitlines()[0] == "report of an identify run"
    assert text.count(str(tex)) == 1 and "left out figure(s) x.pdf" in text, text
    text = str(Report(tex, None, "no PDF: LaTeX failed (x); the log is y", "fit"))
    assert text.splitlines()[0] == "report of a fit run" and "no PDF: LaTeX failed" in text
    from discovery._api._validate import Instance

    assert Instance("discovery.ueda", "UedaSystem").describe() == "a UedaSystem"


def test_a_narrow_interval_s_bounds_are_typeset_apart():
    """The coefficient table's interval keeps digits until its bounds differ."""
    from reports.cells import _coef_rows

    ((_, _, _, iv),) = _coef_rows({"z": 2.06e8}, {"z": 7.7e3}, {"z": (2.06e8, 2.06001e8)})
    assert iv == r"[$2.06000\cdot 10^{8}$, $2.06001\cdot 10^{8}$]", iv
    ((_, _, _, iv),) = _coef_rows({"z": 2.06e8}, {}, {"z": (1.9e8, 2.2e8)})
    assert iv == r"[$1.900\cdot 10^{8}$, $2.200\cdot 10^{8}$]", iv  # wide: 4 digits


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
    # the manifest lists what is there (issue 53: a report.log claimed and never written)
    assert all((run / f).exists() for f in listed), listed
    assert not [p for p in run.iterdir() if p.name.startswith(".vidi-tex-")]


def test_the_fit_report_is_at_least_three_pages_with_model_criteria_figures(runs):
    _need_tex()
    r = report(runs / "fit")
    assert r.pages >= 3 and len(r.figures) == 3
    text = _text(r.pdf)
    for needle in (
        "Conclusions",
        "From the library",
        "criterion",
        "I2",
        "Library, constraints and certificate",
        "Figures",
    ):
        assert needle in text, needle
    # the law is rebuilt from its coefficients by the law grammar, never read as LaTeX
    from discovery.vibroimpact.model.law import ForceLaw
    from reports.lawtex import law_equation

    s = json.loads((runs / "fit" / "summary.json").read_text())
    law = ForceLaw.from_dict(s["selected"]["coefficients"])
    assert law_equation(law) in (runs / "fit" / "report.tex").read_text()


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


def _pages_png(pdf, tmp_path, name):
    """The PDF's pages as PNG bytes (pdftoppm at 50 dpi)."""
    subprocess.run(["pdftoppm", "-r", "50", "-png", str(pdf), str(tmp_path / name)], check=True)
    return [p.read_bytes() for p in sorted(tmp_path.glob(f"{name}*.png"))]


@pytest.mark.skipif(not HAVE_TEX or shutil.which("pdftoppm") is None, reason="TeX not installed")
def test_the_fit_s_model_tex_compiled_once_has_latexmk_s_pages(runs, tmp_path):
    """``vidi fit`` compiles model.tex by one pdflatex pass (``compile_tex(once=True)``):
    the same pages as latexmk's two passes."""

    for way in ("once", "latexmk"):
        d = tmp_path / way
        d.mkdir()
        for name in ("model.tex", "fit_impulse.pdf"):
            shutil.copyfile(runs / "fit" / name, d / name)
        pdf, _ = compile_tex(d / "model.tex", ["fit_impulse.pdf"], once=way == "once")
        assert pdf is not None
    once = _pages_png(tmp_path / "once" / "model.pdf", tmp_path, "once")
    assert len(once) >= 1
    assert once == _pages_png(tmp_path / "latexmk" / "model.pdf", tmp_path, "twice")


@pytest.mark.skipif(not HAVE_TEX, reason="TeX not installed")
def test_a_document_compiled_once_gets_the_passes_its_log_asks_for(tmp_path):
    """A forward reference is resolved: the first pass's log asks for another, and latexmk
    makes it."""

    tex = tmp_path / "doc.tex"
    tex.write_text(
        "\\documentclass{article}\\begin{document}See section~\\ref{s}."
        "\\section{Later}\\label{s}\\end{document}\n"
    )
    pdf, _ = compile_tex(tex, once=True)
    text = subprocess.run(["pdftotext", str(pdf), "-"], capture_output=True, text=True).stdout
    assert "See section 1." in text and "??" not in text


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
    from discovery.reporting import report
    from reports.vibroimpact.study_figures import study_figures

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
    study(cfg, out, workers=1, figures=study_figures)
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
    for fig in ("recovery_noise.pdf", "recovery_map.pdf", "inclusion.pdf"):
        assert fig in tex
    # no refinement, no intervals: no empty coverage chart, and a sentence says why
    assert "coverage.pdf" not in tex and not (out / "coverage.pdf").exists()
    assert "so there is no coverage chart" in text
    assert "^" not in _body(r.pdf) and "ˆ" not in _body(r.pdf)  # "z^2" as an exponent


# ------------------------------------------------- a summary is text, never trusted TeX
PAYLOAD = r"\input{/etc/passwd}\def\x{\x}\x\catcode`\^=12 $^_&%#{}~"


def _poisoned(value):
    """Every string of a summary replaced by TeX that would read a file and loop."""
    if isinstance(value, str):
        return PAYLOAD
    if isinstance(value, list):
        return [_poisoned(v) for v in value]
    if isinstance(value, dict):
        # the command and the result's kind stay (an edited kind is refused by the loader)
        return {k: (v if k in ("command", "result") else _poisoned(v)) for k, v in value.items()}
    return value


def _copy_run(runs, kind, tmp_path):
    d = tmp_path / kind
    shutil.copytree(runs / kind, d)
    for p in d.glob("report.*"):
        p.unlink()
    return d


@pytest.mark.parametrize("kind", ["fit", "identify", "landscape", "ueda"])
def test_an_edited_summary_with_latex_in_every_field_is_text(runs, kind, tmp_path, capsys):
    """LaTeX written into every string field of summary.json (selected.latex, verdicts,
    names, paths...) is printed as text or refused in one line; a law is rebuilt from its
    own text by the law grammar, so the report never runs TeX it read."""
    _need_tex()
    d = _copy_run(runs, kind, tmp_path)
    s = json.loads((d / "summary.json").read_text())
    (d / "summary.json").write_text(json.dumps(_poisoned(s)))
    code = main(["report", str(d)])
    err = capsys.readouterr().err
    assert "Traceback" not in err
    if code == 2:  # a field the report needs as a law (identify's law text) is no law now,
        # or an evaluation's status is none of the four (the report's reading, or the
        # loader's, which names the field's path in the document)
        assert err.count("\n") == 1, err
        assert "is not a force law" in err or re.search(
            r"'([\w.]*\.)?(law|status)' cannot be read", err
        ), err
        assert not (d / "report.tex").exists()
        return
    assert code == 0, err
    tex = (d / "report.tex").read_text()
    assert "\\input{" not in tex and "\\def\\x" not in tex and "\\catcode" not in tex
    assert "\\textbackslash{}input\\{/etc/passwd\\}" in tex
    text = _text(d / "report.pdf")
    assert "root:" not in text and "\\input{/etc/passwd}" in text


def test_the_fit_law_is_never_read_from_the_latex_fields(runs, tmp_path):
    d = _copy_run(runs, "fit", tmp_path)
    s = json.loads((d / "summary.json").read_text())
    s["selected"]["latex"] = r"\input{/etc/passwd}"
    for e in s.get("equivalent") or []:
        e["latex"] = r"\input{/etc/passwd}"
    (d / "summary.json").write_text(json.dumps(s))
    r = report(d, compile=False)
    assert "\\input{/etc/passwd}" not in r.tex.read_text()


@pytest.mark.parametrize("kind", ["verify", "fit", "identify", "landscape", "ueda"])
def test_wrongly_typed_fields_of_an_edited_summary_are_one_line(runs, kind, tmp_path, capsys):
    """Each top-level field (and each field of ``selected``) replaced by a value of another
    type: the report is written or refused in one line (exit 2), never an internal error."""
    d = _copy_run(runs, kind, tmp_path)
    s = json.loads((d / "summary.json").read_text())
    edits = [(k,) for k in s if k != "command"] + [("selected", k) for k in s.get("selected", {})]
    for path in edits:
        for bad in (5, "text", [1, "a"], {"a": 1}, None, True, 1e308):
            t = json.loads(json.dumps(s))
            node = t
            for k in path[:-1]:
                node = node[k]
            node[path[-1]] = bad
            (d / "summary.json").write_text(json.dumps(t))
            code = main(["report", str(d), "--no-pdf"])
            err = capsys.readouterr().err
            assert code in (0, 2), (path, bad, err)
            assert "Traceback" not in err and err.count("\n") <= 1, (path, bad, err)


def test_a_figure_linked_outside_the_directory_is_not_read(runs, tmp_path):
    _need_tex()
    d = _copy_run(runs, "verify", tmp_path)
    outside = tmp_path / "secret.pdf"
    shutil.copy(runs / "fit" / "fit_impulse.pdf", outside)
    (d / "verify.pdf").unlink()
    (d / "verify.pdf").symlink_to(outside)
    r = report(d, timeout=120)
    assert r.pdf is not None and "verify.pdf" in r.message and "links" in r.message
    assert "verify.pdf" not in r.tex.read_text()
    # compile_tex itself refuses a linked figure
    tex = d / "fig.tex"
    tex.write_text(
        "\\documentclass{article}\\usepackage{graphicx}\\begin{document}"
        "\\includegraphics{verify.pdf}\\end{document}\n"
    )
    pdf, why = compile_tex(tex, ["verify.pdf"], timeout=60)
    assert pdf is None and "links" in why


LOOP = "\\documentclass{article}\\begin{document}\\def\\x{\\x}\\x\\end{document}\n"


def _procs_with(word):
    """Live processes whose command line holds ``word``."""
    out = []
    for p in os.listdir("/proc"):
        if p.isdigit():
            try:
                with open(f"/proc/{p}/cmdline", "rb") as fh:
                    cmd = fh.read().replace(b"\0", b" ").decode(errors="replace")
                with open(f"/proc/{p}/stat") as fh:
                    state = fh.read().rsplit(")", 1)[1].split()[0]
            except OSError:
                continue
            if word in cmd and state != "Z" and "pytest" not in cmd:
                out.append(cmd)
    return out


def _wait_for(cond, seconds):
    import time

    end = time.monotonic() + seconds
    while time.monotonic() < end:
        if cond():
            return True
        time.sleep(0.2)
    return cond()


def test_a_looping_tex_file_is_killed_with_its_children_on_timeout(tmp_path):
    _need_tex()
    name = f"loop{os.getpid()}t"
    tex = tmp_path / f"{name}.tex"
    tex.write_text(LOOP)
    pdf, why = compile_tex(tex, timeout=4)
    assert pdf is None and "more than 4 s" in why
    assert _wait_for(lambda: not _procs_with(name), 5), _procs_with(name)
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".vidi-tex-")]


@pytest.mark.parametrize("how", ["SIGTERM", "SIGINT", "SIGTERM-handled", "SIGKILL"])
def test_a_signal_ends_latexmk_and_pdflatex_too(tmp_path, how):
    """vidi ended while pdflatex loops: nothing of the compilation is left running, and
    the staging directory a SIGKILL leaves is removed by the next compilation."""
    _need_tex()
    import signal
    import sys

    name = f"loop{os.getpid()}{how[-4:].lower()}"
    tex = tmp_path / f"{name}.tex"
    tex.write_text(LOOP)
    handler = (
        "import signal, sys\n"
        "def _h(*a):\n    raise SystemExit(143)\n"
        "signal.signal(signal.SIGTERM, _h)\n"
        if how == "SIGTERM-handled"
        else ""
    )
    code = handler + (
        f"from reports.document import compile_tex\ncompile_tex({str(tex)!r}, timeout=300)\n"
    )
    # Ctrl-C as in a terminal, also when the suite runs as a background job (SIGINT ignored)
    proc = subprocess.Popen(
        [sys.executable, "-c", code],
        cwd=os.getcwd(),
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    try:
        assert _wait_for(lambda: any("pdflatex" in c for c in _procs_with(name)), 60)
        sig = {"SIGINT": signal.SIGINT, "SIGKILL": signal.SIGKILL}.get(how, signal.SIGTERM)
        proc.send_signal(sig)
        proc.wait(timeout=30)
        assert _wait_for(lambda: not _procs_with(name), 10), _procs_with(name)
    finally:
        if proc.poll() is None:
            proc.kill()
    left = [p for p in tmp_path.iterdir() if p.name.startswith(".vidi-tex-")]
    if how in ("SIGINT", "SIGTERM-handled"):  # unwound: the staging directory is gone
        assert not left
    # after SIGKILL (or SIGTERM with no handler: Python ends at once) the next
    # compilation removes the staging directory of the dead run
    ok = tmp_path / "ok.tex"
    ok.write_text("\\documentclass{article}\\begin{document}ok\\end{document}\n")
    pdf, _ = compile_tex(ok, timeout=120)
    assert pdf is not None
    assert not [p for p in tmp_path.iterdir() if p.name.startswith(".vidi-tex-")]


def test_an_interrupted_report_leaves_nothing_that_blocks_the_next(runs, tmp_path, monkeypatch):
    """A report killed while compiling (or out of space) has written no report.tex of its
    own outside the manifest: the next report is made, not refused."""
    import reports.document as doc

    d = _copy_run(runs, "identify", tmp_path)

    def boom(*a, **k):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(doc, "compile_tex", boom)
    with pytest.raises(OSError):
        report(d)
    assert not [p for p in d.iterdir() if p.name.startswith(".vidi-tex-")]
    monkeypatch.undo()
    (d / ".vidi-tex-999999999-1.deadbeef").mkdir()  # a staging dir of a killed report
    r = report(d, compile=HAVE_TEX, timeout=120)
    assert r.tex.exists() and not [p for p in d.iterdir() if p.name.startswith(".vidi-tex-")]


def _body(pdf):
    """A report's text up to its provenance (where settings and hashes are verbatim)."""
    return _text(pdf).split("Provenance")[0]


@pytest.mark.parametrize("kind", ["verify", "fit", "fit2", "identify", "landscape", "ueda"])
def test_reports_are_typeset_as_a_person_would(runs, kind):
    """The defects a reader saw: literal carets, laws as raw integers (206000000*z),
    code turned into quotes, verdicts cut to "(and 1 more)", a "--:" label."""
    _need_tex()
    r = report(runs / kind, timeout=120)
    tex, body = r.tex.read_text(), _body(r.pdf)
    assert "\\textasciicircum" not in tex.split("section{Provenance}")[0], kind
    assert "^" not in body and "ˆ" not in body, kind
    assert not re.search(r"(?<![\d.,])\d{6,}(?![\d.])", body), kind
    assert not re.search(r"\d\*z", body), kind
    assert "(and " not in body and "more)" not in body, kind
    assert "−−:" not in body and "--:" not in body
    assert "Eq(" not in body and "Derivative" not in body  # no sympy repr (Ueda)
    summary = json.loads((runs / kind / "summary.json").read_text())
    assert "Eq(" not in str(summary.get("equation", ""))
    assert "``" not in tex and "\\textasciigrave" not in tex.split("section{Provenance}")[0]
    # the consistency rule is typeset once (beside the criteria), not pasted into verdicts
    assert "noise floor, floor +" not in body, kind
    if kind.startswith("fit"):  # the ranking's order is stated, not left to guess
        assert "The ranking: the models consistent with the records first" in body


def test_a_two_scenario_fit_lists_every_scenario_and_record(runs):
    _need_tex()
    r = report(runs / "fit2", timeout=120)
    body = _body(r.pdf)
    for needle in ("Scenarios", "low", "100% #1", "low.csv", "_$x$.csv", "Record 1", "Record 2"):
        assert needle in body, needle
    assert "3.50 · 105" in body.replace("\u22c5", "·") or "3.50" in body


@pytest.mark.parametrize("files", [5, "report.tex", {"a": 1}, None, [1, ["x"]]])
def test_a_malformed_manifest_is_one_line(runs, tmp_path, capsys, files):
    """An edited manifest is a claim the report does not trust: one line, exit 2, and the
    directory as it was (the manifest is not repaired behind the user's back)."""
    d = _copy_run(runs, "landscape", tmp_path)
    man = json.loads((d / ".vidi-manifest.json").read_text())
    man["files"] = files
    (d / ".vidi-manifest.json").write_text(json.dumps(man))
    before = sorted(p.name for p in d.iterdir())
    assert main(["report", str(d), "--no-pdf"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and err.count("\n") == 1
    assert sorted(p.name for p in d.iterdir()) == before
    (d / ".vidi-manifest.json").write_text("[1, 2]")
    assert main(["report", str(d), "--no-pdf"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test_a_file_given_as_the_run_directory_is_one_line(tmp_path, capsys):
    """`vidi report D.csv` (a record, not a run directory): one line saying what to give,
    exit 2, not a remark on a manifest inside the file."""
    f = tmp_path / "D.csv"
    f.write_text("t,F\n0,0\n")
    assert main(["report", str(f), "--no-pdf"]) == 2
    err = capsys.readouterr().err
    assert "is not a run directory" in err and "manifest" not in err and err.count("\n") == 1


def test_the_api_checks_its_arguments(runs):
    from discovery.errors import VidiError
    from discovery.reporting import report as api_report

    with pytest.raises(VidiError, match="compile"):
        api_report(runs / "landscape", compile="no")
    with pytest.raises(VidiError, match="timeout"):
        api_report(runs / "landscape", timeout="60")


TEXT_WIDTH_IN, TEXT_HEIGHT_IN = 6.77, 9.27  # letter paper, 2.2 cm margins


@pytest.mark.parametrize("kind", ["verify", "fit", "fit2", "identify", "landscape", "ueda"])
def test_figures_are_printed_at_the_size_they_were_drawn(runs, kind):
    """Every figure is drawn about as large as the report prints it (scaled by 0.9 or
    more), so text drawn at 7 pt or more stays 6.3 pt or more on paper, where a figure
    drawn 13-17 in wide was shrunk to half its size."""
    _need_tex()
    r = report(runs / kind, compile=False)
    tex = r.tex.read_text()
    found = re.findall(r"height=([0-9.]+)\\textheight,keepaspectratio\]\{([^}]+)\}", tex)
    assert found, kind
    for frac, name in found:
        info = subprocess.run(
            ["pdfinfo", str(runs / kind / name)], capture_output=True, text=True, check=True
        ).stdout
        w, h = (
            float(v) / 72 for v in re.search(r"Page size:\s+([\d.]+) x ([\d.]+)", info).groups()
        )
        scale = min(TEXT_WIDTH_IN / w, float(frac) * TEXT_HEIGHT_IN / h)
        assert scale >= 0.9, (kind, name, w, h, scale)


def test_an_explain_report_lists_the_effects_own_parameters():
    """A machine or observation parameter an effect added (the contact offset's delta0, a
    sensor's lag) is a row of the final model's table, with its unit and interval."""
    from discovery.vibroimpact.explain import EFFECTS
    from reports.context import _effect_parameter_rows

    fm = _ns(effects=("contact_offset",), scenario={"offset": 0.0015}, observation={})
    errors, bounds = {"delta0": 3e-7}, {"delta0": (0.001499, 0.001501)}
    rows = _effect_parameter_rows(fm, errors, bounds, [e.as_dict() for e in EFFECTS])
    assert len(rows) == 1
    assert "delta0" in str(rows[0][0]) and "[m]" in str(rows[0][0])
    # the row's numbers in one form: its error 3e-7 is printed 3.0x10^-7, so the rest too
    assert r"1.499\cdot 10^{-3}" in str(rows[0][3]) and r"3.0\cdot 10^{-7}" in str(rows[0][2])
    # an edited summary without a catalogue
    assert _effect_parameter_rows(fm, errors, bounds, None) == []


def test_the_criteria_table_holds_the_motion_criterion():
    """I5 (the recorded penetration) is a row of every criteria table where the result has
    it, after the force's, with its formula and meaning."""
    from reports.context import _criteria_table, criterion_names

    crit = {"I2": 0.04, "I5": 0.126, "bogus": 1.0}
    assert criterion_names(crit) == ["I2", "I5"]
    rows = _criteria_table(crit, {"I2": 0.02, "I5": 0.012}, {"I2": 0.054, "I5": 0.0295})
    assert "penetration" in str(rows[1][4]) and "0.0295" in str(rows[1][3])


def test_the_limit_rule_names_each_criterion_s_factor():
    """The criteria sections state the limit with the factor each judged criterion has (2
    for I2 and I4, 1.25 for I5), as the verdict applies it: not "2 floor" for all."""
    from discovery.vibroimpact.verify import CONSISTENCY_FACTORS
    from reports.texenv import environment

    text = (
        environment()
        .from_string('((* import "macros.tex.j2" as m *))((( m.limit_rule() )))')
        .render()
    )
    assert r"\max(f\," in text and r"\max(2\," not in text
    for k, f in CONSISTENCY_FACTORS.items():
        assert f"$f = {f:g}$ for" in text and f"$I_{k[1:]}$" in text
    for name in ("verify", "fit"):
        src = (Path(__file__).parents[2] / "reports" / "templates" / f"{name}.tex.j2").read_text()
        assert "m.limit_rule()" in src and r"\max(2\," not in src


def test_the_reports_state_the_rule_from_its_constants(monkeypatch):
    """The rule's words and LaTeX are rendered from the constants the verdict applies: a
    changed factor, spread or slack changes what every report says."""
    import discovery.vibroimpact.verify as ev
    from reports import rules

    monkeypatch.setattr(ev, "CONSISTENCY_FACTORS", {"I2": 3.0, "I4": 2.0, "I5": 1.5})
    monkeypatch.setattr(ev, "CONSISTENCY_SPREAD", 4.0)
    monkeypatch.setattr(ev, "CONSISTENCY_SLACK", 0.01)
    assert rules.rule_text() == (
        "f times the noise floor, f = 3 for I2, 2 for I4 and 1.5 for I5, or the floor plus "
        "4 of its standard deviations, plus 0.01"
    )
    tex = str(rules.rule_tex())
    assert r"+ 4\,\text{sd}) + 0.01$" in tex and "$f = 3$ for $I_2$" in tex


def test_explain_s_unloading_term_carries_its_error_and_interval():
    """The unloading coefficient's standard error and interval (parameter ``d_zd``) are in
    the final model's table, not "--"."""
    from discovery import ForceLaw
    from discovery.vibroimpact.model.law import Term
    from reports.vibroimpact.context import _unloading_rows

    law = ForceLaw.parse("2e8*z").with_unloading([Term.parse("zd")], [4.05e6], 0.0)
    errors = {"z": 3.3e4, "d_zd": 1056.5}
    (row,) = _unloading_rows(law, errors, {"d_zd": (3.99e6, 4.11e6)})
    assert "unloading" in str(row[0]) and "zeta" in str(row[0])
    assert "1056" in str(row[2]) or "1.1" in str(row[2])
    assert "3.990" in str(row[3]) and "4.110" in str(row[3])
    assert _unloading_rows(ForceLaw.parse("2e8*z"), errors, {}) == []


def test_a_contact_models_report_lists_every_record_and_scenario():
    """A contact-models fit on two records names both records and both scenarios."""
    from discovery import ContactModelsResult
    from reports.contact_models import contact_models_context
    from reports.run import run_document

    sc = {"name": "grid-high", "m1": 1e4, "m2": 1e4, "k1": 2.75e7, "c1": 1e5, "A": 5e5}
    s = {
        "data": ["high.csv", "low.csv"],
        "scenario": sc,
        "scenarios": [sc, {**sc, "name": "grid-low", "A": 3.5e5}],
    }
    r = ContactModelsResult(fits=(), selected=None, n_records=2)
    c = contact_models_context(run_document(s, result=r), ".")
    assert [str(r) for r in c["records"]] == ["high.csv", "low.csv"]
    assert c["scenarios"][0][1:] == ["grid-high", "grid-low"]
    src = (Path(__file__).parents[2] / "reports/templates/contact_models.tex.j2").read_text()
    assert "records" in src


def test_identify_s_message_is_not_ended_twice():
    """The optimiser's message ends with a period; the sentence around it is not given a
    second one ("satisfied..")."""
    from reports.run import run_document
    from reports.vibroimpact.context import _identify

    r = _ns(
        law=None,
        checks=(),
        coefficients={},
        standard_errors={},
        intervals=None,
        method="trf",
        criterion="I2",
        n_simulations=3,
        message="Both `ftol` and `xtol` conditions are satisfied.",
    )
    c = _identify(run_document({}, result=r), ".")
    assert not str(c["message"]).endswith(".")


def _ns(**kw):
    from types import SimpleNamespace

    return SimpleNamespace(**kw)


def test_verify_figure_names_each_criterion_s_floor_and_limit_apart():
    """The verify figure's verdict line gives every judged criterion's floor and limit."""
    from reports.vibroimpact.verify_figures import _criterion_text

    ev = _ns(noise_floor={"I2": 0.0335}, limits={"I2": 0.072})
    assert _criterion_text("I2", 1.01, ev) == "I2 1.01 (floor 0.034, limit 0.072)"
    assert _criterion_text("I2", 1.01, _ns(noise_floor={"I2": 0.0335}, limits=None)) == (
        "I2 1.01 (floor 0.034)"
    )


def test_fit_loop_draws_the_model_above_every_impact_s_samples(tmp_path):
    """The model's branches (the unloading one runs along the samples near zero force) are
    drawn above the measured samples of every impact, so none hides them."""
    import numpy as np

    from reports.vibroimpact import fit_figures

    n = 40
    up = np.linspace(0, 1e-3, n)
    zeta = np.concatenate([up, up[::-1]] * 2)
    dz = np.concatenate([np.full(n, 0.5), np.full(n, -0.5)] * 2)
    samples = _ns(zeta=zeta, dzeta=dz, F=2e8 * zeta, impact=np.repeat([0, 1], 2 * n))
    law = lambda z, v: 2e8 * z + 1e6 * np.maximum(v, 0)  # noqa: E731
    result = _ns(samples=samples, selected=_ns(law=law))
    drawn = []
    fit_figures._save = lambda fig, stem: drawn.append(fig)
    try:
        fit_figures.fit_loop_figure(result, str(tmp_path / "loop"))
    finally:
        fit_figures._save = fit_figures.save
    (ax,) = drawn[0].axes
    dots = [ln for ln in ax.lines if ln.get_marker() == "."]
    model = [ln for ln in ax.lines if ln.get_marker() != "." and len(ln.get_xdata())]
    assert len(model) == 4 and min(m.get_zorder() for m in model) > max(
        d.get_zorder() for d in dots
    )
    labels = [t.get_text() for t in ax.get_legend().get_texts()]
    assert "model, impact 0" in labels and "model unloading (dashed)" in labels


def _explain_iteration(F):
    """An explain iteration whose model before reads 0.9 of the force ``F`` and whose
    unloading damping reads it exactly (the force panel's inputs)."""
    return _ns(
        simulated_before=_ns(F=0.9 * F),
        simulated_after=_ns(F=F),
        model_before=_ns(law=_ns(names=["z", "zd"])),
        effect="unloading_damping",
        criteria_before={"I2": 0.136},
        criteria_after={"I2": 0.0245},
        noise_floor={"I2": 0.026},
    )


def test_explain_forces_legend_covers_no_curve():
    """The legend of explain's force panel sits above every curve (it hid the peak)."""
    import numpy as np

    from reports._mpl import print_sizes, subplots
    from reports.vibroimpact.explain_figures import _explain_forces

    t = np.linspace(0, 6e-3, 300)
    F = 2e6 * np.exp(-t / 1.5e-3) * (t > 2e-4)
    imp = _ns(t=t, F=F, support=np.array([[2e-4, 5e-3]]), duration=6e-3, peak=F.max(), noise=0.0)
    it = _explain_iteration(F)
    with print_sizes():  # as explain_figure draws it: one of four panels of the page
        fig, ax = subplots(figsize=(3.3, 3.0))
        _explain_forces(ax, it, imp, 1)
        fig.canvas.draw()
    box = ax.get_legend().get_window_extent()
    top = max(ax.transData.transform(np.c_[ln.get_xdata(), ln.get_ydata()])[:, 1].max()
              for ln in ax.lines)  # fmt: skip
    assert box.y0 > top


def test_explain_forces_show_a_contact_that_crosses_the_folds_end_whole():
    """A contact that begins late in the folded cycle and ends after its start: the panel
    shows it from its onset through its peak (it showed the tail after the fold's start,
    the peak out of view), on times since the onset."""
    import numpy as np

    from reports._mpl import print_sizes, subplots
    from reports.vibroimpact.explain_figures import _explain_forces

    period = 8e-3
    t = np.linspace(0.0, period, 400, endpoint=False)
    since = np.mod(t - 6.5e-3, period)  # the onset at 6.5 ms, the contact 2.5 ms long
    F = np.where(since < 2.5e-3, 5e6 * np.sin(np.pi * since / 2.5e-3), 0.0)
    imp = _ns(
        t=t,
        F=F,
        support=np.array([[0.0, 1e-3], [6.5e-3, period]]),
        duration=period,
        peak=F.max(),
        noise=0.0,
    )
    it = _explain_iteration(F)
    with print_sizes():
        fig, ax = subplots(figsize=(3.3, 3.0))
        _explain_forces(ax, it, imp, 1)
    lo, hi = ax.get_xlim()
    x, y = ax.lines[0].get_xdata(), ax.lines[0].get_ydata()
    shown = (x >= lo) & (x <= hi)
    assert lo < 0.0 < 2.5 < hi  # [ms]: the onset and the end in view
    assert y[shown].max() == y.max() > 4.99e3  # the peak [kN]
    assert np.all(np.diff(x) > 0)  # one run, not the cycle's two pieces


def test_identify_figure_names_the_search_value_and_the_final_check_s():
    """Where the search's criterion and the final check's differ (0.183 against the
    report's 0.189), the figure names both, not one that contradicts the table."""
    import numpy as np

    from reports.vibroimpact import figures

    t = np.linspace(0, 6e-3, 50)
    imp = _ns(t=t, F=1e6 * np.exp(-t / 1e-3), support=np.array([[0.0, 4e-3]]), duration=6e-3)
    law = _ns(names=["z", "zd"], as_dict=lambda: {"z": 3.7e7, "zd": 5.0e6})
    result = _ns(
        law=law,
        iterations=[
            {"coefficients": {"z": 4e7, "zd": 5.1e6}, "n_simulations": 1, "value": 0.21},
            {"coefficients": {"z": 3.7e7, "zd": 5.0e6}, "n_simulations": 3, "value": 0.183},
        ],
        criterion="I2",
        criteria={"I2": 0.183},
        value=0.183,
        checks=[_ns(criteria={"I2": 0.189})],
        n_simulations=46,
        method="least-squares",
    )
    drawn = []
    figures._save = lambda fig, stem: drawn.append(fig)
    try:
        figures.identification_figure(result, imp, [("identified law", imp)], "x")
    finally:
        figures._save = figures.save
    titles = " | ".join(ax.get_title() for ax in drawn[0].axes)
    assert "0.183 in the search,\n0.189 in the final check" in titles
    assert "F_N converging" not in titles and "0.189 in the final check)" in titles


def test_conclusions_follow_the_number_of_records():
    """A fit of two records says the records hold an effect (not "the record holds"); one
    record keeps the singular."""
    from discovery._api._result import SCHEMA_VERSION
    from reports.run import run_document
    from reports.vibroimpact.context import _fit

    sel = {"coefficients": {"z": 2e8}, "terms": ["z"], "consistent": False, "status": "ok"}
    s = {
        "schema_version": SCHEMA_VERSION,
        "result": "fit",
        "selected": sel,
        "ranking": [sel],
        "fit_settings": {"library": "poly:2"},
        "records": [
            {"data": d, "scenario": "grid", "regime": "P1", "impacts": 1, "noise": {}}
            for d in ("high.csv", "low.csv")
        ],
        "equivalent": [{"law": "2e8*z"}],
    }
    text = " ".join(_fit(run_document(s), ".")["conclusions"])
    assert "all 2 records" in text and "the 2 records hold an effect" in text
    assert "the record holds" not in text and "this record" not in text
    assert "fit the 2 records as well within their noise" in text
    one = {**s, "records": s["records"][:1]}
    one = " ".join(_fit(run_document(one), ".")["conclusions"])
    assert "the record holds an effect" in one and "from this record" in one


def test_prose_typesets_every_term_alike():
    """In a note, ``zd`` is typeset as the tables set it, as ``z^2`` and ``z*zd`` are (it
    stayed plain text); a term inside a word, a path or a file name stays text."""
    from reports.lawtex import prose, term_tex

    note = "moved (zd 3.93e+06 -> 3.17e+06; z^2 1.42e+11; z*zd 9.17e+08)"
    text = str(prose(note))
    for t in ("zd", "z^2", "z*zd"):
        assert str(term_tex(t)) in text
    assert "zd " not in text and "(zd" not in text
    assert str(prose("F(zeta, 0) at z = 1")) == r"F($\zeta$, 0) at $\zeta$ = 1"
    kept = str(prose("record z.csv, data/zd, z-axis, zd\\_max, zebra, `zd`"))
    assert "$" not in kept and r"\texttt{zd}" in kept


def test_a_law_in_the_settings_and_the_study_design_is_typeset_whole():
    """A law given as a setting (identify's --start, advise's laws, a study's fixed law) is
    typeset whole, as the report's equations set it: not half math, half text."""
    from reports.cells import _provenance
    from reports.lawtex import law_inline, law_of, prose, value_tex
    from reports.run import run_document
    from reports.vibroimpact.study_context import _study

    start = "1.5e8*z + 0.9e7*zd"
    whole = str(law_inline(law_of(start, "start")))
    row = str(
        _provenance({"settings": {"start": start, "law": [start, "7.3e9*z^1.5"]}}, ".")[-1][1]
    )
    assert f"start={whole}" in row and "*z" not in row and "*$" not in row
    assert f"law={whole}, " + str(law_inline(law_of("7.3e9*z^1.5", "law"))) in row
    design = {"varied": {"law": [start]}, "fixed": {"law": start, "library": "z, zd"}}
    study = _ns(
        design=lambda: design,
        pooled=dict,
        cells=[{"law": start, "runs": 0, "recovered": 0}],
        config=_ns(name=""),
        complete=0,
        n_runs=0,
    )
    c = _study(run_document({}, result=study), ".")
    cells = [str(x) for r in c["design"] for x in r] + [str(x) for x in c["cells"][0]]
    assert whole in cells and f"{whole} (fixed)" in cells and "*z" not in " ".join(cells)
    assert str(value_tex("z,zd")) == r"$\zeta$,$\dot\zeta_{+}$"  # a term list is no law
    assert str(value_tex("z^2*zd")) == str(prose("z^2*zd"))  # a term, not a law of 1 z^2 zd
    assert str(value_tex("linear")) == "linear" and str(value_tex(3)) == "3"
    # a sweep's axis as its range (issue 50: the chart's 200 values of nu ran off the page)
    assert str(value_tex([0.8 + 0.002 * k for k in range(201)])) == (
        "0.8 to 1.2, 201 evenly spaced values"
    )
    assert str(value_tex([1, 2, 4, 8, 16, 32, 64])) == "1 to 64, 7 values"
    assert str(value_tex([1, 2, 3])) == "1, 2, 3"


def test_identify_figure_marks_the_start_only_where_the_search_began():
    """The start marker sat at the start values the report lists (1.5e8, 0.9e7), joined to
    a path that began at its cycle-by-cycle fit (4e7, 5.1e6): a path never taken. The start
    is marked only where the search began from it; otherwise the title says where it
    began (the path, drawn from its first law, is the one searched)."""
    import numpy as np

    from reports.vibroimpact import figures

    t = np.linspace(0, 6e-3, 50)
    imp = _ns(t=t, F=1e6 * np.exp(-t / 1e-3), support=np.array([[0.0, 4e-3]]), duration=6e-3)
    law = _ns(names=["z", "zd"], as_dict=lambda: {"z": 3.7e7, "zd": 5.0e6})
    result = _ns(
        law=law,
        iterations=[
            {"coefficients": {"z": 4e7, "zd": 5.1e6}, "n_simulations": 1, "value": 0.21},
            {"coefficients": {"z": 3.7e7, "zd": 5.0e6}, "n_simulations": 3, "value": 0.183},
        ],
        criterion="I2",
        criteria={"I2": 0.183},
        value=0.183,
        checks=[],
        n_simulations=46,
        method="least-squares",
    )
    drawn = []
    figures._save = lambda fig, stem: drawn.append(fig)
    try:
        figures.identification_figure(result, imp, [], "x", start={"z": 1.5e8, "zd": 0.9e7})
        figures.identification_figure(result, imp, [], "x", start={"z": 4e7, "zd": 5.1e6})
        figures.identification_figure(result, imp, [], "x")
    finally:
        figures._save = figures.save
    away = drawn[0].axes[0]
    assert not [ln for ln in away.lines if ln.get_label().startswith("start")]
    assert max(max(ln.get_xdata()) for ln in away.lines) < 1e8  # nothing drawn at 1.5e8
    assert "from the cycle-by-cycle fit of the given start" in away.get_title()
    (mark,) = [ln for ln in drawn[1].axes[0].lines if ln.get_label().startswith("start")]
    assert (mark.get_xdata()[0], mark.get_ydata()[0]) == (4e7, 5.1e6)
    assert not [ln for ln in drawn[2].axes[0].lines if ln.get_label().startswith("start")]


@pytest.mark.parametrize("kind", ["verify", "identify"])
def test_the_data_table_states_the_contacts_per_cycle(runs, kind):
    """Every command's summary states the record the same way (``Reference.measured``):
    identify's Data table showed "contacts per cycle --" on a record with contacts."""
    from reports.cells import _measured_rows

    m = json.loads((runs / kind / "summary.json").read_text())["measured"]
    assert m["impacts"] >= 1 and m["n_cycles"] >= 1 and "F" in m["noise"]
    rows = dict((str(k), v) for k, v in _measured_rows(m))
    assert rows["contacts per cycle"] == m["impacts"]


def test_a_verdict_is_typeset_without_the_rule_stated_beside_it():
    from reports.lawtex import verdict_tex

    v = (
        "inconsistent: I2 = 0.238 exceeds 0.054, I4 = 0.111 exceeds 0.0231 (max(f x noise "
        "floor, floor + 3 sd) + 0.005, f = 2 for I2, 2 for I4); the law's folded cycle differs"
    )
    out = str(verdict_tex(v))
    assert "noise floor" not in out and "f = 2" not in out
    assert out.startswith("inconsistent: I2 = 0.238 exceeds 0.054, I4 = 0.111 exceeds 0.0231;")
    assert out.endswith("the law's folded cycle differs")


def test_a_ueda_effect_is_named_by_its_catalogue_title():
    from reports.ueda.context import _effect_title

    assert _effect_title("van_der_pol_damping") == "Amplitude-dependent (van der Pol) damping"
    assert _effect_title("gone_effect") == "gone effect"  # a run saved by another version


def test_a_ueda_attractor_report_states_its_oscillator(tmp_path):
    """The attractor's page names the model, its parameters and both exponents (the
    figure's title alone held them), with the Greek letters typeset in the figure."""
    out = tmp_path / "att"
    assert main(["ueda", "attractor", "--periods", "400", "--batches", "4", "--out", str(out)]) == 0
    r = report(out, compile=False)
    tex = r.tex.read_text()
    for words in (
        "parameters",
        "mu=0.2",
        "nu=1.02",
        "largest Lyapunov exponent",
        "second exponent",
    ):
        assert words in tex, words


def test_the_verify_figure_shows_a_transient_record_sample_by_sample(tmp_path):
    """Issue 50: the README's from-rest record (20 periods, the scipy path) is in a
    transient, so each cycle's onset falls at another phase: the fold of four cycles was a
    staircase, and the loop drew force at penetrations down to -0.7 mm (eq. (1): F = 0 for
    zeta <= 0).  The figure shows the verdict's own comparison, on the record's samples:
    one contact's onset at time 0, and the loop where the contact carries force."""
    from discovery import ForceLaw, load_scenario, synthesize, verify
    from reports.vibroimpact.verify_figures import span_view, verify_figure

    sc = load_scenario("paper")
    law = ForceLaw.parse("2.06e8*z + 4e6*zd; unloading: 4e6*zd")
    rec = synthesize(sc, law, periods=20, noise=0.01, seed=1, from_rest=True, integrator="scipy")
    res = verify(sc, rec, law)
    assert res.evaluation.consistent and res.evaluation.comparison == "record span"
    view = span_view(res)
    t, fm, fn = view["t"], view["fm"], view["fn"]
    thr = max(3 * view["sigma"], 0.02 * fm.max())
    assert np.all(fm[t < -1e-4] < thr) and fm[(t >= 0) & (t < 1e-3)].max() > 0.5 * fm.max()
    assert np.max(np.abs(fn - fm)) < 6 * view["sigma"]  # the law tracks the record's samples
    zm, f, zn, _ = view["loop"]
    assert np.mean(zm > -3e-5) > 0.97 and np.mean(zn > -3e-5) > 0.97  # force where zeta > 0
    png, _ = verify_figure(res, str(tmp_path / "verify"))
    assert Path(png).stat().st_size > 10_000


def test_numbers_printed_side_by_side_share_one_form():
    """A coefficient's row printed its standard error as 46836 beside 1.0x10^8, and the
    criteria table an I5 floor as 5.14x10^-4 beside its limit 0.00564: a row's numbers are
    in one form now (the scientific one when any needs it)."""
    from reports.cells import _coef_rows, _criteria_table

    ((_, value, err, iv),) = _coef_rows({"z^2": 1.0e8}, {"z^2": 46836.0}, {"z^2": (9.1e7, 1.1e8)})
    assert value == r"$1.000\cdot 10^{8}$" and err == r"$4.7\cdot 10^{4}$", (value, err)
    assert iv == r"[$9.100\cdot 10^{7}$, $1.100\cdot 10^{8}$]", iv
    (row,) = _criteria_table({"I5": 8.76e-6}, {"I5": 5.14e-4}, {"I5": 0.00564})
    assert row[1:4] == [r"$8.76\cdot 10^{-6}$", r"$5.14\cdot 10^{-4}$", r"$5.64\cdot 10^{-3}$"]
    (row,) = _criteria_table({"I2": 0.0224}, {"I2": 0.0188}, {"I2": 0.0426})
    assert row[1:4] == ["$0.0224$", "$0.0188$", "$0.0426$"]  # none needs it: all plain
    assert num(3.2, sci=True) == "$3.20$" and num(6941, 2, sci=True) == r"$6.9\cdot 10^{3}$"


def test_the_refinement_names_the_search_s_criterion_apart_from_the_check_s():
    """The refinement line said I2 0.183 where the ranking said 0.189 for the same law: the
    search scores a law with the onset sample averaged, the check with point samples. Both
    are named for what they are; where they print alike, one value is."""
    from reports.vibroimpact.context import _refinement_tex

    note = (
        "refined by simulation from the backward step from z + zd + z^2 (38 simulations, I2 0.183)"
    )
    text = str(_refinement_tex(_ns(note=note, criteria={"I2": 0.189}), "I2"))
    assert "$I_{2}$ = $0.183$ at the end of the search" in text, text
    assert "$0.189$ in the check by full simulation" in text and "ranking" in text
    assert "z^2" not in text and r"$\zeta^{2}$" in text and "(38 simulations)" in text
    same = str(_refinement_tex(_ns(note=note, criteria={"I2": 0.1831}), "I2"))
    assert same.count("0.183") == 1 and "search" not in same, same
    assert str(_refinement_tex(_ns(note="not refined", criteria={}), "I2")) == "not refined"


def test_the_check_states_what_is_true_of_the_law_s_motion():
    """ "Steady state P1, P1" was printed beside a verdict saying the law's trajectory had
    not settled: a record whose verdict says so is said to be compared with the trajectory
    over its span; a settled one's steady state is named once."""
    from discovery.vibroimpact.verify.notes import JUDGED_OVER_SPAN
    from reports.vibroimpact.context import _regime_text

    unsettled = (
        "consistent: I2 = 0.05 <= 0.07; the law's trajectory from the measured state has not "
        f"settled by the record's end: over its last cycles it is I2 = 0.1 from the law's "
        f"steady orbit; {JUDGED_OVER_SPAN}"
    )

    def ev(verdict):
        return _ns(regime={"simulated": "P1", "measured": "P1"}, status="ok", verdict=verdict)

    text = str(_regime_text(_ns(evaluations=[ev(unsettled), ev("consistent")], regime="P1, P1")))
    assert "Steady state" not in text and "P1, P1" not in text, text
    assert text.startswith("Record 1: the law's trajectory from the measured state had not")
    assert "record 2: the law's steady state is P1." in text
    both = str(_regime_text(_ns(evaluations=[ev("consistent")] * 2, regime="P1, P1")))
    assert both == "The law's steady state against each of the 2 records is P1.", both
    one = str(_regime_text(_ns(evaluations=[ev(unsettled)], regime="P1")))
    assert "steady state is" not in one and "(it tends to P1)" in one
    two = str(_regime_text(_ns(evaluations=[ev(unsettled)] * 2, regime="P1, P1")))
    assert two.startswith("The law's trajectory from the measured state against each of the 2")
    assert "steady state is" not in two and "P1, P1" not in two
    templates = Path(__file__).parents[2] / "reports/templates"
    for name in ("fit.tex.j2", "model.tex.j2"):
        assert "Steady state ((( regime )))" not in (templates / name).read_text(), name


def test_the_certified_conditions_are_typeset_as_math():
    """The certificate's conditions read as code ("P(zeta, zd) - P(zeta, 0) - margin * zd",
    "bernstein(elevation=2)+grid(1001x1001)"): each is a requirement in the report's
    symbols, the method in words."""
    from reports.vibroimpact.context import _certificate

    conditions = {
        "non_adhesion": {"quantity": "P(zeta, zd)", "holds": True, "grid_min_rel": 0.0},
        "dissipativity": {
            "quantity": "P(zeta, zd) - P(zeta, 0) - margin * zd",
            "holds": True,
            "grid_min_rel": 0.0,
        },
    }
    cert = _ns(
        method="bernstein(elevation=2)+grid(1001x1001)",
        holds=True,
        worst_violation=0.0,
        domain={"zeta_max": 3.1e-4, "zd_max": 0.757},
        conditions=conditions,
    )
    c = _certificate(cert)
    (na, diss) = c["conditions"]
    assert na[:3] == ["non-adhesion", r"$P(\zeta,\dot\zeta_{+}) \ge 0$", "holds"]
    assert diss[1] == r"$P(\zeta,\dot\zeta_{+}) - P(\zeta,0) \ge 0$"
    assert "zeta" not in str(diss[1]).replace(r"\zeta", "") and "margin" not in str(diss[1])
    assert "bernstein(" not in c["method"] and "1001 x 1001 grid" in c["method"]
    with_margin = _certificate(cert, margin=2e3)["conditions"][1][1]
    assert r"\ge m\,\dot\zeta_{+}$" in with_margin and r"2000\,\mathrm{N\,s/m}" in with_margin


def test_the_advise_report_gives_units_the_ranking_rule_and_one_number_form(runs):
    """Bounds without units, a regime change ranked above larger separations without the
    rule said, and a floor 5.14x10^-4 beside a limit 0.00564: the bounds carry N, Hz (kg, m),
    the note says a regime change ranks as infinite, a criterion and its limit share a form."""
    from discovery.vibroimpact.advise.separation import PairSeparation
    from reports.vibroimpact.advise_report import _judged_rows

    tex = report(runs / "advise", compile=False).tex.read_text()
    body = tex.split("section{Scenario}")[0]
    assert re.search(r"\$3\.00\\cdot 10\^\{5\}\$ -- \$6\.00\\cdot 10\^\{5\}\$\\,N", body)
    assert r"$20.0$ -- $30.0$\,Hz" in body
    assert "ranks as if its separation were infinite" in body
    assert "At the advised point" in body
    q = PairSeparation(
        (0, 1),
        3.2,
        (3.2, 5.0),
        ({"I2": 0.12, "I5": 5.14e-4}, {"I2": 0.2}),
        ({"I2": 0.05, "I5": 0.00564}, {"I2": 0.04}),
    )
    rows = _judged_rows(_ns(pairs=(q,)))
    i5 = [r for r in rows if r[3] == "$I_{5}$"]
    assert [r[4:6] for r in i5] == [[r"$5.14\cdot 10^{-4}$", r"$5.64\cdot 10^{-3}$"]], rows
    assert [(r[1], r[2]) for r in rows] == [(1, 2), (1, 2), (2, 1)]


def test_explain_scores_wrap_long_effect_names():
    """The scores panel writes a long effect name on two lines (its labels had taken a third
    of the page's width from the plots), in the order best at the top, the named one green."""
    from reports._mpl import print_sizes, subplots
    from reports.vibroimpact.explain_figures import _explain_scores

    def score(effect, after):
        return _ns(effect=effect, gap="I2", criteria_after={"I2": after})

    it = _ns(
        effect="unloading_damping",
        scores=[score("penetration_velocity_coupling", 0.19), score("unloading_damping", 0.02)],
        criteria_before={"I2": 0.136},
        noise_floor={"I2": 0.026},
    )
    with print_sizes():
        fig, ax = subplots(figsize=(3.3, 3.0))
        _explain_scores(ax, it)
    labels = [t.get_text() for t in ax.get_yticklabels()]
    assert labels == ["penetration velocity\ncoupling", "unloading damping"]
    colors = [p.get_facecolor()[:3] for p in ax.patches]
    assert colors[1][1] > colors[1][0]  # the named one (at the top) green
