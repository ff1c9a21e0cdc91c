"""Survey of ``vidi fit`` on random machines known to 5 %, two noise levels (not a test).

Each record is given to the tool with a designer's sheet off the machine that made it,
calibrated from the record as ``vidi fit`` does.

Usage::

    python -m tests.survey_fit_sheet --draws 0 16 [--workers 2] --out docs/_measured/fit-sheet.jsonl

Draw ``i`` is a case of the generator's category ``CATEGORIES[i % 4]``
(:func:`tests.realistic.draw_case`, seed ``8100 + i``: a random machine, drive and law,
Hunt-Crossley laws included).  Its sheet has the masses, the support stiffness and the
support damping each off by a uniform draw within +-5 % (seed ``8655 + i``).  Each draw is
recorded twice by the independent scipy path from rest (15 periods at 20 kHz after the
generator's transient): force noise 2 % of its peak and motion noise 0.4 % of each
channel's range, and a quarter of that.  On each record: the machine calibrated from the
sheet (:func:`discovery.calibrate`), then :func:`discovery.discover` with the ``poly:2``
library, the calibrated machine and its scale range, no intervals.  A row: the selected law,
whether its support is the true one, whether it is consistent with the record, the largest
relative error of its coefficients on the true support, or the refusal or error.
"""

import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
if not __package__:
    sys.path[0:1] = [str(HERE.parent)]

from tests import measured  # noqa: E402

CATEGORIES = ("p1", "p1-slow", "subharmonic", "short-contact")
#: (force, motion) noise of each draw's two records: shares of the force's peak and of each
#: motion channel's range
NOISE = {"high": (0.02, 0.004), "low": (0.005, 0.001)}
#: the sheet's errors: uniform within +- these shares
SHEET_ERRORS = {"m1": 0.05, "m2": 0.05, "k1": 0.05, "c1": 0.05}
LIBRARY = "poly:2"


def run_draw(i):
    """The two rows of draw ``i`` (one per noise level)."""
    from discovery import calibrate
    from discovery.errors import InputError
    from discovery.vibroimpact.fit.discovery import discover
    from discovery.vibroimpact.model.library import Library
    from tests import realistic as R

    cat = CATEGORIES[i % len(CATEGORIES)]
    case = R.draw_case(cat, 8100 + i)
    sheet = R.sheet_of(case.scenario, 8655 + i, SHEET_ERRORS)
    terms = {t.name for t in Library.parse(LIBRARY).terms}
    base = {
        "draw": i,
        "category": cat,
        "seed": 8100 + i,
        "true": case.law.to_text(),
        "in_library": set(case.law.names) <= terms,
    }
    rows = []
    for level, (fn, mn) in NOISE.items():
        row = {**base, "noise": level}
        t0 = time.perf_counter()
        try:
            rec = R.reference_record(
                case, periods=15, seed=i, force_noise=fn, motion_noise=mn, check=False
            )
            cal = calibrate(sheet, rec, seed=0)
            res = discover(
                cal.scenario,
                rec,
                library=LIBRARY,
                workers=1,
                n_boot_intervals=0,
                progress=False,
                machine_scale=cal.scale_range,
            )
            sel = res.selected
            right = sorted(sel.law.names) == sorted(case.law.names)
            row.update(
                selected=sel.law.to_text(),
                right_support=right,
                consistent=bool(sel.consistent),
                worst_coefficient_error=_worst(sel.law, case.law) if right else None,
            )
        except InputError as exc:  # a record the tool refuses, with its reason
            row["refused"] = str(exc)
        except Exception as exc:  # noqa: BLE001 (a survey row records any failure)
            row["error"] = f"{type(exc).__name__}: {exc}"
        row["seconds"] = time.perf_counter() - t0
        rows.append(row)
    return rows


def _worst(law, truth):
    """The largest relative error of ``law``'s coefficients against ``truth``'s (the same
    support)."""
    got, want = law.as_dict(), truth.as_dict()
    return max(abs(got[k] / want[k] - 1.0) for k in want)


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument(
        "--draws",
        nargs=2,
        type=int,
        metavar=("FIRST", "STOP"),
        required=True,
        help="the draws FIRST .. STOP - 1 (draw i: category i %% 4, seed 8100 + i)",
    )
    p.add_argument("--workers", type=int, default=2, help="processes, one draw each (2)")
    p.add_argument("--out", required=True, help="the run file of the rows (JSON lines)")
    args = p.parse_args(argv)
    out = measured.RunFile(args.out, "survey_fit_sheet", argv, append=True)
    measured.write_pooled(out, run_draw, range(*args.draws), args.workers)
    return 0


if __name__ == "__main__":
    sys.exit(main())


# ------------------------------------------------------------- the docs' table
HEADER = (
    "| category | records | refused (the reason given) | raised an error | true law outside "
    f"`{LIBRARY}` (of them consistent) | right support | consistent | right support, "
    "consistent, coefficients within 5 % | lower noise wrong where higher right |",
    "|---|---|---|---|---|---|---|---|---|",
)


def read_rows(paths):
    """Every row of the run files ``paths`` (a later row of a draw and noise level replacing
    an earlier one)."""
    by = {(r["draw"], r["noise"]): r for p in paths for r in measured.read(p)[1]}
    return [by[k] for k in sorted(by)]


def _rate(k, n):
    return f"{k}/{n}" if n else "--"


def _good(r):
    """The true support, consistent, every coefficient within 5 %."""
    err = r.get("worst_coefficient_error")
    return bool(r.get("right_support") and r.get("consistent") and err is not None and err <= 0.05)


def markdown_row(rows, label):
    """docs/validation.md's row ``label`` (a category or "all"): the rates among the records
    fitted (neither refused nor failed) whose true law the library holds; the records whose
    true law it does not hold counted apart, with how many of them a law of the library
    still matches within the noise."""
    rows = [r for r in rows if label == "all" or r["category"] == label]
    fitted = [r for r in rows if "refused" not in r and "error" not in r]
    inside = [r for r in fitted if r["in_library"]]
    outside = [r for r in fitted if not r["in_library"]]
    cells = [
        label,
        str(len(rows)),
        str(sum("refused" in r for r in rows)),
        str(sum("error" in r for r in rows)),
        f"{len(outside)} ({sum(r['consistent'] for r in outside)})",
        _rate(sum(bool(r["right_support"]) for r in inside), len(inside)),
        _rate(sum(r["consistent"] for r in inside), len(inside)),
        _rate(sum(_good(r) for r in inside), len(inside)),
        str(_pairs(rows)),
    ]
    return "| " + " | ".join(cells) + " |"


def _pairs(rows):
    """Draws whose quieter record is refused, fails or selects a wrong support where the
    noisier one selects the right one (better data must never give a worse answer)."""
    by = {}
    for r in rows:
        by.setdefault(r["draw"], {})[r["noise"]] = r
    return sum(
        bool(p.get("high", {}).get("right_support")) and not p.get("low", {}).get("right_support")
        for p in by.values()
    )
