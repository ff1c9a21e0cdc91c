"""Survey of the experiment loop (:func:`discovery.campaign`): does it settle the true law?

Each draw is a random machine and law of :mod:`tests.realistic` (a category of
``CATEGORIES`` in turn: P1, slow transients, subharmonics with several impacts, short
contacts; a law of each kind), recorded by the independent scipy path from rest.  The
tool is given the machine as a designer's sheet a few percent off (masses, support
stiffness and damping each off by up to +-5 %, seeded); the loop calibrates the machine
from the records.  Every draw runs at two noise levels (force 1 % of its peak, motions
0.2 % of their range; and a quarter of both).  The knobs: the drive amplitude in 0.7-1.3 x
and the frequency in 0.8-1.2 x the first record's, a safe region of three times its peak
force, four records at most.  Each next record is made by the same path at the point the
loop advises, with the true machine.

With ``--family coupled`` the draws are instead ``tests/survey_advise.py``'s laws with a
``z*zd`` share on the paper's machine and the corpus's machine B (whose first record often
leaves rivals), the sheet off the same way: the advised pairs of those runs, with what the
joint fit made of each rival, are the calibration table of the predicted separation
(:func:`calibration_row`).

A run counts as *right* when the loop ends with the true law's support selected (for the
``hertz`` kind, fitted with ``poly:2+hc``; the others with ``poly:2``) and every model still
listed holds the truth's terms.

Run from the repository root (about a minute per run on two cores)::

    python -m tests.survey_campaign --draws 0 12 --out campaign-random.jsonl
    python -m tests.survey_campaign --family coupled --draws 0 12 --out campaign-coupled.jsonl
    python -m tests.survey_campaign --summary campaign.jsonl
"""

import argparse
import json
import sys
import time
import traceback

import numpy as np

from discovery import DiscoverSettings, ForceLaw, campaign
from discovery._files._io import provenance
from discovery.vibroimpact.advise import Knobs, SafeRegion
from tests import measured, survey_advise
from tests import realistic as R

#: (force noise, motion noise) of the two levels
LEVELS = ((0.01, 0.002), (0.0025, 0.0005))
#: the sheet's largest relative error on each machine parameter
SHEET_ERROR = 0.05


def sheet_of(truth, seed):
    """The designer's sheet of the machine ``truth``: its masses and supports a few % off."""
    return R.sheet_of(truth, seed, dict.fromkeys(("m1", "m2", "k1", "c1"), SHEET_ERROR))


def _terms(text):
    return sorted(ForceLaw.parse(text).names)


def _case(draw, family):
    """``(true machine, law, category, kind)`` of a draw of a family."""
    if family == "coupled":
        sc, law, _ = survey_advise.case_of(draw)
        kind = "zzd" if "z*zd" in law.names else "linear"
        return sc, law, "coupled", kind
    category = R.CATEGORIES[draw % len(R.CATEGORIES)]
    case = R.draw_case(category, 7000 + draw)
    return case.scenario, case.law, category, case.kind


def run(draw, level, family="random"):
    t0 = time.time()
    truth, law, category, kind = _case(draw, family)
    sheet = sheet_of(truth, 7000 + draw)
    fnoise, mnoise = LEVELS[level]
    row = {
        "draw": draw,
        "level": level,
        "family": family,
        "category": category,
        "kind": kind,
        "law": law.to_text(),
        "noise": [fnoise, mnoise],
    }

    def record(machine, seed):
        return R.reference_record(
            (machine.with_law(law), law), force_noise=fnoise, motion_noise=mnoise, seed=seed
        )

    def acquire(request):
        m = truth.replace(A=request.amplitude, frequency=request.frequency)
        return record(m, 7000 + draw + 100 * request.step)

    try:
        first = record(truth, 7000 + draw)
        knobs = Knobs(
            (0.7 * truth.A, 1.3 * truth.A),
            (0.8 * truth.frequency, 1.2 * truth.frequency),
            grid=(4, 4),
        )
        library = "poly:2+hc" if kind == "hertz" else "poly:2"
        res = campaign(
            sheet,
            first,
            acquire,
            knobs,
            safe=SafeRegion(max_force=3.0 * float(np.max(first.F))),
            fit=DiscoverSettings(library=library, n_boot_intervals=0),
            workers=2,
            progress=False,
        )
    except Exception as exc:  # noqa: BLE001 - a survey row records what went wrong
        row.update(error=f"{type(exc).__name__}: {exc}", trace=traceback.format_exc()[-2000:])
        row["s"] = time.time() - t0
        return row
    truth_terms = set(law.names)
    row.update(
        stopped=res.stopped,
        records=len(res.records),
        selected=res.law,
        right=_terms(res.law) == sorted(truth_terms)
        and all(truth_terms <= set(ForceLaw.parse(t).names) for t in res.remaining),
        first_right=_terms(res.steps[0].selected) == sorted(truth_terms)
        and len(res.steps[0].candidates) == 1,
        consistent=res.steps[-1].consistent,
        reason=res.reason,
        steps=[s.to_dict() for s in res.steps],
        s=time.time() - t0,
    )
    return row


def summary(rows):
    done = [r for r in rows if "error" not in r]
    for r in rows:
        if "error" in r:
            print(f"{r['draw']:3d}/{r['level']} {r['category']:13s} error: {r['error'][:160]}")
            continue
        print(
            f"{r['draw']:3d}/{r['level']} {r['category']:13s} {r['kind']:6s} {r['stopped']:15s} "
            f"{'right' if r['right'] else 'WRONG'} after {r['records']} record(s) "
            f"({r['s']:.0f} s)"
        )
    right = sum(r["right"] for r in done)
    print(
        f"{len(rows)} runs, {len(done)} without error: right {right}, first record alone "
        f"{sum(r['first_right'] for r in done)}"
    )
    pairs = {}
    for r in done:
        pairs.setdefault(r["draw"], {})[r["level"]] = r["right"]
    worse = [d for d, p in pairs.items() if p.get(0) and p.get(1) is False]
    print(f"draws where the quieter record ends wrong but the noisier right: {worse}")
    return right, len(done)


def predictions(rows):
    """Every advised pair of the selected law and a rival, with what came of it: ``(predicted
    separation or None for a regime/physics one, refitted or None, by, rejected, told
    apart)``, where *rejected* means the rival's support is gone from the next joint fit's
    candidates, and *told apart* that one of the two is (the selected law's, where it was
    the wrong one: the prediction is made as if the selected law were true, and a record
    that rejects the selected law instead settles the pair too)."""
    out = []
    for r in rows:
        steps = r.get("steps") or []
        for k, step in enumerate(steps[:-1]):
            point = step.get("point") or {}
            after = {tuple(_terms(c)) for c in steps[k + 1]["candidates"]}
            for q in point.get("pairs") or []:
                i, j = q["pair"]
                if i != 0:
                    continue
                rival = tuple(_terms(step["candidates"][j]))
                selected = tuple(_terms(step["candidates"][0]))
                gone = rival not in after
                out.append(
                    (
                        q["separation"],
                        q.get("refitted"),
                        q["by"],
                        gone,
                        gone or selected not in after,
                    )
                )
    return out


def _share(items):
    n = len(items)
    return f"{sum(items)} of {n}" if n else "-"


def calibration_row(rows, label):
    """One row of the calibration table: the advised pairs predicted in one class, and how
    many of their rivals the joint fit with the new record rejected."""
    preds = predictions(rows)
    pick = {
        "separated by criteria (> 1)": lambda p: p[2] == "criteria" and p[0] > 1,
        "separated by regime or physics": lambda p: p[2] != "criteria",
        "not separated (<= 1)": lambda p: p[2] == "criteria" and p[0] <= 1,
        "refitted > 1": lambda p: p[1] is not None and p[1] > 1,
        "refitted <= 1": lambda p: p[1] is not None and p[1] <= 1,
    }[label]
    chosen = [p for p in preds if pick(p)]
    rejected, apart = [p[3] for p in chosen], [p[4] for p in chosen]
    return f"| {label} | {len(chosen)} | {_share(rejected)} | {_share(apart)} |"


#: the calibration table's rows
PREDICTED = (
    "separated by criteria (> 1)",
    "separated by regime or physics",
    "not separated (<= 1)",
    "refitted > 1",
    "refitted <= 1",
)

#: the table's rows: the noise levels, then every run
LABELS = {"force 1 %, motions 0.2 %": (0,), "force 0.25 %, motions 0.05 %": (1,), "all": (0, 1)}


def markdown_row(rows, label):
    """One row of docs/advise.md's table: runs, errors, how the loop stopped, how often it
    ends with the true law (and on the first record alone), the records it took, and the
    draws where the quieter record ends wrong but the noisier right (all rows only)."""
    levels = LABELS[label]
    mine = [r for r in rows if r["level"] in levels]
    done = [r for r in mine if "error" not in r]
    stops = {}
    for r in done:
        stops[r["stopped"]] = stops.get(r["stopped"], 0) + 1
    taken = sorted(r["records"] for r in done)
    pairs = {}
    for r in done:
        pairs.setdefault(r["draw"], {})[r["level"]] = r["right"]
    worse = sum(1 for p in pairs.values() if p.get(0) and p.get(1) is False)
    cells = [
        label,
        len(mine),
        len(mine) - len(done),
        ", ".join(f"{k} {v}" for k, v in sorted(stops.items())) or "-",
        f"**{sum(r['right'] for r in done)}**",
        sum(r["right"] and r["records"] == 1 for r in done),
        f"{taken[len(taken) // 2]} / {taken[-1]}" if taken else "-",
        worse if label == "all" else "",
    ]
    return "| " + " | ".join(str(c) for c in cells) + " |"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--draws", nargs=2, type=int, metavar=("FIRST", "STOP"))
    ap.add_argument("--out", help="JSON-lines file the rows are appended to")
    ap.add_argument("--summary", help="count the outcomes of a JSON-lines file")
    ap.add_argument(
        "--family",
        choices=("random", "coupled"),
        default="random",
        help="random: tests.realistic's machines and laws; coupled: survey_advise's laws with "
        "a z*zd share, whose first record often leaves rivals (default: random)",
    )
    args = ap.parse_args(argv)
    if args.summary:
        summary(measured.read(args.summary)[1])
        return 0
    if not (args.draws and args.out):
        ap.error("give --draws FIRST STOP and --out FILE, or --summary FILE")
    versions = provenance()["versions"]
    out = measured.RunFile(args.out, "survey_campaign", argv, append=True)
    for draw in range(*args.draws):
        for level in (0, 1):
            row = run(draw, level, args.family)
            row["versions"] = versions
            out.write(row)
            print(json.dumps({k: row.get(k) for k in ("draw", "level", "stopped", "right", "s")}))
    return 0


if __name__ == "__main__":
    sys.exit(main())
