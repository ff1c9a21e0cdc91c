"""The hidden-effect cases of ``explain`` (the first table of docs/validation.md's "Explain:
measured"), run and saved as a measured run.

Not a test module.  Each case is a record with one hidden effect (or two), made by the
independent scipy path (1 % force noise, 0.2 % of each motion channel's range, 20 kHz, from
rest through a transient) and explained from the linear start.  The records and the calls
of ``explain`` are the tests' own (``tests/vibroimpact/explain/test_explain.py`` and
``test_explain_effects.py``: their helpers are imported, so a case is what its test runs),
except two P4 cases no test builds: stiffening supports ``k3 = 1.5e11`` on the paper's
machine with its own law (``support_case`` of the effects' tests with that ``k3`` and law)
and a set 0.4 on ``tests/vibroimpact/verify/test_verify.py``'s subharmonic machine (its
P4 orbit with three impacts; 16 periods, seed 0).

Run from the repository root (the set case: 15 s on two shared cores; the P4 and the
40-period cases take longer)::

    python -m tests.survey_explain_cases --out docs/_measured/explain-cases.jsonl
    python -m tests.survey_explain_cases --only set --out out/set.jsonl   # one case

The output is a run file (:mod:`tests.measured`, appended to when it exists): a header
naming the commit and code version, then one row per case as it finishes (a later row of a
case replaces an earlier one in the table: ``--only`` runs a case again).  The table
(:func:`markdown_row`, ``make tables``) gives per case the record's regime, the effects
named, their values and the gap each named effect closed.
"""

import argparse
import re
import sys
import time

from tests import measured

#: a case: its label in the table, the effects hidden, whether its record drifts, and the
#: function of the paper's scenario that makes ``(start scenario, record, result)``
CASES = {
    "coupling": ("`2e10*z*zd` (paper)", ("penetration_velocity_coupling",), False),
    "sensor-lag": ("sensor lag 0.1 ms (paper)", ("sensor_lag",), False),
    "unloading": (
        "unloading `4e6*zd` (paper machine, `2.06e8*z + 4e6*zd`)",
        ("unloading_damping",),
        False,
    ),
    "set": ("set 0.4 (same)", ("permanent_set",), False),
    "hertz": (
        "Hertz `1e10*z^1.5` (`1e8*z + 3e6*zd`, paper machine)",
        ("hertzian_stiffening",),
        False,
    ),
    "supports": ("supports `k3 = 5e10` (same as unloading)", ("support_nonlinearity",), False),
    "supports-paper": ("supports `k3 = 1.5e11` (paper)", ("support_nonlinearity",), False),
    "set-subharmonic": (
        "set 0.4 (`tests/vibroimpact/verify/test_verify`'s subharmonic machine)",
        ("permanent_set",),
        False,
    ),
    "mass-loss": ("mass loss 0.5 %/impact, 40 periods (paper)", ("mass_loss",), True),
    "coupling-mass-loss": (
        "coupling + mass loss together",
        ("mass_loss", "penetration_velocity_coupling"),
        True,
    ),
}


def _effects_case(law_name):
    """A case of the effects' tests made by their ``_explain`` (the paper's machine with
    the lighter damper): ``law_name`` is the test module's constant of the hidden law."""

    def run(paper):
        from discovery import ForceLaw
        from tests.vibroimpact.explain import test_explain_effects as T

        rec, res = T._explain(paper, ForceLaw.parse(getattr(T, law_name)))
        return paper.with_law(ForceLaw.parse(T.BASE)), rec, res

    return run


def _coupling(paper):
    from tests.vibroimpact.explain import test_explain as T

    return (paper, *T.hidden_coupling_case(paper))


def _sensor_lag(paper):
    from tests.vibroimpact.explain import test_explain as T

    return (paper, *T.hidden_lag_case(paper))


def _supports(paper):
    from tests.vibroimpact.explain import test_explain_effects as T

    return (paper, *T.support_case(paper))


def _supports_paper(paper):
    from tests.vibroimpact.explain import test_explain_effects as T

    return (paper, *T.support_case(paper, k3=1.5e11, law=paper.law))


def _set_subharmonic(paper):
    """A set 0.4 hidden on test_verify's subharmonic machine (a P4 orbit with three
    impacts), explained from the linear start on the machine's linear law."""
    from discovery.vibroimpact.explain import explain
    from tests import realistic as R
    from tests.vibroimpact.verify.test_verify import _SUB, _SUB_LAW

    law = _SUB_LAW.with_unloading(permanent_set=0.4)
    rec = R.reference_record((_SUB.with_law(law), law), periods=16, seed=0, check=False)
    sc = _SUB.with_law(_SUB_LAW)
    return sc, rec, explain(sc, rec, "linear", n_boot_intervals=0)


def _mass_loss(paper):
    from tests.vibroimpact.explain import test_explain_effects as T

    return (paper, *T.mass_loss_case(paper, paper.law))


def _coupling_mass_loss(paper):
    from discovery import ForceLaw
    from tests.vibroimpact.explain import test_explain_effects as T

    return (paper, *T.mass_loss_case(paper, ForceLaw.parse(T.COUPLED)))


RUNS = {
    "coupling": _coupling,
    "sensor-lag": _sensor_lag,
    "unloading": _effects_case("UNLOADING"),
    "set": _effects_case("SET"),
    "hertz": _effects_case("HERTZ"),
    "supports": _supports,
    "supports-paper": _supports_paper,
    "set-subharmonic": _set_subharmonic,
    "mass-loss": _mass_loss,
    "coupling-mass-loss": _coupling_mass_loss,
}

_GAP = re.compile(r"refitted, (\w+) \S+ -> ")


def _step(it):
    """A named iteration: its effect, the criterion its gap was measured on (from its
    evidence; I2 where that does not say), before and after, and its noise floor."""
    found = _GAP.search(it.evidence or "")
    key = found[1] if found else "I2"
    return {
        "effect": it.effect,
        "key": key,
        "before": it.criteria_before.get(key),
        "after": it.criteria_after.get(key),
        "floor": it.noise_floor.get(key),
        "criteria_before": it.criteria_before,
        "criteria_after": it.criteria_after,
        "noise_floor": it.noise_floor,
    }


def _values(res):
    """``({effect: value}, {effect: standard error or None})`` of the effects the final
    model keeps."""
    from discovery.vibroimpact.explain import effect

    values, errors = {}, {}
    for eid in res.final_model.effects:
        eff = effect(eid)
        values[eid] = float(res.final_model.value(eff))
        names = [eff.parameters[0].name] + ([eff.key] if eff.target == "term" else [])
        se = next((res.uncertainties[n] for n in names if n in res.uncertainties), None)
        errors[eid] = None if se is None else float(se)
    return values, errors


def run_case(name, paper=None):
    """The row of case ``name``: the record's regime (read from the record), the effects
    named, kept and taken out, each named step's gap, the final model's values and law,
    and the time taken (an error in the case: its message)."""
    from discovery import load_scenario
    from discovery._files._io import provenance

    label, hidden, drifting = CASES[name]
    prov = provenance()
    row = {"case": name, "hidden": label, "hidden_effects": list(hidden), "drifting": drifting}
    row.update(versions=prov["versions"], git=prov["git"])
    paper = paper or load_scenario("paper")
    t0 = time.perf_counter()
    try:
        sc, rec, res = RUNS[name](paper)
    except Exception as exc:  # noqa: BLE001 (a survey row records any failure)
        return {**row, "error": f"{type(exc).__name__}: {exc}", "seconds": time.perf_counter() - t0}
    seconds = time.perf_counter() - t0
    from discovery.vibroimpact.verify import Reference

    ref = Reference.from_measurement(rec, sc)
    values, errors = _values(res)
    law = res.final_model.law
    row.update(
        regime=ref.regime,
        impacts=ref.impacts,
        read=sorted((res.settings or {}).get("read") or {}),
        named=[it.effect for it in res.iterations if it.effect],
        kept=list(res.final_model.effects),
        dropped=[d["effect"] for d in res.dropped],
        steps=[_step(it) for it in res.iterations if it.effect],
        values=values,
        errors=errors,
        law=law.as_dict(),
        final=str(res.final_model),
        consistent=res.consistent,
        stopped=res.stopped_because,
        criteria=res.criteria,
        noise_floor=res.noise_floor,
        seconds=seconds,
        explain_seconds=res.seconds,
    )
    return row


def read_rows(paths):
    """The cases of the run files ``paths`` (in the order the runs started), a later row
    of a case replacing an earlier one."""
    return list({r["case"]: r for p in paths for r in measured.read(p)[1]}.values())


def _num(x, digits=3):
    """``x`` to ``digits`` significant digits, an exponent written ``2.01e10``."""
    if x is None:
        return "-"
    text = f"{x:.{digits}g}"
    if "e" in text:
        mantissa, exp = text.split("e")
        text = f"{mantissa}e{int(exp)}"
    return text


def _regime(r):
    k = r.get("impacts") or 0
    text = r["regime"] + (f", {k} impacts" if k > 1 else "")
    text += ", drifting" if r.get("drifting") else ""
    return text if r["regime"] == "P1" else f"**{text}**"


def _named(r):
    """The effects read before the loop (the supports the machine's own equations read),
    then those named, in order."""
    gone = r.get("dropped") or ()
    read = [f"`{e}` (read before the loop)" for e in r.get("read") or ()]
    names = [f"`{e}`" + (" (taken out)" if e in gone else "") for e in r["named"]]
    if not names:
        return ", ".join(read) or "nothing"
    wrong = not read and r["named"][0] not in r["hidden_effects"]
    return ", ".join(read + names) + (" (not the hidden effect first)" if wrong else "")


def _recovered(r):
    """The values of the effects the final model keeps (with their standard errors where
    the fit gives them); a stiffening support's with the law's coefficients, which it
    trades against."""
    parts = []
    for eid in [*(r.get("read") or ()), *r["named"]]:
        if eid not in r["values"]:
            continue
        se = r["errors"].get(eid)
        parts.append(_num(r["values"][eid]) + (f" +- {_num(se, 2)}" if se else ""))
    if parts and "support_nonlinearity" in r["values"]:
        parts[-1] += "; law " + ", ".join(_num(c) for c in r["law"].values())
    return ", ".join(parts) or "-"


def _gap(r):
    """Each named step's gap (its criterion before and after, its noise floor), with the
    bar (3x, or 1.5 floors) where a step falls short of it; with nothing named, the final
    model's I2 and its floor."""
    if not r["steps"]:
        floor = r["noise_floor"].get("I2")
        what = "read before the loop, nothing named" if r.get("read") else "nothing named"
        return f"I2 {_num(r['criteria'].get('I2'))} (floor {_num(floor)}), {what}"
    parts = []
    for s in r["steps"]:
        before, after, floor = s["before"], s["after"], s["floor"]
        text = f"{s['key']} {_num(before)} -> {_num(after)} (floor {_num(floor)})"
        if before is not None and after:
            bar = after <= before / 3 or (floor is not None and after <= 1.5 * floor)
            text += "" if bar else f": {before / after:.1f}x, short of the 3x bar"
        parts.append(text)
    return "; ".join(parts)


def markdown_row(rows, name):
    """The table's row of case ``name`` (hidden, regime, named, recovered, gap); a case
    with no row says so, and one whose run raised gives the error."""
    r = next((r for r in rows if r["case"] == name), None)
    if r is None:
        return f"| {CASES[name][0]} | not run |  |  |  |"
    if "error" in r:
        return f"| {r['hidden']} | - | - | - | {r['error'].replace('|', '/')} |"
    cells = [r["hidden"], _regime(r), _named(r), _recovered(r), _gap(r)]
    return "| " + " | ".join(cells) + " |"


HEADER = ("| hidden | regime | named | recovered | gap |", "|---|---|---|---|---|")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, help="run file (tests.measured) the rows go to")
    ap.add_argument("--only", nargs="+", choices=list(CASES), help="run these cases only")
    args = ap.parse_args(argv)
    out = measured.RunFile(args.out, "survey_explain_cases", argv, append=True)
    from discovery import load_scenario

    paper = load_scenario("paper")
    for name in args.only or CASES:
        row = run_case(name, paper)
        out.write(row)
        print(markdown_row([row], name), f"({row['seconds']:.0f} s)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
