"""What the reports of Ueda's commands (attractor, chart, discover, explain) say."""

from __future__ import annotations

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


def _ueda(s, run_dir):
    cmd = s.get("command", "ueda")
    c = {"title": f"Ueda's forced oscillator: {cmd.replace('ueda ', '')}"}
    rows = []
    for key in ("model", "regime", "terms", "forcing", "residual_rms", "n_windows"):
        if key in s:
            val = s[key]
            rows.append(
                [
                    key.replace("_", " "),
                    prose(", ".join(map(str, val)))
                    if isinstance(val, list)
                    else (
                        prose("; ".join(f"{k}={v}" for k, v in val.items()))
                        if isinstance(val, dict)
                        else (num(val) if isinstance(val, float) else prose(val))
                    ),
                ]
            )
    c["facts"] = rows
    coefs = s.get("coefficients") or (s.get("final_model") or {}).get("coefficients")
    c["model"] = ueda_equation(coefs) if coefs else Tex("--")
    c["coefficients"] = _coef_rows(
        s.get("coefficients") or {}, s.get("standard_errors"), term=ueda_term_tex
    )
    ver = s.get("verification") or {}
    c["verification"] = [
        [k.replace("_", " "), num(v) if isinstance(v, int | float) else v]
        for k, v in ver.items()
        if isinstance(v, int | float | str) and not isinstance(v, bool)
    ]
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
    fr = s.get("fractions")
    if isinstance(fr, dict):
        grid = "x".join(str(g) for g in s.get("grid") or [])
        share = ", ".join(f"{k} {100 * v:.0f} %" for k, v in fr.items() if v)
        periods = ", ".join(f"{k} ({v} points)" for k, v in (s.get("periods_found") or {}).items())
        concl.append(
            f"Over nu in {s.get('nu_range')} and B in {s.get('B_range')} on a {grid} "
            f"grid the regimes are: {share}." + (f" Periods found: {periods}." if periods else "")
        )
    if "effects_added" in s:
        gaps = "; ".join(
            f"{k.replace('_', ' ')} {v['before']:.3g} -> {v['after']:.3g} ({v['ratio']:.0f}x)"
            for k, v in (s.get("gap") or {}).items()
            if isinstance(v, dict)
        )
        added = ", ".join(str(e).replace("_", " ") for e in s["effects_added"]) or "none"
        concl.append(
            f"Effects named and added: {added}; the gap: {gaps}. The final model is "
            f"{'consistent' if s.get('consistent') else 'NOT consistent'} with the "
            f"record. Stopped because {s.get('stopped_because', '--')}."
        )
        final = s.get("final_model") or {}
        if final.get("coefficients"):
            c["coefficients"] = _coef_rows(
                final["coefficients"], final.get("standard_errors"), term=ueda_term_tex
            )
    if "lyapunov" in s and isinstance(s["lyapunov"], dict):
        L = s["lyapunov"]
        concl.append(
            f"Largest Lyapunov exponent {L.get('value', float('nan')):.4g} per unit "
            "time: " + ("chaotic." if L.get("value", 0) > 0.01 else "not chaotic.")
        )
    c["conclusions"] = [prose(x) for x in concl] or ["See the tables and figures."]
    c["figures"] = _figures(run_dir, ["discover", "explain", "attractor", "basins", "chart"])
    return c
