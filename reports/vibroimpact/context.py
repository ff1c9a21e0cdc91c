"""What the reports of the vibro-impact commands (verify, fit, identify, landscape,
explain) say: each turns its run's document into the template's context, with conclusions
written from the numbers."""

from __future__ import annotations

import math
import re

from discovery.wording import records as the_records
from discovery.wording import verb

from ..cells import (
    _DOMAIN,
    _coef_rows,
    _criteria_table,
    _figures,
    _measured_rows,
    _model_tex,
    _scenarios_table,
    _transient,
    criterion_tex,
)
from ..lawtex import (
    law_inline,
    law_of,
    prose,
    term_tex,
    verdict_tex,
)
from ..rules import rule_text
from ..texenv import Tex, escape, num, scientific


# ----------------------------------------------------------------------------- kinds
def _verify(doc, run_dir):
    r = doc.result
    ev = r.evaluation
    c = {
        "title": "Verification of a contact law against a record",
        "law": _model_tex(r.law, "law"),
        # the record's measured block and the start are the run's (not kept by a loaded result)
        "measured": _measured_rows(doc.summary.get("measured")),
        "criteria": _criteria_table(ev.criteria, ev.noise_floor, ev.limits),
        "verdict": verdict_tex(ev.verdict or ev.message or "--"),
        "consistent": bool(ev.consistent),
        "regime": ev.regime or {},
        "impacts": ev.impacts or {},
        "start": doc.summary.get("start") or {},
        "default_start": r.default_start,
    }
    lim = ev.limits or {}
    crit = ev.criteria or {}
    concl = []
    nothing = _nothing_compared(ev)
    c["nothing_compared"] = nothing and prose(nothing)
    if nothing:
        concl.append(f"The law is inconsistent with the record: {nothing}.")
    elif c["consistent"]:
        concl.append(
            f"The law is consistent with the record: every judged criterion is within "
            f"its limit (I2 {crit.get('I2', float('nan')):.3g} against "
            f"{lim.get('I2', float('nan')):.3g}), the limit being what the true law "
            f"scores on records this noisy ({rule_text()})."
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
    if reg.get("simulated") and reg.get("measured") != reg.get("simulated"):
        concl.append(
            f"The measured regime is {reg.get('measured')}, the simulated one "
            f"{reg.get('simulated')}."
        )
    if not nothing and _transient(ev.verdict):
        concl.append(
            "The law's simulation from the measured state is not yet steady over the "
            "record's span: the record was compared with that trajectory, block by block, "
            "not with the law's steady orbit."
        )
    c["conclusions"] = [prose(x) for x in concl]
    c["figures"] = _figures(run_dir, ["verify"])
    if nothing:  # the figure shows the measured force alone
        for f in c["figures"]:
            f["caption"] = prose(f"The measured force alone: {nothing}.")
    return c


def _nothing_compared(ev):
    """Why a verification has no criteria (its simulation failed, has no periodic steady
    state, or never touches), as a clause; ``""`` when it was compared."""
    if ev.criteria:
        return ""
    if ev.status == "failed":
        return (
            f"the law's simulation failed ({ev.message or 'no message'}), so there is no simulated "
            "force to compare with the measured one"
        )
    if ev.status == "nonperiodic":
        return (
            "the law has no stable periodic steady state, so there is no simulated orbit to "
            "compare with the measured cycle"
        )
    if ev.status == "no-contact":
        return "the simulated bodies never come into contact, so there is no force to compare"
    return "no criteria were computed"


def _terms_tex(terms):
    """Term names as math, comma separated."""
    return Tex(", ".join(term_tex(t) for t in terms))


def _selected_conclusions(r):
    """What the data support (the selected terms, consistent or not), the equivalent
    models, the warnings and the selected law's contact defects, from a
    :class:`~discovery.DiscoveryResult`."""
    sel = r.selected
    concl = []
    lib = r.settings.get("library", "?")
    n_rec = len(r.records) or 1
    records = the_records(n_rec, every=True)
    if sel.consistent:
        concl.append(
            Tex(
                f"From the library \\texttt{{{escape(lib)}}}, the data support the terms "
                f"{_terms_tex(sel.law.names)}: the selected law is consistent with {records} "
                "by full simulation."
            )
        )
    else:
        concl.append(
            Tex(
                f"From the library \\texttt{{{escape(lib)}}}, the best-supported terms are "
                f"{_terms_tex(sel.law.names)}, but no model of the library is consistent with "
                f"{records} by full simulation: {the_records(n_rec)} "
                f"{verb(n_rec, 'holds', 'hold')} an effect these "
                "polynomials do not describe (or the scenario is wrong). "
                "\\texttt{vidi explain} names the missing effect."
            )
        )
    if r.equivalent:
        concl.append(
            Tex(
                f"{len(r.equivalent)} other model(s) fit {the_records(n_rec)} as well within "
                f"{verb(n_rec, 'its', 'their')} noise (listed under Selection). They cannot "
                f"be told apart from {verb(n_rec, 'this record', 'these records')}; another "
                "operating point (another drive amplitude or frequency) or lower noise "
                "would separate them."
            )
        )
    if r.warnings:
        concl.append(Tex(f"The run gave {len(r.warnings)} warning(s); see Notes from the run."))
    if sel.defects:
        concl.append(prose("The selected law has contact defects: " + "; ".join(sel.defects)))
    return concl


def _record_checks(sel, records):
    """Each record's own check of the selected law (a model checked against several
    records): criteria, floors, limits, full verdict."""
    if len(sel.evaluations) < 2:
        return []
    out = []
    for i, ev in enumerate(sel.evaluations):
        rec = records[i] if i < len(records) else None
        out.append(
            {
                "name": f"Record {i + 1}: {rec.data if rec else '--'} (scenario "
                f"{rec.scenario if rec else '--'})",
                "criteria": _criteria_table(ev.criteria, ev.noise_floor, ev.limits),
                "verdict": verdict_tex(ev.verdict or ev.message or "--"),
            }
        )
    return out


def _condition_tex(name, margin=0.0):
    """A certified condition's name and its requirement as math (the quantity the
    certificate bounds below, in the report's symbols); an unknown one's name as text."""
    p, p0, zd = r"P(\zeta,\dot\zeta_{+})", r"P(\zeta,0)", r"\dot\zeta_{+}"
    rhs = "0" if not margin else rf"m\,{zd}"
    known = {
        "non_adhesion": ("non-adhesion", rf"${p} \ge 0$"),
        "dissipativity": ("dissipativity", rf"${p} - {p0} \ge {rhs}$"),
        "monotone_elastic": ("monotone elastic part", r"$\zeta\,\partial_\zeta P(\zeta,0) \ge 0$"),
    }
    label, req = known.get(name, (str(name).replace("_", " "), None))
    if req is not None and margin and name == "dissipativity":
        req += r", $m = " + num(margin).strip("$") + r"\,\mathrm{N\,s/m}$"
    return label, Tex(req) if req is not None else Tex("--")


def _method_text(method):
    """The certificate's method in words (``bernstein(elevation=2)+grid(1001x1001)``: a
    Bernstein bound after degree elevation 2 and a 1001 x 1001 grid); as given otherwise."""
    m = re.fullmatch(r"bernstein\(elevation=(\d+)\)\+grid\((\d+)x(\d+)\)", str(method))
    if m is None:
        return str(method)
    return f"Bernstein bounds (degree elevation {m[1]}) and the minimum over a {m[2]} x {m[3]} grid"


def _certificate(cert, margin=0.0):
    """The certificate's cells (``--`` and "fails" without one): each condition's
    requirement as math."""
    if cert is None:
        return {"method": "--", "holds": False, "worst": num(None), "domain": {}, "conditions": []}
    rows = []
    for k, v in cert.conditions.items():
        label, req = _condition_tex(k, margin)
        rows.append(
            [label, req, "holds" if v.get("holds") else "FAILS", num(v.get("grid_min_rel"))]
        )
    return {
        "method": _method_text(cert.method),
        "holds": bool(cert.holds),
        "worst": num(cert.worst_violation),
        "domain": {
            _DOMAIN.get(k, k): num(v)
            for k, v in cert.domain.items()
            if isinstance(v, int | float) and not math.isnan(v)
        },
        "conditions": rows,
    }


_REFINED = re.compile(
    r"refined by simulation from the (?P<origin>.+) \((?P<n>\d+) simulations, "
    r"(?P<crit>I\d) (?P<value>[-+.\de]+)\)"
)


def _refinement_tex(sel, crit):
    """The refinement's note with its criterion beside the check's: the search scores a law
    with the force averaged over the sample that holds each contact onset (continuous in
    the coefficients), the check by full simulation (the ranking's and the criteria table's
    value) with point samples, so the two can differ for the same law; one value where
    they print alike."""
    note = sel.note or ""
    m = _REFINED.fullmatch(note)
    if m is None:
        return prose(note) if note else Tex("--")
    searched, checked = float(m["value"]), sel.criteria.get(crit)
    name = criterion_tex(m["crit"])
    head = prose(f"refined by simulation from the {m['origin']} ({m['n']} simulations")
    if checked is None or num(searched) == num(checked):
        return Tex(f"{head}; {name} = {num(searched)})")
    return Tex(
        f"{head}); {name} = {num(searched)} at the end of the search, which averages the "
        "force over the sample holding each contact onset, and "
        f"{num(checked)} in the check by full simulation (point samples: the value of the "
        "ranking and of the criteria table)"
    )


def _regime_text(sel):
    """What the check by full simulation found of the selected law's motion, true of every
    record: its steady state, or, where the verdict says its trajectory from the measured
    state had not settled over the record's span, that (and the regime it tends to)."""
    evs = list(sel.evaluations or ())
    if not evs:
        return Tex("Steady state " + escape(sel.regime or "--") + ".")
    regs = [escape((ev.regime or {}).get("simulated") or ev.status or "--") for ev in evs]
    moving = [_transient(ev.verdict) for ev in evs]
    every = f" against each of the {len(evs)} records" if len(evs) > 1 else ""
    if not any(moving) and len(set(regs)) == 1:
        return Tex(f"The law's steady state{every} is {regs[0]}.")
    if all(moving) and len(set(regs)) == 1:
        return Tex(
            f"The law's trajectory from the measured state{every} had not settled by the "
            f"record's end (it tends to {regs[0]}), so the record was compared with that "
            "trajectory over its own span, block by block."
        )
    parts = []
    for k, (reg, unsettled) in enumerate(zip(regs, moving, strict=True)):
        who = f"record {k + 1}: " if len(evs) > 1 else ""
        parts.append(
            f"{who}the law's trajectory from the measured state had not settled by the "
            f"record's end (it tends to {reg}), so the record was compared with that "
            "trajectory over its own span, block by block"
            if unsettled
            else f"{who}the law's steady state is {reg}"
        )
    text = "; ".join(parts)
    return Tex(text[0].upper() + text[1:] + ".")


def _fit(doc, run_dir):
    r = doc.result
    sel = r.selected
    crit = r.settings.get("criterion", "I2")
    iv = sel.intervals
    records = r.records
    # the ranking's criterion column in one form
    ranked_sci = scientific(*(m.criteria.get(crit) for m in r.ranking))
    c = {
        "title": "Discovery of a contact law",
        "model": _model_tex(sel.law, "selected.coefficients"),
        "coefficients": _coef_rows(
            sel.law.as_dict(), sel.standard_errors, iv.bounds if iv is not None else {}
        ),
        "interval_method": (iv.method if iv is not None else None) or "no bootstrap intervals",
        "criteria": _criteria_table(sel.criteria, sel.noise_floor, sel.limits),
        "record_checks": _record_checks(sel, records),
        "verdict": verdict_tex(sel.verdict or "--"),
        "regime": _regime_text(sel),
        "refinement": _refinement_tex(sel, crit),
        "library": r.settings.get("library", "--"),
        "selection": r.settings.get("selection", "--"),
        "scoring": r.settings.get("scoring", "--"),
        "criterion": criterion_tex(crit),
        "rank_within": _rank_within(r.settings.get("ranking_rule") or {}),
        "records": [
            [rec.data, rec.scenario, rec.regime, rec.impacts]
            + [num(rec.noise.get("F")), rec.noise.get("n_cycles", "--")]
            for rec in records
        ],
        "certificate": _certificate(
            r.certificate, (r.settings.get("estimator") or {}).get("margin") or 0.0
        ),
        "ranking": [
            [
                str(i + 1),
                _terms_tex(m.law.names),
                m.regime,
                num(m.bic, 6),
                num(m.criteria.get(crit), sci=ranked_sci),
                ("yes" if m.consistent else "no") + ("; no contact law" if m.defects else ""),
            ]
            for i, m in enumerate(r.ranking)
        ],
        "demoted": [
            Tex(f"\\#{i + 1} " + prose("; ".join(m.defects)))
            for i, m in enumerate(r.ranking)
            if m.defects
        ],
        "equivalent": [
            {
                "model": _model_tex(e.get("law") or e.get("coefficients"), f"equivalent[{i}].law"),
                "reason": prose(e.get("reason", "")),
                "separate": prose(e.get("separate", "")),
            }
            for i, e in enumerate(r.equivalent)
        ],
        "warnings": [prose(w) for w in r.warnings],
        # the scenarios as the command was given them (a result keeps their names only)
        "scenarios": _scenarios_table(
            doc.summary.get("scenarios") or [doc.summary.get("scenario")]
        ),
        "the_records": the_records(len(records)),
    }
    c["conclusions"] = _selected_conclusions(r)
    c["figures"] = _figures(run_dir, ["fit_impulse", "fit_surface", "fit_loop"])
    return c


def _identify(doc, run_dir):
    r = doc.result
    # the identified law against the record, with its noise floor (the command checks one)
    one = r.checks[0] if r.checks else None
    c = {
        "title": "Identification of a contact law by simulation",
        "model": _model_tex(r.law, "law"),
        "coefficients": _coef_rows(
            r.coefficients or {},
            r.standard_errors,
            r.intervals.bounds if r.intervals is not None else {},
            # the start as given and the record's measured block are the run's
            start=doc.summary.get("start") or {},
        ),
        "measured": _measured_rows(doc.summary.get("measured")),
        "criteria": _criteria_table(
            one and one.criteria,
            one and one.noise_floor,
            one.limits if len(r.checks) == 1 else {},
        ),
        "verdict": verdict_tex((one and one.verdict) or "--"),
        "method": r.method or "--",
        "criterion": criterion_tex(r.criterion or "I2"),
        "n_simulations": r.n_simulations if r.n_simulations is not None else "--",
        "message": prose(str(r.message).rstrip(".")),  # the template ends it
    }
    consistent = bool(one and one.consistent)
    concl = [
        f"{r.method or '?'} spent {r.n_simulations if r.n_simulations is not None else '?'} "
        f"simulations; the identified law is {'consistent' if consistent else 'NOT consistent'} "
        "with the record."
    ]
    if not consistent:
        concl.append(
            "An inconsistent result after identification means either a missing "
            "effect (run `vidi explain`) or a local minimum: start nearer (the "
            "coefficients of `vidi fit`), or look at the landscape."
        )
    c["conclusions"] = [prose(x) for x in concl]
    c["figures"] = _figures(run_dir, ["identification"])
    return c


def _landscape(doc, run_dir):
    r = doc.result
    terms = list(r.terms or ("?", "?"))
    n = int(r.consistent.sum()) if r.consistent is not None else 0
    law = doc.summary.get("law")  # the law and the grid as the command was given them
    c = {
        "title": "Criteria landscape over two coefficients",
        "terms": [term_tex(t) for t in terms[:2]],
        "law": law_inline(law_of(law, "law")) if law else Tex("--"),
        "grid": "x".join(str(g) for g in doc.summary.get("grid") or []),
        "minima": [
            [
                criterion_tex(k),
                num(m["alpha1"]),
                num(m["alpha2"]),
                num(m["value"]),
                m["regime"],
                "yes" if m["consistent"] else "no",
            ]
            for k, m in r.minima().items()
            if m is not None
        ],
        "noise_floor": [[criterion_tex(k), num(v)] for k, v in (r.noise_floor or {}).items()],
        "n_consistent": n,
        "regimes": ", ".join(f"{k}: {v}" for k, v in r.regime_counts().items()),
        "reference": (r.reference or {}).get("source", "--"),
    }
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


def _effect_parameter_rows(model, errors, intervals, catalogue):
    """Rows of the added effects' own parameters (a machine parameter such as the contact
    offset, an observation's such as a sensor's lag), by the catalogue's names and units:
    ``model`` the final :class:`~discovery.vibroimpact.explain.effects.Model`, ``errors``
    and ``intervals`` its parameters' standard errors and bounds."""
    if not isinstance(catalogue, list):
        return []
    values = {**(model.scenario or {}), **(model.observation or {})}
    rows = []
    for e in catalogue:
        if not isinstance(e, dict) or e.get("id") not in (model.effects or ()):
            continue
        key, params = e.get("key"), e.get("parameters") or []
        if key not in values or not params or not isinstance(params[0], dict):
            continue
        name, unit = str(params[0].get("name")), str(params[0].get("unit", ""))
        rows += _coef_rows(
            {name: values[key]},
            errors,
            intervals,
            term=lambda n, u=unit: Tex(r"\texttt{" + escape(n) + "} [" + escape(u) + "]"),
        )
    return rows


def _unloading_rows(law, errors, intervals):
    """Rows of the unloading branch's terms of ``law``, with the standard errors and
    intervals of their coefficients (parameters ``d_<term>``, as the unloading-damping
    effect names them)."""
    unl = zip([t.name for t in law.unloading], law.unloading_coefficients, strict=True)
    return _coef_rows(
        {f"d_{k}": v for k, v in unl},
        errors,
        intervals,
        term=lambda n: Tex("unloading " + term_tex(n[2:], unloading=True)),
    )


def _explain(doc, run_dir):
    r = doc.result
    fm = r.final_model
    its = r.iterations or ()
    iv = r.intervals.bounds if r.intervals is not None else {}
    stopped = r.stopped_because
    c = {
        "title": "The missing physical effect",
        "model": _model_tex(fm.law, "final_model.text"),
        "coefficients": _coef_rows(fm.law.as_dict(), r.uncertainties, iv)
        + _unloading_rows(fm.law, r.uncertainties, iv)
        # the effects' catalogue is the command's (the result does not keep it)
        + _effect_parameter_rows(fm, r.uncertainties, iv, doc.summary.get("catalogue")),
        "effects": [str(e).replace("_", " ") for e in fm.effects or ()],
        "criteria": _criteria_table(r.criteria, r.noise_floor, r.limits),
        "stopped": prose("--" if stopped is None else stopped),
        "iterations": [
            [
                str(k + 1),
                str(it.effect or "nothing named").replace("_", " "),
                num((it.criteria_before or {}).get("I2")),
                num((it.criteria_after or {}).get("I2")),
                num((it.noise_floor or {}).get("I2")),
                prose(it.evidence or ""),
            ]
            for k, it in enumerate(its)
        ],
        "separability": [
            [
                s.get("effect", "--"),
                num(s.get("before")),
                num(s.get("after")),
                num(s.get("floor")),
                "yes" if s.get("separable") else "no",
            ]
            for s in r.separability or ()
        ],
    }
    named_its = [it for it in its if it.effect]
    if named_its:
        named = ", ".join(str(it.effect).replace("_", " ") for it in named_its)
        state = "consistent" if r.consistent else "still NOT consistent"
        concl = [
            f"Named and added: {named}. The gap to the record shrank as the table shows; "
            f"the final model is {state} with the record."
        ]
    else:
        concl = [
            "No effect was added: "
            + str("the start model already agrees with the record" if stopped is None else stopped)
        ]
    concl += [
        f"Taken out of the final model: {str(d['effect']).replace('_', ' ')}, {d['reason']}."
        for d in r.dropped or ()
    ]
    c["conclusions"] = [prose(x) for x in concl]
    c["figures"] = _figures(run_dir, ["explain", "localise", "screen", "drift"])
    return c


def _rank_within(rule):
    """How close to the best criterion a model must be to be ranked by BIC (the ranking
    rule's ``sim_rtol`` and ``sim_atol``), as LaTeX."""
    rtol, atol = rule.get("sim_rtol", 0.1), rule.get("sim_atol", 0.005)
    return Tex(f"{num(100 * rtol)}\\,\\% (or {num(atol)})")
