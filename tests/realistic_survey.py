"""Survey of the realistic test-case generator and of verification on its records (not a test).

Usage::

    python tests/realistic_survey.py --n 5 [--first-seed 0] [--categories p1,subharmonic]
    python tests/realistic_survey.py --properties --n 6 [--noise-seeds 2] [--verbose]

Draws N cases per category (seeds first-seed .. first-seed + N - 1, reproducible).

Without ``--properties`` it prints category, seed, regime, impacts, max |multiplier|,
contact fraction, tries, the law, the seconds to draw the case (all of it, reference
checks included), the default transient [periods] and the seconds to make and check
its default reference record (15 periods at 20 kHz after the default transient; part
of the draw time).  A note says how many accepted draws the reference check dropped.

With ``--properties`` it verifies, on ``--noise-seeds`` noisy records of each case
(default record: 15 periods at 20 kHz, 1 % force and 0.2 % motion noise), the true
law and every wrong law of :func:`realistic.wrong_laws` (one real term dropped, one
coefficient off by 30 %) with :func:`discovery.vibroimpact.verify.evaluate`, and prints per
category and in all:

* the rate at which the true law is consistent with its record;
* the rate at which a wrong law is inconsistent, among the *detectable* ones (its I2
  against the noise-free record exceeds ``2 x noise floor + 0.005``, the floor being
  the one computed on the noisy record; or another regime there): see
  :class:`realistic.Trial`;

with their counts, and every failure of either property on its own line.  ``--out FILE``
also writes every trial as a JSON line to a run file of :mod:`tests.measured` (the
measured tables of docs/validation.md are rendered from such files, :mod:`tests.tables`).
"""

import argparse
import math
import sys
import time
from collections import defaultdict
from pathlib import Path
from types import SimpleNamespace

HERE = Path(__file__).resolve().parent
if not __package__:  # run as a script: python tests/realistic_survey.py
    # the repository root must come before tests/ (tests/constraints would shadow the
    # top-level constraints package)
    sys.path[0:1] = [str(HERE.parent)]

from tests import measured  # noqa: E402
from tests import realistic as R  # noqa: E402

_TRIAL_FIELDS = (
    "label",
    "status",
    "consistent",
    "detectable",
    "i2",
    "floor_i2",
    "i2_clean",
    "regime",
    "verdict",
    "i2_rule",
)


def trial_row(cat, seed, noise_seed, tr):
    """One trial as a JSON-able row of a run file (NaN as None)."""
    row = {"category": cat, "seed": seed, "noise_seed": noise_seed, "law": str(tr.law)}
    for k in _TRIAL_FIELDS:
        v = getattr(tr, k)
        if k in ("consistent", "i2_rule") or (k == "detectable" and v is not None):
            v = bool(v)
        elif k in ("i2", "floor_i2", "i2_clean"):
            v = None if v is None or math.isnan(float(v)) else float(v)
        row[k] = v
    return row


def trials_of(rows):
    """The ``(category, seed, noise_seed, trial)`` tuples of run-file rows (for :func:`rates`)."""
    return [(r["category"], r["seed"], r["noise_seed"], SimpleNamespace(**r)) for r in rows]


def markdown_row(rows, label):
    """One row of docs/validation.md's table of the verification properties: the true law
    consistent, the detectable wrong laws inconsistent, the undetectable ones."""
    r = rates(trials_of(rows))
    return f"| {label} | {_pct(*r['true'])} | {_pct(*r['wrong'])} | {r['undetectable']} |"


def category_row(rows, label):
    """One row of the per-category table: ``label`` a category in backquotes (its records'
    trials) or ``all`` (every record's)."""
    name = label.strip("`")
    mine = rows if name == "all" else [r for r in rows if r["category"] == name]
    return markdown_row(mine, label)


def _pct(k, n):
    return f"{k}/{n} = {100.0 * k / n:.1f} %".replace(".0 %", " %") if n else f"{k}/{n}"


def _draw_table(args):
    head = (
        f"{'category':<14} {'seed':>4} {'regime':<6} {'imp':>3} {'max|mu|':>7} "
        f"{'contact':>7} {'tries':>5} {'draw s':>6} {'trans':>5} {'ref s':>6}  law"
    )
    print(head)
    print("-" * len(head))
    for cat in args.categories.split(","):
        for seed in range(args.first_seed, args.first_seed + args.n):
            t0 = time.perf_counter()
            try:
                case = R.draw_case(cat, seed)
            except RuntimeError as exc:
                print(f"{cat:<14} {seed:>4} {exc}")
                continue
            t_draw = time.perf_counter() - t0
            trans = R.default_transient(case)
            # the draw made (and checked) the noise-free default record: its time
            rec = f"{case.reference_seconds:6.1f}"
            print(
                f"{cat:<14} {seed:>4} {case.regime:<6} {case.impacts:>3} "
                f"{case.max_multiplier:7.3f} {case.contact_fraction:7.3f} {case.tries:>5} "
                f"{t_draw:6.1f} {trans:>5} {rec:>6}  [{case.kind}] {case.law}"
                + (
                    f"  (reference check dropped {len(case.reference_rejects)})"
                    if case.reference_rejects
                    else ""
                ),
                flush=True,
            )


def rates(trials):
    """``{"true": (consistent, n), "wrong": (inconsistent, detectable n),
    "undetectable": n, "failed": n}`` over ``(category, seed, noise_seed, Trial)``; and
    ``"true_i2"``, ``"wrong_i2"``: the same by the rule on I2 alone."""
    out = {
        "true": [0, 0],
        "wrong": [0, 0],
        "undetectable": 0,
        "failed": 0,
        "true_i2": [0, 0],
        "wrong_i2": [0, 0],
    }
    for *_, tr in trials:
        if tr.label == "true":
            out["true"][0] += tr.consistent
            out["true"][1] += 1
            out["true_i2"][0] += tr.i2_rule
            out["true_i2"][1] += 1
        elif tr.detectable is None:
            out["failed"] += 1
        elif tr.detectable:
            out["wrong"][0] += not tr.consistent
            out["wrong"][1] += 1
            out["wrong_i2"][0] += not tr.i2_rule
            out["wrong_i2"][1] += 1
        else:
            out["undetectable"] += 1
    return out


def _fmt_rate(k, n):
    return f"{k}/{n} = {100.0 * k / n:5.1f} %" if n else f"{k}/{n}"


def _properties(args):
    from discovery.vibroimpact.verify import CONSISTENCY_FACTOR, CONSISTENCY_SLACK
    from discovery.vibroimpact.verify import evaluate as ev_mod

    crit = getattr(sys.modules[ev_mod.__module__], "CONSISTENCY_CRITERIA", ("I2",))
    print(
        f"consistency rule: {', '.join(crit)} <= {CONSISTENCY_FACTOR:g} x noise floor + "
        f"{CONSISTENCY_SLACK:g}, same regime; noise seeds per case {args.noise_seeds}"
    )
    all_trials = []
    out = measured.RunFile(args.out, "realistic_survey", args.argv) if args.out else None
    t_start = time.perf_counter()
    for cat in args.categories.split(","):
        for seed in range(args.first_seed, args.first_seed + args.n):
            t0 = time.perf_counter()
            try:
                case = R.draw_case(cat, seed)
            except RuntimeError as exc:
                print(f"{cat:<14} {seed:>4} {exc}", flush=True)
                continue
            t_draw = time.perf_counter() - t0
            for ns in range(args.noise_seeds):
                t1 = time.perf_counter()
                try:
                    kw = R.field_record_kw(case) if args.field else {}
                    trials = R.verification_trials(case, ns, **kw)
                except RuntimeError as exc:  # the record disagrees with the kernel
                    print(f"{cat:<14} {seed:>4} noise {ns}: {exc}", flush=True)
                    continue
                all_trials += [(cat, seed, ns, tr) for tr in trials]
                for tr in trials if out is not None else ():
                    out.write(trial_row(cat, seed, ns, tr))
                r = rates([(cat, seed, ns, tr) for tr in trials])
                print(
                    f"{cat:<14} {seed:>4} n{ns} {case.regime:<3} imp {case.impacts} "
                    f"contact {case.contact_fraction:.3f} [{case.kind}] true "
                    f"{'ok ' if trials[0].consistent else 'BAD'} I2 {trials[0].i2:.3f} "
                    f"(floor {trials[0].floor_i2:.3f}, clean {trials[0].i2_clean:.4f}); "
                    f"wrong inconsistent {r['wrong'][0]}/{r['wrong'][1]} detectable "
                    f"(+{r['undetectable']} undetectable, {r['failed']} failed)  "
                    f"draw {t_draw:.1f} s, verify {time.perf_counter() - t1:.1f} s",
                    flush=True,
                )
                for tr in trials:
                    bad = (tr.label == "true" and not tr.consistent) or (
                        tr.label != "true" and tr.detectable and tr.consistent
                    )
                    if bad or args.verbose:
                        print(
                            f"    {'FAIL' if bad else '    '} {tr.label:<14} {tr.status:<11} "
                            f"{tr.regime:<5} I2 {tr.i2:.4f} floor {tr.floor_i2:.4f} clean "
                            f"{tr.i2_clean:.4f} detectable {tr.detectable}: {tr.verdict}",
                            flush=True,
                        )
    print()
    print(
        f"{'category':<14} {'true law consistent':>24} {'wrong law inconsistent':>26} "
        f"{'undetectable':>12} {'failed':>6}"
    )
    by_cat = defaultdict(list)
    for row in all_trials:
        by_cat[row[0]].append(row)
    for cat, rows in [*by_cat.items(), ("all", all_trials)]:
        r = rates(rows)
        print(
            f"{cat:<14} {_fmt_rate(*r['true']):>24} {_fmt_rate(*r['wrong']):>26} "
            f"{r['undetectable']:>12} {r['failed']:>6}"
        )
    if "I4" in crit:
        print("with the rule on I2 alone (same regime, I2 <= 2 x floor + 0.005):")
        for cat, rows in [*by_cat.items(), ("all", all_trials)]:
            r = rates(rows)
            print(f"{cat:<14} {_fmt_rate(*r['true_i2']):>24} {_fmt_rate(*r['wrong_i2']):>26}")
    print(f"({time.perf_counter() - t_start:.0f} s)")


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=5, help="cases per category")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--categories", default=",".join(R.CATEGORIES))
    ap.add_argument(
        "--properties",
        action="store_true",
        help="verify the true and wrong laws on noisy records (rates)",
    )
    ap.add_argument(
        "--noise-seeds", type=int, default=1, help="noisy records per case (with --properties)"
    )
    ap.add_argument("--verbose", action="store_true", help="every trial on its own line")
    ap.add_argument(
        "--field",
        action="store_true",
        help="the field-like setting (realistic.FIELD): slow P1 up to multiplier "
        "0.995, records after at most 250 periods from rest, 5 or 20 kHz",
    )
    ap.add_argument("--out", metavar="JSONL", help="with --properties: also write a run file")
    args = ap.parse_args(argv)
    args.argv = sys.argv[1:] if argv is None else argv
    if args.field:
        R.MAX_MULTIPLIER = R.FIELD["multiplier"]
    if args.properties:
        _properties(args)
    else:
        _draw_table(args)


if __name__ == "__main__":
    main()
