"""What the reports of Ueda's commands (attractor, chart, discover, explain) say.

One function per command reads its run's typed result (``doc.result``: an
:class:`~discovery.ueda.Attractor`, a :class:`~discovery.ueda.regime_chart.Chart`, a
:class:`~discovery.ueda.equation_discovery.Discovery` or an
:class:`~discovery.ueda.explanation.Explanation`) and, for what the command line adds (the
forcing as given, the discovered equation's verification), its summary.
"""

from __future__ import annotations

from discovery.errors import InputError

from ..cells import (
    _coef_rows,
    _figures,
)
from ..lawtex import (
    prose,
    ueda_equation,
    ueda_term_tex,
)
from ..texenv import Tex, num

#: the figures of a Ueda report, in this order (whichever the run wrote)
_FIGURES = ["discover", "explain", "attractor", "basins", "chart"]


def _fact(name, value):
    """A row of the facts table: a sequence joined by commas, a mapping as ``k=v`` pairs,
    a float as a number, anything else as text."""
    if isinstance(value, list | tuple):
        cell = prose(", ".join(map(str, value)))
    elif isinstance(value, dict):
        cell = prose("; ".join(f"{k}={v}" for k, v in value.items()))
    else:
        cell = num(value) if isinstance(value, float) else prose(value)
    return [name.replace("_", " "), cell]


def _forcing(doc):
    """The facts row of the forcing as the command line gave it (none when saved from
    Python)."""
    forcing = doc.summary.get("forcing")
    return [] if forcing is None else [_fact("forcing", forcing)]


def _page(doc, run_dir, facts, conclusions, *, coefficients=None, standard_errors=None):
    """The context of a Ueda report: its title, the facts rows, the equation and
    coefficients table of ``coefficients`` (``{term: value}``, none: no equation), the
    conclusions and the figures."""
    return {
        "title": f"Ueda's forced oscillator: {doc.command.replace('ueda ', '')}",
        "facts": facts,
        "model": ueda_equation(coefficients) if coefficients else Tex("--"),
        "coefficients": _coef_rows(coefficients or {}, standard_errors, term=ueda_term_tex),
        "verification": [],
        "conclusions": [prose(x) for x in conclusions] or ["See the tables and figures."],
        "figures": _figures(run_dir, _FIGURES),
    }


def _ueda_attractor(doc, run_dir):
    r = doc.result
    L = r.lyapunov
    concl = [
        f"Largest Lyapunov exponent {L.value:.4g} per unit time: "
        + ("chaotic." if L.value > 0.01 else "not chaotic.")
    ]
    s, L = r.system, r.lyapunov
    facts = [
        _fact("model", s.model),
        _fact("parameters", {k: f"{getattr(s, k):g}" for k in ("mu", "gamma", "k", "B", "nu")}),
        _fact("regime", r.regime.regime),
        _fact("largest Lyapunov exponent", f"{L.value:.4g} (standard error {L.stderr:.2g})"),
        _fact("second exponent", f"{L.second:.4g}"),
    ]
    return _page(doc, run_dir, facts, concl)


def _ueda_chart(doc, run_dir):
    r = doc.result
    grid = f"{r.nu.size}x{r.B.size}"
    nu_range, B_range = [float(r.nu[0]), float(r.nu[-1])], [float(r.B[0]), float(r.B[-1])]
    share = ", ".join(f"{k} {100 * v:.0f} %" for k, v in r.fractions().items() if v)
    periods = ", ".join(f"P{n} ({c} points)" for n, c in r.period_counts().items())
    concl = [
        f"Over nu in {nu_range} and B in {B_range} on a {grid} "
        f"grid the regimes are: {share}." + (f" Periods found: {periods}." if periods else "")
    ]
    return _page(doc, run_dir, [], concl)


def _ueda_discover(doc, run_dir):
    r = doc.result
    facts = [_fact("terms", r.terms), *_forcing(doc)]
    facts += [_fact("residual_rms", r.residual_rms), _fact("n_windows", r.n_windows)]
    # the verification by simulation is the command line's (not part of the discovery)
    ver = doc.summary.get("verification") or {}
    concl = []
    if ver:
        state = "consistent" if ver.get("consistent") else "NOT consistent"
        concl.append(
            f"Verification by simulation: {state}"
            f" (energy distance {ver.get('energy_distance', float('nan')):.3g} against "
            f"the record's own floor {ver.get('floor_q95', float('nan')):.3g}; regime of "
            f"the record {ver.get('regime_record', '?')}, of the model "
            f"{ver.get('regime_model', '?')})."
        )
    c = _page(
        doc, run_dir, facts, concl, coefficients=r.coefficients, standard_errors=r.standard_errors
    )
    c["verification"] = [
        [k.replace("_", " "), num(v) if isinstance(v, int | float) else v]
        for k, v in ver.items()
        if isinstance(v, int | float | str) and not isinstance(v, bool)
    ]
    return c


def _ueda_explain(doc, run_dir):
    r = doc.result
    gaps = "; ".join(
        f"{k.replace('_', ' ')} {v['before']:.3g} -> {v['after']:.3g} ({v['ratio']:.0f}x)"
        for k, v in r.gap.items()
    )
    added = ", ".join(_effect_title(e) for e in r.effects_added) or "none"
    stopped = "--" if r.stopped_because is None else r.stopped_because
    verdict = (
        ""  # the reason it stopped says so
        if "consistent" in stopped
        else f" The final model is {'consistent' if r.consistent else 'NOT consistent'} "
        "with the record."
    )
    concl = [
        f"Effects named and added: {added}; the gap: {gaps}.{verdict} Stopped because {stopped}."
    ]
    return _page(
        doc,
        run_dir,
        _forcing(doc),
        concl,
        coefficients=r.coefficients,
        standard_errors=r.standard_errors,
    )


def _effect_title(effect_id):
    """A catalogue effect's title (``Amplitude-dependent (van der Pol) damping``), or its
    id in words when the catalogue no longer has it (a run saved by another version)."""
    from discovery.ueda.effects import effect  # the catalogue loads the compiled kernel

    try:
        return effect(str(effect_id)).title
    except InputError:
        return str(effect_id).replace("_", " ")
