"""Survey of the realistic test-case generator (not a test).

Usage::

    python tests/realistic_survey.py --n 5 [--first-seed 0] [--categories p1,subharmonic]

Draws N cases per category (seeds first-seed .. first-seed + N - 1) and prints
category, seed, regime, impacts, max |multiplier|, contact fraction, tries, the law,
the seconds to draw the case (all of it, reference checks included), the default
transient [periods] and the seconds to make and check its default reference record
(15 periods at 20 kHz after the default transient; part of the draw time).  A note
says how many accepted draws the reference check dropped.
"""

import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
# the repository root must come before tests/ (tests/constraints would shadow the
# top-level constraints package)
sys.path[0:1] = [str(HERE.parent)]
sys.path.append(str(HERE))

import realistic as R  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, default=5, help="cases per category")
    ap.add_argument("--first-seed", type=int, default=0)
    ap.add_argument("--categories", default=",".join(R.CATEGORIES))
    args = ap.parse_args(argv)
    head = (f"{'category':<14} {'seed':>4} {'regime':<6} {'imp':>3} {'max|mu|':>7} "
            f"{'contact':>7} {'tries':>5} {'draw s':>6} {'trans':>5} {'ref s':>6}  law")
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
            print(f"{cat:<14} {seed:>4} {case.regime:<6} {case.impacts:>3} "
                  f"{case.max_multiplier:7.3f} {case.contact_fraction:7.3f} {case.tries:>5} "
                  f"{t_draw:6.1f} {trans:>5} {rec:>6}  [{case.kind}] {case.law}"
                  + (f"  (reference check dropped {len(case.reference_rejects)})"
                     if case.reference_rejects else ""), flush=True)


if __name__ == "__main__":
    main()
