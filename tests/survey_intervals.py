"""Coverage of the 95 % bootstrap intervals on random machines and laws, per class.

Not a test module: a survey (``python -m tests.survey_intervals --records 64``).  Record
``i`` is drawn by :func:`tests.realistic.draw_case` (a random machine and law; the
category cycles through P1, slow P1, subharmonic and short contact, the law's kind is drawn:
linear, penetration-velocity coupling with a random share of the damping, Hunt-Crossley),
recorded by the independent scipy path from rest (:func:`tests.realistic.reference_record`)
at a random sample rate of 5-20 kHz (not a multiple of the drive frequency), at low noise
(force 0.5 % of its peak, motion 0.1 % of each channel's range) or high noise (3 %, 0.3 %)
in turn.  The true support is identified by output error from a start 20 % off the truth,
with bootstrap intervals (:func:`discovery.vibroimpact.fit.identification.bootstrap_intervals`),
and each interval is checked against the truth.  One JSON line per record (``--out FILE``:
a run file of :mod:`tests.measured`, headed by the commit and code version); ``--summary
FILE`` prints the coverage per class (category, kind, coupling share, noise level) of the
fits consistent with their records.  ``--workers N`` runs records in N processes.
``--corpus`` runs the thirteen records of ``../shared/corpus`` instead (each one's true law
identified from a start 20 % off, the same intervals; the class is the record's name).
"""

import argparse
import json
import sys
import time
from concurrent.futures import ProcessPoolExecutor, as_completed

import numpy as np

from . import measured
from . import realistic as R

NOISE = {"low": (0.005, 0.001), "high": (0.03, 0.003)}


def _classes(case):
    kind = case.kind
    if kind == "zzd":
        # the share of the damping on z*zd at the typical penetration: strong or weak
        kind = (
            "coupling-strong"
            if "z*zd" in case.law.names and _share(case) >= 0.5
            else "coupling-weak"
        )
    return kind


def _share(case):
    d = case.law.as_dict()
    return d["z*zd"] / (d["z*zd"] + d["zd"] / max(_z0(case), 1e-12))


def _z0(case):
    sc = case.scenario
    mu = sc.m1 * sc.m2 / (sc.m1 + sc.m2)
    wc = np.sqrt(case.law.as_dict().get("z", 0.0) / mu) if "z" in case.law.names else 1.0
    return sc.scales()[1] / wc


def _identified(sc, ref, truth, rng, *, seed, n_boot, noise, refit):
    """``truth`` identified on ``ref`` from a start 20 % off (each parameter up or down at
    random from ``rng``), least squares, with bootstrap intervals."""
    from discovery import identify

    start = truth.with_coefficients(
        [c * (1 + 0.2 * rng.choice([-1, 1])) for c in truth.coefficients]
    )
    return identify(
        sc,
        ref,
        start,
        criterion="I2",
        method="least-squares",
        max_simulations=200,
        n_boot_intervals=n_boot,
        interval_noise=noise,
        interval_refit=refit,
        seed=seed,
    )


def run(i, *, n_boot=30, noise_model="cycles", periods=12, refit="two-step"):
    from discovery.vibroimpact.verify import Reference, evaluate

    t0 = time.perf_counter()
    category = R.CATEGORIES[i % len(R.CATEGORIES)]
    level = ("low", "high")[(i // len(R.CATEGORIES)) % 2]
    fnoise, mnoise = NOISE[level]
    rng = np.random.default_rng(7000 + i)
    fs = float(rng.uniform(5000.0, 20000.0))
    row = {
        "i": i,
        "code": _code(),
        "category": category,
        "noise": level,
        "fs": fs,
        "interval_noise": noise_model,
        "interval_refit": refit,
    }
    try:
        case = R.draw_case(category, 100 + i)
        sc, law = case.scenario, case.law
        rec = R.reference_record(
            case,
            periods=periods,
            fs=fs,
            force_noise=fnoise,
            motion_noise=mnoise,
            seed=i,
            check=False,
        )
        ref = Reference.from_measurement(rec, sc)
        res = _identified(sc, ref, law, rng, seed=i, n_boot=n_boot, noise=noise_model, refit=refit)
        ev = evaluate(sc, res.law, ref)
    except Exception as exc:  # a survey records every outcome
        row.update(error=f"{type(exc).__name__}: {exc}", seconds=time.perf_counter() - t0)
        return row
    row.update(
        kind=_classes(case),
        law=law.to_text(),
        regime=case.regime,
        identified=res.law.as_dict(),
        consistent=bool(ev.consistent),
        covered={},
        z={},
        seconds=time.perf_counter() - t0,
    )
    if res.intervals is None:
        row["no_intervals"] = True
        return row
    for name, true in law.as_dict().items():
        lo, hi = res.intervals.bounds[name]
        sd = res.intervals.sd[name]
        row["covered"][name] = bool(lo <= true <= hi)
        row["z"][name] = (res.law.as_dict()[name] - true) / sd if sd > 0 else float("inf")
        se = res.standard_errors.get(name, 0.0)
        row.setdefault("z_jacobian", {})[name] = (
            (res.law.as_dict()[name] - true) / se if se > 0 else float("inf")
        )
    return row


def _corpus_model(name):
    """``(scenario, model, truth)`` of a corpus record: its true law, with an unloading
    damper or a contact offset as the effect parameter explain fits (``d_zd``, ``delta0``)."""
    from discovery import ForceLaw, load_scenario
    from discovery.vibroimpact.explain.effects import Model, effect

    from .test_corpus import CORPUS

    d = CORPUS / name
    text = json.loads((d / "truth.json").read_text())["law"]
    sc = load_scenario(str(d / "scenario.toml"))
    if name == "c11-contact-offset":  # 2e8*(z - 0.0015) + 5e6*zd beyond the offset
        model = Model(ForceLaw.parse("2e8*z + 5e6*zd")).with_effect(
            effect("contact_offset"), 0.0015
        )
    else:
        law = ForceLaw.parse(text)
        model = Model(ForceLaw(law.terms, law.coefficients))
        for t, c in zip(law.unloading, law.unloading_coefficients, strict=True):
            assert t.name == "zd", text  # the corpus's unloading branches are dampers
            model = model.with_effect(effect("unloading_damping"), c)
    return sc, model, dict(zip(model.names, model.coefficients, strict=True))


def run_corpus(name, *, n_boot=30, noise_model="cycles", refit="two-step"):
    """One corpus record (``../shared/corpus/NAME``): its true model identified from a
    start 20 % off (every parameter up or down at random), with bootstrap intervals, each
    checked against the truth."""
    from discovery import Measurement
    from discovery.vibroimpact.verify import Reference

    from .test_corpus import CORPUS

    t0 = time.perf_counter()
    row = {"i": name, "code": _code(), "category": "corpus", "noise": "corpus", "kind": name}
    try:
        sc, model, truth = _corpus_model(name)
        rng = np.random.default_rng(int(name[1:3]))
        m = Measurement.from_csv(str(CORPUS / name / "measured.csv"))
        ref = Reference.from_measurement(m, sc)
        res = _identified(
            sc, ref, model, rng, seed=0, n_boot=n_boot, noise=noise_model, refit=refit
        )
        fitted = res.law  # the model identify fitted (a law with effects)
    except Exception as exc:  # a survey records every outcome
        row.update(error=f"{type(exc).__name__}: {exc}", seconds=time.perf_counter() - t0)
        return row
    est = dict(zip(fitted.names, fitted.coefficients, strict=True))
    row.update(
        law=str(model.law),
        identified=est,
        consistent=bool(res.consistent),
        covered={},
        z={},
        seconds=time.perf_counter() - t0,
    )
    if res.intervals is None:
        row["no_intervals"] = True
        return row
    for k, true in truth.items():
        lo, hi = res.intervals.bounds[k]
        sd = res.intervals.sd[k]
        row["covered"][k] = bool(lo <= true <= hi)
        row["z"][k] = (est[k] - true) / sd if sd > 0 else float("inf")
    return row


def _code():
    from discovery.vibroimpact.studies.run_files import code_version

    return code_version()


CLASSES = {
    "category": ("p1", "p1-slow", "short-contact", "subharmonic"),
    "kind": ("linear", "coupling-strong", "coupling-weak", "hertz"),
    "noise": ("low", "high"),
}


def _covered(rows):
    """The rows with intervals (fits consistent with their records) and, per class, the
    covered flags of their coefficients (None for a class no record fell in)."""
    ok = [r for r in rows if "error" not in r and r.get("consistent") and r.get("covered")]
    by = {
        key: [[c for r in ok if r[key] == n for c in r["covered"].values()] for n in names]
        for key, names in CLASSES.items()
    }
    return ok, by, [v for r in ok for v in r["covered"].values()]


def markdown_row(rows, label):
    """One row of docs/validation.md's coverage table: the coverage per class and in all,
    and the code versions that made the rows (a class no record fell in is left blank)."""
    ok, by, allv = _covered(rows)
    cells = [f"{label} ({len(ok)} of {len(rows)} records with intervals)"]
    for classes in by.values():
        rates = [f"{sum(v)}/{len(v)}" if v else "-" for v in classes]
        cells.append(" / ".join(rates) if any(classes) else "")
    cells.append(f"{sum(allv)}/{len(allv)} = **{sum(allv) / max(len(allv), 1):.1%}**")
    codes = sorted({r.get("code", "?") for r in rows})
    cells.append(", ".join(codes))
    return "| " + " | ".join(cells) + " |"


def readme_row(rows, label):
    """The same row as the README shows it: whole percentages per class."""
    _, by, allv = _covered(rows)
    cells = [label]
    for classes in by.values():
        rates = [f"{100 * sum(v) / len(v):.0f}" if v else "-" for v in classes]
        cells.append(" / ".join(rates) + " %" if any(classes) else "")
    cells.append(f"{sum(allv)}/{len(allv)} = {100 * sum(allv) / max(len(allv), 1):.1f} %")
    return "| " + " | ".join(cells) + " |"


def read_rows(paths):
    """The rows of the run files ``paths`` (:func:`tests.measured.read`); a record run
    again in a later file replaces its row; a row without its own code version takes its
    run's (or, for runs before the survey recorded it, the run's commit)."""
    rows = {}
    for path in paths:
        header, found = measured.read(path)
        for r in found:
            if "code" not in r and (header.get("code") or header.get("commit")):
                r["code"] = header.get("code") or header["commit"]
            rows[r["i"]] = r
    return list(rows.values())


def summary(rows):
    ok = [r for r in rows if "error" not in r and r.get("consistent") and r.get("covered")]
    print(
        f"records: {len(rows)}; errors {sum('error' in r for r in rows)}; fits not "
        f"consistent {sum(r.get('consistent') is False for r in rows)}; with intervals "
        f"{len(ok)}"
    )
    allv = [v for r in ok for v in r["covered"].values()]
    if not allv:
        return
    print(f"all: {sum(allv)}/{len(allv)} = {sum(allv) / len(allv):.1%} of coefficients")
    jac = [abs(v) <= 1.96 for r in ok for v in r.get("z_jacobian", {}).values()]
    if jac:
        print(f"Jacobian standard errors (+-1.96 SE): {sum(jac)}/{len(jac)} = {np.mean(jac):.1%}")
    for key in ("category", "kind", "noise"):
        by = {}
        for r in ok:
            by.setdefault(r[key], []).extend(r["covered"].values())
        for k, v in sorted(by.items()):
            print(f"  {key:8s} {k:16s} {sum(v):3d}/{len(v):3d} = {sum(v) / len(v):.1%}")


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--records", type=int, default=64)
    p.add_argument("--first", type=int, default=0)
    p.add_argument("--bootstrap", type=int, default=30)
    p.add_argument("--noise", default="cycles", choices=("cycles", "white"))
    p.add_argument("--refit", default="two-step", choices=("two-step", "full"))
    p.add_argument("--workers", type=int, default=1)
    p.add_argument("--summary", metavar="JSONL", nargs="+")
    p.add_argument("--markdown", metavar="LABEL", help="with --summary: the table row")
    p.add_argument("--corpus", action="store_true", help="the corpus's records instead")
    p.add_argument("--out", metavar="JSONL", help="also write the rows to this run file")
    a = p.parse_args(argv)
    if a.summary:
        rows = read_rows(a.summary)
        print(markdown_row(rows, a.markdown)) if a.markdown else summary(rows)
        return 0
    if a.corpus:
        from .test_corpus import NAMES

        idx = NAMES
    else:
        idx = range(a.first, a.first + a.records)
    rows = []
    kw = {"n_boot": a.bootstrap, "noise_model": a.noise, "refit": a.refit}
    out = measured.RunFile(a.out, "survey_intervals", argv) if a.out else None

    def done(row):  # each record's line as soon as it is done
        rows.append(row)
        print(json.dumps(row), flush=True)
        if out is not None:
            out.write(row)

    if a.workers > 1:
        with ProcessPoolExecutor(a.workers) as ex:
            futures = [ex.submit(_run_kw, (i, kw)) for i in idx]
            for f in as_completed(futures):
                done(f.result())
    else:
        for i in idx:
            done(_run_kw((i, kw)))
    summary(rows)
    return 0


def _run_kw(args):
    i, kw = args
    return run_corpus(i, **kw) if isinstance(i, str) else run(i, **kw)


if __name__ == "__main__":
    sys.exit(main())
