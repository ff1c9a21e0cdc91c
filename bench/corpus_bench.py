"""The corpus, old against new: what each record's commands find, and how long they take.

Every record of ``../shared/corpus`` (a simulator not ours, with its truth) is judged with
its true law (``vidi verify``), fitted (``vidi fit``) and explained (``vidi explain``, from
the linear start) with the baseline's code (:data:`paired_bench.BASELINE`) and with this
checkout's, one right after the other (the order alternating record by record), each side
run once untimed first.  Compared record by record, old against new and each against the
record's truth: the true law's verdict, the selected support and its verdict, the effects
explain names and its final verdict.  The time of each command is a ratio new / old per
record, and the median over the records is the command's figure (one pair per record: the
records are the repeats).

    python corpus_bench.py                                 # every record and command
    python corpus_bench.py --records c02 c14 --commands explain
"""

import argparse
import json
import statistics
import sys

from paired_bench import BASELINE, CORPUS, ROOT, WORK, _vidi, baseline_tree, compiled

sys.path.insert(0, str(ROOT))

#: the commands run on each record (the record's own files added), by name
COMMANDS = ("verify", "fit", "explain")


def records(only=None):
    """``[(name, folder, truth)]`` of the corpus's records (those whose name starts with one
    of ``only``, given)."""
    out = []
    for d in sorted(CORPUS.iterdir()) if CORPUS.is_dir() else []:
        if not (d / "truth.json").is_file():
            continue
        if only and not any(d.name.startswith(o) for o in only):
            continue
        out.append((d.name, d, json.loads((d / "truth.json").read_text())))
    return out


def _truth_law(truth):
    """The truth's law as the grammar reads it, or None (c11's offset is written outside it)."""
    from discovery import ForceLaw
    from discovery.errors import InputError

    try:
        return ForceLaw.parse(truth["law"])
    except (InputError, ValueError):
        return None


def words(command, folder, truth):
    """The command line of ``command`` on the record in ``folder`` (None: not run there)."""
    files = ["--data", str(folder / "measured.csv"), "--scenario", str(folder / "scenario.toml")]
    if command == "verify":
        return None if _truth_law(truth) is None else ["verify", *files, "--law", truth["law"]]
    if command == "fit":
        return ["fit", *files, "--intervals", "0"]
    return ["explain", *files]


def found(command, summary):
    """What a command's ``summary.json`` says it found, in the terms the sides are compared
    by: the verdict; for fit the selected terms too, for explain the named effects."""
    if command == "verify":
        return {"consistent": bool(summary.get("consistent"))}
    if command == "fit":
        sel = summary.get("selected") or {}
        return {"terms": sorted(sel.get("terms") or []), "consistent": bool(sel.get("consistent"))}
    named = sorted(it["effect"] for it in summary.get("iterations", []) if it.get("effect"))
    return {"named": named, "consistent": bool(summary.get("consistent"))}


def right(command, what, truth):
    """Whether a side's finding ``what`` is the truth's: the true law consistent; the
    selected support the true law's (where the truth is a polynomial of the library: no
    hidden effect outside it); the effects named those hidden (none on a clean record).
    None where the truth does not say."""
    hidden = truth.get("hidden_effect")
    hidden = sorted([hidden] if isinstance(hidden, str) else hidden or [])
    if command == "verify":
        return what["consistent"]
    if command == "fit":
        law = _truth_law(truth)
        if law is None or any(h not in ("penetration_velocity_coupling",) for h in hidden):
            return None
        return what["terms"] == sorted(law.names)
    return what["named"] == hidden


def _side(code, argv, cwd, out):
    """``(seconds, summary)`` of one side's run (``(None, error)`` when it failed)."""
    try:
        seconds = _vidi(code, argv + ["--out", out], cwd)
    except RuntimeError as exc:
        return None, {"error": str(exc).splitlines()[-1][:200]}
    return seconds, json.loads((cwd / out / "summary.json").read_text())


def pair(command, argv, cwd, old, k, truth):
    """One record's command, old and new in turn (new first on even ``k``): each side's
    seconds, finding and whether it is right, the ratio, and whether the findings agree."""
    sides = {}
    order = [("new", ROOT), ("old", old)]
    for name, code in order if k % 2 == 0 else order[::-1]:
        seconds, summary = _side(code, argv, cwd, f"{name}_{command}")
        what = None if "error" in summary else found(command, summary)
        sides[name] = {
            "seconds": seconds,
            "found": what if what is not None else summary,
            "right": None if what is None else right(command, what, truth),
            "counts": summary.get("counts") if name == "new" else None,
        }
    new, old_ = sides["new"]["seconds"], sides["old"]["seconds"]
    return {
        **sides,
        "ratio": new / old_ if new and old_ else None,
        "same": sides["new"]["found"] == sides["old"]["found"],
    }


def bench_corpus(only=None, commands=COMMANDS):
    """Every record's ``commands``, old and new (:func:`pair`), and each command's summary:
    ``{"baseline", "records": {name: {command: pair}}, "commands": {command: summary}}``."""
    old = baseline_tree()
    compiled(old, ROOT)
    out = {"baseline": BASELINE, "records": {}, "commands": {}}
    for k, (name, folder, truth) in enumerate(records(only)):
        cwd = WORK / "corpus" / name
        cwd.mkdir(parents=True, exist_ok=True)
        row = out["records"].setdefault(name, {})
        for command in commands:
            argv = words(command, folder, truth)
            if argv is None:
                continue
            if k == 0:  # untimed: both sides' kernels compiled and cached
                _side(ROOT, argv, cwd, "warm")
                _side(old, argv, cwd, "warm")
            row[command] = pair(command, argv, cwd, old, k, truth)
            print_record(name, command, row[command])
    for command in commands:
        out["commands"][command] = summary(out["records"], command)
    return out


def summary(rows, command):
    """One command over the records: the median ratio, how many findings agree, how many
    each side got right, and the records where the findings differ."""
    got = [(name, r[command]) for name, r in rows.items() if command in r]
    ratios = [p["ratio"] for _, p in got if p["ratio"] is not None]
    judged = [p for _, p in got if p["new"]["right"] is not None or p["old"]["right"] is not None]
    return {
        "ratio": statistics.median(ratios) if ratios else None,
        "ratios": ratios,
        "records": len(got),
        "same": sum(p["same"] for _, p in got),
        "judged": len(judged),
        "right_new": sum(bool(p["new"]["right"]) for p in judged),
        "right_old": sum(bool(p["old"]["right"]) for p in judged),
        "differ": [
            {"record": name, "new": p["new"]["found"], "old": p["old"]["found"]}
            for name, p in got
            if not p["same"]
        ],
        "seconds_new": sum(p["new"]["seconds"] or 0.0 for _, p in got),
        "seconds_old": sum(p["old"]["seconds"] or 0.0 for _, p in got),
    }


def _text(what):
    if what is None:
        return "-"
    if "error" in what:
        return f"failed ({what['error'][:60]})"
    verdict = "consistent" if what["consistent"] else "inconsistent"
    if "terms" in what:
        return f"{' + '.join(what['terms'])} ({verdict})"
    if "named" in what:
        return f"{', '.join(what['named']) or 'nothing'} ({verdict})"
    return verdict


def print_record(name, command, p):
    mark = {True: "right", False: "wrong", None: ""}
    ratio = "-" if p["ratio"] is None else f"{p['ratio']:.2f}"
    print(
        f"  {name:24s} {command:8s} new/old {ratio:>5s}  new: {_text(p['new']['found'])} "
        f"{mark[p['new']['right']]}; old: {_text(p['old']['found'])} {mark[p['old']['right']]}"
        f"{'' if p['same'] else '  (differ)'}",
        flush=True,
    )


def print_corpus(result):
    print(f"the corpus, old ({result['baseline']}) against new, one pair a record:")
    for command, s in result["commands"].items():
        ratio = "-" if s["ratio"] is None else f"{s['ratio']:.2f}"
        print(
            f"  {command:8s} new/old {ratio} (median of {len(s['ratios'])} records; "
            f"{s['seconds_new']:.0f} s against {s['seconds_old']:.0f} s in all); the same "
            f"finding on {s['same']}/{s['records']}; right {s['right_new']}/{s['judged']} new, "
            f"{s['right_old']}/{s['judged']} old"
        )
        for d in s["differ"]:
            print(f"    differs on {d['record']}: new {_text(d['new'])}; old {_text(d['old'])}")


def main(argv=None, parse_only=False):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--records", nargs="+", help="only the records whose names start so")
    ap.add_argument("--commands", nargs="+", choices=COMMANDS, default=list(COMMANDS))
    a = ap.parse_args(argv)
    if parse_only:
        return a
    print_corpus(bench_corpus(a.records, a.commands))
    return 0


if __name__ == "__main__":
    sys.exit(main())
