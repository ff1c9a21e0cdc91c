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

Second operating point (``--second-point advised random``, issue 33's loop): in a
periodic steady state every impact arrives at one velocity ``v0``, so Hunt-Crossley
(constant ``lambda``) and Lankarani-Nikravesh / Flores (``lambda`` set by ``e`` and each
impact's ``v0``) make the same record at one operating point.  When the first record's fit
reports equivalent models, a second record of the same machine and law is made (the same
scipy path, the same noise levels, noise seed ``seed + 1``) at another drive setting and
both records are fitted jointly (shared ``k, n, e / lambda``):

* ``advised``: the point :func:`discovery.advise` proposes for the first fit's selected
  and equivalent models, the drive amplitude in ``--amplitude-range`` (default 0.5..2 x)
  and the frequency in ``--frequency-range`` (0.7..1.4 x) of the first record's, the noise
  of the first record, and a safe region of ``--max-force-factor`` (3) times its peak force;
* ``random``: a point drawn uniformly in the same bounds (``default_rng([seed, 2])``;
  drawn again, up to 5 times, where no record with contact can be made there);
* ``none``: the first fit alone.

The joint fit fits the first fit's selected and equivalent models (``--joint-models
candidates``, the default) or every model (``all``).  Each row holds every arm, the code
version (git commit) and every setting.

Run from the repository root (the package of the checkout is imported):
    python -m tests.survey_contact_models --per-model 4 --poly 4 \
        --out out/survey_contact_models.jsonl
    python -m tests.survey_contact_models --models hunt-crossley \
        lankarani-nikravesh --seeds 1 2 3 --second-point advised random --boot 0 \
        --out out/two_points.jsonl
The output is a run file (:mod:`tests.measured`, appended to when it exists): a header
naming the command, commit and code version, then one JSON line per record as it is made;
then a summary table on stdout.  ``--workers N`` makes N records at once, in processes (the
rows do not depend on it; a record's ``seconds`` do, on a machine with fewer free cores).
docs/validation.md's table of the named models (:func:`models_row`, ``make tables``)
combines the rows of several runs (``docs/_measured/contact-models-*.jsonl``), and
docs/contact-models.md's table of the second operating point (:func:`markdown_row`) those of
``contact-two-points.jsonl``.
"""

import argparse
import math
import sys
import time
from pathlib import Path

import numpy as np

if not __package__:  # run as a script: python tests/survey_contact_models.py
    # the repository root, not tests/ (whose constraints/ and reports/ folders of tests are
    # packages that would shadow the top-level ones)
    sys.path[0:1] = [str(Path(__file__).resolve().parents[1])]

from discovery._files._io import git_state, provenance  # noqa: E402
from discovery.errors import InputError, VidiError  # noqa: E402
from discovery.vibroimpact.advise import Knobs, NoiseModel, SafeRegion, advise  # noqa: E402
from discovery.vibroimpact.dynamics.steady_states import steady_state  # noqa: E402
from discovery.vibroimpact.fit.contact_fit import fit_contact_models  # noqa: E402
from discovery.vibroimpact.fit.identification import bootstrap_intervals  # noqa: E402
from discovery.vibroimpact.model.contact_models import (  # noqa: E402
    ContactModel,
    restitution_ratio,
)
from discovery.vibroimpact.model.contact_registry import CONTACT_MODELS  # noqa: E402
from discovery.vibroimpact.verify import Reference  # noqa: E402
from tests import measured  # noqa: E402
from tests.realistic import draw_case, reference_record  # noqa: E402

#: the named models, each with its parameters in order
MODELS = {name: spec.parameters for name, spec in CONTACT_MODELS.items()}

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


def make_record(truth_name, seed):
    """``(scenario, law, true model or None, record)`` of a truth and seed, or None when
    no usable draw was found in 30 tries."""
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
        return sc, law, truth, meas
    return None


def one_record(truth_name, seed, max_sim, n_boot=30, second=("none",), opts=None):
    made = make_record(truth_name, seed)
    if made is None:
        return {"truth": truth_name, "seed": seed, "skipped": True}
    sc, law, truth, meas = made
    t0 = time.perf_counter()
    res = fit_contact_models(sc, meas, max_simulations=max_sim, n_boot=0)
    row = {
        "truth": truth_name,
        "seed": seed,
        "law": law.to_text(),
        "scenario": sc.as_dict(),
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
        if fit.consistent is not None and n_boot:
            model = ContactModel(truth_name, tuple(fit.parameters[k] for k in MODELS[truth_name]))
            iv = bootstrap_intervals(sc, Reference.from_measurement(meas, sc), model, n_boot=n_boot)
            row["boot_intervals"] = (
                None if iv is None else {k: list(v) for k, v in iv.bounds.items()}
            )
            row["boot_covered"] = _covered(row, boot=True)
    arms = [a for a in second if a != "none"]
    if arms:
        row["second"] = second_points(res, sc, law, meas, seed, arms, max_sim, opts or {})
    return row


def _bounds(sc, opts):
    """The knobs' bounds around the first record's drive setting."""
    ar, fr = opts.get("amplitude_range", (0.5, 2.0)), opts.get("frequency_range", (0.7, 1.4))
    return Knobs(
        (ar[0] * sc.A, ar[1] * sc.A),
        (fr[0] * sc.frequency, fr[1] * sc.frequency),
        grid=tuple(opts.get("grid", (4, 4))),
        refine=int(opts.get("refine", 2)),
    )


def _joint(res, sc0, meas0, law, point, seed, max_sim, opts):
    """The second record at ``point = (A, f)`` and the joint fit of both records; None
    when no record with contact can be made there."""
    sc1 = sc0.replace(A=float(point[0]), frequency=float(point[1]))
    try:
        meas1 = reference_record((sc1, law), periods=12, seed=seed + 1, check=False)
        Reference.from_measurement(meas1, sc1)
    except (VidiError, RuntimeError, ValueError) as exc:
        return None, f"{type(exc).__name__}: {exc}"
    names = (
        None if opts.get("joint_models", "candidates") == "all" else [res.selected, *res.equivalent]
    )
    t0 = time.perf_counter()
    joint = fit_contact_models(
        [sc0, sc1], [meas0, meas1], models=names, max_simulations=max_sim, n_boot=0
    )
    return {
        "point": [float(point[0]), float(point[1])],
        "models": names,
        "selected": joint.selected,
        "equivalent": list(joint.equivalent),
        "fits": [f.to_dict() for f in joint.fits],
        "seconds": time.perf_counter() - t0,
    }, ""


def second_points(res, sc, law, meas, seed, arms, max_sim, opts):
    """``{arm: outcome}`` of the second record at the advised and at a random point
    (``{"made": False, "why": ...}`` where none was made: the first fit lists no
    equivalent model, or only models that make the same force at every impact velocity
    (advise refuses: no point separates them; then neither arm makes a record), advise
    finds no usable point, or no record can be made)."""
    if res.selected is None or not res.equivalent:
        why = "the first fit lists no equivalent model" if res.selected else "none consistent"
        return {arm: {"made": False, "why": why} for arm in arms}
    knobs = _bounds(sc, opts)
    out = {}
    if "advised" in arms:
        t0 = time.perf_counter()
        noise = NoiseModel.from_measurement(meas, sc, seed=seed)
        safe = SafeRegion(max_force=opts.get("max_force_factor", 3.0) * float(np.max(meas.F)))
        try:
            adv = advise(sc, res, knobs, noise, safe, workers=1)
        except InputError as exc:  # only same-force twins left: no point separates them
            return {arm: {"made": False, "why": str(exc)} for arm in arms}
        b = adv.best
        info = {"advise_seconds": time.perf_counter() - t0, "candidates": list(adv.laws)}
        if b is None:
            out["advised"] = {"made": False, "why": "advise found no usable point", **info}
        else:
            info.update(
                smallest_separation=b.smallest_separation(frozenset(adv.inseparable)),
                inseparable=[list(q) for q in adv.inseparable],
                regimes=[p.regime for p in b.predictions],
            )
            got, why = _joint(res, sc, meas, law, (b.amplitude, b.frequency), seed, max_sim, opts)
            out["advised"] = (
                {"made": True, **got, **info}
                if got
                else {"made": False, "why": why, "point": [b.amplitude, b.frequency], **info}
            )
    if "random" in arms:
        rng = np.random.default_rng([seed, 2])
        tried = []
        for _ in range(5):
            point = (rng.uniform(*knobs.amplitude), rng.uniform(*knobs.frequency))
            got, why = _joint(res, sc, meas, law, point, seed, max_sim, opts)
            if got:
                out["random"] = {"made": True, **got, "draws": len(tried) + 1, "refused": tried}
                break
            tried.append({"point": list(point), "why": why})
        else:
            out["random"] = {"made": False, "why": "no record at 5 random points", "refused": tried}
    return out


def final(row, arm):
    """``(selected, equivalent)`` a row ends with in an arm: the joint fit's where a
    second record was made, else the first fit's."""
    got = (row.get("second") or {}).get(arm) if arm != "none" else None
    if got and got.get("made"):
        return got["selected"], got["equivalent"]
    return row["selected"], row["equivalent"]


_FAMILY = {
    "hunt-crossley": "constant lambda",
    "lankarani-nikravesh": "lambda by v0",
    "flores": "lambda by v0",
}


def settled(row, arm):
    """The truth selected or equivalent, and no model of the other damping family
    (constant ``lambda`` against ``lambda`` set by each impact's ``v0``) still consistent:
    what a second operating point can decide (Lankarani-Nikravesh and Flores make the same
    force wherever ``r <= 3/4``; no record tells them apart)."""
    sel, eq = final(row, arm)
    names = [sel, *eq] if sel else []
    fam = _FAMILY.get(row["truth"])
    return row["truth"] in names and all(_FAMILY.get(m, fam) == fam for m in names)


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
    arms = sorted({a for r in rows for a in (r.get("second") or {})})
    if arms:
        lines += ["", arm_table(rows, ["none", *arms])]
    return "\n".join(lines)


ARM_NAMES = {"none": "one point", "advised": "advised", "random": "random"}


def read_rows(files):
    """The rows of run files (a record surveyed twice, a run resumed, counts once: its last
    row)."""
    rows = [r for f in files for r in measured.read(f)[1]]
    return list({(r["truth"], r["seed"]): r for r in rows}.values())


def stamp(files, rows):
    """The line under the docs' table: its run files and the commits their rows were made
    by (each row records its code version)."""
    commits = sorted({(r.get("code") or {}).get("commit") or "not recorded" for r in rows})
    return (
        "*Rendered by `make tables` from the survey runs in `docs/_measured/`: "
        + ", ".join(f"`{f.name}`" for f in files)
        + " (rows made by commit "
        + ", ".join(c[:7] for c in commits)
        + ").*"
    )


def markdown_row(rows, label):
    """The docs' row of a truth and an arm (``label``: ``"hunt-crossley/advised"``): records,
    right name, right or equivalent, settled, and settled where the first record left the
    other damping family open (the counts of :func:`arm_table`)."""
    name, arm = label.split("/")
    rs = [r for r in rows if r["truth"] == name and not r.get("skipped")]
    open_ = [r for r in rs if r["truth"] in [r["selected"], *r["equivalent"]]]
    open_ = [r for r in open_ if not settled(r, "none")]
    right = sum(final(r, arm)[0] == name for r in rs)
    either = sum(name in [final(r, arm)[0], *final(r, arm)[1]] for r in rs)
    done = sum(settled(r, arm) for r in rs)
    n = len(rs)
    return (
        f"| {name} | {ARM_NAMES[arm]} | {n} | {right}/{n} | {either}/{n} | {done}/{n} | "
        f"{sum(settled(r, arm) for r in open_)}/{len(open_)} |"
    )


#: docs/validation.md's table of the named models: a row per truth, then ``"all"`` (the
#: line under it: every parameter of every record together)
MODELS_LABELS = (*MODELS, "polynomial", "all")

MODELS_HEADER = (
    "| truth | records | right name selected | right name selected or equivalent | in their "
    "95 % intervals (Jacobian) | (bootstrap) |",
    "|---|---|---|---|---|---|",
)


def _coverage(rows, boot=False):
    """``{parameter: [inside its interval, per record]}`` of the rows' true models (the
    Jacobian's intervals, or with ``boot`` the bootstrap's, where a row has them)."""
    covered = [_covered(r, boot) for r in rows if not boot or r.get("boot_intervals")]
    return {k: [c[k] for c in covered if k in c] for k in PARAMS_CHECKED}


def _coverage_cell(cov):
    return ", ".join(f"{k} {sum(v)}/{len(v)}" for k, v in cov.items() if v) or "-"


def _together(rows, boot=False):
    """``(inside, intervals)``: every checked parameter of every named-model row."""
    named = [r for r in rows if r["truth"] in MODELS]
    flat = [x for v in _coverage(named, boot).values() for x in v]
    return sum(flat), len(flat)


def models_row(rows, label):
    """docs/validation.md's row of a truth (``label``: a model or ``"polynomial"``): its
    records, the right name selected, selected or equivalent, and how many of each true
    parameter lie in the true model's 95 % intervals; a polynomial truth: how many records
    had a named model selected.  ``"all"``: the line under the table (a list of lines),
    every parameter of every record together."""
    rows = [r for r in rows if not r.get("skipped")]
    if label == "all":
        parts = []
        for boot, whose in ((False, "the Jacobian's"), (True, "the bootstrap's")):
            k, n = _together(rows, boot)
            if n:
                parts.append(f"{k}/{n} = {100 * k / n:.1f} % inside {whose} intervals")
        return ["", "All parameters together: " + (", ".join(parts) or "no intervals") + "."]
    rs = [r for r in rows if r["truth"] == label]
    n = len(rs)
    if label == "polynomial":
        named = sum(r["selected"] is not None for r in rs)
        none = sum(r["selected"] is None for r in rs)
        return (
            f"| polynomial | {n} | a named model selected {named}/{n} (no named model "
            f"consistent with {none} of the {n}) | | | |"
        )
    right = sum(r["selected"] == label for r in rs)
    either = sum(label in [r["selected"], *r["equivalent"]] for r in rs)
    cells = [
        label,
        n,
        f"{right}/{n}",
        f"{either}/{n}",
        _coverage_cell(_coverage(rs)),
        _coverage_cell(_coverage(rs, boot=True)),
    ]
    return "| " + " | ".join(str(c) for c in cells) + " |"


def _setting(rows, key):
    """The values of a setting over the rows (``"60/200"`` where runs differ)."""
    seen = []
    for r in rows:
        v = (r.get("settings") or {}).get(key)
        if v is not None and v not in seen:
            seen.append(v)
    return "/".join(str(v) for v in seen) or "?"


def models_stamp(files, rows):
    """The line under docs/validation.md's table of the named models: each run file with
    its commit and date, the records, the fits' budget, the median time of a record's fits
    and the records the bootstrap was run on."""
    runs = []
    for f in files:
        head, _ = measured.read(f)
        commit = f"commit {head['commit']}" if head.get("commit") else "commit not recorded"
        runs.append(f"`{f.name}` ({commit}, {str(head.get('started', '?'))[:10]})")
    done = [r for r in rows if not r.get("skipped")]
    seconds = [r["seconds"] for r in done if r.get("seconds") is not None]
    median = f"{float(np.median(seconds)):.0f} s" if seconds else "?"
    boot = [r for r in done if r.get("boot_intervals")]
    skipped = len(rows) - len(done)
    return (
        "*Rendered by `make tables` from the survey runs in `docs/_measured/`: "
        + ", ".join(runs)
        + f": {len(done)} records"
        + (f" (and {skipped} seed{'s' * (skipped > 1)} skipped: no usable draw)" if skipped else "")
        + f", each fitted by every model (up to {_setting(done, 'max_simulations')} "
        f"simulations a fit; median {median} a record), the bootstrap "
        f"({_setting(boot, 'boot')} replicates) for the true model's fit on {len(boot)}.*"
    )


def arm_table(rows, arms):
    """Per truth and arm: the right name selected, right or equivalent, settled
    (:func:`settled`), and in how many records a second record was made."""
    lines = [
        "truth                 arm       records  right name  right or equivalent  settled  "
        "second record made  settled where the first left the other family open"
    ]
    for name in MODELS:
        rs = [r for r in rows if r["truth"] == name and not r.get("skipped")]
        if not rs:
            continue
        # the records whose first fit left a model of the other damping family consistent
        open_ = [r for r in rs if r["truth"] in [r["selected"], *r["equivalent"]]]
        open_ = [r for r in open_ if not settled(r, "none")]
        for arm in arms:
            right = sum(final(r, arm)[0] == name for r in rs)
            either = sum(name in [final(r, arm)[0], *final(r, arm)[1]] for r in rs)
            done = sum(bool(((r.get("second") or {}).get(arm) or {}).get("made")) for r in rs)
            lines.append(
                f"{name:<21s} {arm:<9s} {len(rs):7d}  {right:4d}/{len(rs):<5d} "
                f"{either:4d}/{len(rs):<14d} {sum(settled(r, arm) for r in rs):3d}/{len(rs):<4d}"
                f" {done if arm != 'none' else '-':>4}"
                f"{sum(settled(r, arm) for r in open_):>20d}/{len(open_)}"
            )
        seeds = sorted(r["seed"] for r in rs)
        lines.append(f"{'':21s} seeds {' '.join(map(str, seeds))}")
    return "\n".join(lines)


def _one(context, job):
    """One record in an executor's worker."""
    max_sim, boot, second, opts = context
    return one_record(*job, max_sim, boot, second, opts)


def _records(jobs, context, workers):
    """The rows of ``jobs`` (``(truth, seed)``), as they are made (in ``workers``
    processes: in the order they finish)."""
    if workers <= 1:
        for job in jobs:
            yield _one(context, job)
        return
    from discovery.numerics.executor import make_executor
    from discovery.warm import warm

    warm()  # numba's cache built here, before the workers load it
    with make_executor(workers) as ex:
        for _, row in ex.run(_one, jobs, context):
            yield row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--per-model", type=int, default=2)
    ap.add_argument("--poly", type=int, default=2)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--max-simulations", type=int, default=60)
    ap.add_argument(
        "--models",
        nargs="+",
        choices=[*MODELS, "polynomial"],
        help="the truths surveyed (default: every model, --per-model each, and --poly "
        "polynomial laws)",
    )
    ap.add_argument(
        "--seeds",
        nargs="+",
        type=int,
        help="the seeds of each truth (instead of --per-model and --seed)",
    )
    ap.add_argument(
        "--second-point",
        nargs="+",
        choices=("none", "advised", "random"),
        default=["none"],
        help="second records made where the first fit reports equivalent models (one run "
        "may make both on the same first record)",
    )
    ap.add_argument(
        "--joint-models",
        choices=("candidates", "all"),
        default="candidates",
        help="the joint fit's models: the first fit's selected and equivalent, or all",
    )
    ap.add_argument("--amplitude-range", nargs=2, type=float, default=(0.5, 2.0))
    ap.add_argument("--frequency-range", nargs=2, type=float, default=(0.7, 1.4))
    ap.add_argument("--max-force-factor", type=float, default=3.0)
    ap.add_argument("--advise-grid", nargs=2, type=int, default=(4, 4))
    ap.add_argument("--advise-refine", type=int, default=2)
    ap.add_argument(
        "--boot",
        type=int,
        default=30,
        help="bootstrap replicates of the true model's intervals (0: none)",
    )
    ap.add_argument(
        "--workers", type=int, default=1, help="records made at once, in processes (default 1)"
    )
    ap.add_argument(
        "--out",
        default=["out/survey_contact_models.jsonl"],
        nargs="+",
        help="the run file the rows are appended to (with --summarize: the files to read)",
    )
    ap.add_argument(
        "--summarize", action="store_true", help="only print the table of the rows in --out"
    )
    a = ap.parse_args(argv)
    if a.summarize:
        print(summary(read_rows(a.out)))
        return
    out = measured.RunFile(a.out[0], "survey_contact_models", argv, append=True)
    rows = []
    truths = a.models or [*MODELS, "polynomial"]
    if a.seeds:
        jobs = [(m, seed) for seed in a.seeds for m in truths]
    else:
        jobs = [
            (m, a.seed + 1000 * j + i)
            for i in range(a.per_model)
            for j, m in enumerate(MODELS)
            if m in truths
        ]
        if "polynomial" in truths:
            jobs += [("polynomial", a.seed + 9000 + i) for i in range(a.poly)]
        # interleave so a run cut short still has every model
        jobs.sort(key=lambda j: (j[1] % 1000, j[0]))
    opts = {
        "amplitude_range": tuple(a.amplitude_range),
        "frequency_range": tuple(a.frequency_range),
        "max_force_factor": a.max_force_factor,
        "grid": tuple(a.advise_grid),
        "refine": a.advise_refine,
        "joint_models": a.joint_models,
    }
    commit, dirty = git_state()
    stamp = {
        "code": {"commit": commit, "dirty": dirty},
        "versions": provenance()["versions"],
        "settings": {k: (list(v) if isinstance(v, tuple) else v) for k, v in vars(a).items()},
    }
    context = (a.max_simulations, a.boot, tuple(a.second_point), opts)
    for row in _records(jobs, context, a.workers):
        row.update(stamp)
        rows.append(row)
        out.write(row)
        print(
            f"{row['truth']:<20s} seed {row['seed']}: selected {row.get('selected')} "
            f"equivalent {row.get('equivalent')} covered {row.get('covered')} "
            f"{row.get('seconds', 0):.0f} s",
            flush=True,
        )
        for arm, got in (row.get("second") or {}).items():
            what = (
                f"at {got['point'][0]:.4g} N, {got['point'][1]:.4g} Hz: selected "
                f"{got['selected']} equivalent {got['equivalent']} {got['seconds']:.0f} s"
                if got.get("made")
                else f"none made ({got.get('why')})"
            )
            print(f"    {arm:<8s} {what}", flush=True)
    print(summary(rows))


if __name__ == "__main__":
    main()
