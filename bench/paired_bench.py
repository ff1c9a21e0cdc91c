"""Old against new on the same machine in one run: whole commands, paired, with their counts.

A shared machine's load comes and goes; a ratio of two timings taken minutes apart measures
the load as much as the code.  Here every command runs with the baseline code (a checkout of
:data:`BASELINE`, made once in ``bench/_work/baseline``) and with this checkout, one right
after the other, in alternating order, ``pairs`` times; the figure is the median of the
pairs' ratios (new / old).  Both sides run the same command line on the same inputs, made
once by this checkout; each side runs the command once untimed first (its kernels compiled
and cached).  Beside each ratio: the work the new code counted (``summary.json``'s
``counts``: laws judged against a record, criterion sets, steady states, periods), numbers
no machine changes.

    python paired_bench.py                 # every command, 3 pairs
    python paired_bench.py --quick         # verify and the fits, 2 pairs
    python paired_bench.py --commands contact-models --pairs 2
"""

import argparse
import csv
import json
import os
import shutil
import statistics
import subprocess
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
WORK = ROOT / "bench" / "_work"
#: the code the ratios are measured against (issue 52's baseline)
BASELINE = "44858e9"
LAW = "2.06e8*z + 1.28e7*zd"
#: name -> (the command's words after ``vidi``, in quick mode too)
COMMANDS = {
    "verify": (["verify", "--data", "R.csv", "--law", LAW], True),
    "fit": (["fit", "--data", "R.csv", "--intervals", "0"], True),
    "explain": (["explain", "--data", "R.csv", "--start", "linear"], False),
    # the five named models on the README's record (M.csv), intervals included
    "contact-models": (["fit", "--data", "M.csv", "--library", "contact-models"], False),
    # the README's quickstart, as a newcomer types it (Q.csv: 12 periods on the orbit)
    "fit-readme": (["fit", "--data", "Q.csv"], True),
    # the demo's fit (make demo): its two 30-period records at two drive amplitudes, jointly
    "fit-demo": (
        "fit --scenario high.toml --scenario low.toml --data high.csv --data low.csv".split(),
        False,
    ),
}
#: the field-like corpus (records of a simulator not ours, ``../shared/corpus``): explain on
#: the records issue 52 names, each with its own scenario
CORPUS = ROOT.parent / "shared" / "corpus"
for _name in ("c02-steep-onset", "c06-unloading-damping", "c12-coupling-unloading"):
    if (CORPUS / _name / "measured.csv").is_file():
        _files = ["--data", str(CORPUS / _name / "measured.csv")]
        _files += ["--scenario", str(CORPUS / _name / "scenario.toml")]
        COMMANDS[f"explain-{_name[:3]}"] = (["explain", *_files], False)


#: the shipped paper study (``examples/study_paper.toml``: 120 runs on every core, tables only),
#: paired on its own (``python run.py paper-study``; 8 minutes a pair on two cores)
STUDY = ["study", "--config", str(ROOT / "examples" / "study_paper.toml"), "--no-figures"]
#: the study table's columns compared cell by cell, old against new (what a run found, not
#: how long it took)
STUDY_COLUMNS = ("recovered", "equivalent", "fp_per_run", "fn_per_run", "covered", "consistent")


def baseline_tree():
    """The baseline checkout (a git worktree, made once)."""
    tree = WORK / "baseline"
    if not (tree / "discovery").is_dir():
        WORK.mkdir(parents=True, exist_ok=True)
        subprocess.run(
            ["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), BASELINE],
            check=True,
            capture_output=True,
        )
    return tree


def compiled(*trees):
    """Both sides read their modules' bytecode, as an installed package does (``make
    install`` writes it): where PYTHONDONTWRITEBYTECODE is set, a side without it would
    compile ~130 modules per command, a cost of the install, not of the code."""
    for tree in trees:
        subprocess.run(
            [sys.executable, "-m", "compileall", "-q", "discovery", "reports", "constraints"],
            cwd=tree,
            check=True,
            capture_output=True,
        )


def _vidi(code_root, words, cwd):
    """Run ``vidi WORDS`` with the package of ``code_root``; returns seconds."""
    env = {**os.environ, "PYTHONPATH": str(code_root)}
    t0 = time.perf_counter()
    run = subprocess.run(
        [sys.executable, "-c", "import sys; from discovery.cli import main; sys.exit(main())"]
        + words
        + ["--overwrite"],
        cwd=cwd,
        env=env,
        capture_output=True,
        text=True,
        check=False,
    )
    seconds = time.perf_counter() - t0
    if run.returncode != 0:
        raise RuntimeError(f"{code_root.name}: vidi {' '.join(words)}: {run.stderr[-800:]}")
    return seconds


def record(cwd):
    """The bench records: the paper's machine from rest by the scipy path, 1 % noise (a
    record in its transient, as the README's first record), the README's record of the
    named models, the README quickstart's record and the demo's two records."""
    _vidi(
        ROOT,
        [
            "simulate",
            "--law",
            LAW + "; unloading: 4e6*zd",
            "--from-rest",
            "--periods",
            "30",
            "--integrator",
            "scipy",
            "--noise",
            "0.01",
            "--position-noise",
            "0.002",
            "--out",
            "R.csv",
        ],  # fmt: skip
        cwd,
    )
    # the README's 20-period record of the paper's machine (its named-models example)
    words = ["simulate", "--scenario", "paper", "--law", LAW, "--periods", "20", "--fs", "20000"]
    _vidi(ROOT, words + ["--noise", "0.01", "--seed", "1", "--out", "M.csv"], cwd)
    # the README quickstart's record: its fit had gone from 7 s to 19 s unseen by the records
    # above (a damping-only law restarted where each simulation takes 0.25 s: CHANGELOG)
    words = ["simulate", "--scenario", "paper", "--periods", "12", "--noise", "0.01"]
    _vidi(ROOT, words + ["--seed", "1", "--out", "Q.csv"], cwd)
    # the demo's records (the Makefile's demo target): its machine at two drive amplitudes,
    # from rest by the scipy path, the contact damping while unloading
    machine = "m1 = 1.0e4\nm2 = 1.0e4\nk1 = 2.75e7\nc1 = 1.0e5\nfrequency = 25.0\n"
    law = "2.06e8*z + 4e6*zd"
    for name, amplitude, seed in (("high", "5.0e5", "1"), ("low", "3.5e5", "2")):
        (cwd / f"{name}.toml").write_text(
            f'name = "grid-{name}"\n[machine]\n{machine}A = {amplitude}\n[law]\ntext = "{law}"\n'
        )
        words = ["simulate", "--scenario", f"{name}.toml", "--law", f"{law}; unloading: 4e6*zd"]
        words += ["--from-rest", "--integrator", "scipy", "--periods", "30", "--noise", "0.01"]
        _vidi(ROOT, words + ["--seed", seed, "--out", f"{name}.csv"], cwd)


def paired(name, words, pairs, cwd, old, *, fresh=False):
    """``{"ratio", "ratios", "new", "old", "counts"}`` of one command; with ``fresh`` (a
    study, which reuses the runs it finds in ``--out``) each timed run starts from an empty
    ``--out`` and the untimed first runs do two of its runs only."""
    out_new, out_old = ["--out", f"new_{name}"], ["--out", f"old_{name}"]
    warm = ["--max-runs", "2"] if fresh else []
    _vidi(ROOT, words + out_new + warm, cwd)  # untimed: compiled and cached
    _vidi(old, words + out_old + warm, cwd)
    new, base = [], []
    for k in range(pairs):
        order = [(ROOT, out_new, new), (old, out_old, base)]
        for code, out, times in order if k % 2 == 0 else order[::-1]:
            if fresh:  # the study's results and its work directory beside them
                for d in (out[1], f".{out[1]}.vidi-study"):
                    shutil.rmtree(cwd / d, ignore_errors=True)
            times.append(_vidi(code, words + out, cwd))
    ratios = [n / o for n, o in zip(new, base, strict=True)]
    summary = json.loads((cwd / f"new_{name}" / "summary.json").read_text())
    return {
        "ratio": statistics.median(ratios),
        "ratios": ratios,
        "new": new,
        "old": base,
        "counts": summary.get("counts"),
    }


def bench_paired(quick=False, pairs=None, only=None):
    """Every command of :data:`COMMANDS` (the quick ones with ``quick``; those named in
    ``only`` with it), old and new."""
    old = baseline_tree()
    compiled(old, ROOT)
    pairs = pairs or (2 if quick else 3)
    cwd = WORK / "paired"
    shutil.rmtree(cwd, ignore_errors=True)
    cwd.mkdir(parents=True)
    record(cwd)
    out = {"baseline": BASELINE, "pairs": pairs, "commands": {}}
    for name, (words, in_quick) in COMMANDS.items():
        if (quick and not in_quick) or (only and name not in only):
            continue
        out["commands"][name] = paired(name, words, pairs, cwd, old)
        print_paired({"commands": {name: out["commands"][name]}}, head=False)
    return out


def _cells(path):
    with open(path, newline="") as fh:
        rows = list(csv.DictReader(fh))
    return {tuple(r[k] for k in ("force_noise", "periods", "selection")): r for r in rows}


def _simulations(path):
    with open(path, newline="") as fh:
        return sum(int(float(r["simulations"] or 0)) for r in csv.DictReader(fh))


def study_tables(cwd, name):
    """The two sides' study tables compared: ``{"cells", "same_cells", "differ",
    "simulations_new", "simulations_old"}`` (``differ``: each cell whose
    :data:`STUDY_COLUMNS` differ, with both sides' values)."""
    new, old = _cells(cwd / f"new_{name}" / "cells.csv"), _cells(cwd / f"old_{name}" / "cells.csv")
    differ = []
    for key, row in new.items():
        a = {c: row.get(c) for c in STUDY_COLUMNS}
        b = {c: old.get(key, {}).get(c) for c in STUDY_COLUMNS}
        if a != b:
            differ.append({"cell": list(key), "new": a, "old": b})
    return {
        "cells": len(new),
        "same_cells": len(new) - len(differ),
        "differ": differ,
        "simulations_new": _simulations(cwd / f"new_{name}" / "runs.csv"),
        "simulations_old": _simulations(cwd / f"old_{name}" / "runs.csv"),
    }


def bench_paper_study(pairs=3):
    """The shipped paper study (:data:`STUDY`), old and new in turn, ``pairs`` times, with
    its tables compared cell by cell (:func:`study_tables`)."""
    old = baseline_tree()
    compiled(old, ROOT)
    cwd = WORK / "paired-study"
    shutil.rmtree(cwd, ignore_errors=True)
    cwd.mkdir(parents=True)
    out = paired("paper-study", STUDY, pairs, cwd, old, fresh=True)
    out.update(study_tables(cwd, "paper-study"))
    out["counts"] = {"simulations": out["simulations_new"]}
    return {"baseline": BASELINE, "pairs": pairs, "commands": {"paper-study": out}}


def print_study(result):
    """The paired study's line and its tables' agreement."""
    print_paired(result)
    r = result["commands"]["paper-study"]
    print(
        f"  paper study: {r['same_cells']}/{r['cells']} cells the same ({', '.join(STUDY_COLUMNS)}"
        f"); simulations {r['simulations_new']} against {r['simulations_old']} "
        f"({r['simulations_new'] / r['simulations_old']:.2f})"
    )
    for d in r["differ"]:
        print(f"    differs: {d['cell']}: new {d['new']}, old {d['old']}")


def print_paired(result, head=True):
    if head:
        print(f"old ({result['baseline']}) against new, paired ({result['pairs']} pairs):")
    for name, r in result["commands"].items():
        c = r.get("counts") or {}
        counted = ", ".join(f"{k} {v}" for k, v in c.items())
        each = ", ".join(f"{x:.2f}" for x in r["ratios"])
        new, old = statistics.median(r["new"]), statistics.median(r["old"])
        print(
            f"  {name:14s} new/old {r['ratio']:.2f} (pairs {each}; new median {new:.1f} s, "
            f"old {old:.1f} s)  counts: {counted}"
        )


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--quick", action="store_true", help="verify and the fits only, 2 pairs")
    ap.add_argument("--pairs", type=int, help="pairs per command (default 3; 2 with --quick)")
    ap.add_argument("--commands", nargs="+", choices=list(COMMANDS), help="only these commands")
    args = ap.parse_args(argv)
    res = bench_paired(args.quick, args.pairs, args.commands)
    print_paired(res)
    return 0


if __name__ == "__main__":
    sys.exit(main())
