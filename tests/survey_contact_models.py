"""Survey: are records of the named contact models identified by the right name, with
``k, n, e`` inside their 95 % intervals; and is a named model selected in place of a
polynomial law?

Records: random machines of ``tests/realistic.py`` (category ``p1``), recorded by the
independent scipy path from rest (``reference_record``), 12 periods, 1 % force noise,
0.2 % motion noise.  Named-model laws: ``n`` uniform in [1, 1.5], ``e`` uniform in
[0.3, 0.9], stiffness matched to the machine's contact frequency at its typical
penetration (``tests/realistic.py``'s draw), Kelvin-Voigt and Hertz-damper damping from
the same damping ratio range.  Polynomial laws: the draws of ``tests/realistic.py``
(linear, ``z*zd`` and Hertz with ``z^1.5*zd`` damping in loading only).

Run:  .venv/bin/python tests/survey_contact_models.py --per-model 4 --poly 4 \
          --out out/survey_contact_models.jsonl
One JSON line per record (appended as it goes), then a summary table on stdout.
"""

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.append(str(Path(__file__).resolve().parents[1]))  # for tests.measured

from realistic import draw_case, reference_record  # noqa: E402

from discovery.errors import VidiError  # noqa: E402
from discovery.vibroimpact.dynamics.steady_state import steady_state  # noqa: E402
from discovery.vibroimpact.fit.contact_fit import fit_contact_models  # noqa: E402
from discovery.vibroimpact.fit.identify import bootstrap_intervals  # noqa: E402
from discovery.vibroimpact.model.contact_models import (  # noqa: E402
    MODELS,
    ContactModel,
    restitution_ratio,
)
from discovery.vibroimpact.verify import Reference  # noqa: E402
from tests import measured  # noqa: E402

PARAMS_CHECKED = ("k", "n", "e", "lambda", "c")


def named_law(case, name, rng):
    """A named model on a drawn machine: stiffness from the draw's contact frequency at its
    typical penetration, ``n`` in [1, 1.5], ``e`` in [0.3, 0.9]."""
    sc = case.scenario
    mu = sc.m1 * sc.m2 / (sc.m1 + sc.m2)
    wc = 2 * math.pi * sc.frequency * 10 ** rng.uniform(0.0, 0.8)
    v = sc.scales()[1]
    z0 = v / wc
    k_lin = mu * wc**2
    n = {"kelvin-voigt": 1.0, "hertz-damper": 1.5}.get(name, float(rng.uniform(1.0, 1.5)))
    e = float(rng.uniform(0.3, 0.9))
    k = k_lin * z0 ** (1 - n)
    if name in ("kelvin-voigt", "hertz-damper"):
        xi = 10 ** rng.uniform(-1.0, -0.3)
        return ContactModel(name, (k, 2 * xi * math.sqrt(k_lin * mu))), e
    if name == "hunt-crossley":
        return ContactModel(name, (k, n, k * restitution_ratio("lankarani-nikravesh", e) / v)), e
    return ContactModel(name, (k, n, e)), e


def _usable(sc, law):
    try:
        ss = steady_state(sc, law)
    except VidiError:
        return False
    return ss.periodic and ss.impacts >= 1


def one_record(truth_name, seed, max_sim):
    rng = np.random.default_rng(seed)
    for attempt in range(30):
        case = draw_case("p1", int(seed * 100 + attempt), check_reference=False)
        if truth_name == "polynomial":
            sc, law, truth = case.scenario, case.law, None
        else:
            truth, _ = named_law(case, truth_name, rng)
            law = truth.law
            sc = case.scenario.replace(law=law)
            if not _usable(sc, law):
                continue
        try:
            meas = reference_record((sc, law), periods=12, seed=seed, check=False)
            Reference.from_measurement(meas, sc)  # a record the verdict can read
        except (VidiError, RuntimeError, ValueError):
            continue
        break
    else:
        return {"truth": truth_name, "seed": seed, "skipped": True}
    t0 = time.perf_counter()
    res = fit_contact_models(sc, meas, max_simulations=max_sim, n_boot=0)
    row = {
        "truth": truth_name,
        "seed": seed,
        "law": law.to_text(),
        "true_params": None if truth is None else truth.params,
        "selected": res.selected,
        "equivalent": list(res.equivalent),
        "seconds": time.perf_counter() - t0,
        "fits": [f.to_dict() for f in res.fits],
    }
    if truth is not None:
        row["covered"] = _covered(row)
        fit = res.fit(truth_name)
        row["true_consistent"] = fit.consistent
        # the bootstrap through the record-span processing, for the true model's fit
        if fit.consistent is not None:
            model = ContactModel(truth_name, tuple(fit.parameters[k] for k in MODELS[truth_name]))
            iv = bootstrap_intervals(sc, Reference.from_measurement(meas, sc), model, n_boot=30)
            row["boot_intervals"] = (
                None if iv is None else {k: list(v) for k, v in iv.bounds.items()}
            )
            row["boot_covered"] = _covered(row, boot=True)
    return row


def _covered(row, boot=False):
    """``{parameter: inside its 95 % interval}`` of the true model's fit in a row (the
    Jacobian's intervals, or with ``boot`` the bootstrap's)."""
    fit = next(f for f in row["fits"] if f["model"] == row["truth"])
    ivs = (row.get("boot_intervals") or {}) if boot else fit["intervals"]
    out = {}
    for key in MODELS[row["truth"]]:
        if key not in ivs:
            continue
        lo, hi = ivs[key]
        out[key] = bool(lo <= row["true_params"][key] <= hi)
    return out


def summary(rows):
    lines = [
        "truth                 records  right name  right or equivalent  in their 95 % intervals"
    ]
    for name in [*MODELS, "polynomial"]:
        rs = [r for r in rows if r["truth"] == name and not r.get("skipped")]
        if not rs:
            continue
        if name == "polynomial":
            wrong = sum(r["selected"] is not None for r in rs)
            lines.append(
                f"{name:<21s} {len(rs):7d}  a named model selected: {wrong}/{len(rs)} "
                f"(none consistent: {sum(r['selected'] is None for r in rs)})"
            )
            continue
        right = sum(r["selected"] == name for r in rs)
        either = sum(r["selected"] == name or name in r["equivalent"] for r in rs)
        cov = {k: [c[k] for c in map(_covered, rs) if k in c] for k in PARAMS_CHECKED}
        cov_text = ", ".join(f"{k} {sum(v)}/{len(v)}" for k, v in cov.items() if v)
        boot = [_covered(r, boot=True) for r in rs if r.get("boot_intervals")]
        bcov = {k: [c[k] for c in boot if k in c] for k in PARAMS_CHECKED}
        if boot:
            cov_text += "; bootstrap: " + ", ".join(
                f"{k} {sum(v)}/{len(v)}" for k, v in bcov.items() if v
            )
        lines.append(
            f"{name:<21s} {len(rs):7d}  {right:4d}/{len(rs):<5d} "
            f"{either:4d}/{len(rs):<14d} {cov_text}"
        )
    return "\n".join(lines)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-model", type=int, default=2)
    ap.add_argument("--poly", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-simulations", type=int, default=60)
    ap.add_argument("--out", default="out/survey_contact_models.jsonl", nargs="+")
    ap.add_argument(
        "--summarize", action="store_true", help="only print the table of the rows in --out"
    )
    a = ap.parse_args(argv)
    if a.summarize:
        rows = [r for f in a.out for r in measured.read(f)[1]]
        print(summary(rows))
        return
    out = measured.RunFile(a.out[0], "survey_contact_models", argv, append=True)
    rows = []
    jobs = [(m, a.seed + 1000 * j + i) for i in range(a.per_model) for j, m in enumerate(MODELS)]
    jobs += [("polynomial", a.seed + 9000 + i) for i in range(a.poly)]
    # interleave so a run cut short still has every model
    jobs.sort(key=lambda j: (j[1] % 1000, j[0]))
    for name, seed in jobs:
        row = one_record(name, seed, a.max_simulations)
        rows.append(row)
        out.write(row)
        print(
            f"{name:<20s} seed {seed}: selected {row.get('selected')} "
            f"equivalent {row.get('equivalent')} covered {row.get('covered')} "
            f"{row.get('seconds', 0):.0f} s",
            flush=True,
        )
    print(summary(rows))


if __name__ == "__main__":
    main()
