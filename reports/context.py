"""What a report says, computed from a run's ``summary.json`` alone.

One function per run kind turns the summary into the template's context: tables (rows of
cells), the model as LaTeX, the figures the run wrote, and conclusions written from the
numbers (which terms the data support, what is inconsistent and where, what would separate
models the record cannot tell apart). Nothing here reads a result object: the report of a
run made last year reads the same as today's.
"""

from __future__ import annotations

import re
from pathlib import Path

from discovery.vibroimpact.verify.criteria import CRITERIA as _REGISTRY
from discovery.vibroimpact.verify.criteria import MOTION_DEFINITIONS, definition

from .lawtex import (
    law_equation,
    law_inline,
    law_of,
    prose,
    term_tex,
    ueda_equation,
    ueda_term_tex,
    unit_tex,
)
from .texenv import Tex, escape, num

__all__ = ["context", "KINDS", "criterion_names"]


def criterion_names(*mappings):
    """The criteria of the registry (its order, then the motion's: I5) found in any of
    ``mappings``; a name neither defines (an edited summary) is not shown."""
    return [
        k
        for k in (*_REGISTRY, *MOTION_DEFINITIONS)
        if any(isinstance(m, dict) and k in m for m in mappings)
    ]


def criterion_tex(name):
    """``$I_{2}$`` for the paper's criteria, the name in typewriter for any other."""
    name = str(name)
    if re.fullmatch(r"I\d", name):
        return Tex(f"$I_{{{name[1]}}}$")
    return Tex(r"\texttt{" + escape(name) + "}")


def criterion_definition(name):
    """The registry's formula and meaning of a criterion, as one table cell."""
    d = definition(name)
    formula = f"${d.latex}$: " if d.latex else ""
    return Tex(formula + escape(d.meaning or "--"))


FIGURE_CAPTIONS = {
    "verify": "Measured force (black) and the law's simulated force (red), folded on the "
    "drive phase over the record's span; with positions, the force-penetration loop and both "
    "penetrations over the contacts (what I5 compares).",
    "fit_impulse": "Measured impulse and the simulated steady states of the best models.",
    "fit_surface": Tex(
        r"The selected law over the ($\zeta$, $\dot\zeta_+$) plane with the contact samples."
    ),
    "fit_loop": "Loading and unloading branches, measured and modelled, for a few impacts.",
    "identification": "Identification: the path of the best law so far and the simulated "
    "force converging to the measured one.",
    "landscape": "Criteria over the two coefficients; the noise floor and the consistent "
    "region are marked.",
    "discover": "Recovered equation: strobe points, coefficients with error bars and the "
    "verification by simulation.",
    "attractor": "Stroboscopic points and a trajectory of the attractor.",
    "basins": "Basins of the coexisting attractors.",
    "chart": "Regime chart over the forcing frequency and amplitude.",
    "explain": "The missing effect: where the model disagrees before and after it is added.",
    "explain_loops": "The final model against the record: the force-penetration loop and both "
    "penetrations over the contacts (what I5 compares).",
    "recovery_noise": "Exact-support recovery against the force noise, per selection method "
    "and record length (Wilson 95 % intervals).",
    "recovery_map": "Recovery over force noise and record length, per selection method "
    "(recovered/runs in each cell).",
    "coverage": "Share of true coefficients inside their 95 % intervals (exact supports), "
    "against the nominal 95 %.",
    "inclusion": "How often each term was selected, per method and noise level.",
}


# the certificate's domain bounds by their symbols
_DOMAIN = {"zeta_max": Tex(r"$\zeta_{\max}$"), "zd_max": Tex(r"$\dot\zeta_{+,\max}$")}

# figures drawn a page tall at the text width (their text 7-8 pt when printed)
_TALL = ("explain", "discover", "landscape", "identification")


def _model_tex(value, where):
    """The equation of a law rebuilt from its text or coefficients (never read as LaTeX);
    ``--`` when the summary has none."""
    if value in (None, "", {}):
        return Tex("--")
    return law_equation(law_of(value, where))


def _provenance(s, run_dir):
    v = s.get("versions") or {}
    git = s.get("git") or {}
    rows = [
        ["command", Tex(r"\texttt{vidi " + escape(s.get("command", "?")) + "}")],
        ["created", s.get("created", "--")],
        ["vidi", v.get("vibroimpact-discovery", "--")],
        [
            "git commit",
            (git.get("commit") or "--")[:12]
            + (" (uncommitted changes)" if git.get("dirty") else ""),
        ],
        ["platform", s.get("platform", "--")],
        [
            "libraries",
            ", ".join(f"{k} {val}" for k, val in v.items() if k != "vibroimpact-discovery"),
        ],
    ]
    for name, inp in (s.get("inputs") or {}).items():
        if isinstance(inp, dict):
            rows.append(
                [
                    f"input {name}",
                    f"{inp.get('path', '')} (sha256 {str(inp.get('sha256', ''))[:16]}...)",
                ]
            )
    settings = s.get("settings") or {}
    shown = {
        k: val
        for k, val in settings.items()
        if k not in ("command", "func", "out", "ueda_command") and val not in (None, False)
    }
    rows.append(["settings", prose("; ".join(f"{k}={val}" for k, val in shown.items()) or "--")])
    return rows


def _scenario_rows(sc):
    if not sc:
        return []
    units = {
        "m1": "kg",
        "m2": "kg",
        "k1": "N/m",
        "c1": "N s/m",
        "A": "N",
        "frequency": "Hz",
        "g": "m/s^2",
        "k3": "N/m^3",
        "mass_loss": "per impact",
    }
    rows = [["name", sc.get("name", "--")]]
    for k, unit in units.items():
        if k in sc and not (k in ("k3", "mass_loss") and not sc[k]):
            rows.append([k, Tex(num(sc[k]) + r"\ " + unit_tex(unit))])
    if sc.get("law"):
        rows.append(["reference law", law_inline(law_of(sc["law"], "scenario.law"))])
    return rows


def _scenarios_table(scenarios):
    """Every scenario of a run side by side: one column per scenario."""
    scs = [sc for sc in scenarios if isinstance(sc, dict)]
    if not scs:
        return None
    per = [_scenario_rows(sc) for sc in scs]
    labels = [r[0] for r in per[0]]
    rows = []
    for i, label in enumerate(labels):
        rows.append([label, *(p[i][1] if i < len(p) and p[i][0] == label else "--" for p in per)])
    return rows


def _criteria_table(criteria, floor, limits=None):
    """Rows: criterion, value, noise floor, limit (when judged: ``--`` for a criterion the
    consistency rule does not judge), its formula and meaning (the criteria registry)."""
    rows = []
    for k in criterion_names(criteria):
        lim = (limits or {}).get(k)
        rows.append(
            [
                criterion_tex(k),
                num(criteria[k]),
                num((floor or {}).get(k)),
                num(lim) if lim is not None else Tex("--"),
                criterion_definition(k),
            ]
        )
    return rows


def _measured_rows(m, records=None):
    if not m:
        return []
    noise = m.get("noise")
    noise_f = noise.get("F") if isinstance(noise, dict) else noise
    rows = [
        ["drive periods per cycle", m.get("n_periods", "--")],
        ["cycles in the record", m.get("n_cycles", "--")],
        ["contacts per cycle", m.get("impacts", "--")],
        ["force noise (sd)", Tex(num(noise_f) + r"\,N")],
        ["peak force", Tex(num(m.get("peak")) + r"\,N")],
        ["contact time", Tex(num(m.get("contact_time")) + r"\,s")],
    ]
    if isinstance(noise, dict) and "dt" in noise:
        rows.insert(0, ["sampling step", Tex(num(noise["dt"]) + r"\,s")])
    return rows


def _figures(run_dir, order):
    figs = []
    for stem in order:
        for p in sorted(Path(run_dir).glob(f"{stem}*.pdf")):
            if p.stem in ("report", "model"):
                continue
            base = p.stem.split("_")[0] if p.stem not in FIGURE_CAPTIONS else p.stem
            figs.append(
                {
                    "file": p.name,
                    "caption": FIGURE_CAPTIONS.get(p.stem, FIGURE_CAPTIONS.get(base, p.stem)),
                    # a figure drawn a page tall (explain's four panels) is printed so
                    "height": Tex("0.75" if base in _TALL else "0.55"),
                }
            )
    seen, out = set(), []
    for f in figs:
        if f["file"] not in seen:
            seen.add(f["file"])
            out.append(f)
    return out


def _transient(verdict):
    return "transient" in (verdict or "")


def _intervals(entry):
    iv = entry.get("intervals") or {}
    return iv.get("bounds", iv) if isinstance(iv, dict) else {}


def _coef_rows(coefs, errors=None, intervals=None, start=None, term=term_tex):
    rows = []
    for k, v in coefs.items():
        lo_hi = (intervals or {}).get(k)
        rows.append(
            [
                term(k),
                num(v, 4),
                num((errors or {}).get(k), 2),
                Tex(f"[{num(lo_hi[0], 4)}, {num(lo_hi[1], 4)}]") if lo_hi else Tex("--"),
            ]
            + ([num((start or {}).get(k), 3)] if start is not None else [])
        )
    return rows


# ----------------------------------------------------------------------------- kinds
def _verify(s, run_dir):
    c = {
        "title": "Verification of a contact law against a record",
        "law": _model_tex(s.get("law"), "law"),
        "data": s.get("data"),
        "measured": _measured_rows(s.get("measured")),
        "criteria": _criteria_table(s.get("criteria"), s.get("noise_floor"), s.get("limits")),
        "verdict": prose(s.get("verdict") or s.get("message") or "--"),
        "consistent": bool(s.get("consistent")),
        "regime": s.get("regime") or {},
        "impacts": s.get("impacts") or {},
        "start": s.get("start") or {},
        "default_start": s.get("default_start"),
    }
    lim = s.get("limits") or {}
    crit = s.get("criteria") or {}
    concl = []
    if c["consistent"]:
        concl.append(
            f"The law is consistent with the record: every judged criterion is within "
            f"its limit (I2 {crit.get('I2', float('nan')):.3g} against "
            f"{lim.get('I2', float('nan')):.3g}), the limit being what the true law "
            "scores on records this noisy (twice the noise floor, or the floor plus "
            "three of its standard deviations, plus 0.005)."
        )
    else:
        over = [k for k in lim if crit.get(k, 0) > lim[k]]
        concl.append(
            "The law is inconsistent with the record"
            + (
                f": {', '.join(over)} exceed{'s' if len(over) == 1 else ''} the noise limit"
                if over
                else ""
            )
            + (
                ". The figure shows where the simulated force and penetration depart "
                "from the measured ones"
                if "I5" in over
                else ". The figure shows where the simulated force departs from the measured one"
            )
            + "; `vidi explain` names the effect most likely missing."
        )
    reg = c["regime"]
    if reg and reg.get("measured") != reg.get("simulated"):
        concl.append(
            f"The measured regime is {reg.get('measured')}, the simulated one "
            f"{reg.get('simulated')}."
        )
    if _transient(s.get("verdict")):
        concl.append(
            "The law's simulation from the measured state is not yet steady over the "
            "record's span: the record was compared with that trajectory, block by block, "
            "not with the law's steady orbit."
        )
    c["conclusions"] = [prose(x) for x in concl]
    c["figures"] = _figures(run_dir, ["verify"])
    return c


def _terms_tex(terms):
    """Term names as math, comma separated."""
    return Tex(", ".join(term_tex(t) for t in terms))


def _selected_conclusions(s):
    sel = s.get("selected") or {}
    concl = []
    terms = sel.get("terms") or list((sel.get("coefficients") or {}).keys())
    lib = (s.get("fit_settings") or {}).get("library", "?")
    n_rec = len(s.get("records") or []) or 1
    records = "the record" if n_rec == 1 else f"all {n_rec} records"
    if sel.get("consistent"):
        concl.append(
            Tex(
                f"From the library \\texttt{{{escape(lib)}}}, the data support the terms "
                f"{_terms_tex(terms)}: the selected law is consistent with {records} by "
                "full simulation."
            )
        )
    else:
        concl.append(
            Tex(
                f"From the library \\texttt{{{escape(lib)}}}, the best-supported terms are "
                f"{_terms_tex(terms)}, but no model of the library is consistent with "
                f"{records} by full simulation: the record holds an effect these "
                "polynomials do not describe (or the scenario is wrong). "
                "\\texttt{vidi explain} names the missing effect."
            )
        )
    eq = s.get("equivalent") or []
    if eq:
        concl.append(
            Tex(
                f"{len(eq)} other model(s) fit the record as well within its noise (listed "
                "under Selection). They cannot be told apart from this record; a second "
                "operating point (another drive amplitude or frequency) or lower noise "
                "would separate them."
            )
        )
    if s.get("warnings"):
        concl.append(Tex(f"The run gave {len(s['warnings'])} warning(s); see Notes from the run."))
    if sel.get("contact_defects"):
        concl.append(
            prose("The selected law has contact defects: " + "; ".join(sel["contact_defects"]))
        )
    return concl


def _record_checks(sel, records):
    """Each record's own check of the selected law: criteria, floors, limits, full verdict."""
    out = []
    for i, ev in enumerate(sel.get("records") or []):
        rec = records[i] if i < len(records) and isinstance(records[i], dict) else {}
        out.append(
            {
                "name": f"Record {i + 1}: {rec.get('data', '--')} (scenario "
                f"{rec.get('scenario', '--')})",
                "criteria": _criteria_table(
                    ev.get("criteria"), ev.get("noise_floor"), ev.get("limits")
                ),
                "verdict": prose(ev.get("verdict") or ev.get("message") or "--"),
            }
        )
    return out


def _fit(s, run_dir):
    sel = s.get("selected") or {}
    fs = s.get("fit_settings") or {}
    cert = s.get("certificate") or {}
    c = {
        "title": "Discovery of a contact law",
        "model": _model_tex(sel.get("coefficients"), "selected.coefficients"),
        "coefficients": _coef_rows(
            sel.get("coefficients") or {}, sel.get("standard_errors"), _intervals(sel)
        ),
        "interval_method": sel.get("interval_method") or "no bootstrap intervals",
        "criteria": _criteria_table(sel.get("criteria"), sel.get("noise_floor"), sel.get("limits")),
        "record_checks": _record_checks(sel, s.get("records") or []),
        "verdict": prose(sel.get("verdict") or "--"),
        "regime": sel.get("regime", "--"),
        "refinement": sel.get("refinement", "--"),
        "library": fs.get("library", "--"),
        "selection": fs.get("selection", "--"),
        "scoring": fs.get("scoring", "--"),
        "criterion": criterion_tex(fs.get("criterion", "I2")),
        "records": [
            [
                r.get("data", "--"),
                r.get("scenario", "--"),
                r.get("regime", "--"),
                r.get("impacts", "--"),
                num((r.get("noise") or {}).get("F")),
                (r.get("noise") or {}).get("n_cycles", "--"),
            ]
            for r in s.get("records") or []
        ],
        "certificate": {
            "method": cert.get("method", "--"),
            "holds": bool(cert.get("holds")),
            "worst": num(cert.get("worst_violation")),
            "domain": {
                _DOMAIN.get(k, k): num(v)
                for k, v in (cert.get("domain") or {}).items()
                if isinstance(v, int | float)
            },
            "conditions": [
                [
                    k.replace("_", " "),
                    v.get("quantity", ""),
                    "holds" if v.get("holds") else "FAILS",
                    num(v.get("grid_min_rel")),
                ]
                for k, v in (cert.get("conditions") or {}).items()
            ],
        },
        "ranking": [
            [
                str(i + 1),
                _terms_tex(m.get("terms") or []),
                m.get("regime", "--"),
                num(m.get("bic"), 6),
                num((m.get("criteria") or {}).get(fs.get("criterion", "I2"))),
                "yes" if m.get("consistent") else "no",
            ]
            for i, m in enumerate(s.get("ranking") or [])
        ],
        "equivalent": [
            {
                "model": _model_tex(e.get("law") or e.get("coefficients"), f"equivalent[{i}].law"),
                "reason": prose(e.get("reason", "")),
                "separate": prose(e.get("separate", "")),
            }
            for i, e in enumerate(s.get("equivalent") or [])
        ],
        "warnings": [prose(w) for w in s.get("warnings") or []],
        "scenarios": _scenarios_table(s.get("scenarios") or [s.get("scenario")]),
    }
    c["conclusions"] = _selected_conclusions(s)
    c["figures"] = _figures(run_dir, ["fit_impulse", "fit_surface", "fit_loop"])
    return c


def _identify(s, run_dir):
    c = {
        "title": "Identification of a contact law by simulation",
        "model": _model_tex(s.get("law") or s.get("coefficients"), "law"),
        "coefficients": _coef_rows(
            s.get("coefficients") or {},
            s.get("standard_errors"),
            _intervals(s),
            start=s.get("start") or {},
        ),
        "measured": _measured_rows(s.get("measured")),
        "criteria": _criteria_table(s.get("criteria"), s.get("noise_floor"), s.get("limits")),
        "verdict": prose(s.get("verdict") or "--"),
        "method": s.get("method", "--"),
        "criterion": criterion_tex(s.get("criterion", "I2")),
        "n_simulations": s.get("n_simulations", "--"),
        "message": prose(s.get("message", "")),
    }
    concl = [
        f"{s.get('method', '?')} spent {s.get('n_simulations', '?')} simulations; the "
        f"identified law is {'consistent' if s.get('consistent') else 'NOT consistent'} "
        "with the record."
    ]
    if not s.get("consistent"):
        concl.append(
            "An inconsistent result after identification means either a missing "
            "effect (run `vidi explain`) or a local minimum: start nearer (the "
            "coefficients of `vidi fit`), or look at the landscape."
        )
    c["conclusions"] = [prose(x) for x in concl]
    c["figures"] = _figures(run_dir, ["identification"])
    return c


def _landscape(s, run_dir):
    terms = s.get("terms") or ["?", "?"]
    mins = s.get("minima") or {}
    c = {
        "title": "Criteria landscape over two coefficients",
        "terms": [term_tex(t) for t in terms[:2]],
        "law": law_inline(law_of(s["law"], "law")) if s.get("law") else Tex("--"),
        "grid": "x".join(str(g) for g in s.get("grid") or []),
        "minima": [
            [
                criterion_tex(k),
                num(m.get("alpha1")),
                num(m.get("alpha2")),
                num(m.get("value")),
                m.get("regime", "--"),
                "yes" if m.get("consistent") else "no",
            ]
            for k, m in mins.items()
        ],
        "noise_floor": [
            [criterion_tex(k), num(v)] for k, v in (s.get("noise_floor") or {}).items()
        ],
        "n_consistent": s.get("n_consistent", 0),
        "regimes": ", ".join(f"{k}: {v}" for k, v in (s.get("regimes") or {}).items()),
        "reference": (s.get("reference") or {}).get("source", "--"),
    }
    n = s.get("n_consistent", 0)
    c["conclusions"] = [
        f"{n} grid point(s) are consistent with the reference within the noise limit"
        + (
            "; the consistent region's size is the coefficients' uncertainty from this record."
            if n
            else "; no pair of these coefficients explains the record on this grid."
        )
    ]
    c["figures"] = _figures(run_dir, ["landscape"])
    return c


def _effect_parameter_rows(fm, catalogue):
    """Rows of the added effects' own parameters (a machine parameter such as the contact
    offset, an observation's such as a sensor's lag), by the catalogue's names and units."""
    if not isinstance(catalogue, list):
        return []
    values = {**(fm.get("scenario") or {}), **(fm.get("observation") or {})}
    rows = []
    for e in catalogue:
        if not isinstance(e, dict) or e.get("id") not in (fm.get("effects") or []):
            continue
        key, params = e.get("key"), e.get("parameters") or []
        if key not in values or not params or not isinstance(params[0], dict):
            continue
        name, unit = str(params[0].get("name")), str(params[0].get("unit", ""))
        rows += _coef_rows(
            {name: values[key]},
            fm.get("uncertainties"),
            _intervals(fm),
            term=lambda n, u=unit: Tex(r"\texttt{" + escape(n) + "} [" + escape(u) + "]"),
        )
    return rows


def _explain(s, run_dir):
    fm = s.get("final_model") or {}
    its = s.get("iterations") or []
    c = {
        "title": "The missing physical effect",
        "model": _model_tex(fm.get("text") or fm.get("coefficients"), "final_model.text"),
        "coefficients": _coef_rows(
            fm.get("coefficients") or {}, fm.get("uncertainties"), _intervals(fm)
        )
        + [
            [Tex("unloading " + term_tex(k, unloading=True)), num(v, 4), Tex("--"), Tex("--")]
            for k, v in (fm.get("unloading") or {}).items()
        ]
        + _effect_parameter_rows(fm, s.get("catalogue")),
        "effects": [str(e).replace("_", " ") for e in fm.get("effects") or []],
        "criteria": _criteria_table(s.get("criteria"), s.get("noise_floor"), s.get("limits")),
        "stopped": prose(s.get("stopped_because", "--")),
        "iterations": [
            [
                str(k + 1),
                str(it.get("effect") or "nothing named").replace("_", " "),
                num((it.get("criteria_before") or {}).get("I2")),
                num((it.get("criteria_after") or {}).get("I2")),
                num((it.get("noise_floor") or {}).get("I2")),
                prose(it.get("evidence", "")),
            ]
            for k, it in enumerate(its)
        ],
        "separability": [
            [
                r.get("effect", "--"),
                num(r.get("before")),
                num(r.get("after")),
                num(r.get("floor")),
                "yes" if r.get("separable") else "no",
            ]
            for r in s.get("separability") or []
        ],
    }
    named_its = [it for it in its if it.get("effect")]
    if named_its:
        named = ", ".join(str(it["effect"]).replace("_", " ") for it in named_its)
        state = "consistent" if s.get("consistent") else "still NOT consistent"
        concl = [
            f"Named and added: {named}. The gap to the record shrank as the table shows; "
            f"the final model is {state} with the record."
        ]
    else:
        concl = [
            "No effect was added: "
            + str(s.get("stopped_because", "the start model already agrees with the record"))
        ]
    c["conclusions"] = [prose(x) for x in concl]
    c["figures"] = _figures(run_dir, ["explain", "localise", "screen", "drift"])
    return c


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


def _frac(k, n, ci=None):
    """``k/n (lo--hi)``, or -- without cases."""
    if not n:
        return Tex("--")
    out = escape(f"{k}/{n}")
    if ci and ci[0] == ci[0]:
        out += f" ({ci[0]:.2f}--{ci[1]:.2f})"
    return Tex(out)


def _study(s, run_dir):
    d = s.get("design") or {}
    varied = list(d.get("varied") or {})
    pooled = s.get("pooled") or {}
    cells = s.get("cells") or []
    c = {
        "title": "Model-term selection study" + (f": {s['name']}" if s.get("name") else ""),
        "design": [
            [Tex(r"\texttt{" + escape(k) + "}"), prose(", ".join(map(str, v)))]
            for k, v in (d.get("varied") or {}).items()
        ]
        + [
            [Tex(r"\texttt{" + escape(k) + "}"), prose(f"{v} (fixed)")]
            for k, v in (d.get("fixed") or {}).items()
        ]
        + [
            ["fit options", "; ".join(f"{k}={v}" for k, v in (d.get("fit") or {}).items()) or "--"],
            [
                "record options",
                "; ".join(f"{k}={v}" for k, v in (d.get("record") or {}).items()) or "--",
            ],
            ["seeds", ", ".join(map(str, d.get("seeds") or []))],
            [
                "runs",
                f"{s.get('complete', 0)} of {s.get('runs', 0)} done ({d.get('cells', '?')} cells)",
            ],
        ],
        "varied": varied,
        "pooled": [
            [
                m,
                _frac(p["recovered"], p["runs"], p.get("recovery_ci")),
                f"{p['equivalent']}/{p['runs']}",
                num(p.get("fp_per_run"), 2),
                _frac(p["covered"], p["intervals"], p.get("coverage_ci")),
                p.get("failed", 0),
            ]
            for m, p in pooled.items()
        ],
        "cells": [
            [
                *(prose(str(row.get(f, ""))) for f in varied),
                _frac(
                    row["recovered"],
                    row["runs"],
                    (row.get("recovery_low"), row.get("recovery_high")),
                ),
                num(row.get("fp_per_run"), 2),
                _frac(row.get("covered", 0), row.get("intervals", 0)),
                num(row.get("coef_error_median"), 2),
            ]
            for row in cells
        ],
    }
    concl = []
    if pooled:
        rate = {m: p["recovered"] / max(p["runs"], 1) for m, p in pooled.items()}
        top = [m for m in pooled if rate[m] == max(rate.values())]
        p = pooled[top[0]]
        concl.append(
            f"Across the study, {' and '.join(top)} recovered the exact true support "
            f"most often: {p['recovered']} of {p['runs']} runs"
            + (" each." if len(top) > 1 else ".")
        )
        for m, p in pooled.items():
            if p["intervals"]:
                share = p["covered"] / p["intervals"]
                lo, hi = p["coverage_ci"]
                verdict = (
                    "consistent with the nominal 95 %"
                    if lo <= 0.95 <= hi
                    else "below the nominal 95 %: the intervals are too narrow"
                    if hi < 0.95
                    else "above the nominal 95 %"
                )
                concl.append(
                    f"{m}: the 95 % intervals held the truth in {share:.0%} of "
                    f"{p['intervals']} cases ({lo:.2f}--{hi:.2f}), {verdict}."
                )
    if pooled and not any(p.get("intervals") for p in pooled.values()):
        concl.append(
            "No run has coefficient intervals (they come from the refinement by "
            "simulation: set refine = [true]), so there is no coverage chart."
        )
    concl.append(
        "Records were made by the independent scipy path from rest; no selection "
        "used the truth (no oracle settings)."
    )
    c["conclusions"] = concl
    c["figures"] = _figures(run_dir, ["recovery_noise", "recovery_map", "coverage", "inclusion"])
    return c


KINDS = {
    "verify": _verify,
    "fit": _fit,
    "identify": _identify,
    "landscape": _landscape,
    "explain": _explain,
    "ueda attractor": _ueda,
    "ueda chart": _ueda,
    "ueda discover": _ueda,
    "ueda explain": _ueda,
    "study": _study,
}
TEMPLATES = {
    "verify": "verify",
    "fit": "fit",
    "identify": "identify",
    "landscape": "landscape",
    "explain": "explain",
    "study": "study",
}


def context(summary, run_dir):
    """The template context of a run: the kind's own part plus provenance and scenario."""
    kind = summary.get("command")
    build = KINDS.get(kind)
    named = kind == "fit" and summary.get("library") == "contact-models"
    if named:
        from .contact_models import contact_models_context  # the named models' fit

        build = contact_models_context
    if build is None:
        from discovery.errors import InputError

        raise InputError(f"no report for a {kind!r} run; reports cover {', '.join(KINDS)} runs")
    c = build(summary, run_dir)
    c["kind"] = kind
    c["template"] = ("contact_models" if named else TEMPLATES.get(kind, "ueda")) + ".tex.j2"
    c["provenance"] = _provenance(summary, run_dir)
    c["scenario"] = _scenario_rows(summary.get("scenario"))
    c["data"] = summary.get("data") or (summary.get("settings") or {}).get("data")
    c["seconds"] = summary.get("seconds")
    return c
