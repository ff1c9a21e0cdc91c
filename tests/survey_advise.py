"""Survey of ``advise``: does a record at the advised point settle the law?

For each case (a machine, a true law, a noise seed) a first record is made by the
independent scipy path (:func:`tests.realistic.reference_record`: 1 % force noise, 0.2 % of
each motion channel's range, 20 kHz, 15 periods after the transient from rest) and fitted
(``discover``, the polynomial library ``poly:2``; ``--force-noise`` sets another force noise
for both records).  A case counts only when that fit lists
one or more ``equivalent`` models (two or more candidate laws).  Then:

1. ``advise`` over the candidates (the selected law and its equivalents), with the drive
   amplitude in 0.7..1.3 x and the frequency in 0.8..1.2 x the first record's, the noise of
   the first record, and a safe region of three times the first record's peak force;
2. a second record at the advised point (same path, same noise levels, another seed),
   fitted jointly with the first (``discover`` with both records);
3. the same with a second record at a random point of the same bounds (seeded).

A case is *settled* when the joint fit selects the true law's terms.  The machines are the
paper's (``paper.toml``) and the corpus's machine B (``/work/shared/corpus``, or the same
numbers when the corpus is absent).

Run from the repository root (several minutes per case on two cores)::

    python -m tests.survey_advise --cases 0 6 --out advise.jsonl
    python -m tests.survey_advise --summary advise.jsonl
"""

import argparse
import json
import sys
import time
import traceback

import numpy as np

from discovery import ForceLaw, discover, load_scenario
from discovery._files._io import provenance
from discovery.vibroimpact.advise import Knobs, NoiseModel, SafeRegion, advise
from discovery.vibroimpact.model.scenario import Scenario
from tests import measured
from tests import realistic as R

CORPUS_B = {"m1": 9000.0, "m2": 6000.0, "k1": 2.2e7, "c1": 8e4, "A": 4.2e5, "frequency": 26.0}

# (machine, true law): laws with a z*zd share, whose single record often leaves
# z + zd + z*zd and z + z*zd + zd^2 (or a coefficient trade) equivalent
LAWS = (
    ("paper", "2.06e8*z + 8e6*zd + 4e9*z*zd"),
    ("corpus", "1.5e8*z + 3e6*zd + 8e10*z*zd"),
    ("paper", "2.06e8*z + 5e6*zd + 1.2e10*z*zd"),
    ("corpus", "1.5e8*z + 2e6*zd + 4e10*z*zd"),
    ("paper", "2.06e8*z + 1.28e7*zd"),
    ("corpus", "1.5e8*z + 4e6*zd"),
)


def machine(name):
    if name == "paper":
        return load_scenario("paper")
    return Scenario(**CORPUS_B, name="corpus-B")


def case_of(i):
    """``(scenario with its true law, law, noise seed)`` of case ``i``."""
    name, text = LAWS[i % len(LAWS)]
    law = ForceLaw.parse(text)
    return machine(name).with_law(law), law, 1000 + i


FORCE_NOISE = [0.01]  # set by --force-noise


def record(scenario, law, seed):
    return R.reference_record(
        (scenario, law), force_noise=FORCE_NOISE[0], motion_noise=0.002, seed=seed
    )


def fit(scenarios, records):
    return discover(scenarios, records, n_boot_intervals=0, workers=1)


def _settles(res, law):
    return sorted(res.selected.law.names) == sorted(law.names)


def second_fit(sc0, rec0, law, point, seed):
    """Joint fit of the first record and one at ``point = (A, f)``."""
    sc1 = sc0.replace(A=float(point[0]), frequency=float(point[1]))
    try:
        rec1 = record(sc1, law, seed)
        res = fit([sc0, sc1], [rec0, rec1])
    except Exception as exc:  # a point where the record or fit fails does not settle
        return {"point": list(point), "settled": False, "error": f"{type(exc).__name__}: {exc}"}
    return {
        "point": list(point),
        "settled": _settles(res, law),
        "selected": res.selected.law.to_text(),
        "selected_terms": list(res.selected.law.names),
        "equivalent": [e["terms"] for e in res.equivalent],
    }


def run_case(i):
    t0 = time.time()
    sc, law, seed = case_of(i)
    row = {
        "i": i,
        "machine": sc.name,
        "law": law.to_text(),
        "seed": seed,
        "force_noise": FORCE_NOISE[0],
    }
    rec0 = record(sc, law, seed)
    res0 = fit(sc, rec0)
    laws = [res0.selected.law] + [ForceLaw.from_dict(e["coefficients"]) for e in res0.equivalent]
    row.update(
        first_selected=res0.selected.law.to_text(),
        first_settled=_settles(res0, law),
        candidates=[x.to_text() for x in laws],
    )
    if len(laws) < 2:
        row.update(counted=False, why="the first fit lists no equivalent model", s=time.time() - t0)
        return row
    knobs = Knobs((0.7 * sc.A, 1.3 * sc.A), (0.8 * sc.frequency, 1.2 * sc.frequency), grid=(4, 4))
    noise = NoiseModel.from_measurement(rec0, sc)
    peak = float(np.max(rec0.F))
    adv = advise(sc, laws, knobs, noise, SafeRegion(max_force=3.0 * peak), workers=2)
    b = adv.best
    row["counted"] = b is not None
    if b is None:
        row.update(why="no usable point", s=time.time() - t0)
        return row
    row["advised"] = {
        "point": [b.amplitude, b.frequency],
        "smallest_separation": b.smallest_separation(frozenset(adv.inseparable)),
        "inseparable": [list(q) for q in adv.inseparable],
        "separates": adv.separates,
        "regime_change": any(p.regime_change for p in b.pairs),
        "regimes": [p.regime for p in b.predictions],
    }
    rng = np.random.default_rng(seed)
    rand = (rng.uniform(*knobs.amplitude), rng.uniform(*knobs.frequency))
    row["with_advised"] = second_fit(sc, rec0, law, (b.amplitude, b.frequency), seed + 1)
    row["with_random"] = second_fit(sc, rec0, law, rand, seed + 1)
    row["s"] = time.time() - t0
    return row


def resolved(fit, law_text):
    """Settled, and every model still listed as equivalent holds the true law's terms (the
    truth plus a negligible term cannot be told from it within the noise anywhere)."""
    truth = set(ForceLaw.parse(law_text).names)
    return bool(fit["settled"]) and all(truth <= set(e) for e in fit.get("equivalent") or [])


def summary(rows):
    counted = [r for r in rows if r.get("counted")]
    adv = sum(r["with_advised"]["settled"] for r in counted)
    rnd = sum(r["with_random"]["settled"] for r in counted)
    first = sum(bool(r.get("first_settled")) for r in counted)
    adv_res = sum(resolved(r["with_advised"], r["law"]) for r in counted)
    rnd_res = sum(resolved(r["with_random"], r["law"]) for r in counted)
    for r in rows:
        if not r.get("counted"):
            print(f"{r['i']:3d} {r['machine']:9s} {r['law']:34s} not counted: {r.get('why')}")
            continue
        a = r["advised"]
        print(
            f"{r['i']:3d} {r['machine']:9s} {r['law']:34s} {len(r['candidates'])} candidates; "
            f"advised A {a['point'][0]:.3g} f {a['point'][1]:.3g} (sep "
            f"{a['smallest_separation']:.3g}{', regime' if a['regime_change'] else ''}): "
            f"{'settled' if r['with_advised']['settled'] else 'not settled'}; random: "
            f"{'settled' if r['with_random']['settled'] else 'not settled'}"
        )
    print(
        f"counted cases {len(counted)} of {len(rows)}: the first record alone selects the true "
        f"law in {first}; with a second record at the advised point {adv}, at a random point "
        f"{rnd}"
    )
    print(
        f"  and no rival law left equivalent (only supersets of the truth): advised {adv_res}, "
        f"random {rnd_res}"
    )
    return adv, rnd, len(counted)


def markdown_row(rows, label):
    """One row of docs/validation.md's table: cases run and counted, how many select the
    true law (the first record alone, with the advised and with the random second record)
    and how many leave no rival law equivalent."""
    counted = [r for r in rows if r.get("counted")]
    cells = [
        label,
        len(rows),
        len(counted),
        sum(bool(r["first_settled"]) for r in counted),
        f"**{sum(r['with_advised']['settled'] for r in counted)}**",
        sum(r["with_random"]["settled"] for r in counted),
        f"**{sum(resolved(r['with_advised'], r['law']) for r in counted)}**",
        sum(resolved(r["with_random"], r["law"]) for r in counted),
    ]
    return "| " + " | ".join(str(c) for c in cells) + " |"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", nargs=2, type=int, metavar=("FIRST", "STOP"))
    ap.add_argument("--out", help="JSON-lines file the rows are appended to")
    ap.add_argument("--summary", help="count the outcomes of a JSON-lines file")
    ap.add_argument(
        "--force-noise", type=float, default=0.01, help="force noise of both records (0.01)"
    )
    args = ap.parse_args(argv)
    FORCE_NOISE[0] = args.force_noise
    if args.summary:
        summary(measured.read(args.summary)[1])
        return 0
    if not (args.cases and args.out):
        ap.error("give --cases FIRST STOP and --out FILE, or --summary FILE")
    versions = provenance()["versions"]
    out = measured.RunFile(args.out, "survey_advise", argv, append=True)
    for i in range(*args.cases):
        try:
            row = run_case(i)
        except Exception as exc:
            row = {"i": i, "machine": "?", "law": "?", "counted": False, "why": repr(exc)}
            traceback.print_exc()
        row["versions"] = versions
        out.write(row)
        print(json.dumps(row, default=float)[:400], flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
