"""Random survey of the missing-effect workflow (the README's rates).

Draws machines and laws with the test generator (:func:`tests.realistic.draw_case`: P1,
slow P1, subharmonic and short-contact categories in turn), hides one effect, makes a
record with the independent scipy path (1 % force noise, 0.2 % of each motion channel's
range, 20 kHz, from rest through the draw's transient) and runs ``explain`` from the linear
start:

* a ``zzd`` draw hides its own ``z*zd`` share (``penetration_velocity_coupling``);
* a ``linear`` draw hides, at random, nothing, a set 0.2-0.5, unloading damping 0.3-0.8 of
  the loading damper, or stiffening supports at 10-50 % of ``k1`` at the grid's excursion;
* a Hertz-type draw is skipped (its law has no linear start).

Run from the repository root (about 40 minutes for 60 draws on two cores)::

    python -m tests.survey_explain --draws 0 60 --out survey.jsonl
    python -m tests.survey_explain --summary survey.jsonl

Each output line is one draw (JSON) with the versions it ran with.
"""

import argparse
import collections
import sys
import time

import numpy as np

from discovery import ForceLaw
from discovery._io import provenance
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


def draw(i):
    """One survey row (a dict)."""
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
        res = explain(sc, rec, "linear")
        row.update(
            seconds=time.perf_counter() - t0,
            named=[it.effect for it in res.iterations if it.effect],
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
    if "error" in r or not r.get("true_consistent"):
        return "invalid: the true model is not consistent with its own record"
    named, hidden = r["named"], r["hidden"]
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


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument(
        "--draws", nargs=2, type=int, metavar=("FIRST", "STOP"), help="draw indices FIRST .. STOP-1"
    )
    ap.add_argument("--out", help="run file (tests.measured) the rows are appended to")
    ap.add_argument("--summary", help="count the outcomes of a JSON-lines file")
    args = ap.parse_args(argv)
    if args.summary:
        rows = measured.read(args.summary)[1]
        for r in rows:
            print(
                f"{r['i']:3d} {r['category']:14s} {r.get('regime', '-'):4s} "
                f"{r.get('hidden', '-'):30s} {outcome(r)}"
            )
        print(dict(collections.Counter(outcome(r) for r in rows)))
        return 0
    if not (args.draws and args.out):
        ap.error("give --draws FIRST STOP and --out FILE, or --summary FILE")
    out = measured.RunFile(args.out, "survey_explain", argv, append=True)
    for i in range(*args.draws):
        out.write(draw(i))
    return 0


if __name__ == "__main__":
    sys.exit(main())
