"""``report``: a run directory's LaTeX report, compiled to PDF.

The report is a pure function of the run's ``summary.json`` and the figures it wrote: the
same directory gives the same ``report.tex`` (and the PDF, up to TeX's timestamps).
Compilation runs ``latexmk`` with shell escape off and TeX's file access restricted to the
compile directory (``openin_any=p``, ``openout_any=p``), in a private staging directory;
only a finished PDF is moved into the run directory. Without TeX the ``.tex`` is written and
one line says which Debian packages to install.
"""

from __future__ import annotations

import contextlib
import json
import os
import re
import shutil
import subprocess
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

from .context import context
from .texenv import Tex, environment

__all__ = ["Report", "report", "render", "SNIPPETS", "TEX_PACKAGES", "compile_tex"]

TEX_PACKAGES = (
    "latexmk texlive-latex-recommended texlive-latex-extra texlive-fonts-recommended lmodern"
)
SNIPPETS = ("model", "table", "criteria", "figure")
_SAFE_FILE = re.compile(r"^[A-Za-z0-9_.-]+\.pdf$")


@dataclass
class Report:
    """Where a report went and what happened to it.

    Attributes
    ----------
    tex : Path
        The LaTeX source (``report.tex``, or ``snippet-KIND.tex``).
    pdf : Path or None
        The compiled PDF, or None (no TeX, a snippet, or a failed compilation).
    message : str
        One line: what was written, or why there is no PDF and the fix.
    kind : str
        The run kind (``fit``, ``verify``, ...).
    pages : int or None
        Pages of the PDF.
    """

    tex: Path
    pdf: Path | None
    message: str
    kind: str
    pages: int | None = None
    figures: list = field(default_factory=list)

    def __str__(self):
        article = "an" if self.kind[0] in "aeiou" else "a"
        lines = [f"report of {article} {self.kind} run", f"  source: {self.tex}"]
        if self.pdf is not None:
            lines.append(f"  PDF: {self.pdf}" + (f" ({self.pages} pages)" if self.pages else ""))
        lines.append(f"  {self.message}")
        return "\n".join(lines)


def _load(run_dir):
    from discovery.errors import InputError

    d = Path(run_dir)
    if not d.is_dir():
        raise InputError(
            f"{str(run_dir)!r} is not a run directory; give the --out directory "
            "of a vidi command (it holds summary.json)"
        )
    p = d / "summary.json"
    try:
        summary = json.loads(p.read_text(encoding="utf-8"))
    except FileNotFoundError:
        raise InputError(
            f"{str(run_dir)!r} has no summary.json: not a vidi run directory; "
            "give the --out directory of a vidi command"
        ) from None
    except (OSError, ValueError, UnicodeDecodeError):
        raise InputError(
            f"{str(p)!r} is not readable JSON; run the command again to rewrite it"
        ) from None
    if not isinstance(summary, dict) or "command" not in summary:
        raise InputError(
            f"{str(p)!r} is not a vidi summary (no 'command'); give the --out "
            "directory of a vidi command"
        )
    return summary


def render(summary, run_dir, snippet=None, template=None):
    """The report's LaTeX text (or one snippet's) from a summary and its run directory;
    ``template`` names another document of the run (``"model"``: the fit's model.tex)."""
    from discovery.errors import InputError

    ctx = context(summary, run_dir)
    ctx["figures"] = [
        dict(f, file=Tex(f["file"])) for f in ctx["figures"] if _SAFE_FILE.match(f["file"])
    ]
    ctx["created"] = summary.get("created", "")
    env = environment()
    if template is not None:
        return env.get_template(f"{template}.tex.j2").render(**ctx)
    if snippet is None:
        return env.get_template(ctx["template"]).render(**ctx)
    if snippet not in SNIPPETS:
        raise InputError(f"unknown snippet {snippet!r}; choose one of {', '.join(SNIPPETS)}")
    if snippet == "model" and ctx.get("model") in (None, "--"):
        raise InputError(
            f"a {ctx['kind']} run has no model to paste; use --snippet criteria, table or figure"
        )
    if snippet == "figure" and not ctx["figures"]:
        raise InputError(f"the {ctx['kind']} run wrote no PDF figure to paste")
    return env.get_template("snippets.tex.j2").render(snippet=snippet, **ctx)


def _first_error(log_text):
    lines = log_text.splitlines()
    for k, ln in enumerate(lines):
        if ln.startswith("!"):
            more = next((x.strip() for x in lines[k + 1 : k + 3] if x.strip().startswith("l.")), "")
            return (ln[1:].strip() + (f" ({more})" if more else ""))[:200]
    return "see the log"


def _pages(pdf):
    try:
        out = subprocess.run(["pdfinfo", str(pdf)], capture_output=True, text=True, timeout=30)
    except (OSError, subprocess.TimeoutExpired):
        return None
    m = re.search(r"^Pages:\s+(\d+)", out.stdout, re.M)
    return int(m.group(1)) if m else None


def compile_tex(tex_path, figures=(), timeout=300):
    """Compile ``tex_path`` (with the figure files beside it) in a private directory.

    Returns ``(pdf_path or None, message)``. The PDF replaces ``NAME.pdf`` beside the source
    only when the compilation succeeded; on failure ``NAME.log`` is kept beside it and the
    message names the first TeX error.
    """
    tex = Path(tex_path)
    if shutil.which("latexmk") is None or shutil.which("pdflatex") is None:
        return None, (
            f"no PDF: TeX is not installed; wrote {tex}; to compile it, install "
            f"TeX Live: apt-get install {TEX_PACKAGES}"
        )
    env = dict(os.environ, openin_any="p", openout_any="p", shell_escape="f", TEXMFOUTPUT="")
    with tempfile.TemporaryDirectory(prefix=".vidi-tex-", dir=tex.parent) as work:
        w = Path(work)
        shutil.copy2(tex, w / tex.name)
        for f in figures:
            src = tex.parent / f
            if src.is_file():
                shutil.copy2(src, w / f)
        cmd = [
            "latexmk",
            "-pdf",
            "-interaction=nonstopmode",
            "-halt-on-error",
            "-no-shell-escape",
            "-quiet",
            tex.name,
        ]
        try:
            run = subprocess.run(
                cmd, cwd=w, capture_output=True, text=True, timeout=timeout, env=env
            )
        except subprocess.TimeoutExpired:
            return None, f"no PDF: latexmk took more than {timeout} s; the source is {tex}"
        pdf = w / tex.with_suffix(".pdf").name
        log = w / tex.with_suffix(".log").name
        if run.returncode != 0 or not pdf.is_file():
            text = log.read_text(errors="replace") if log.is_file() else run.stdout + run.stderr
            kept = tex.with_suffix(".log")
            with contextlib.suppress(OSError):
                shutil.copy2(log, kept)
            return None, (f"no PDF: LaTeX failed ({_first_error(text)}); the log is {kept}")
        dest = tex.with_suffix(".pdf")
        tmp = dest.with_name(f".{dest.name}.tmp")
        shutil.copy2(pdf, tmp)
        os.replace(tmp, dest)
    with contextlib.suppress(OSError):
        tex.with_suffix(".log").unlink()  # a log of an earlier failure is stale now
    return dest, f"wrote {dest}"


def _check_ours(run_dir, names):
    """Refuse, before writing, to replace a file of these names that vidi did not write
    (not in the run's manifest): a user's own ``report.tex`` is never overwritten."""
    from discovery._io import MANIFEST
    from discovery.errors import InputError

    d = Path(run_dir)
    try:
        listed = set(json.loads((d / MANIFEST).read_text(encoding="utf-8")).get("files") or [])
    except (OSError, ValueError, AttributeError):
        listed = set()
    for name in names:
        p = d / name
        if os.path.lexists(p) and (name not in listed or p.is_symlink() or not p.is_file()):
            raise InputError(
                f"{str(p)!r} exists and was not written by vidi; move it away "
                "(the report would replace it)"
            )


def _record_in_manifest(run_dir, names):
    """Add the report's files to the run's manifest: they are vidi's, so a later run into
    the directory may replace them (and never mistakes them for a user's)."""
    from discovery._io import MANIFEST, atomic_write_text

    p = Path(run_dir) / MANIFEST
    try:
        man = json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return
    files = set(man.get("files") or [])
    files.update(names)
    man["files"] = sorted(files)
    atomic_write_text(p, json.dumps(man, indent=2) + "\n")


def report(run_dir, *, snippet=None, compile=True, timeout=300):
    """Write ``run_dir/report.tex`` from the run's results and compile ``report.pdf``.

    Parameters
    ----------
    run_dir : str or Path
        The ``--out`` directory of a ``vidi`` run (``verify``, ``fit``, ``identify``,
        ``landscape``, ``explain`` or a ``ueda`` command).
    snippet : str, optional
        One piece to paste into a paper instead of the whole report: ``"model"`` (the
        equation), ``"table"`` (coefficients), ``"criteria"`` (criteria with noise floors)
        or ``"figure"``; written to ``snippet-KIND.tex`` and not compiled.
    compile : bool
        Compile the PDF (when TeX is installed).

    Returns
    -------
    Report
    """
    from discovery._io import atomic_write_text

    summary = _load(run_dir)
    text = render(summary, run_dir, snippet)
    d = Path(run_dir)
    name = "report.tex" if snippet is None else f"snippet-{snippet}.tex"
    _check_ours(
        d, [name] if snippet is not None or not compile else [name, "report.pdf", "report.log"]
    )
    tex = d / name
    atomic_write_text(tex, text)
    ctx_figs = re.findall(r"\\includegraphics(?:\[[^\]]*\])?\{([^}]+)\}", text)
    written = [name]
    if snippet is not None or not compile:
        _record_in_manifest(d, written)
        return Report(tex, None, f"wrote {tex}", summary["command"], None, ctx_figs)
    pdf, message = compile_tex(tex, ctx_figs, timeout=timeout)
    if pdf is not None:
        written.append(pdf.name)
    _record_in_manifest(d, written)
    return Report(
        tex, pdf, message, summary["command"], _pages(pdf) if pdf is not None else None, ctx_figs
    )
