"""The field-like corpus's tables of docs/validation.md: the true law, the law 30 % off and
``explain`` on each of the thirteen records of ``../shared/corpus``.

Not a test module: a survey (``python -m tests.survey_corpus --out FILE``; minutes on two
cores).  For each record (:func:`tests.test_corpus._load`: its scenario, measurement and
true law, c11's as a linear law behind a contact offset):

* the true law verified: I2 and I5 with their limits and floors, the verdict, the regime the
  record reads and the one the law's orbit has (and, on c10, the soft law that hides its
  unloading damping);
* every coefficient of the true law (its unloading branch's too) scaled by 0.7 and by 1.3:
  how many are inconsistent;
* ``explain`` from ``z + zd`` (the record's own scenario, 30 bootstrap replicates): the
  effects named, each one's gap before and after with its floor, the final model's
  parameters with their 95 % intervals, and the truth in the same terms
  (:func:`tests.survey_intervals._corpus_model`).

One JSON line per record in a run file of :mod:`tests.measured` (headed by the commit and
code version); ``--records c01,c02`` runs some of them, appended to ``--out`` with
``--append`` (a later row of a record replaces an earlier one in the tables).
:func:`markdown_row` and :func:`effects_row` make the tables' rows (``python -m
tests.tables``).
"""

import argparse
import re
import sys
import time

from . import measured

#: laws verified besides the truth: c10's soft spring with more damping matches the force
#: within its noise but not the recorded penetration
ALSO = {"c10-unloading-stiff": ("3.99e7*z + 5.95e6*zd",)}

CRITERIA = ("I2", "I5")


def _scores(ev):
    """A verification's criteria, limits and floors of I2 and I5."""
    out = {}
    for k in CRITERIA:
        if k in ev.criteria:
            out[k] = float(ev.criteria[k])
            out[f"{k}_limit"] = float((ev.limits or {}).get(k, float("nan")))
            out[f"{k}_floor"] = float(ev.noise_floor.get(k, float("nan")))
    return out


def _verified(sc, ref, law):
    from discovery.vibroimpact.verify import verify

    res = verify(sc, ref, law, check_default_start=False)
    ev = res.evaluation
    return {
        "law": law.to_text(),
        "consistent": bool(res.consistent),
        "verdict": res.verdict,
        "regime": {"measured": ev.regime.get("measured"), "simulated": ev.regime.get("simulated")},
        # the verdict's words for a law whose trajectory has not settled over the span
        # (verify/notes.py; "still in a transient" before 2026-11-27)
        "transient": "has not settled" in res.verdict or "still in a transient" in res.verdict,
        **_scores(ev),
    }


def _scaled(sc, ref, law):
    """Every coefficient of ``law`` (its unloading branch's too) times 0.7 and 1.3: the ones
    still consistent."""
    from discovery.vibroimpact.verify import verify

    n = len(law.coefficients)
    values = [*law.coefficients, *law.unloading_coefficients]
    labels = [*law.names, *(f"unloading {t.name}" for t in law.unloading)]
    consistent, total = [], 0
    for i, term in enumerate(labels):
        for f in (0.7, 1.3):
            c = list(values)
            c[i] *= f
            scaled = law.with_coefficients(c[:n]).with_unloading(coefficients=c[n:])
            total += 1
            if not verify(sc, ref, scaled, check_default_start=False).consistent:
                continue
            consistent.append(f"{term} x{f}")
    return {"total": total, "inconsistent": total - len(consistent), "consistent": consistent}


def _iteration(it):
    return {
        "effect": it.effect,
        **{f"{k}_before": it.criteria_before.get(k) for k in CRITERIA},
        **{f"{k}_after": it.criteria_after.get(k) for k in CRITERIA},
        **{f"{k}_floor": it.noise_floor.get(k) for k in CRITERIA},
    }


def _explained(sc, m, machine_scale=None, known=None):
    """``explain`` from ``z + zd``: what it named and the model it ended with."""
    from discovery.vibroimpact.explain import explain

    t0 = time.perf_counter()
    res = explain(
        sc, m, "linear", workers=1, n_boot_intervals=30, machine_scale=machine_scale, known=known
    )
    final = res.final_model
    got = dict(zip(final.names, map(float, final.coefficients), strict=True))
    bounds = res.intervals.bounds if res.intervals is not None else {}
    return {
        "named": [it.effect for it in res.iterations if it.effect],
        "iterations": [_iteration(it) for it in res.iterations if it.effect],
        "consistent": bool(res.consistent),
        "stopped_because": res.stopped_because,
        "criteria": {k: res.criteria.get(k) for k in CRITERIA},
        "floor": {k: res.noise_floor.get(k) for k in CRITERIA},
        "limits": {k: res.limits.get(k) for k in CRITERIA},
        "final": str(final),
        "parameters": got,
        "intervals": {k: [float(lo), float(hi)] for k, (lo, hi) in bounds.items()},
        "separability": [
            {k: s.get(k) for k in ("effect", "before", "after", "floor", "separable")}
            for s in res.separability
        ],
        "seconds": time.perf_counter() - t0,
    }


def run(name):
    """One record's row (a dict)."""
    from discovery import ForceLaw, load_scenario
    from discovery.vibroimpact.verify import Reference

    from .survey_intervals import _corpus_model
    from .test_corpus import CORPUS, _load

    t0 = time.perf_counter()
    row = {"i": name}
    try:
        sc, m, law, truth = _load(name)
        row.update(
            law=truth["law"],
            hidden=truth.get("hidden_effect"),
            regime=truth.get("regime", f"P{truth.get('regime_check', {}).get('period', '?')}"),
            offset=sc.offset if sc.offset else None,
        )
        ref = Reference.from_measurement(m, sc)
        row["verified"] = _verified(sc, ref, law)
        row["also"] = [_verified(sc, ref, ForceLaw.parse(t)) for t in ALSO.get(name, ())]
        row["scaled"] = _scaled(sc, ref, law)
        # explain starts from the record's own scenario (c11's without its offset)
        own = load_scenario(str(CORPUS / name / "scenario.toml"))
        row["truth"] = _corpus_model(name)[2]
        row["explain"] = _explained(*_as_vidi_explain(own, m, truth))
    except Exception as exc:  # a survey records every outcome
        row["error"] = f"{type(exc).__name__}: {exc}"
    row["seconds"] = time.perf_counter() - t0
    return row


def _as_vidi_explain(own, m, truth):
    """``(scenario, record, machine scale, known)`` as ``vidi explain`` gives them: on a
    sheet record (c14-c16: its scenario is the designer's sheet) the machine calibrated from
    the record, with its scale's range and the force sensor's lag it found."""
    from discovery import calibrate

    if "true_machine" not in truth:
        return own, m, None, None
    cal = calibrate(own, m)
    lag = cal.parameters.get("force_lag")
    return cal.scenario, m, cal.scale_range, {"sensor_lag": lag["record"]} if lag else None


# --------------------------------------------------------------------------- the tables

EFFECTS = {
    "penetration_velocity_coupling": "coupling",
    "unloading_damping": "unloading damping",
    "hertzian_stiffening": "Hertz",
    "contact_offset": "contact offset",
}


def _effect(name):
    return EFFECTS.get(name, name.replace("_", " "))


def _g(x, digits=2):
    """``x`` as the pages write a criterion: ``1.15``, ``0.027`` (``digits`` decimals past
    the point's zero; one more for ``digits=3``: ``0.0131``)."""
    if x is None:
        return "-"
    if abs(x) >= 1:
        return f"{x:.{digits + 1}g}"
    return f"{x:.{digits + 1}f}" if abs(x) >= 0.01 else f"{x:.{digits + 2}f}"


def _exp(text):
    return text.replace("e+0", "e").replace("e-0", "e-").replace("e+", "e")


def _e(x):
    """Four figures: ``1.504e8``."""
    return _exp(f"{x:.3e}")


def _short(x):
    """As short as it reads: ``1.5e8``, ``0.0015``."""
    return _exp(f"{x:.4g}")


_TERM = re.compile(r"^z[z^*d.0-9]*$|^zd[z^*d.0-9]*$")


def _law(parameters):
    """A model's text from its parameters, four figures each: ``1.131e8*z + 7.05e6*zd``,
    an effect's parameter after it (``1.23e8*z + 4.056e6*zd, set = 0.95``)."""
    terms = [f"{_short(v)}*{n}" for n, v in parameters.items() if _TERM.match(n)]
    other = [f"{n} = {_short(v)}" for n, v in parameters.items() if not _TERM.match(n)]
    return ", ".join([" + ".join(terms), *other])


def _text(law):
    """A law's text (``39900000*z + 5950000*zd``) as :func:`_law` writes it."""
    coefficient, name = zip(*(t.split("*", 1) for t in law.split(" + ")), strict=True)
    return _law(dict(zip(name, map(float, coefficient), strict=True)))


def _find(rows, label):
    key = label.split()[0]
    found = [r for r in rows if str(r["i"]).split("-")[0] == key]
    if not found:
        raise SystemExit(f"no corpus row for {key}")
    return found[-1]


def _verdict(v):
    return "consistent" if v["consistent"] else "inconsistent"


def _failing(v):
    return [k for k in CRITERIA if k in v and v[k] > v[f"{k}_limit"]]


def _law_cell(r, *, floors):
    """The true law's verification: ``consistent (I2 0.027, floor 0.025)`` (``floors``) or
    ``consistent (I2 0.034 / 0.063, I5 0.037 / 0.083)`` (each against its limit)."""
    v = r["verified"]
    if floors:
        return f"{_verdict(v)} (I2 {_g(v['I2'])}, floor {_g(v['I2_floor'])})"
    scores = ", ".join(f"{k} {_g(v[k])} / {_g(v[f'{k}_limit'])}" for k in CRITERIA if k in v)
    cell = f"{_verdict(v)} ({scores})"
    if r.get("offset"):
        cell = f"{_verdict(v)} with `{_text(v['law'])}` and `offset = {r['offset']:g}` ({scores})"
    for o in r.get("also", ()):
        fails = _failing(o)
        by = f" by {', '.join(fails)}" if fails and not o["consistent"] else ""
        scores = ", ".join(f"{k} {_g(o[k])} / {_g(o[f'{k}_limit'])}" for k in CRITERIA if k in o)
        cell += f"; the soft law `{_text(o['law'])}` {_verdict(o)}{by} ({scores})"
    return cell


def _regime_cell(r):
    reg = r["verified"]["regime"]
    note = ": still in a transient" if r["verified"]["transient"] else ""
    return f"{reg['measured']} ({reg['simulated']}{note})"


def _scaled_cell(r):
    s = r["scaled"]
    if s["inconsistent"] == s["total"]:
        return f"all {s['total']} inconsistent"
    return f"{s['inconsistent']} of {s['total']} inconsistent ({', '.join(s['consistent'])} not)"


def _step(it, limits):
    """One named effect: its gap before and after, on I2 (or on I5 when I2 was within its
    limit), with the floor."""
    k = "I2"
    if it["I2_before"] is not None and it["I2_before"] <= (limits.get("I2") or float("inf")):
        k = "I5" if it.get("I5_before") is not None else "I2"
    return (
        f"{_effect(it['effect'])} named, {k} {_g(it[f'{k}_before'])} -> "
        f"{_g(it[f'{k}_after'])} (floor {_g(it[f'{k}_floor'])})"
    )


def _final(x, truth):
    """The final model's parameters, against the truth (``truth``: in the model's terms
    when it has the truth's parameters) with their intervals."""
    got, bounds = x["parameters"], x["intervals"]
    if set(got) != set(truth):
        true = ", ".join(f"{n} {_short(v)}" for n, v in truth.items())
        return f"`{_law(got)}` (true {true})"
    names = list(got)
    cell = ", ".join(f"{n} {_e(got[n])}" for n in names)
    cell += f" (true {', '.join(_short(truth[n]) for n in names)})"
    if not bounds:
        return cell + ", no intervals"
    missed = [n for n in names if n in bounds and not bounds[n][0] <= truth[n] <= bounds[n][1]]
    if not missed:
        return cell + ", each in its interval"
    return (
        cell
        + "; "
        + ", ".join(
            f"the `{n}` interval [{_e(bounds[n][0])}, {_e(bounds[n][1])}] misses" for n in missed
        )
    )


def _explain_cell(r):
    if "error" in r:
        return f"error: {r['error']}"
    x = r["explain"]
    lim = x["limits"]
    if not x["named"]:
        cell = "nothing named" if x["consistent"] else f"nothing named, inconsistent: {x['final']}"
        hidden = r.get("hidden")
        hidden = hidden if isinstance(hidden, list) else [hidden] if hidden else []
        for s in x["separability"]:
            if s["effect"] in hidden and s["after"] is not None:
                tell = "lowers" if s["separable"] else "does not lower"
                cell += (
                    f": `{_law(x['parameters'])}` consistent; "
                    f"{_effect(s['effect'])} refitted {tell} I2 by its floor "
                    f"({_g(s['before'], 3)} -> {_g(s['after'], 3)}, floor {_g(s['floor'])})"
                )
        return cell
    cell = ", then ".join(_step(it, lim) for it in x["iterations"])
    if not x["consistent"]:
        cell += f"; inconsistent: {x['stopped_because']}"
    return f"{cell}: {_final(x, r['truth'])}"


def markdown_row(rows, label):
    """A row of the first corpus table (c01-c07): the true law verified with its I2 and
    floor, the regime read (simulated), the coefficients 30 % off, explain."""
    r = _find(rows, label)
    if "error" in r:
        return f"| {label} | error: {r['error']} |  |  |  |"
    cells = [label, _law_cell(r, floors=True), _regime_cell(r), _scaled_cell(r), _explain_cell(r)]
    return "| " + " | ".join(cells) + " |"


def effects_row(rows, label):
    """A row of the second corpus table (c08-c16): the true law verified (I2 and I5
    against their limits; c10's soft law too), explain."""
    r = _find(rows, label)
    if "error" in r:
        return f"| {label} | error: {r['error']} |  |"
    return f"| {label} | {_law_cell(r, floors=False)} | {_explain_cell(r)} |"


def read_rows(paths):
    """The rows of the run files ``paths``, a record's later row replacing an earlier one."""
    rows = {}
    for path in paths:
        for r in measured.read(path)[1]:
            rows[r["i"]] = r
    return list(rows.values())


def main(argv=None):
    from .test_corpus import NAMES

    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--records", help="comma-separated prefixes (c01,c02); all by default")
    p.add_argument("--out", metavar="JSONL", required=True, help="the run file of the rows")
    p.add_argument("--append", action="store_true", help="continue --out instead of replacing")
    a = p.parse_args(argv)
    names = list(NAMES)
    if a.records:
        keys = a.records.split(",")
        names = [n for n in names if n.split("-")[0] in keys or n in keys]
    if not names:
        p.error(f"no corpus record matches {a.records!r} (the corpus: {', '.join(NAMES)})")
    out = measured.RunFile(a.out, "survey_corpus", argv, append=a.append)
    for k, name in enumerate(names, 1):
        print(f"[{k}/{len(names)}] {name} ...", flush=True)
        row = run(name)
        out.write(row)
        x = row.get("explain", {})
        print(
            f"[{k}/{len(names)}] {name}: {row.get('error') or _verdict(row['verified'])}, "
            f"scaled {row.get('scaled', {}).get('inconsistent')}/"
            f"{row.get('scaled', {}).get('total')} inconsistent, named {x.get('named')} "
            f"({row['seconds']:.0f} s)",
            flush=True,
        )
    return 0


if __name__ == "__main__":
    sys.exit(main())
