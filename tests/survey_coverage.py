"""Coverage of the coefficient intervals: how often each 95 % interval holds the truth.

Not a test module: a survey (``python -m tests.survey_coverage --records 25``).  For each
machine and seed a record is made by the independent scipy path from rest
(:func:`tests.realistic.reference_record`: sample rate not a multiple of the drive
frequency, force noise 2 % of the peak, motion noise 0.2 % of each channel's range), the
true support is identified by output error (:func:`discovery.identify`) from a start
20 % off the truth (each coefficient up or down at random), verified
(:func:`discovery.vibroimpact.verify.evaluate`), and every coefficient's interval (``identify``'s
standard errors, +-1.96 SE) is checked against the truth.  One JSON line per record;
``--summary`` prints
the coverage per machine and term.
"""

import argparse
import json
import sys
import time

import numpy as np

from discovery import ForceLaw, Scenario, identify
from discovery.vibroimpact.verify import Reference, evaluate

from . import measured
from . import realistic as R

# the corpus machine (an independent simulator's shake-out grid) and the paper's machine
_CORPUS = Scenario(m1=9000.0, m2=6000.0, k1=2.2e7, c1=8e4, A=4.2e5, frequency=26.0)
MACHINES = {
    "corpus-coupling": (_CORPUS, "1.5e8*z + 3e6*zd + 8e10*z*zd"),
    "corpus-linear": (_CORPUS, "1.5e8*z + 6e6*zd"),
    "paper-linear": (None, "2.06e8*z + 1.28e7*zd"),
}


def run(machine, seed, *, fs=20000.0, periods=12, force_noise=0.02, motion_noise=0.002, n_boot=0):
    from discovery import load_scenario

    sc, text = MACHINES[machine]
    sc = sc or load_scenario("paper")
    law = ForceLaw.parse(text)
    t0 = time.perf_counter()
    rec = R.reference_record(
        (sc, law),
        periods=periods,
        fs=fs,
        force_noise=force_noise,
        motion_noise=motion_noise,
        seed=seed,
        check=False,
    )
    rng = np.random.default_rng(1000 + seed)
    start = law.with_coefficients([c * (1 + 0.2 * rng.choice([-1, 1])) for c in law.coefficients])
    ref = Reference.from_measurement(rec, sc)
    res = identify(
        sc,
        ref,
        start,
        criterion="I2",
        method="least-squares",
        max_simulations=200,
        n_boot_intervals=n_boot,
        seed=seed,
    )
    ev = evaluate(sc, res.law, ref)
    row = {
        "machine": machine,
        "seed": seed,
        "law": text,
        "fs": fs,
        "periods": periods,
        "force_noise": force_noise,
        "motion_noise": motion_noise,
        "identified": res.law.as_dict(),
        "standard_errors": res.standard_errors,
        "n_simulations": res.n_simulations,
        "seconds": time.perf_counter() - t0,
        "covered": {},
        "z_scores": {},
        "consistent": bool(ev.consistent),
        "I2": ev.criteria.get("I2"),
        "I2_floor": ev.noise_floor.get("I2"),
    }
    for name, true in law.as_dict().items():
        c, se = res.law.as_dict()[name], res.standard_errors.get(name, float("nan"))
        row["z_scores"][name] = (c - true) / se if se > 0 else float("inf")
        row["covered"][name] = bool(abs(c - true) <= 1.96 * se)
        if res.intervals is not None:
            lo, hi = res.intervals.bounds[name]
            row.setdefault("covered_bootstrap", {})[name] = bool(lo <= true <= hi)
    return row


def summary(rows):
    """Coverage over the records whose identified law is consistent with them (the fit
    converged); the others are counted apart: their verdict says the fit failed."""
    bad = [r for r in rows if not r.get("consistent", True)]
    print(f"fits not consistent with their record (did not converge): {len(bad)}/{len(rows)}")
    rows = [r for r in rows if r.get("consistent", True)]
    by = {}
    for r in rows:
        for name, ok in r["covered"].items():
            by.setdefault((r["machine"], name), []).append(ok)
    boot = [ok for r in rows for ok in r.get("covered_bootstrap", {}).values()]
    if boot:
        print(f"bootstrap intervals: {sum(boot)}/{len(boot)} = {sum(boot) / len(boot):.1%}")
    allv = [ok for v in by.values() for ok in v]
    print(
        f"Jacobian 95 % intervals: {sum(allv)}/{len(allv)} = "
        f"{sum(allv) / max(len(allv), 1):.1%} ({len(rows)} records)"
    )
    for (m, name), v in sorted(by.items()):
        print(f"  {m:18s} {name:6s} {sum(v)}/{len(v)}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--records", type=int, default=25, help="seeds per machine")
    p.add_argument("--machines", default=",".join(MACHINES))
    p.add_argument(
        "--bootstrap",
        type=int,
        default=0,
        help="replicates of the bootstrap intervals (0 = Jacobian only)",
    )
    p.add_argument("--summary", metavar="JSONL", help="summarise an earlier run's output")
    p.add_argument("--out", metavar="JSONL", help="also write the rows to this run file")
    a = p.parse_args(argv)
    if a.summary:
        summary(measured.read(a.summary)[1])
        return 0
    out = measured.RunFile(a.out, "survey_coverage", argv) if a.out else None
    rows = []
    for m in a.machines.split(","):
        for seed in range(a.records):
            row = run(m, seed, n_boot=a.bootstrap)
            rows.append(row)
            print(json.dumps(row), flush=True)
            if out is not None:
                out.write(row)
    summary(rows)
    return 0


if __name__ == "__main__":
    sys.exit(main())
