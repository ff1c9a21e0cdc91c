"""The README's measured paragraphs, rendered from a run of :mod:`tests.survey_readme`.

Not a test module.  Each function takes the run's rows (its header first, as a row of kind
``"run"``: :func:`read_rows`) and returns the markdown lines :mod:`tests.tables` puts
between a page's markers: the set-up line (``setup``), what the demo shows (``demo``) and
the expected times (``times``).  Every number and every verdict word comes from the run, so
the text says what the code did when it was measured, and ``make tables --check`` tells
when a page no longer does.
"""

import re
import textwrap

from . import measured

#: what each of the demo law's coefficients is called in a sentence
_ROLES = {"z": "spring", "zd": "loading damper", "d_zd": "unloading damper"}
#: the README's command blocks, as the times table names them
_BLOCK_NAMES = {
    "demo": "`make demo`",
    "quickstart": "quickstart",
    "quickstart-explain": "quickstart",
    "quickstart-ueda": "Ueda quickstart",
    "chart": "Ueda's regime chart",
}


def read_rows(files):
    """The rows of run files ``files``, each file's header first as a row of kind ``run``."""
    out = []
    for path in files:
        header, rows = measured.read(path)
        out += [{"kind": "run", **header}, *rows]
    return out


def _one(rows, kind):
    found = [r for r in rows if r.get("kind") == kind]
    return found[-1] if found else None


def duration(seconds):
    """``0.84 s``, ``14 s``, ``2 min 5 s``."""
    if seconds < 10:
        return f"{seconds:.2g} s" if seconds < 1 else f"{seconds:.1f} s"
    if seconds < 120:
        return f"{seconds:.0f} s"
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes} min {rest} s"


def sci(x, digits=4):
    """``2.076e8`` (the README's form of a coefficient)."""
    mantissa, exponent = f"{x:.{digits - 1}e}".split("e")
    return f"{mantissa}e{int(exponent)}"


def _when(rows):
    """The run's day, and its machine in words: cores and the load over the run."""
    run = _one(rows, "run") or {}
    machine = run.get("machine") or {}
    load = _one(rows, "load")
    where = f"{machine.get('cores', '?')} cores"
    if load:
        low, high = f"{load['low']:.1f}", f"{load['high']:.1f}"
        where += f", load {low}" if low == high else f", load {low}-{high}"
    return str(run.get("started", "?"))[:10], where


def setup_lines(rows):
    """The set-up paragraph under the two commands."""
    day, where = _when(rows)
    install = _one(rows, "install") or {}
    test = _one(rows, "test")
    demo = _one(rows, "demo-total")
    compiled = sum((install.get("compile") or {}).values())
    parts = []
    if install.get("seconds") is not None:
        parts.append(
            f"`make install` took {duration(install['seconds'])} (pip without its download "
            f"cache, then {duration(compiled)} compiling the simulators once)"
        )
    elif compiled:
        parts.append(f"compiling the simulators once took {duration(compiled)}")
    if demo:
        parts.append(f"`make demo` {duration(demo['seconds'])} more")
    if test:
        parts.append(f"`make test` {duration(test['seconds'])}")
    return [
        "(`make test` leaves out the long surveys, marked `slow`; `make test-slow` runs them",
        "and `make test-all` both; CI (`.ci/run`) runs `make test`, `make docs` (this site,",
        "warnings as errors), `make test-slow` and `make lint`. `make tex` installs TeX Live",
        "from apt for the PDF reports; without it they are `.tex`.",
        *_item(f"From a fresh clone, measured on {day} ({where}): " + ", ".join(parts) + ".)", ""),
    ]


def _verdict(consistent):
    return "**consistent**" if consistent else "**inconsistent**"


def _holds(explain):
    """Which of the final law's intervals hold the demo's true coefficients."""
    held, missed = [], []
    for name, truth in explain["truths"].items():
        low, high = explain["intervals"].get(name, (None, None))
        role = _ROLES.get(name, f"`{name}` term")
        if low is None:
            missed.append(f"the {role}'s is not in the final law")
        elif low <= truth <= high:
            held.append(role)
        else:
            gap = min(abs(truth - low), abs(truth - high)) / abs(truth)
            missed.append(f"the {role}'s misses it by {100 * gap:.2g} %")
    truths = ", ".join(
        sci(v, 3).replace(".00e", "e").replace(".0e", "e") for v in explain["truths"].values()
    )
    if not missed:
        return f"each holds the truth (`{truths}`)"
    said = " and ".join(f"the {r}'s" for r in held)
    return (f"{said} hold the truth (`{truths}`), " if held else "") + "; ".join(missed)


def _item(text, indent="   "):
    """``text`` wrapped as the README's source is (a numbered item's lines indented), its
    code spans whole."""
    kept = re.sub(r"`[^`]*`", lambda m: m.group().replace(" ", "\0"), text)
    kept = re.sub(r"(\d) (s|min|%)\b", "\\1\0\\2", kept)  # a number keeps its unit
    lines = textwrap.wrap(kept, 92, subsequent_indent=indent, break_on_hyphens=False)
    return [line.replace("\0", " ") for line in lines]


def demo_lines(rows):
    """The numbered list of what the demo shows."""
    demo = _one(rows, "demo")
    if demo is None:
        raise SystemExit("the readme run has no demo row")
    verify, fit, explain = demo["verify"], demo["fit"], demo["explain"]
    limits = sorted({f"{x:.2g}" for x in fit["limits_I2"]})
    limits = f"a limit of {limits[0]}" if len(limits) == 1 else f"limits of {', '.join(limits)}"
    first = (
        f"1. `verify`: the designer's linear law `{demo['truth']['start']}` is "
        f"{_verdict(verify['consistent'])} with the record (I2 {verify['criteria']['I2']:.3g} "
        f"against a limit of {verify['limits']['I2']:.3g}, I4 {verify['criteria']['I4']:.3g} "
        f"against {verify['limits']['I4']:.3g}); its figure sets the measured force against the "
        "simulated one contact by contact;"
    )
    second = (
        f"2. `fit` on both records: {'a' if fit['consistent'] else 'no'} polynomial of "
        f"`{fit['library']}` is consistent (the selected law, `{' + '.join(fit['terms'])}`, has a "
        f"mean I2 of {fit['I2']:.3g} over the {fit['records']} records, against {limits} on "
        "each)" + ("" if fit["consistent"] else ": the missing physics is not a loading term") + ";"
    )
    third = "3. `explain` on the high-amplitude record, from the linear start, "
    if explain["named"]:
        named = ", then ".join(f"`{e}`" for e in explain["named"])
        third += (
            f"**names {named}** (score test, then a refit with exact Jacobians: I2 "
            f"{explain['before']:.3g} -> {explain['after']:.3g} against the start's floor of "
            f"{explain['floor']:.3g}; the other effects' refits stay at I2 "
            f"{explain['others']:.3g} or more) and ends "
        )
    else:
        third += "names nothing and ends "
    bounds = ", ".join(f"`[{sci(a)}, {sci(b)}]`" for a, b in explain["intervals"].values())
    third += (
        f"{_verdict(explain['consistent'])} at `{_short_law(explain['final'])}` with 95 % "
        f"bootstrap intervals ({explain['replicates']} replicates) {bounds}: "
        f"{_holds(explain)};"
    )
    return [
        *_item(first),
        *_item(second),
        *_item(third),
        "4. `report`: `out/demo/{verify,fit,explain}/report.pdf`.",
    ]


def _short_law(text):
    """A law's text with its coefficients to four digits."""
    return re.sub(r"\d+(?:\.\d+)?(?:e[+-]?\d+)?(?=\*)", lambda m: sci(float(m.group())), text)


def _command(row):
    """The times table's command cell: a demo's command by its name, others in full."""
    words = row["command"].split()
    if row["block"] == "demo":
        return f"`{' '.join(words[:2])}`"
    return f"`{row['command']}`"


def times_lines(rows):
    """The expected times: a table of each command as the run timed it."""
    day, where = _when(rows)
    lines = ["| command | in | time (CPU) |", "|---|---|---|"]
    install = _one(rows, "install")
    if install and install.get("seconds") is not None:
        lines.append(
            f"| `make install` (fresh clone) | set-up | {duration(install['seconds'])} "
            f"({duration(install['cpu'])}) |"
        )
    if install and install.get("compile"):
        parts = ", ".join(f"{k} {duration(v)}" for k, v in install["compile"].items())
        lines.append(f"| compiling the simulators once (in `make install`) | set-up | {parts} |")
    total = _one(rows, "demo-total")
    if total:
        lines.append(
            f"| `make demo` after `make install` | `make demo` | {duration(total['seconds'])} "
            f"({duration(total['cpu'])}) |"
        )
    grouped = {}
    for row in rows:
        if row.get("kind") == "command":
            grouped.setdefault((row["block"], _command(row)), []).append(row)
    for (block, command), runs in grouped.items():
        times = ", ".join(duration(r["seconds"]) for r in runs)
        cpu = ", ".join(duration(r["cpu"]) for r in runs)
        lines.append(f"| {command} | {_BLOCK_NAMES.get(block, block)} | {times} ({cpu}) |")
    test = _one(rows, "test")
    if test:
        lines.append(
            "| `make test` (less the two test modules that read this run) | set-up | "
            f"{duration(test['seconds'])} ({duration(test['cpu'])}) |"
        )
    return [
        f"**Expected times**, measured on {day} ({where}), each command as a user runs it (the",
        "wall time, and in brackets the CPU time of its processes; the compiled kernels cached",
        "after `make install`; a busier machine takes longer):",
        "",
        *lines,
    ]
