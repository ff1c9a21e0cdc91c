"""Random survey of the missing-effect workflow (the table of docs/validation.md).

Draws machines and laws with the test generator (:func:`tests.realistic.draw_case`: P1,
slow P1, subharmonic and short-contact categories in turn), hides one effect, makes a
record with the independent scipy path (1 % force noise, 0.2 % of each motion channel's
range, 20 kHz, from rest through the draw's transient) and runs ``explain`` from the linear
start:

* a ``zzd`` draw hides its own ``z*zd`` share (``penetration_velocity_coupling``);
* a ``linear`` draw hides, at random, nothing, a set 0.2-0.5, unloading damping 0.3-0.8 of
  the loading damper, or stiffening supports at 10-50 % of ``k1`` at the grid's excursion;
* a Hertz-type draw is skipped (its law has no linear start).

Run from the repository root (60 draws: about 15 minutes with two workers on two cores)::

    python -m tests.survey_explain --draws 0 60 --workers 2 --out survey.jsonl
    python -m tests.survey_explain --summary survey.jsonl

The output is a run file (:mod:`tests.measured`): a header naming the commit and code
version, then one line per draw (JSON, in the order the draws finish).  ``--workers N`` runs
N draws at once, each ``explain`` in one process (the default, one draw at a time, gives
each ``explain``'s screening refits every core; the result does not depend on it).  The
table of docs/validation.md (:func:`markdown_row`, ``make tables``) and ``--summary`` count
the draws by :func:`outcome`.
"""

import argparse
import collections
import re
import sys
import time

import numpy as np

from discovery import ForceLaw
from discovery._files._io import provenance
from discovery.vibroimpact.explain import explain
from discovery.vibroimpact.verify import Reference, evaluate
from tests import measured
from tests import realistic as R

CATEGORIES = ("p1", "subharmonic", "p1-slow", "short-contact")
HIDDEN = ("none", "permanent_set", "unloading_damping", "support_nonlinearity")


def _hide(case, rng):
    """``(hidden effect id, true scenario, true law, start law)``, or None for a Hertz-type
    draw."""
    law, sc = case.law, case.scenario
    if case.kind == "zzd":
        base = ForceLaw.parse(
            " + ".join(f"{c!r}*{n}" for n, c in law.as_dict().items() if n != "z*zd")
        )
        return "penetration_velocity_coupling", sc, law, base
    if case.kind != "linear":
        return None
    hidden = HIDDEN[int(rng.integers(len(HIDDEN)))]
    true, true_sc = law, sc
    if hidden == "permanent_set":
        true = law.with_unloading(permanent_set=float(np.round(rng.uniform(0.2, 0.5), 2)))
    elif hidden == "unloading_damping":
        c = law.as_dict()["zd"]
        true = law.with_unloading((law.terms[1],), (float(np.round(rng.uniform(0.3, 0.8), 2)) * c,))
    elif hidden == "support_nonlinearity":
        x = abs(float(sc.initial_state()[0])) + sc.scales()[0]
        true_sc = sc.replace(k3=float(f"{rng.uniform(0.1, 0.5) * sc.k1 / x**2:.2e}"))
    return hidden, true_sc, true, law


def draw(i, workers=None):
    """One survey row (a dict); ``workers``: processes for ``explain``'s screening refits."""
    cat = CATEGORIES[i % len(CATEGORIES)]
    seed = 1000 + i
    prov = provenance()
    row = {"i": i, "category": cat, "seed": seed, "versions": prov["versions"], "git": prov["git"]}
    try:
        case = R.draw_case(cat, seed)
    except RuntimeError as exc:
        return {**row, "skip": str(exc)}
    got = _hide(case, np.random.default_rng(seed))
    if got is None:
        return {**row, "skip": f"{case.kind} law (no linear start)"}
    hidden, true_sc, true, base = got
    row.update(
        regime=case.regime,
        impacts=case.impacts,
        hidden=hidden,
        true=true.to_text(),
        k3=true_sc.k3,
        start=base.to_text(),
    )
    sc = case.scenario.with_law(base)
    try:
        rec = R.reference_record((true_sc.with_law(true), true), periods=15, seed=seed, check=False)
        ev = evaluate(true_sc, true, Reference.from_measurement(rec, sc, n_boot=16, seed=0))
        row.update(true_consistent=ev.consistent, true_verdict=ev.verdict)
        t0 = time.perf_counter()
        res = explain(sc, rec, "linear", workers=workers)
        row.update(
            seconds=time.perf_counter() - t0,
            named=[it.effect for it in res.iterations if it.effect],
            kept=list(res.final_model.effects),
            dropped=[d["effect"] for d in res.dropped],
            I2_start=(res.iterations[0].criteria_before if res.iterations else res.criteria).get(
                "I2"
            ),
            I2_final=res.criteria.get("I2"),
            floor=res.noise_floor.get("I2"),
            start_consistent=not res.iterations,
            consistent=res.consistent,
            stopped=res.stopped_because,
            final=str(res.final_model),
        )
    except Exception as exc:  # noqa: BLE001 (a survey row records any failure)
        row["error"] = f"{type(exc).__name__}: {exc}"
    return row


def outcome(r):
    """The row's class for the rates."""
    if "skip" in r:
        return "skipped"
    if "error" in r and r.get("true_consistent"):
        return "explain raised an error"
    if "error" in r or not r.get("true_consistent"):
        return "invalid: the true model is not consistent with its own record"
    # the effects the final model keeps (an effect named early and taken out again, once a
    # later refit made it negligible, is not the answer); rows from before that step: named
    named, hidden = r.get("kept", r["named"]), r["hidden"]
    if hidden == "none":
        return "clean: nothing added" if not named else "false discovery"
    if not named:
        if r["start_consistent"]:
            return "too weak: the linear start is consistent"
        if "I4 alone" in r["stopped"]:
            return "too weak: I2 within its noise, I4 alone fails"
        return "missed"
    if named[0] != hidden:
        return "wrong effect named"
    shrinks = r["I2_final"] <= r["I2_start"] / 3 or r["I2_final"] <= 1.5 * r["floor"]
    return "named, gap shrinks to the bar" if shrinks else "named, gap short of the bar"


#: the outcomes of a hidden effect that shows in I2 (the start's I2 beyond its limit)
BEYOND = (
    "named, gap shrinks to the bar",
    "named, gap short of the bar",
    "wrong effect named",
    "missed",
)

#: the table's rows: a category of draws, or all of them
LABELS = {
    "P1": ("p1",),
    "slow P1": ("p1-slow",),
    "subharmonic": ("subharmonic",),
    "short contact": ("short-contact",),
    "all": CATEGORIES,
}


def read_rows(paths):
    """The draws of the run files ``paths`` (in the order the runs started), a later row of
    a draw replacing an earlier one, in the order of the draws."""
    by_draw = {r["i"]: r for p in paths for r in measured.read(p)[1]}
    return [by_draw[i] for i in sorted(by_draw)]


def _kept(r):
    """The effects the row's final model keeps (rows from before that was recorded: the
    effects named)."""
    return r.get("kept", r.get("named")) or ()


def counts(rows):
    """``{outcome: draws}`` of ``rows``, with ``"more than one kept"`` (any draw whose
    final model keeps more than one effect)."""
    out = collections.Counter(outcome(r) for r in rows)
    out["more than one kept"] = sum(len(_kept(r)) > 1 for r in rows)
    return out


def _percent(k, n, of=False):
    """``k (P %)`` of ``n`` (``k of n (P %)`` with ``of``)."""
    text = f"{k} of {n}" if of else str(k)
    return f"{text} ({100 * k / n:.0f} %)" if n else text


def markdown_row(rows, label):
    """One row of docs/validation.md's table: the draws of ``label``'s categories by
    :func:`outcome` (the columns: see the page)."""
    rows = [r for r in rows if r["category"] in LABELS[label]]
    n = counts(rows)
    skipped = [r for r in rows if "skip" in r]
    hertz = sum("no linear start" in r["skip"] for r in skipped)
    nothing = sum(k for o, k in n.items() if o.startswith("invalid")) + len(skipped) - hertz
    clean = n["clean: nothing added"] + n["false discovery"]
    weak = n["too weak: the linear start is consistent"]
    weak_i4 = n["too weak: I2 within its noise, I4 alone fails"]
    beyond = sum(n[o] for o in BEYOND)
    raised = n["explain raised an error"]
    bold = "**{}**".format if label == "all" else str
    cells = [
        bold(label),
        len(rows),
        hertz,
        nothing,
        f"{n['false discovery']} of {clean}",
        f"{weak + weak_i4}" + (f" ({weak_i4} by I4 alone)" if weak_i4 else ""),
        bold(raised) if raised else raised,
        beyond,
        bold(_percent(n["named, gap shrinks to the bar"], beyond)),
        n["named, gap short of the bar"],
        bold(n["wrong effect named"]),
        n["missed"],
        n["more than one kept"],
    ]
    return "| " + " | ".join(str(c) for c in cells) + " |"


def readme_row(rows, label):
    """The README's row: the draws (``label`` after their number); where the start's I2 is
    beyond its limit, the right effect named first with the gap to the bar; wrong effects
    named; false discoveries; ``explain`` raising an error."""
    n = counts(rows)
    beyond = sum(n[o] for o in BEYOND)
    clean = n["clean: nothing added"] + n["false discovery"]
    cells = [
        f"{len(rows)} {label}",
        _percent(n["named, gap shrinks to the bar"], beyond, of=True),
        n["wrong effect named"],
        f"{n['false discovery']} of {clean}",
        n["explain raised an error"],
    ]
    return "| " + " | ".join(str(c) for c in cells) + " |"


def _is_miss(r):
    """A draw the rates count against ``explain`` (a false discovery, the right effect
    short of the bar, a wrong effect, nothing named for an effect that shows, more than one
    effect kept, ``explain`` raising an error) or one whose run raised an error."""
    o = outcome(r)
    return (
        o in ("false discovery", *BEYOND[1:])
        or len(_kept(r)) > 1
        or ("error" in r and "skip" not in r)
    )


def _g(x):
    return "-" if x is None else f"{x:.3g}"


def _hidden_cell(r):
    hidden = r.get("hidden", "-")
    if hidden == "support_nonlinearity":
        return f"{hidden} (k3 {r['k3']:.3g})"
    if hidden in ("permanent_set", "unloading_damping"):
        part = r["true"].split(";", 1)[-1].strip()
        return f"{hidden} (`{re.sub(r'[0-9.]+', lambda m: f'{float(m[0]):.3g}', part)}`)"
    return hidden


def misses_rows(rows, label=None):
    """The rows of docs/validation.md's table of the misses (one per draw, or one saying
    there are none)."""
    out = []
    for r in rows:
        if not _is_miss(r):
            continue
        k = r.get("impacts")
        regime = r.get("regime", "-") + (f", {k} impact{'s' * (k > 1)}" if k else "")
        gone = r.get("dropped") or ()
        named = (
            ", ".join(
                f"`{e}`" + (" (taken out)" if e in gone else "") for e in r.get("named") or ()
            )
            or "nothing"
        )
        if "error" in r:
            named, gap = "-", r["error"].replace("|", "/")
        else:
            gap = f"{_g(r['I2_start'])} -> {_g(r['I2_final'])} (floor {_g(r['floor'])})"
        cells = [r["i"], r["category"], regime, _hidden_cell(r), named, gap, outcome(r)]
        out.append("| " + " | ".join(str(c) for c in cells) + " |")
    return out or ["| none |  |  |  |  |  |  |"]


def _draw(context, i):
    """One draw in an executor's worker (its ``explain`` in that process)."""
    return draw(i, workers=1)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--draws", nargs=2, type=int, metavar=("FIRST", "STOP"), help="draw indices FIRST .. STOP-1"
    )
    ap.add_argument("--out", help="run file (tests.measured) the rows are appended to")
    ap.add_argument(
        "--workers", type=int, default=1, help="draws run at once, in processes (default 1)"
    )
    ap.add_argument("--summary", help="count the outcomes of a JSON-lines file")
    args = ap.parse_args(argv)
    if args.summary:
        rows = read_rows([args.summary])
        for r in rows:
            print(
                f"{r['i']:3d} {r['category']:14s} {r.get('regime', '-'):4s} "
                f"{r.get('hidden', '-'):30s} {outcome(r)}"
            )
        print(dict(counts(rows)))
        return 0
    if not (args.draws and args.out):
        ap.error("give --draws FIRST STOP and --out FILE, or --summary FILE")
    out = measured.RunFile(args.out, "survey_explain", argv, append=True)
    draws = list(range(*args.draws))
    if args.workers > 1:
        from discovery.numerics.executor import make_executor
        from discovery.warm import warm

        warm()  # numba's cache built here, before the workers load it
        with make_executor(args.workers) as ex:
            for k, row in ex.run(_draw, draws):
                out.write(row)
                print(f"draw {draws[k]}: {outcome(row)}", flush=True)
    else:
        for i in draws:
            row = draw(i)
            out.write(row)
            print(f"draw {i}: {outcome(row)}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
