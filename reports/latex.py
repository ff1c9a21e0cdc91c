"""LaTeX documents as pure functions of results, and their compilation to PDF."""

import shutil
import subprocess
from pathlib import Path

__all__ = ["model_tex", "compile_pdf"]


_SPECIAL = {"\\": r"\textbackslash{}", "_": r"\_", "%": r"\%", "&": r"\&", "#": r"\#",
            "$": r"\$", "{": r"\{", "}": r"\}", "^": r"\textasciicircum{}",
            "~": r"\textasciitilde{}", "<": r"$<$", ">": r"$>$"}


def _esc(text):
    """Text safe for LaTeX (special characters escaped)."""
    return "".join(_SPECIAL.get(ch, ch) for ch in str(text))


def _math(v, digits=4):
    """A number as LaTeX math (no dollars)."""
    mant, _, exp = f"{v:.{digits - 1}e}".partition("e")
    return mant if int(exp) == 0 else rf"{mant}\cdot 10^{{{int(exp)}}}"


def _num(v, digits=4):
    """A number for text or tables (in dollars; '--' when missing)."""
    if v is None or v != v:
        return "--"
    return f"${_math(v, digits)}$"


def _law_tex(entry):
    """LaTeX of an ``equivalent`` entry's law."""
    from discovery.law import ForceLaw, Term

    d = entry["coefficients"]
    return ForceLaw(tuple(Term.parse(k) for k in d), tuple(d.values())).latex()


def model_tex(result, scenario):
    """A standalone LaTeX document describing a discovered law.

    Parameters
    ----------
    result : DiscoveryResult
    scenario : Scenario

    Returns
    -------
    str
    """
    sel = result.selected
    cert = result.certificate
    se = sel.standard_errors
    rows = "\n".join(rf"  \texttt{{{_esc(k)}}} & {_num(v)} & {_num(se.get(k))} \\"
                     for k, v in sel.law.as_dict().items())
    floor = sel.noise_floor
    floors = " & ".join(_num(floor.get(k), 2) for k in ("I0", "I1", "I2", "I3", "I4"))
    warn = "".join(rf"\item {_esc(w)}" + "\n" for w in result.warnings)
    warn = (r"\paragraph{Warnings.}" + "\n" + r"\begin{itemize}" + "\n" + warn
            + r"\end{itemize}" + "\n") if warn else ""
    equiv = "".join(rf"\item ${e_law}$: {_esc(e['reason'])}; {_esc(e['separate'])}" + "\n"
                    for e, e_law in ((e, _law_tex(e)) for e in result.equivalent))
    equiv = (r"\paragraph{Models the record cannot tell apart}" + " (consistent, within the "
             "noise of the selected one):\n" + r"\begin{itemize}" + "\n" + equiv
             + r"\end{itemize}" + "\n") if equiv else ""
    nrec = len(result.references) or 1
    crit = " & ".join(_num(sel.criteria.get(k)) for k in ("I0", "I1", "I2", "I3", "I4"))
    ranking = "\n".join(
        rf"  {i + 1} & \texttt{{{_esc(', '.join(m.law.names))}}} & {m.regime} & "
        rf"{_num(m.candidate.bic, 6)} & {_num(m.candidate.cv_error, 3)} & "
        rf"{_num(m.criteria.get(result.settings['criterion']), 3)} \\"
        for i, m in enumerate(result.ranking))
    dom = cert.domain
    return rf"""\documentclass[11pt]{{article}}
\usepackage{{amsmath,booktabs}}
\usepackage[margin=2.5cm]{{geometry}}
\begin{{document}}
\section*{{Discovered contact law: scenario \texttt{{{_esc(scenario.name)}}}}}
For $\zeta>0$, with $\dot\zeta_+=\max(\dot\zeta,0)$ (and $F=0$ for $\zeta\le 0$):
\begin{{equation}}
F(\zeta,\dot\zeta) = \max\Bigl(0,\; {sel.law.latex()}\Bigr)
\end{{equation}}
\begin{{center}}
\begin{{tabular}}{{lrr}}
\toprule
term & coefficient (SI) & standard error \\
\midrule
{rows}
\bottomrule
\end{{tabular}}
\end{{center}}
\paragraph{{Certificate.}} {_esc(cert.method)} on $\zeta\in[0,{_math(dom['zeta_max'])}]$ m,
$\dot\zeta_+\in[0,{_math(dom['zd_max'])}]$ m/s:
conditions {'hold' if cert.holds else 'DO NOT hold'}, worst relative violation
{_num(cert.worst_violation)}.

Standard errors from the output-error Jacobian at the refined coefficients
(residual variance estimated from the fit{'' if se else '; not computed: no refinement'}).

\paragraph{{Simulation check.}} Steady state {sel.regime}; criteria against the
measured impulse ({'mean over ' + str(nrec) + ' records' if nrec > 1 else 'one record'}),
with the noise floor (what the true law would score on records this noisy):
\begin{{center}}
\begin{{tabular}}{{lccccc}}
\toprule
 & $I_0$ & $I_1$ & $I_2$ & $I_3$ & $I_4$ \\
\midrule
criteria & {crit} \\
noise floor & {floors} \\
\bottomrule
\end{{tabular}}
\end{{center}}
Verdict: {_esc(sel.verdict)}.

{warn}{equiv}
\paragraph{{Ranking}} (selection \texttt{{{_esc(result.settings['selection'])}}},
library \texttt{{{_esc(result.settings['library'])}}}):
\begin{{center}}
\begin{{tabular}}{{rlllll}}
\toprule
\# & terms & regime & BIC & CV error & {_esc(result.settings['criterion'])} \\
\midrule
{ranking}
\bottomrule
\end{{tabular}}
\end{{center}}
\end{{document}}
"""


def compile_pdf(tex_path, timeout=180):
    """Compile a standalone LaTeX file beside itself with latexmk (pdflatex).

    Returns ``(pdf_path, None)`` on success, ``(None, reason)`` when TeX Live is not
    installed or the compilation fails (the ``.tex`` file is kept either way).  Auxiliary
    files are removed.
    """
    tex = Path(tex_path)
    if shutil.which("latexmk") is None:
        return None, ("no PDF: latexmk not found (install TeX Live: apt-get install latexmk "
                      "texlive-latex-recommended texlive-latex-extra)")
    cmd = ["latexmk", "-pdf", "-interaction=nonstopmode", "-halt-on-error", "-quiet", tex.name]
    try:
        run = subprocess.run(cmd, cwd=tex.parent, capture_output=True, text=True,
                             timeout=timeout)
    except subprocess.TimeoutExpired:
        _clean(tex)
        return None, f"no PDF: latexmk took more than {timeout} s"
    reason = None
    pdf = tex.with_suffix(".pdf")
    if run.returncode != 0 or not pdf.exists():
        log = tex.with_suffix(".log")
        text = log.read_text(errors="replace") if log.exists() else run.stdout
        first = [ln for ln in text.splitlines() if ln.startswith("!")][:1]
        reason = "no PDF: LaTeX failed" + (f" ({first[0][1:].strip()})" if first else "")
    _clean(tex)
    return (None, reason) if reason else (pdf, None)


def _clean(tex):
    """Remove latexmk's auxiliary files (and a failed run's partial PDF)."""
    subprocess.run(["latexmk", "-C" if not tex.with_suffix(".pdf").exists() else "-c",
                    tex.name], cwd=tex.parent, capture_output=True, timeout=60)
