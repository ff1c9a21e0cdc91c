"""The speed history of docs/validation.md: one row per ``make bench`` run.

Not a test module.  ``docs/_measured/bench-history.jsonl`` is a run file of
:mod:`tests.measured` whose rows are the benchmark runs, each with the commit of the code it
measured (``+dirty`` when the checkout had changes), when it ran, the commit that saved its
``bench/results.json`` and its figures as that file had them.  ``make bench`` appends its run
(``bench/run.py``); ``python -m tests.bench_history`` rebuilds the file from every version of
``bench/results.json`` in the git history (``git log --follow``), keeping rows appended since
that were never committed.

A results file holds one run, or two when ``python run.py kernel`` measured the kernel again
afterwards: that section then has its own ``kernel_vs_scipy_provenance`` and is a run of its
own (a *partial* run: the kernel's figures only; ``python run.py paper-study``'s paired
paper study likewise).  :func:`columns` picks the table's runs (the
last :data:`COLUMNS`; a partial run measured again by the next partial run before any full
one is left out) and :func:`markdown_row` makes each row of the table from the numbers (keys
missing from older runs are blank cells).

    python -m tests.bench_history                          # rebuild from the git history
    python -m tests.bench_history --append bench/results.json  # add a results file's runs
"""

import argparse
import json
import subprocess
import sys

from . import measured

PATH = measured.MEASURED / "bench-history.jsonl"
RESULTS = "bench/results.json"

#: the runs the table shows, newest last
COLUMNS = 7

#: a results file's keys that describe its run rather than measure something
_META = {"cores", "versions", "git", "platform", "created", "settings"}


def _short(git):
    """``a9e87b2`` / ``de0d289+dirty`` from a provenance's ``git`` (None when not recorded)."""
    if not git or not git.get("commit"):
        return None
    return git["commit"][:7] + ("+dirty" if git.get("dirty") else "")


def _run(prov, sections, results, saved_in, partial):
    return {
        "commit": _short(prov.get("git")),
        "git": (prov.get("git") or {}).get("commit"),
        "created": prov.get("created"),
        "saved_in": saved_in,
        "partial": partial,
        "sections": sections,
        "cores": results.get("cores"),
        "platform": prov.get("platform"),
        "versions": prov.get("versions"),
        "results": {k: results[k] for k in sections},
    }


def runs_in(results, saved_in=None):
    """The runs of one ``bench/results.json`` (a dict): the whole bench's, less the sections
    measured again later with their own ``SECTION_provenance``, and one for each of those."""
    again = {k.removesuffix("_provenance") for k in results if k.endswith("_provenance")}
    sections = [
        k for k in results if k not in _META and not k.endswith("_provenance") and k not in again
    ]
    out = [_run(results, sections, results, saved_in, partial=False)]
    for k in sorted(again):
        if k in results:
            out.append(_run(results[f"{k}_provenance"], [k], results, saved_in, partial=True))
    return out


def key(run):
    """A run's identity: the commit it measured and when it ran."""
    return (run.get("git"), run.get("created"))


def merge(rows, new):
    """``rows`` with the runs ``new`` added (a run already there keeps the version with more
    sections, and the commit that saved it once known), in the order they ran."""
    by = {key(r): r for r in rows}
    for r in new:
        old = by.get(key(r))
        if old is None:
            by[key(r)] = r
            continue
        keep = r if len(r["sections"]) > len(old["sections"]) else old
        by[key(r)] = {**keep, "saved_in": old.get("saved_in") or r.get("saved_in")}
    return sorted(by.values(), key=lambda r: str(r.get("created")))


def from_git():
    """Every run of every version of ``bench/results.json`` in the git history, each with
    the commit that first saved it."""
    log = measured.git("log", "--follow", "--format=%h", "--", RESULTS)
    rows = []
    for commit in reversed((log or "").split()):
        try:
            text = subprocess.run(
                ["git", "show", f"{commit}:{RESULTS}"],
                cwd=measured.ROOT,
                capture_output=True,
                text=True,
                check=True,
            ).stdout
            results = json.loads(text)
        except (subprocess.SubprocessError, ValueError):
            continue  # a version that is not there under that name, or not JSON
        rows = merge(rows, runs_in(results, saved_in=commit))
    return rows


def _header():
    return measured.stamp(
        "bench_history",
        [],
        command="python -m tests.bench_history",
    ) | {
        "note": "one row per make bench run, from bench/results.json as each commit that "
        "changed it saved it (git log --follow), with the commit and date of the run; make "
        "bench appends its run; 'commit' above is the code that gathered the rows, each row "
        "names the code that made it"
    }


def write(rows, path=PATH):
    """Write the run file: a fresh header, then ``rows``."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "w") as fh:
        print(json.dumps({"run": _header()}), file=fh)
        for r in rows:
            print(json.dumps(r, default=float), file=fh)


def append(results, path=PATH):
    """Add the runs of ``results`` (a results file's dict) that ``path`` lacks; the new runs."""
    header, rows = measured.read(path) if path.exists() else ({}, [])
    known = {key(r) for r in rows}
    new = [r for r in runs_in(results) if key(r) not in known]
    if not header:
        write(merge(rows, new), path)
        return new
    with open(path, "a") as fh:
        for r in new:
            print(json.dumps(r, default=float), file=fh)
    return new


# --------------------------------------------------------------------------- the table


def label(run):
    """A run's column: its commit (the commit that saved it when it recorded none)."""
    return run["commit"] or f"saved in {run['saved_in']}"


def read_rows(paths):
    """The runs of the run files ``paths``, in the order they ran (one run once)."""
    rows = []
    for path in paths:
        rows = merge(rows, measured.read(path)[1])
    return rows


def columns(runs, n=COLUMNS):
    """The last ``n`` runs, less a partial run whose sections the next run measured again
    as a partial run too (the same figures measured again before the next full bench)."""
    kept = []
    for i, r in enumerate(runs):
        later = [s for s in runs[i + 1 :] if set(r["sections"]) & set(s["sections"])]
        if r["partial"] and later and later[0]["partial"]:
            continue
        kept.append(r)
    return kept[-n:]


def header(runs):
    cols = columns(runs)
    return (
        "| figure | " + " | ".join(label(r) for r in cols) + " |",
        "|---" * (len(cols) + 1) + "|",
    )


#: what a partial run measured, by its section
PARTIAL = {
    "kernel_vs_scipy": "the kernel's figures only",
    "paired_study": "the paper study only",
    "paired_corpus": "the corpus only",
}


def _partial(run):
    return "; ".join(PARTIAL.get(s, s) for s in run["sections"])


def stamp(files, runs):
    """The line under the table: the run file, and each column's commit and date."""
    cols = columns(runs)
    shown = ", ".join(
        f"{label(r)} ({str(r['created'])[:10]}"
        + (f", saved in {r['saved_in']}" if r.get("saved_in") and r["commit"] else "")
        + (f", {_partial(r)}" if r["partial"] else "")
        + ")"
        for r in cols
    )
    names = ", ".join(f"`{p.name}`" for p in files)
    return (
        f"*Rendered by `make tables` from {names} in `docs/_measured/` (`make bench`'s runs, "
        f"{len(runs)} so far; `python -m tests.bench_history` gathers them from the git "
        f"history): the columns are the runs at {shown}.*"
    )


def _get(run, *path):
    x = run["results"]
    for p in path:
        if not isinstance(x, dict) or p not in x:
            return None
        x = x[p]
    return x


def _sig(x, digits=2):
    """``x`` to ``digits`` significant figures, no exponent: ``0.69``, ``28``, ``175``."""
    if x is None:
        return ""
    if abs(x) >= 10 ** (digits - 1):
        return f"{x:.0f}"
    return f"{float(f'{x:.{digits}g}'):g}"


def _paths(run, fmt):
    """``fmt(closed)`` with the stepped free flights' figure after it when measured."""
    closed = _get(run, "kernel_vs_scipy", "free_flight_paths", "closed")
    stepped = _get(run, "kernel_vs_scipy", "free_flight_paths", "integrate")
    if closed is None:
        return None
    cell = fmt(closed)
    if stepped is not None:
        cell += f" (stepped flights: {fmt(stepped)})"
    return cell


def _kernel(run):
    k = _get(run, "kernel_vs_scipy")
    if k is None:
        return ""
    cell = _paths(run, lambda d: f"{d['speedup']:.0f}x / {d['long_run_40_periods_speedup']:.0f}x")
    return cell or f"{k['speedup']:.0f}x / {k['long_run_40_periods_speedup']:.0f}x"


def _steady(run):
    cell = _paths(run, lambda d: f"{_sig(d['steady_state_seconds'] * 1e3, 3)} ms")
    one = _get(run, "landscape_41x41", "one_steady_state_seconds")
    if cell is None and one is not None:
        cell = f"{_sig(one * 1e3, 3)} ms"
    return cell or ""


def _cold_vs_scipy(run):
    return _paths(run, lambda d: f"{d['steady_state_speedup_over_scipy']:.0f}x") or ""


def _landscape(run):
    L = _get(run, "landscape_41x41")
    if L is None:
        return ""
    return f"{L['seconds']:.1f} s ({L['steady_state_equivalents_per_point']:.2f})"


def _identify(run):
    ls = _get(run, "identification", "least-squares", "simulations_to_0.1%")
    cd = _get(run, "identification", "coordinate-descent", "simulations_to_0.1%")
    if ls is None:
        return ""
    return f"{ls} ({cd})" if cd is not None else str(ls)


def _verify(run):
    v = _get(run, "pipeline", "verify_20_periods")
    if v is None:
        return ""
    return f"{_sig(v['ratio_to_one_steady_state'])} x ({v['seconds']:.2f} s)"


def _wall_ratio(d):
    """``55.6 s, 4523 x``: the wall time and the ratio to one steady state."""
    if d is None:
        return ""
    if "error" in d:
        return "failed"
    return f"{d['seconds']:.1f} s, {d['ratio_to_one_steady_state']:.0f} x"


def _parallel(d, same=None):
    if d is None or "parallel_speedup" not in d:
        return ""
    cell = f"{d['parallel_speedup']:.2f}x"
    if d.get("cores") not in (None, 2):
        cell += f" on {d['cores']}"
    if same is not None and d.get(same) is False:
        cell += ", another ranking"
    return cell


def _seconds(x, fmt=""):
    return "" if x is None or x == "" else f"{format(x, fmt)} s"


#: the table's rows: each label and its cell from a run
ROWS = {
    "`vidi --help`": lambda r: _seconds(_get(r, "start_up", "vidi_help_seconds"), ".2f"),
    "first command after `make install` (`vidi steady`)": lambda r: _seconds(
        _sig(_get(r, "cold_start", "first_command_after_install_seconds"))
    ),
    "the same with an empty numba cache (it compiles)": lambda r: _seconds(
        _sig(_get(r, "cold_start", "first_command_empty_cache_seconds"), 3)
    ),
    "kernel vs scipy at equal accuracy, one period / 40 periods": _kernel,
    "one steady state (the paper's law, cold)": _steady,
    "one cold steady state vs the scipy path (its time for the periods integrated)": (
        _cold_vs_scipy
    ),
    "landscape 41x41, continuation (steady-state equivalents per point)": _landscape,
    "landscape 41x41, cold search at every point": lambda r: _seconds(
        _get(r, "landscape_41x41", "cold_seconds"), ".1f"
    ),
    "identify, least squares: simulations to 0.1 % (coordinate descent's)": _identify,
    "`verify`, 20-period record": _verify,
    "`discover poly:2, refine` (100-period run-up with positions; one process)": lambda r: (
        _wall_ratio(_get(r, "pipeline", "discover_poly:2"))
    ),
    "`discover poly:2` on 2 processes over 1 (same ranking)": lambda r: _parallel(
        _get(r, "pipeline", "discover_poly:2"), "same_ranking_all_cores"
    ),
    "`discover poly:3, refine`": lambda r: _wall_ratio(_get(r, "pipeline", "discover_poly:3")),
    "`explain`, full catalogue": lambda r: _wall_ratio(_get(r, "explain")),
    "`explain` on 2 processes over 1": lambda r: _parallel(_get(r, "explain")),
    "Ueda chart 60x60": lambda r: _seconds(_get(r, "ueda", "chart", "seconds"), ".1f"),
    "the paper study over the baseline's, paired (`make bench-study`)": lambda r: _study(r),
    "`explain` on the corpus over the baseline's, paired (`make bench-corpus`)": lambda r: _corpus(
        r
    ),
}


def _study(run):
    r = _get(run, "paired_study", "commands", "paper-study")
    return "" if r is None else f"{r['ratio']:.2f} ({r['same_cells']}/{r['cells']} cells same)"


def _corpus(run):
    r = _get(run, "paired_corpus", "commands", "explain")
    if r is None or r["ratio"] is None:
        return ""
    return f"{r['ratio']:.2f} ({r['same']}/{r['records']} records same)"


def markdown_row(runs, label_):
    """The table's row ``label_`` (a key of :data:`ROWS`): a cell per column's run."""
    cells = [ROWS[label_](r) for r in columns(runs)]
    return "| " + " | ".join([label_, *cells]) + " |"


def readme_lines(runs):
    """The README's bullet on speed, from the last full bench run of ``runs``."""
    full = [r for r in runs if not r["partial"]]
    if not full:
        raise SystemExit("no full bench run in docs/_measured/bench-history.jsonl")
    run = full[-1]
    kernel = _get(run, "kernel_vs_scipy") or {}
    fit = _get(run, "pipeline", "discover_poly:2") or {}
    explain = _get(run, "explain") or {}
    steady = _get(run, "pipeline", "one_steady_state_seconds")
    return [
        "- the shipped study (`make study`) and `make bench` (speed, and scaling over the "
        f"cores; the last full run, {run['created'][:10]} on {run['cores']} cores):",
        f"  the compiled kernel at equal accuracy is {_sig(kernel.get('speedup'), 3)}x the "
        f"scipy path over one drive period, {_sig(kernel.get('long_run_40_periods_speedup'), 4)}x"
        f" over 40 and {_sig(kernel.get('steady_state_speedup_over_scipy'), 3)}x for a cold "
        f"steady state ({_sig(1e3 * steady)} ms); on the bench's records `fit` (`discover "
        f"poly:2, refine`) takes {_sig(fit.get('seconds'))} s in one process and `explain` "
        f"{_sig(explain.get('seconds'))} s on {explain.get('cores')} cores;",
        *_paired_lines(_get(run, "paired")),
        *_study_lines(runs),
        *_corpus_lines(runs),
    ]


def _study_lines(runs):
    """The README's line on the paired paper study: the last run that measured it (``make
    bench-study``, a run of its own), none before one has."""
    done = [r for r in runs if _get(r, "paired_study", "commands", "paper-study")]
    if not done:
        return []
    run = done[-1]
    r = run["results"]["paired_study"]["commands"]["paper-study"]
    pairs = run["results"]["paired_study"]["pairs"]
    return [
        f"  the shipped paper study (`make bench-study`, 120 runs, tables only; at "
        f"{label(run)}, {str(run['created'])[:10]}, medians of {pairs} pairs) "
        f"{r['ratio']:.2f}, with {r['simulations_new'] / r['simulations_old']:.2f} of the "
        f"simulations and the same table in {r['same_cells']} of its {r['cells']} cells;"
    ]


#: the corpus's commands the README names, and what their findings are
_CORPUS_NAMES = {
    "verify": ("`verify` with the true law", "verdicts"),
    "fit": ("`fit`", "selected laws and verdicts"),
    "explain": ("`explain`", "named effects and verdicts"),
}


def _corpus_lines(runs):
    """The README's line on the paired corpus: the last run that measured it (``make
    bench-corpus``, a run of its own), none before one has."""
    done = [r for r in runs if _get(r, "paired_corpus", "commands")]
    if not done:
        return []
    run = done[-1]
    commands = run["results"]["paired_corpus"]["commands"]
    parts = [
        f"{text} {c['ratio']:.2f} (the same {what} on {c['same']} of {c['records']} records; "
        f"right {c['right_new']}/{c['judged']} against {c['right_old']}/{c['judged']})"
        for k, (text, what) in _CORPUS_NAMES.items()
        if (c := commands.get(k)) and c["ratio"] is not None
    ]
    return [
        f"  on the corpus (`make bench-corpus`, every record once a side; at {label(run)}, "
        f"{str(run['created'])[:10]}, medians over the records): {'; '.join(parts)};"
    ]


#: the paired commands the README names, and how
_PAIRED_NAMES = {
    "verify": "`verify`",
    "fit": "`fit`",
    "fit-readme": "the quickstart's `fit`",
    "fit-demo": "the demo's `fit`",
    "contact-models": "the named contact models",
    "explain": "`explain`",
    "explain-c02": "`explain` on corpus c02",
    "explain-c06": "c06",
    "explain-c12": "c12",
}


def _paired_lines(paired):
    """The README's line on the paired commands of a run (none when it paired none): each
    command's time as a fraction of the baseline's, on the same machine in the same run."""
    commands = (paired or {}).get("commands") or {}
    named = [(text, commands[k]["ratio"]) for k, text in _PAIRED_NAMES.items() if k in commands]
    if not named:
        return []
    ratios = ", ".join(f"{text} {ratio:.2f}" for text, ratio in named)
    return [
        f"  each command's time over the same command's with {paired['baseline']}, run in turn "
        f"on the same machine (medians of {paired['pairs']} pairs): {ratios};"
    ]


def readme_stamp(files, runs):
    """The line under the README's paragraph: the run it is made from, its commit and date."""
    run = [r for r in runs if not r["partial"]][-1]
    names = ", ".join(f"`{p.name}`" for p in files)
    parts = [f"the last full `make bench` run, at {label(run)} ({str(run['created'])[:10]})"]
    for target, section in (("bench-study", "paired_study"), ("bench-corpus", "paired_corpus")):
        done = [r for r in runs if _get(r, section, "commands")]
        if done:
            parts.append(
                f"the last `make {target}` run, at {label(done[-1])} "
                f"({str(done[-1]['created'])[:10]})"
            )
    runs_text = parts[0] if len(parts) == 1 else ", ".join(parts[:-1]) + " and " + parts[-1]
    return f"*Rendered by `make tables` from {names} in `docs/_measured/`: {runs_text}.*"


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--append", metavar="RESULTS", help="add this results file's runs")
    ap.add_argument("--out", default=str(PATH), help="the run file (default: %(default)s)")
    a = ap.parse_args(argv)
    from pathlib import Path

    out = Path(a.out)
    if a.append:
        new = append(json.loads(Path(a.append).read_text()), out)
        print(f"{out}: {len(new)} new run(s) {', '.join(label(r) for r in new)}")
        return 0
    kept = measured.read(out)[1] if out.exists() else []
    rows = merge(from_git(), kept)
    write(rows, out)
    print(f"wrote {out}: {len(rows)} runs")
    return 0


if __name__ == "__main__":
    sys.exit(main())
