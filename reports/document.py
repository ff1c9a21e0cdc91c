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
import secrets
import shutil
import signal
import stat
import subprocess
import threading
from dataclasses import dataclass, field
from pathlib import Path

from discovery.outputs import finish_handed_off

from .context import context
from .run import RunDocument, run_document
from .texenv import Tex, environment

__all__ = [
    "Report",
    "report",
    "render",
    "RunDocument",
    "SNIPPETS",
    "TEX_PACKAGES",
    "compile_tex",
]

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
        from discovery.wording import a

        kind = re.sub(r"^ueda\b", "Ueda", self.kind)
        lines = [f"report of {a(kind)} run", f"  source: {self.tex}"]
        if self.pdf is not None:
            lines.append(f"  PDF: {self.pdf}" + (f" ({self.pages} pages)" if self.pages else ""))
        message = self.message
        for path in (self.pdf, self.tex):  # a file the lines above name already
            if path is not None and message.startswith(f"wrote {path}"):
                message = message[len(f"wrote {path}") :].lstrip("; ")
        if message:
            lines.append(f"  {message}")
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


#: how many of a run's figures a template of :func:`render` shows (the others: every one)
TEMPLATE_FIGURES = {"model": 1}


def render(summary, run_dir, snippet=None, template=None, skipped=None):
    """The report's LaTeX text (or one snippet's) from a run's document (a summary dict or
    a :class:`~reports.run.RunDocument`) and its run directory; ``template`` names another
    document of the run (``"model"``: the fit's model.tex).

    The report reads the run's typed result (``doc.result``) and, for what only the summary
    holds (the command's provenance, input names), the summary. Every field is read as
    text: a law is rebuilt from its own text by the law grammar, every other string is
    escaped. A field of the wrong type (an edited summary) is one
    :class:`~discovery.errors.InputError`. A figure that is a link or not a plain file of
    the run directory is left out (its name appended to ``skipped``).
    """
    import jinja2

    from discovery.errors import InputError, VidiError

    doc = run_document(summary)
    try:
        ctx = context(doc, run_dir)
        figures = []
        # a figure being printed is waited for where it is checked, those a template does
        # not show are not (the fit's model.tex shows its first)
        for f in ctx["figures"][: TEMPLATE_FIGURES.get(template)]:
            if _safe_figure(run_dir, f["file"]) is not None:
                figures.append(dict(f, file=Tex(f["file"])))
            elif skipped is not None:
                skipped.append(f["file"])
        ctx["figures"] = figures
        ctx["created"] = doc.summary.get("created", "")
        env = environment()
        if template is not None:
            return env.get_template(f"{template}.tex.j2").render(**ctx)
        if snippet is None:
            return env.get_template(ctx["template"]).render(**ctx)
        if snippet not in SNIPPETS:
            raise InputError(f"unknown snippet {snippet!r}; choose one of {', '.join(SNIPPETS)}")
        if snippet == "model" and ctx.get("model") in (None, "--"):
            raise InputError(
                f"a {ctx['kind']} run has no model to paste; use --snippet criteria, table "
                "or figure"
            )
        if snippet == "figure" and not ctx["figures"]:
            raise InputError(f"the {ctx['kind']} run wrote no PDF figure to paste")
        return env.get_template("snippets.tex.j2").render(snippet=snippet, **ctx)
    except VidiError:
        raise
    except (
        TypeError,
        AttributeError,
        KeyError,
        ValueError,
        IndexError,
        OverflowError,
        jinja2.TemplateError,
    ) as exc:
        where = Path(run_dir) / "summary.json"
        why = " ".join(str(exc).split())[:120]
        raise InputError(
            f"{str(where)!r} has a field of the wrong type or a missing one "
            f"({type(exc).__name__}: {why}); run the command again to rewrite it"
        ) from None


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


_STAGE = re.compile(r"^\.vidi-tex-(?P<pid>\d+)-(?P<start>\d+)\.[0-9a-f]+$")


def _stage_dir(parent):
    """A private staging directory ``.vidi-tex-PID-START.TOKEN`` in ``parent`` (the PID and
    its start time name the run that owns it); stale ones of killed runs are removed first."""
    from discovery.outputs import process_start

    clean_stale_staging(parent)
    pid = os.getpid()
    d = Path(parent) / f".vidi-tex-{pid}-{process_start(pid)}.{secrets.token_hex(4)}"
    d.mkdir(mode=0o700)
    return d


def clean_stale_staging(parent):
    """Remove the ``.vidi-tex-*`` staging directories in ``parent`` whose run is gone (a
    report killed with SIGKILL, or a machine that lost power); returns what was removed."""
    from discovery.outputs import process_alive

    gone = []
    try:
        entries = list(os.scandir(parent))
    except OSError:
        return gone
    for e in entries:
        m = _STAGE.match(e.name)
        if (
            m
            and e.is_dir(follow_symlinks=False)
            and not process_alive(int(m["pid"]), int(m["start"]))
        ):
            shutil.rmtree(e.path, ignore_errors=True)
            gone.append(Path(e.path))
    return gone


def _safe_figure(parent, name):
    """``parent/name`` when it is a plain file inside ``parent`` (no link, no path), else
    None: a figure replaced by a link to a file elsewhere is never read into the PDF."""
    if not _SAFE_FILE.match(name):
        return None
    src = Path(parent) / name
    finish_handed_off([src])  # a PDF a forked child prints is there first
    try:
        st = os.lstat(src)
    except OSError:
        return None
    return src if stat.S_ISREG(st.st_mode) else None


def _kill_group(proc):
    """End latexmk and every child it started (its own process group)."""
    with contextlib.suppress(OSError):
        os.killpg(proc.pid, signal.SIGKILL)
    with contextlib.suppress(OSError, subprocess.TimeoutExpired):
        proc.wait(timeout=10)


_PR_SET_PDEATHSIG = 1


def _die_with_parent():
    """In the child, before exec: SIGTERM when the parent (vidi) dies, even by SIGKILL
    (Linux); ``timeout`` passes it on to latexmk's whole group."""
    import ctypes
    import ctypes.util

    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(ctypes.util.find_library("c") or None, use_errno=True)
        libc.prctl(_PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0)


def _run_latexmk(cmd, cwd, env, timeout):
    """Run latexmk in its own session (process group); on a timeout, an interrupt or any
    error the whole group is killed, so no pdflatex outlives the report. Under coreutils'
    ``timeout`` (when installed) the group also ends by itself a little after ``timeout``
    and when vidi is killed outright. Returns ``(returncode, output)`` or raises
    :class:`subprocess.TimeoutExpired`."""
    if shutil.which("timeout") is not None:
        cmd = ["timeout", "-s", "KILL", str(int(timeout) + 10), *cmd]
    proc = subprocess.Popen(
        cmd,
        preexec_fn=_die_with_parent if os.name == "posix" else None,
        cwd=cwd,
        env=env,
        stdin=subprocess.DEVNULL,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        errors="replace",
        start_new_session=True,
    )
    old = None
    if threading.current_thread() is threading.main_thread():
        # outside the CLI SIGTERM would end Python at once and leave the group running:
        # for the compilation it ends the group first, then Python as before
        with contextlib.suppress(ValueError, OSError):
            if signal.getsignal(signal.SIGTERM) in (signal.SIG_DFL, None):

                def _term(signum, frame):
                    _kill_group(proc)
                    signal.signal(signal.SIGTERM, signal.SIG_DFL)
                    os.kill(os.getpid(), signal.SIGTERM)

                old = signal.signal(signal.SIGTERM, _term)
    try:
        out, _ = proc.communicate(timeout=timeout)
        return proc.returncode, out or ""
    finally:
        if proc.returncode is None or proc.poll() is None:
            _kill_group(proc)
        else:
            with contextlib.suppress(OSError):  # a child latexmk left behind, if any
                os.killpg(proc.pid, signal.SIGKILL)
        if old is not None:
            with contextlib.suppress(ValueError, OSError):
                signal.signal(signal.SIGTERM, old)


LATEXMK = ["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape"]
PDFLATEX = ["pdflatex", "-interaction=nonstopmode", "-halt-on-error", "-no-shell-escape"]
#: a pdflatex log that asks for another pass
_RERUN = re.compile(r"Rerun to get|Label\(s\) may have changed|There were undefined references")


def _compiled(tex, w, env, timeout, once):
    """latexmk's passes over ``tex`` in ``w``; with ``once`` one pdflatex pass, then latexmk
    only where its log asks for another.  Returns ``(returncode, output)``."""
    if once:
        code, output = _run_latexmk([*PDFLATEX, tex.name], w, env, timeout)
        log = w / tex.with_suffix(".log").name
        if code != 0 or not log.is_file() or not _RERUN.search(log.read_text(errors="replace")):
            return code, output
    return _run_latexmk([*LATEXMK, "-quiet", tex.name], w, env, timeout)


def compile_tex(tex_path, figures=(), timeout=300, staged=None, once=False):
    """Compile ``tex_path`` (with the figure files beside it) in a private directory.

    Returns ``(pdf_path or None, message)``. The PDF replaces ``NAME.pdf`` beside the source
    only when the compilation succeeded; on failure ``NAME.log`` is kept beside it and the
    message names the first TeX error. latexmk and its children run in their own process
    group, killed together on a timeout, Ctrl-C or SIGTERM. A figure that is a link (or not
    a plain file in the source's directory) is left out, and the message says so.
    ``staged``: a staging directory that already holds the source (see :func:`report`).
    ``once``: a document that shows no table of contents, list or page count of its own
    (the fit's model.tex) is compiled by one pdflatex pass: latexmk runs a second only
    because the first wrote the ``.aux`` it reads, which changes no page of such a document
    (0.16 s against 0.47 s); where the pass's log asks for another (a label changed, an
    undefined reference) latexmk makes them.
    """
    tex = Path(tex_path)
    if shutil.which("latexmk") is None or shutil.which("pdflatex") is None:
        return None, (
            f"no PDF: TeX is not installed; wrote {tex}; to compile it, install "
            f"TeX Live: apt-get install {TEX_PACKAGES}"
        )
    env = dict(os.environ, openin_any="p", openout_any="p", shell_escape="f", TEXMFOUTPUT="")
    own = staged is None
    w = _stage_dir(tex.parent) if own else Path(staged)
    try:
        if own:
            shutil.copyfile(tex, w / tex.name)
        skipped = []
        for f in figures:
            src = _safe_figure(tex.parent, f)
            if src is None:
                skipped.append(f)
            else:
                shutil.copyfile(src, w / f, follow_symlinks=False)
        if skipped:
            return None, (
                f"no PDF: figure(s) {', '.join(skipped)} are links or not plain files in "
                f"{tex.parent}; they are not read (run the command again to redraw them)"
            )
        try:
            code, output = _compiled(tex, w, env, timeout, once)
        except subprocess.TimeoutExpired:
            return None, f"no PDF: latexmk took more than {timeout} s; the source is {tex}"
        pdf = w / tex.with_suffix(".pdf").name
        log = w / tex.with_suffix(".log").name
        if code != 0 or not pdf.is_file():
            text = log.read_text(errors="replace") if log.is_file() else output
            kept = tex.with_suffix(".log")
            with contextlib.suppress(OSError):
                shutil.copyfile(log, kept)
            return None, (f"no PDF: LaTeX failed ({_first_error(text)}); the log is {kept}")
        dest = tex.with_suffix(".pdf")
        if own:
            os.replace(pdf, dest)
        else:
            dest = pdf  # the caller moves it into place
    finally:
        if own:
            shutil.rmtree(w, ignore_errors=True)
    with contextlib.suppress(OSError):
        tex.with_suffix(".log").unlink()  # a log of an earlier failure is stale now
    return dest, f"wrote {dest}"


def _manifest(run_dir):
    """``(manifest dict or None, the names it lists)``: only a JSON object's list of plain
    names counts (a manifest edited to hold ``"files": 5``, a string or paths lists none)."""
    from discovery.outputs import MANIFEST

    try:
        man = json.loads((Path(run_dir) / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError, UnicodeDecodeError):
        return None, set()
    if not isinstance(man, dict):
        return None, set()
    files = man.get("files")
    names = {
        f for f in (files if isinstance(files, list) else []) if isinstance(f, str) and "/" not in f
    }
    return man, names


def _check_ours(run_dir, names):
    """Refuse, before writing, to replace a file of these names that vidi did not write
    (not in the run's manifest): a user's own ``report.tex`` is never overwritten."""
    from discovery.errors import InputError

    d = Path(run_dir)
    listed = _manifest(d)[1]
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
    from discovery.outputs import MANIFEST, atomic_write_text

    p = Path(run_dir) / MANIFEST
    man, files = _manifest(run_dir)
    if man is None:
        return
    files.update(names)
    man["files"] = sorted(files)
    atomic_write_text(p, json.dumps(man, indent=2) + "\n")


def _settle_manifest(run_dir, names):
    """Drop from the run's manifest the report's names that were claimed and not written
    (the log of a compilation that succeeded, the PDF of one that failed): the manifest
    lists the files that are there."""
    from discovery.outputs import MANIFEST, atomic_write_text

    d = Path(run_dir)
    man, files = _manifest(d)
    gone = {n for n in names if n in files and not (d / n).exists()}
    if man is None or not gone:
        return
    man["files"] = sorted(files - gone)
    atomic_write_text(d / MANIFEST, json.dumps(man, indent=2) + "\n")


def _draw_report_figures(doc, d):
    """Draw the figures a run's command did not (:func:`reports.contact_models.
    drawn_by_report`) into the run directory, entered in its manifest first (a file of
    those names vidi did not write is never replaced)."""
    from .contact_models import drawn_by_report

    drawn = drawn_by_report(doc)
    names = [f"{stem}{ext}" for stem, _ in drawn for ext in (".png", ".pdf")]
    if not names:
        return
    _check_ours(d, names)
    _record_in_manifest(d, names)
    for stem, draw in drawn:
        draw(str(d / stem))


def report(run_dir, *, snippet=None, compile=True, timeout=300, summary=None):
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
    summary : dict or RunDocument, optional
        The run's document when the caller has read it already (``discovery.report``
        reads it through ``discovery.load`` and gives its typed result with it); default:
        ``run_dir/summary.json``.

    Returns
    -------
    Report

    The report's names are entered in the run's manifest before any of them is written,
    and the source and PDF are made in a staging directory and moved into place when
    done: a report interrupted (or out of space) leaves nothing that blocks the next one,
    and the staging directory of a killed report is removed by the next.
    """
    from discovery.outputs import atomic_write_text

    doc = run_document(_load(run_dir) if summary is None else summary)
    d = Path(run_dir)
    _draw_report_figures(doc, d)
    skipped = []
    text = render(doc, run_dir, snippet, skipped=skipped)
    name = "report.tex" if snippet is None else f"snippet-{snippet}.tex"
    names = [name] if snippet is not None or not compile else [name, "report.pdf", "report.log"]
    _check_ours(d, names)
    _record_in_manifest(d, names)  # claimed first: a killed report leaves vidi's names only
    clean_stale_staging(d)
    tex = d / name
    ctx_figs = re.findall(r"\\includegraphics(?:\[[^\]]*\])?\{([^}]+)\}", text)
    note = (
        f"; left out figure(s) {', '.join(skipped)}: links or not plain files (not read)"
        if skipped
        else ""
    )
    if snippet is not None or not compile:
        atomic_write_text(tex, text)
        return Report(tex, None, f"wrote {tex}{note}", doc.command, None, ctx_figs)
    w = _stage_dir(d)
    try:
        (w / name).write_text(text, encoding="utf-8")
        pdf, message = compile_tex(tex, ctx_figs, timeout=timeout, staged=w)
        os.replace(w / name, tex)
        if pdf is not None:
            dest = d / "report.pdf"
            os.replace(pdf, dest)
            pdf, message = dest, f"wrote {dest}"
    finally:
        shutil.rmtree(w, ignore_errors=True)
    _settle_manifest(d, names)
    return Report(
        tex,
        pdf,
        message + note,
        doc.command,
        _pages(pdf) if pdf is not None else None,
        ctx_figs,
    )
