"""LaTeX documents as pure functions of results."""

__all__ = ["model_tex"]


_SPECIAL = {"\\": r"\textbackslash{}", "_": r"\_", "%": r"\%", "&": r"\&", "#": r"\#",
            "$": r"\$", "{": r"\{", "}": r"\}", "^": r"\textasciicircum{}",
            "~": r"\textasciitilde{}"}


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
    rows = "\n".join(rf"  \texttt{{{_esc(k)}}} & {_num(v)} \\" for k, v in
                     sel.law.as_dict().items())
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
\begin{{tabular}}{{lr}}
\toprule
term & coefficient (SI) \\
\midrule
{rows}
\bottomrule
\end{{tabular}}
\end{{center}}
\paragraph{{Certificate.}} {_esc(cert.method)} on $\zeta\in[0,{_math(dom['zeta_max'])}]$ m,
$\dot\zeta_+\in[0,{_math(dom['zd_max'])}]$ m/s:
conditions {'hold' if cert.holds else 'DO NOT hold'}, worst relative violation
{_num(cert.worst_violation)}.

\paragraph{{Simulation check.}} Steady state {sel.regime};
criteria against the measured impulse:
\begin{{center}}
\begin{{tabular}}{{ccccc}}
\toprule
$I_0$ & $I_1$ & $I_2$ & $I_3$ & $I_4$ \\
\midrule
{crit} \\
\bottomrule
\end{{tabular}}
\end{{center}}

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
