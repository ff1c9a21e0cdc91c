"""Table-driven bad inputs of every ``vidi`` command (and of the API
they rest on).

Every CLI case must: exit with code 2, print exactly one line on stderr starting with
``vidi: error:`` that contains the case's needle, print no traceback, and leave the
working directory exactly as it was (earlier results included: every file's bytes,
mode and mtime, and no new file or directory, staging included).
"""

import hashlib
import os
import stat
from pathlib import Path

import numpy as np
import pytest

import discovery
from discovery.cli import main
from discovery.errors import VidiError
from discovery.vibroimpact.dynamics.synthetic import synthesize

GOOD_TOML = """\
name = "bench"
[machine]
m1 = 1.0e4
m2 = 1.0e4
k1 = 2.75e7
c1 = 1.0e5
A = 5.0e5
frequency = 25.0
[law]
text = "2.06e8*z + 1.28e7*zd"
"""


def _toml(old, new):
    assert old in GOOD_TOML
    return GOOD_TOML.replace(old, new)


SCENARIOS = {
    "bool.toml": _toml("m1 = 1.0e4", "m1 = true"),
    "text.toml": _toml("m2 = 1.0e4", 'm2 = "1.0e4"'),
    "nan.toml": _toml("c1 = 1.0e5", "c1 = nan"),
    "infk.toml": _toml("k1 = 2.75e7", "k1 = inf"),
    "hugeA.toml": _toml("A = 5.0e5", "A = 1e300"),
    "hugem.toml": _toml("m1 = 1.0e4", "m1 = 1e30"),
    "negm.toml": _toml("m2 = 1.0e4", "m2 = -1.0e4"),
    "zerof.toml": _toml("frequency = 25.0", "frequency = 0"),
    "table.toml": GOOD_TOML + "[solver]\nrtol = 1e-9\n",
    "typo.toml": _toml("[machine]", "[machnie]"),
    "key.toml": _toml("A = 5.0e5", "A = 5.0e5\nmass3 = 4.0"),
    "lawkey.toml": _toml("text =", "txt ="),
    "emptylaw.toml": _toml('text = "2.06e8*z + 1.28e7*zd"', 'text = ""'),
    "badlaw.toml": _toml("2.06e8*z + 1.28e7*zd", "2.06e8*x"),
    "nomachine.toml": 'name = "x"\n',
    "missing.toml": _toml("k1 = 2.75e7\n", ""),
    "invalid.toml": "[machine\nm1 = 1",
    "initial.toml": GOOD_TOML + "[initial]\nw1 = 0.0\nv1 = 0.0\n",
    "name.toml": _toml('name = "bench"', "name = 3"),
}


def _table(t, F):
    return "t,F\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), F.tolist(), strict=True))


@pytest.fixture(scope="module")
def workspace(tmp_path_factory, paper):
    """Inputs (good and bad) and earlier results of every command."""
    w = tmp_path_factory.mktemp("bad_inputs")
    rec = synthesize(paper, paper.law, periods=6, fs=20000.0)
    rec.to_csv(w / "good.csv")
    text = (w / "good.csv").read_text()
    t = np.arange(1000) / 20000.0
    gap = rec.t.copy()
    gap[300:] += 1 / 20000.0
    jitter = rec.t + np.random.default_rng(1).uniform(-0.3, 0.3, rec.t.size) / 20000.0
    k = np.flatnonzero(rec.F > 0)
    cut = int(k[np.flatnonzero(np.diff(k) > 1)[0]]) + 200  # the first contact, cut at t = 0
    csvs = {
        "nan.csv": "t,F\n0,0\n1e-4,nan\n2e-4,0\n3e-4,0\n",
        "inf.csv": "t,F\n0,0\n1e-4,0\n2e-4,-inf\n3e-4,0\n",
        "emptycell.csv": "t,F\n0,0\n1e-4,\n2e-4,0\n3e-4,0\n",
        "textcell.csv": "t,F\n0,0\n1e-4,12 kN\n2e-4,0\n3e-4,0\n",
        "shortrow.csv": "t,F,w1\n0,0,0\n1e-4,0\n2e-4,0,0\n3e-4,0,0\n",
        "hugeF.csv": text.replace("\n", "\n", 1).splitlines()[0]
        + "\n"
        + "\n".join(
            ln if i != 5 else "0.00025,1e300,0,0,0,0" for i, ln in enumerate(text.splitlines()[1:])
        )
        + "\n",
        "hugew.csv": "t,F,w1\n0,0,0\n1e-4,0,2e4\n2e-4,0,0\n3e-4,0,0\n",
        "dup.csv": "t,F\n0,0\n1e-4,1\n1e-4,2\n3e-4,0\n4e-4,0\n",
        "decreasing.csv": "t,F\n0,0\n2e-4,1\n1e-4,2\n3e-4,0\n",
        "gap.csv": _table(gap, rec.F),
        "jitter.csv": _table(jitter, rec.F),
        "nocol.csv": text.replace("t,F,", "time_s,force_N,", 1),
        "headeronly.csv": "t,F\n",
        "empty.csv": "",
        "three.csv": "t,F\n0,0\n1e-4,1\n2e-4,0\n",
        "duphdr.csv": "t,F,F\n0,0,0\n1e-4,0,0\n2e-4,0,0\n3e-4,0,0\n",
        "zeros.csv": _table(t, np.zeros_like(t)),
        "cutoff.csv": _table(rec.t[:cut], rec.F[:cut]),
    }
    for name, body in csvs.items():
        (w / name).write_text(body)
    (w / "latin1.csv").write_bytes("t,F\n0,0\n1e-4,1\n# d\u00e9bit\n".encode("latin-1"))
    (w / "nul.csv").write_bytes(b"t,F\n0,\x00\x001\n")
    (w / "latin1.toml").write_bytes(_toml('"bench"', '"b\u00e9nch"').encode("latin-1"))
    for name, body in SCENARIOS.items():
        (w / name).write_text(body)
    (w / "good.toml").write_text(GOOD_TOML)
    (w / "adir").mkdir()
    (w / "adir" / "notes.txt").write_text("not a result")
    (w / "afile").write_text("a file")
    (w / "datadir").mkdir()
    (w / "datadir" / "in.csv").write_text(text)
    (w / "datadir" / "summary.json").write_text("{}")
    # earlier results: a simulate record with its summary and a verify output directory
    cwd = os.getcwd()
    os.chdir(w)
    try:
        assert main(["simulate", "--periods", "3", "--out", "rec.csv"]) == 0
        assert main(["verify", "--data", "rec.csv", "--out", "res"]) == 0
    finally:
        os.chdir(cwd)
    return w


def _snapshot(root):
    snap = {}
    for dirpath, dirnames, filenames in os.walk(root):
        for n in dirnames + filenames:
            p = os.path.join(dirpath, n)
            st = os.lstat(p)
            digest = None
            if stat.S_ISREG(st.st_mode):
                with open(p, "rb") as fh:
                    digest = hashlib.sha256(fh.read()).hexdigest()
            snap[os.path.relpath(p, root)] = (
                stat.S_IFMT(st.st_mode),
                st.st_mode & 0o7777,
                st.st_size,
                st.st_mtime_ns,
                digest,
            )
    return snap


V = ["verify", "--data", "good.csv", "--out", "res"]  # valid verify arguments
S = ["simulate", "--out", "rec.csv"]  # valid simulate arguments


def _verify_data(name, *extra):
    return ["verify", "--data", name, "--out", "res", *extra]


CASES = [
    # ---------------------------------------------------------------- the command line
    (
        "unknown-command",
        ["simulat"],
        "unknown command 'simulat' (did you mean 'simulate'?); choose one of",
    ),
    (
        "unknown-option",
        ["steady", "--bogus"],
        "unknown option '--bogus'; see vidi steady --help",
    ),
    ("stray-value", ["steady", "paper"], "unrecognized option(s) or value(s) paper"),
    ("missing-required", ["verify", "--data", "good.csv"], "missing required option(s) --out"),
    ("missing-all-required", ["verify"], "missing required option(s) --data, --out"),
    ("law-without-value", ["steady", "--law"], "--law needs a value"),
    ("law-then-option", ["steady", "--law", "--out", "res"], "--law needs a value"),
    ("flag-with-value", ["simulate", "--from-rest=yes", "--out", "rec.csv"], "--from-rest"),
    # ------------------------------------------------------------------------ laws
    ("law-syntax", ["steady", "--law", "2*q"], "cannot read force law"),
    ("law-empty", ["steady", "--law", ""], "--law is empty"),
    ("law-blank", ["steady", "--law", "  "], "--law is empty"),
    ("law-constant", ["steady", "--law", "5"], "a constant term is not allowed"),
    ("law-no-exponent", ["steady", "--law", "z^"], "expected an exponent"),
    ("law-negative-exponent", ["steady", "--law", "1e8*z^-1"], "negative exponent"),
    ("law-overflow", ["steady", "--law", "1e999*z"], "must be a finite number"),
    ("too-stiff", ["steady", "--law", "1e308*z + 1e7*zd"], "too stiff for this machine"),
    (
        "orphan-time-offset",
        ["landscape", "--time-offset", "0.1", "--grid", "3x3", "--out", "r9"],
        "--time-offset acts only with --data",
    ),
    (
        "orphan-columns",
        ["landscape", "--columns", "F=force", "--out", "r9"],
        "--columns acts only with --data",
    ),
    (
        "orphan-budget",
        ["fit", "--data", "rec.csv", "--no-refine", "--max-simulations", "5", "--out", "r9"],
        "has no effect with --no-refine",
    ),
    (
        "exponent-too-large",
        ["fit", "--data", "rec.csv", "--library", "z,zd,z^1e4", "--out", "r9"],
        "exponent 10000 on z is above 10",
    ),
    ("law-code", ["steady", "--law", "__import__('os')"], "cannot read force law"),
    ("law-never-pushes", ["steady", "--law=-1e8*z"], "never pushes the bodies apart"),
    ("law-all-zero", ["steady", "--law", "0*z"], "has no non-zero coefficient"),
    (
        "law-negative-stiffness",
        ["steady", "--law=-2.06e8*z + 1.28e7*zd"],
        "has a negative stiffness",
    ),
    ("verify-law-negative-stiffness", [*V, "--law=-2e8*z + 2e7*zd"], "negative stiffness"),
    (
        "law-not-dissipative",
        ["steady", "--law", "2.06e8*z - 1e9*zd"],
        "condition (6), dissipativity",
    ),
    ("verify-law-never-pushes", [*V, "--law=-2e8*z - 1e7*zd"], "never pushes"),
    ("law-dangling-op", ["steady", "--law", "1e8*z +"], "expected a number, 'z' or 'zd'"),
    ("law-missing-star", ["steady", "--law", "1e8 z"], "expected '*' between factors"),
    ("simulate-law-empty", [*S, "--law", ""], "--law is empty"),
    ("verify-law-empty", [*V, "--law", " "], "--law is empty"),
    ("verify-law-syntax", [*V, "--law", "1e8*zeta"], "cannot read force law"),
    # ------------------------------------------------------------------- scenarios
    ("scenario-missing", ["steady", "--scenario", "nope.toml"], "does not exist"),
    ("scenario-directory", ["steady", "--scenario", "adir"], "is a directory"),
    ("scenario-empty", ["steady", "--scenario", ""], "the scenario is empty"),
    (
        "scenario-bool",
        ["steady", "--scenario", "bool.toml"],
        "m1 must be a number in kg, got a boolean",
    ),
    ("scenario-text", ["steady", "--scenario", "text.toml"], "got text '1.0e4'"),
    ("scenario-nan", ["steady", "--scenario", "nan.toml"], "scenario c1 = nan N s/m is invalid"),
    ("scenario-inf", ["steady", "--scenario", "infk.toml"], "scenario k1 = inf"),
    ("scenario-huge-A", ["steady", "--scenario", "hugeA.toml"], "<= 1e+12 N"),
    ("scenario-huge-m", ["steady", "--scenario", "hugem.toml"], "<= 1e+09 kg"),
    ("scenario-negative-m", ["steady", "--scenario", "negm.toml"], "must be finite, > 0"),
    ("scenario-zero-f", ["steady", "--scenario", "zerof.toml"], "frequency = 0 Hz is invalid"),
    (
        "scenario-unknown-table",
        ["steady", "--scenario", "table.toml"],
        "unknown table(s) or key(s) solver; valid are name, [machine], [law], [initial]",
    ),
    ("scenario-table-typo", ["steady", "--scenario", "typo.toml"], "machnie"),
    (
        "scenario-unknown-key",
        ["steady", "--scenario", "key.toml"],
        "unknown [machine] key(s) mass3; valid keys are m1, m2",
    ),
    ("scenario-law-key", ["steady", "--scenario", "lawkey.toml"], "unknown [law] key(s) txt"),
    ("scenario-law-empty", ["steady", "--scenario", "emptylaw.toml"], "[law] needs text"),
    ("scenario-law-syntax", ["steady", "--scenario", "badlaw.toml"], "cannot read force law"),
    ("scenario-no-machine", ["steady", "--scenario", "nomachine.toml"], "needs a [machine]"),
    ("scenario-missing-key", ["steady", "--scenario", "missing.toml"], "missing k1"),
    ("scenario-invalid-toml", ["steady", "--scenario", "invalid.toml"], "is not valid TOML"),
    ("scenario-initial", ["steady", "--scenario", "initial.toml"], "[initial] needs w1, v1"),
    ("scenario-name", ["steady", "--scenario", "name.toml"], "name must be non-empty text"),
    ("scenario-latin1", ["steady", "--scenario", "latin1.toml"], "not UTF-8 text"),
    ("simulate-scenario-bool", [*S, "--scenario", "bool.toml"], "got a boolean"),
    ("verify-scenario-table", [*V, "--scenario", "table.toml"], "unknown table(s)"),
    # ------------------------------------------------------------- simulate options
    (
        "periods-zero",
        [*S, "--periods", "0"],
        "--periods: '0' is out of range; give an integer >= 1",
    ),
    ("periods-negative", [*S, "--periods", "-3"], "--periods: '-3' is out of range"),
    ("periods-fraction", [*S, "--periods", "2.5"], "'2.5' is not an integer"),
    ("periods-text", [*S, "--periods", "ten"], "'ten' is not an integer"),
    ("periods-huge", [*S, "--periods", "1000000"], "<= 100000"),
    ("fs-zero", [*S, "--fs", "0"], "--fs: '0' is out of range; give a finite number > 0"),
    ("fs-negative", [*S, "--fs", "-5"], "--fs: '-5' is out of range"),
    ("fs-nan", [*S, "--fs", "nan"], "--fs: 'nan' is out of range"),
    ("fs-inf", [*S, "--fs", "inf"], "--fs: 'inf' is out of range"),
    ("fs-text", [*S, "--fs", "20kHz"], "--fs: '20kHz' is not a number"),
    ("fs-1e9", [*S, "--fs", "1e9"], "<= 1e+08 Hz"),
    (
        "samples-too-many",
        [*S, "--fs", "5e7", "--periods", "100"],
        "is 2e+08 samples; the limit is 2e+06: lower --fs or --periods",
    ),
    ("samples-too-few", [*S, "--fs", "10", "--periods", "1"], "only 0.4 samples"),
    ("noise-negative", [*S, "--noise", "-0.1"], "--noise: '-0.1' is out of range"),
    ("noise-nan", [*S, "--noise", "nan"], "--noise: 'nan' is out of range"),
    ("noise-above-one", [*S, "--noise", "2"], "<= 1"),
    ("position-noise-negative", [*S, "--position-noise", "-1"], "--position-noise"),
    ("seed-negative", [*S, "--seed", "-1"], "--seed: '-1' is out of range; give an integer >= 0"),
    ("seed-fraction", [*S, "--seed", "1.5"], "--seed: '1.5' is not an integer"),
    # ------------------------------------------------ silently accepted before (issue 16)
    (
        "repeated-law",
        ["steady", "--law", "1e8*z", "--law", "2e8*z", "--out", "res2"],
        "--law is given twice",
    ),
    (
        "repeated-data",
        ["verify", "--data", "good.csv", "--data", "good.csv", "--out", "res"],
        "--data is given twice",
    ),
    (
        "repeated-scenario",
        ["steady", "--scenario", "paper", "--scenario=light", "--out", "r3"],
        "--scenario is given twice",
    ),
    (
        "denormal-spring",
        ["steady", "--law", "1e-320*z", "--out", "r4"],
        "below the smallest normal number",
    ),
    (
        "fullwidth-digit-law",
        ["steady", "--law", "\uff12e8*z", "--out", "r5"],
        "cannot read force law",
    ),
    (
        "fullwidth-digit-option",
        ["simulate", "--periods", "\uff13", "--out", "r6.csv"],
        "is not an integer",
    ),
    (
        "huge-law",
        [
            "steady",
            "--law",
            " + ".join(f"{k + 1}*z^{1 + k / 20:g}" for k in range(150)),
            "--out",
            "r7",
        ],
        "a contact law has a few",
    ),
    # -------------------------------------------------------------- simulate --out
    ("simulate-out-empty", ["simulate", "--out", ""], "--out is empty"),
    ("simulate-out-directory", ["simulate", "--out", "adir"], "is a directory; give a file"),
    ("simulate-out-not-csv", ["simulate", "--out", "rec.txt"], "must name a .csv file"),
    (
        "simulate-out-is-scenario",
        ["simulate", "--scenario", "good.toml", "--out", "good.toml"],
        "is the input file",
    ),
    (
        "simulate-out-parent-file",
        ["simulate", "--out", "afile/x.csv"],
        "is a file, not a directory",
    ),
    ("simulate-out-unwritable", ["simulate", "--out", "/proc/self/x.csv"], "cannot write in"),
    ("simulate-summary-is-dir", ["simulate", "--out", "summ.csv"], "summary"),
    # ---------------------------------------------------------------- output dirs
    ("steady-out-empty", ["steady", "--out", ""], "--out is empty"),
    ("steady-out-file", ["steady", "--out", "afile"], "is an existing file"),
    (
        "steady-out-input",
        ["steady", "--scenario", "good.toml", "--out", "good.toml"],
        "is the input file",
    ),
    ("steady-out-cwd", ["steady", "--out", "."], "is the current directory"),
    ("steady-out-parent", ["steady", "--out", ".."], "is the current directory or above it"),
    ("steady-out-not-result", ["steady", "--out", "adir"], "not an earlier vidi result"),
    ("steady-out-unwritable", ["steady", "--out", "/proc/self/out"], "cannot write in"),
    ("steady-out-parent-file", ["steady", "--out", "afile/out"], "is a file, not a directory"),
    ("verify-out-empty", ["verify", "--data", "good.csv", "--out", ""], "--out is empty"),
    (
        "verify-out-is-data",
        ["verify", "--data", "good.csv", "--out", "good.csv"],
        "is the input file",
    ),
    (
        "verify-out-holds-data",
        ["verify", "--data", "datadir/in.csv", "--out", "datadir"],
        "holds the input file",
    ),
    ("verify-out-file", ["verify", "--data", "good.csv", "--out", "afile"], "is an existing file"),
    (
        "verify-out-not-result",
        ["verify", "--data", "good.csv", "--out", "adir"],
        "not an earlier vidi result",
    ),
    (
        "verify-out-unwritable",
        ["verify", "--data", "good.csv", "--out", "/proc/self/v"],
        "cannot write in",
    ),
    # -------------------------------------------------------------- verify options
    ("n-boot-zero", [*V, "--n-boot", "0"], "--n-boot: '0' is out of range"),
    ("n-boot-negative", [*V, "--n-boot", "-4"], "--n-boot: '-4' is out of range"),
    ("verify-seed-negative", [*V, "--seed", "-2"], "--seed: '-2' is out of range"),
    ("time-offset-nan", [*V, "--time-offset", "nan"], "--time-offset: 'nan' is out of range"),
    ("time-offset-text", [*V, "--time-offset", "soon"], "is not a number"),
    ("columns-syntax", [*V, "--columns", "t:time"], "write OURS=THEIRS pairs"),
    ("columns-unknown", [*V, "--columns", "time=t"], "unknown name 'time'"),
    ("columns-absent", [*V, "--columns", "F=force_N"], "has no column 'force_N'"),
    ("columns-twice", [*V, "--columns", "t=t,t=F"], "t is mapped twice"),
    ("columns-same", [*V, "--columns", "F=t"], "nothing is left for t"),
    ("columns-same-twice", [*V, "--columns", "t=t,F=t"], "same column"),
    # ----------------------------------------------------------------- records
    ("data-missing", _verify_data("nope.csv"), "does not exist"),
    ("data-directory", _verify_data("adir"), "is a directory; give the CSV file itself"),
    ("data-empty-path", _verify_data(""), "the data file name is empty"),
    ("data-latin1", _verify_data("latin1.csv"), "is not UTF-8 text (byte 0xe9"),
    ("data-nul", _verify_data("nul.csv"), "contains NUL bytes"),
    ("data-empty", _verify_data("empty.csv"), "is empty"),
    ("data-header-only", _verify_data("headeronly.csv"), "has a header but no data rows"),
    ("data-no-t-column", _verify_data("nocol.csv"), "--columns t=NAME,F=NAME"),
    ("data-duplicate-header", _verify_data("duphdr.csv"), "F appear more than once"),
    ("data-nan", _verify_data("nan.csv"), "non-finite value 'nan' at line 3"),
    ("data-inf", _verify_data("inf.csv"), "non-finite value '-inf' at line 4"),
    ("data-empty-cell", _verify_data("emptycell.csv"), "column F is empty at line 3"),
    ("data-text-cell", _verify_data("textcell.csv"), "non-numeric value '12 kN' at line 3"),
    ("data-short-row", _verify_data("shortrow.csv"), "line 3 has 2 field(s)"),
    ("data-huge-force", _verify_data("hugeF.csv"), "beyond the accepted |F| <= 1e+12 N"),
    ("data-huge-position", _verify_data("hugew.csv"), "|w1| <= 1000 m"),
    ("data-duplicate-time", _verify_data("dup.csv"), "duplicate time t = 0.0001 at lines 3 and 4"),
    ("data-decreasing-time", _verify_data("decreasing.csv"), "not increasing at line 4"),
    ("data-gap", _verify_data("gap.csv"), "is not uniformly sampled"),
    ("data-jitter", _verify_data("jitter.csv"), "up to 10 % is resampled"),
    ("data-three-rows", _verify_data("three.csv"), "at least 4 samples"),
    ("data-no-contact", _verify_data("zeros.csv"), "no sample exceeds the threshold"),
    ("data-cut-off-contact", _verify_data("cutoff.csv"), "is cut off at the record's start"),
]


# ------------------------------------------- fit, identify and landscape (checked first)
F = ["fit", "--data", "good.csv", "--out", "fitres"]  # valid fit arguments
I = ["identify", "--data", "good.csv", "--start", "1.5e8*z + 0.9e7*zd", "--out", "idres"]
L = ["landscape", "--grid", "3x3", "--workers", "1", "--out", "landres"]

CASES += [
    ("fit-shortlist-zero", [*F, "--shortlist", "0"], "--shortlist: '0' is out of range"),
    ("fit-stability-negative", [*F, "--stability", "-5"], "--stability: '-5' is out of range"),
    ("fit-max-terms-zero", [*F, "--max-terms", "0"], "--max-terms: '0' is out of range"),
    ("fit-margin-negative", [*F, "--margin", "-1"], "--margin: '-1' is out of range"),
    ("fit-seed-negative", [*F, "--seed", "-1"], "--seed: '-1' is out of range"),
    ("fit-budget-one", [*F, "--max-simulations", "1"], "--max-simulations: '1' is out of range"),
    (
        "fit-out-is-input",
        ["fit", "--data", "good.csv", "--out", "good.csv"],
        "is the input file 'good.csv'",
    ),
    ("fit-out-is-file", ["fit", "--data", "good.csv", "--out", "afile"], "is an existing file"),
    ("fit-out-empty", ["fit", "--data", "good.csv", "--out", ""], "--out is empty"),
    (
        "fit-out-foreign-dir",
        ["fit", "--data", "good.csv", "--out", "adir"],
        "not an earlier vidi result",
    ),
    ("fit-select-unknown", [*F, "--select", "nope"], "--select: invalid choice 'nope'"),
    ("fit-score-unknown", [*F, "--score", "r2"], "--score: invalid choice 'r2'"),
    ("fit-criterion-unknown", [*F, "--criterion", "I9"], "--criterion: invalid choice 'I9'"),
    ("fit-library-bad", [*F, "--library", "+"], "library '+' names no terms"),
    (
        "fit-data-missing",
        ["fit", "--data", "missing.csv", "--out", "fitres"],
        "'missing.csv' does not exist",
    ),
    ("fit-data-dir", ["fit", "--data", "adir", "--out", "fitres"], "'adir' is a directory"),
    ("fit-columns-absent", [*F, "--columns", "t=time"], "has no column 'time'"),
    (
        "fit-scenarios-mismatch",
        [*F, "--data", "good.csv", *["--scenario", "paper"] * 3],
        "one --scenario per --data",
    ),
    ("fit-scenario-bool", [*F, "--scenario", "bool.toml"], "got a boolean"),
    (
        "fit-data-nan",
        ["fit", "--data", "nan.csv", "--out", "fitres"],
        "non-finite value 'nan' at line 3",
    ),
    (
        "fit-data-no-positions",
        ["fit", "--data", "cutoff.csv", "--out", "fitres"],
        "needs the positions w1 and w2",
    ),
    (
        "identify-start-empty",
        ["identify", "--data", "good.csv", "--start", "", "--out", "idres"],
        "--start is empty",
    ),
    (
        "identify-start-missing",
        ["identify", "--data", "good.csv", "--out", "idres"],
        "missing required option(s) --start",
    ),
    ("identify-xtol-negative", [*I, "--xtol", "-1"], "--xtol: '-1' is out of range"),
    ("identify-xtol-nan", [*I, "--xtol", "nan"], "--xtol: 'nan' is out of range"),
    (
        "identify-budget-one",
        [*I, "--max-simulations", "1"],
        "--max-simulations: '1' is out of range",
    ),
    ("identify-method-unknown", [*I, "--method", "simplex"], "--method: invalid choice 'simplex'"),
    ("identify-landscape-dir", [*I, "--landscape", "adir"], "--landscape 'adir'"),
    ("identify-landscape-file", [*I, "--landscape", "afile"], "--landscape 'afile'"),
    ("identify-out-is-input", [*I[:-1], "good.csv"], "is the input file 'good.csv'"),
    ("identify-start-zero", [*I[:4], "0*z + 1e7*zd", *I[5:]], "must be non-zero"),
    ("identify-start-not-dissipative", [*I[:4], "2e8*z - 1e7*zd", *I[5:]], "condition (6)"),
    ("identify-n-boot-zero", [*I, "--n-boot", "0"], "--n-boot: '0' is out of range"),
    ("landscape-range-crosses-zero", [*L, "--range0=-1e8:1e8"], "reaches zero"),
    ("landscape-range-reversed", [*L, "--range0", "3e8:1e8"], "needs LOW < HIGH"),
    ("landscape-range-nan", [*L, "--range0", "nan:1e8"], "nan is not a finite number"),
    (
        "ueda-chart-B-unbounded",
        ["ueda", "chart", "--B", "0:1e300:2", "--out", "uc"],
        "must lie in [-1000, 1000]",
    ),
    (
        "ueda-chart-nu-tiny",
        ["ueda", "chart", "--nu", "1e-300:1.1:3", "--out", "uc"],
        "must lie in [0.01, 100]",
    ),
    ("ueda-simulate-nu-tiny", ["ueda", "simulate", "--nu", "1e-300", "--out", "u.csv"], ">= 0.01"),
    ("landscape-range-text", [*L, "--range1", "abc"], "must look like LOW:HIGH"),
    (
        "landscape-grid-syntax",
        ["landscape", "--grid", "4by4", "--out", "landres"],
        "must look like 41x41",
    ),
    (
        "landscape-grid-too-small",
        ["landscape", "--grid", "1x1", "--out", "landres"],
        "at least 2 points per axis",
    ),
    (
        "landscape-workers-zero",
        ["landscape", "--grid", "3x3", "--workers", "0", "--out", "landres"],
        "--workers: '0' is out of range",
    ),
    ("landscape-law-one-term", [*L, "--law", "2e8*z"], "has 1 term(s)"),
    ("landscape-law-empty", [*L, "--law", ""], "--law is empty"),
    ("landscape-data-no-contact", [*L, "--data", "zeros.csv"], "no contact found"),
    ("landscape-n-boot-zero", [*L, "--n-boot", "0"], "--n-boot: '0' is out of range"),
    ("landscape-out-is-file", [*L[:-1], "afile"], "is an existing file"),
    ("fit-library-near-miss", [*F, "--library", "contact-model"], "did you mean 'contact-models'"),
    (
        "verify-law-model-misspelt",
        [*V, "--law", "hunt-crosley: k=2e9, n=1.5, lambda=3e9"],
        "did you mean 'hunt-crossley'",
    ),
    (
        "study-config-missing",
        ["study", "--config", "nope.toml", "--out", "stres"],
        # the example by its full path (the package runs from its source tree here)
        f"such as {Path(discovery.__file__).parents[1] / 'examples' / 'study_paper.toml'}",
    ),
]


def test_enough_cases():
    assert len(CASES) >= 100
    assert len({c[0] for c in CASES}) == len(CASES)


@pytest.mark.parametrize(("argv", "needle"), [c[1:] for c in CASES], ids=[c[0] for c in CASES])
def test_bad_input(workspace, monkeypatch, capsys, argv, needle):
    monkeypatch.chdir(workspace)
    if needle == "summary":  # the summary's path of `--out summ.csv` is a directory
        (workspace / "summ.summary.json").mkdir(exist_ok=True)
    before = _snapshot(workspace)
    rc = main(list(argv))
    out, err = capsys.readouterr()
    # (a failure found mid-run follows the progress lines of the stages before it)
    lines = [ln for ln in err.splitlines() if not ln.endswith(" ...")]
    assert rc == 2, (rc, err)
    assert len(lines) == 1, err
    assert lines[0].startswith("vidi: error: "), err
    assert needle in lines[0], lines[0]
    assert "Traceback" not in err + out
    assert "np.float64" not in lines[0]
    assert _snapshot(workspace) == before


# -------------------------------------------------------------------- API-level inputs
def _api_cases():
    from discovery import ForceLaw, Measurement, load_scenario
    from discovery._files._io import check_output
    from discovery.vibroimpact.model.scenario import Scenario

    t = np.arange(10) / 1000.0
    return [
        ("law-none", lambda w: ForceLaw.parse(None), "must be text"),
        ("law-bytes", lambda w: ForceLaw.parse(b"z"), "must be text"),
        (
            "scenario-bool",
            lambda w: Scenario(m1=True, m2=1, k1=0, c1=0, A=0, frequency=1),
            "got a boolean",
        ),
        (
            "scenario-text",
            lambda w: Scenario(m1=1, m2="1", k1=0, c1=0, A=0, frequency=1),
            "got text",
        ),
        (
            "scenario-law-text",
            lambda w: Scenario(m1=1, m2=1, k1=0, c1=0, A=0, frequency=1, law="z"),
            "must be a ForceLaw",
        ),
        ("scenario-dir", lambda w: load_scenario(w), "is a directory"),
        (
            "impulse-of-no-steady-state",
            lambda w: discovery.impulse_from_steady_state(
                load_scenario("paper"), ForceLaw.parse("2e8*z + 1e7*zd"), None
            ),
            "ss must be a SteadyState",
        ),
        (
            "columns-not-dict",
            lambda w: Measurement.from_csv(w / "good.csv", columns=["t"]),
            "columns must map",
        ),
        (
            "columns-unknown",
            lambda w: Measurement.from_csv(w / "good.csv", columns={"x": "t"}),
            "unknown name 'x'",
        ),
        ("measurement-shape", lambda w: Measurement(t, t[:5]), "equal length"),
        ("measurement-channel", lambda w: Measurement(t, t, {"w1": t[:3]}), "has 3 samples"),
        (
            "measurement-gap",
            lambda w: Measurement(np.r_[t, 1.0], np.r_[t, 0.0]),
            "not uniformly sampled",
        ),
        ("measurement-huge", lambda w: Measurement(t, t * 1e20), "|F| <= 1e+12 N"),
        ("check-output-empty", lambda w: check_output(""), "--out is empty"),
        ("check-output-file", lambda w: check_output(w / "afile"), "is an existing file"),
    ]


@pytest.mark.parametrize("case", range(14))
def test_api_bad_input(workspace, case):
    name, call, needle = _api_cases()[case]
    before = _snapshot(workspace)
    with pytest.raises(VidiError) as exc:  # InputError (a ValueError) or VidiTypeError
        call(workspace)
    assert isinstance(exc.value, TypeError | ValueError)
    msg = str(exc.value)
    assert needle in msg and "\n" not in msg, (name, msg)
    assert _snapshot(workspace) == before


@pytest.mark.parametrize(
    "exc",
    [
        ValueError("operands could not be broadcast together"),
        TypeError("unsupported operand"),
        IndexError("index 5"),
    ],
)
def test_a_bug_is_exit_1_not_bad_input(monkeypatch, capsys, exc):
    """Only the package's own errors (VidiError) are bad input (exit 2); a numpy shape error
    or any other exception from a bug is exit 1 with one line asking for a report."""
    import importlib

    R = importlib.import_module("discovery.vibroimpact.dynamics.law_response")

    def broken(*args, **kwargs):
        raise exc

    monkeypatch.setattr(R, "response", broken)
    from discovery.cli import main

    assert main(["steady", "--scenario", "paper"]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("vidi: error: internal error") and len(err.splitlines()) == 1, err


def test_a_huge_record_is_refused_before_it_is_read(tmp_path, monkeypatch, capsys):
    """Issue 53: a 10-million-row record (908 MB) given to verify ran for minutes with
    nothing printed, its memory at ten times the file; a record over the stated size is one
    line before any of it is read (a sparse file: nothing on the disk)."""
    monkeypatch.chdir(tmp_path)
    with open("huge.csv", "wb") as fh:
        fh.write(b"t,F\n")
        fh.truncate(201 * 2**20)
    assert main(["verify", "--data", "huge.csv", "--out", "res"]) == 2
    err = capsys.readouterr().err.strip()
    assert "is 201 MB; records up to 200 MB" in err and "\n" not in err
    assert not (tmp_path / "res").exists()
