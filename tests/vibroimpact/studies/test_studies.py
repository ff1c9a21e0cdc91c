"""Model-term selection studies: configuration, runs, resumption, executors, tables."""

import json
import math
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.vibroimpact.studies import FACTORS, load_study, study, wilson
from discovery.vibroimpact.studies.config import run_key
from discovery.vibroimpact.studies.records import clean_record, field_record
from reports.vibroimpact.study_figures import study_figures

ROOT = Path(__file__).resolve().parents[3]
VIDI = [sys.executable, "-c", "import sys; from discovery.cli import main; sys.exit(main())"]

# the paper's law, two noise levels and two methods, regression only: 8 runs in seconds
QUICK = {
    "name": "quick",
    "seeds": 2,
    "factors": {
        "law": ["2.06e8*z + 1.28e7*zd"],
        "force_noise": [0.01, 0.05],
        "periods": [6],
        "library": ["z, zd, z^2, z*zd"],
        "selection": ["best-subset", "stlsq"],
        "refine": [False],
    },
}
TIMING = {"seconds", "seconds_median", "code_version"}


def _files(d):
    return sorted((Path(d) / "runs").glob("*.json"))


def _runs(d):
    out = {}
    for f in _files(d):
        r = json.loads(f.read_text())
        out[r["key"]] = {k: v for k, v in r.items() if k not in TIMING}
    return out


def _cells(d):
    lines = (Path(d) / "cells.csv").read_text().splitlines()
    cols = lines[0].split(",")
    keep = [i for i, c in enumerate(cols) if c not in TIMING]
    # the library text holds commas inside quotes: compare whole lines minus timing columns
    import csv

    rows = list(csv.reader(lines))
    return [[r[i] for i in keep] for r in rows]


# ------------------------------------------------------------------ configuration
def test_config_product_seeds_and_keys():
    cfg = load_study(QUICK)
    assert cfg.n_runs == 8 and len(cfg.cells) == 4
    assert cfg.varied == ("force_noise", "selection")
    runs = cfg.runs("v1")
    assert len({r["key"] for r in runs}) == 8
    # the key is a hash of the full description and the code version
    assert runs[0]["key"] == run_key(runs[0], "v1") != run_key(runs[0], "v2")
    other = load_study({**QUICK, "factors": {**QUICK["factors"], "fs": [20000.0]}})
    assert {r["key"] for r in other.runs("v1")}.isdisjoint({r["key"] for r in runs})
    # a run is self-contained: machine parameters and law text, no file names
    assert runs[0]["scenarios"][0]["m1"] == 1.0e4 and runs[0]["law"].endswith("*zd")
    assert set(FACTORS) <= set(cfg.cells[0])


def test_config_rows_and_scenario_tables():
    cfg = load_study(
        {
            "seeds": [3],
            "rows": [
                {"scenario": [{"base": "paper", "A": 3.5e5}, "paper"], "periods": 4},
                {"selection": "stlsq"},
            ],
        }
    )
    assert cfg.seeds == (3,) and len(cfg.cells) == 2
    runs = cfg.runs()
    assert [s["A"] for s in runs[0]["scenarios"]] == [3.5e5, 5.0e5]
    assert runs[1]["selection"] == "stlsq" and runs[1]["periods"] == FACTORS["periods"]


@pytest.mark.parametrize(
    "bad, words",
    [
        ({"factors": {"noise": [0.1]}}, "unknown factor"),
        ({"factors": {"force_noise": 0.1}}, "must be a non-empty list"),
        ({"factors": {"force_noise": [1.5]}}, "fractions in [0, 1)"),
        ({"factors": {"selection": ["lasso"]}}, "selection 'lasso' is unknown"),
        ({"factors": {"periods": [2.5]}}, "whole numbers"),
        ({"seeds": 0}, "seeds = 0"),
        ({"seeds": [1, 1]}, "repeats a seed"),
        ({"fit": {"max_term": 3}}, "unknown [fit] key"),
        ({"record": {"transient": "long"}}, 'transient is "auto"'),
        ({"factors": {"refine": [True]}, "rows": [{}]}, "not both"),
        ({"factors": {"scenario": [{"base": "paper", "mass": 3}]}}, "unknown scenario key"),
        ({"factors": {"law": ["2e8*z +"]}}, ""),
        # every [fit] and [record] option by the API's own checks, types strict
        ({"fit": {"max_terms": "four"}}, "[fit] max_terms must be an integer"),
        ({"fit": {"max_terms": -3}}, "[fit] max_terms must be an integer in [1, 64]; got -3"),
        ({"fit": {"criterion": "I9"}}, "criterion must be one of 'I0', 'I1', 'I2', 'I3', 'I4'"),
        ({"fit": {"max_simulations": 0}}, "max_simulations must be an integer >= 2"),
        ({"fit": {"scoring": "r2"}}, "scoring must be one of"),
        ({"fit": {"physics": "no"}}, "physics must be a bool"),
        ({"fit": {"n_boot": 10**9}}, "n_boot must be at most 10000"),
        ({"fit": {"n_boot_intervals": 3}}, "n_boot_intervals must be 0 or an integer >= 5"),
        ({"record": {"velocities": "no"}}, "velocities is true or false; got 'no'"),
        ({"factors": {"law": ["-2e8*z"]}}, "never pushes the bodies apart"),
        ({"factors": {"scenario": [{"base": "paper", "m2": 1e-300}]}}, "too stiff"),
        ({"factors": {"scenario": [{"base": "paper", "A": "big"}]}}, "A = 'big' is not a number"),
        # bounds on cells, runs and samples, with the number
        (
            {
                "factors": {
                    "force_noise": [i / 1e4 for i in range(1000)],
                    "fs": [1e3 + i for i in range(1000)],
                }
            },
            "make 1000000 cells",
        ),
        ({"seeds": 100000, "factors": {"force_noise": [0.01, 0.02]}}, "= 200000 runs"),
        ({"factors": {"periods": [10000], "fs": [1e7]}}, "is 4e+09 samples a record"),
    ],
)
def test_config_refuses_bad_studies_in_one_line(bad, words):
    bad = {
        "factors": {"law": ["2.06e8*z + 1.28e7*zd"], **bad.get("factors", {})},
        **{k: v for k, v in bad.items() if k != "factors"},
    }
    with pytest.raises(InputError) as err:
        load_study(bad)
    assert words in str(err.value) and "\n" not in str(err.value)


def test_a_huge_study_file_is_not_read_whole():
    with pytest.raises(InputError, match="larger than 1048576 bytes"):
        load_study("/dev/zero")


def test_wilson_interval_closed_form():
    lo, hi = wilson(5, 10)
    assert lo == pytest.approx(0.2366, abs=1e-4) and hi == pytest.approx(0.7634, abs=1e-4)
    assert wilson(0, 4)[0] == 0.0 and wilson(4, 4)[1] == 1.0
    assert all(math.isnan(x) for x in wilson(0, 0))


# ------------------------------------------------------------------ records
def test_field_record_noise_is_relative_to_each_channel(paper):
    law = paper.law
    clean = clean_record(paper, law, 4, 10000.0, 30)
    m = field_record(
        paper, law, periods=4, fs=10000.0, transient=30, force_noise=0.02, motion_noise=0.01, seed=5
    )
    t, y, F, *_ = clean
    assert np.array_equal(m.t, t) and m.t[0] == pytest.approx(30 * paper.period)
    assert np.std(m.F - F) == pytest.approx(0.02 * np.max(np.abs(F)), rel=0.1)
    for name, row in (("w1", 0), ("v1", 1), ("w2", 2), ("v2", 3)):
        assert np.std(m.channels[name] - y[row]) == pytest.approx(0.01 * np.ptp(y[row]), rel=0.1)
    again = field_record(
        paper, law, periods=4, fs=10000.0, transient=30, force_noise=0.02, motion_noise=0.01, seed=5
    )
    assert np.array_equal(again.F, m.F)  # seeds are explicit


# ------------------------------------------------------------------ a study end to end
@pytest.fixture(scope="module")
def quick_serial(tmp_path_factory):
    out = tmp_path_factory.mktemp("study") / "serial"
    return study(QUICK, out, workers=1, figures=study_figures), out


def test_study_runs_scores_and_writes_tables(quick_serial):
    res, out = quick_serial
    assert res.executed == 8 and res.reused == 0 and len(res.runs) == 8
    assert len(_files(out)) == 8
    for f in (
        "cells.csv",
        "runs.csv",
        "inclusion.csv",
        "summary.json",
        "config.json",
        "recovery_noise.png",
        "recovery_map.pdf",
        "inclusion.png",
    ):
        assert (out / f).stat().st_size > 0, f
    assert not (out / "coverage.png").exists()  # no refinement, no intervals: no empty chart
    for r in res.runs:
        assert r["status"] == "ok", r.get("error")
        assert r["tp"] + r["fn"] == 2 and r["tp"] + r["fp"] == len(r["selected"])
        assert r["exact"] == (sorted(r["selected"]) == ["z", "zd"])
        assert r["coef_error"] >= 0 and set(r["criteria"]) >= {"I0", "I2", "I3"}
    # the runs' seconds over the wall time (one worker here: close to 1)
    eff = json.loads((out / "summary.json").read_text())["parallel_efficiency"]
    assert 0.3 < eff <= 1.05
    # the aggregates follow from the runs
    for row, ci in zip(res.cells, range(4), strict=True):
        rs = [r for r in res.runs if r["cell"] == ci]
        assert row["recovered"] == sum(r["exact"] for r in rs) and row["runs"] == 2
    # at 1 % noise best-subset finds the paper's law on both seeds
    best = next(
        c for c in res.cells if c["selection"] == "best-subset" and c["force_noise"] == 0.01
    )
    assert best["recovered"] == 2
    summary = json.loads((out / "summary.json").read_text())
    assert summary["versions"]["numpy"] and summary["runs"] == 8
    assert summary["pooled"]["best-subset"]["runs"] == 4
    assert summary["design"]["varied"]["selection"] == ["best-subset", "stlsq"]
    text = str(res)
    assert "8 runs" in text and "recovery" in text
    df = res.table()
    assert len(df) == 4 and "recovery_low" in df.columns
    assert len(res.table(runs=True)) == 8


def test_study_resumes_in_slices_with_the_same_tables(quick_serial, tmp_path):
    _, full = quick_serial
    out = tmp_path / "sliced"
    a = study(QUICK, out, workers=1, max_runs=3, figures=False)
    assert a.executed == 3 and len(_files(out)) == 3 and len(a.runs) == 3
    b = study(QUICK, out, workers=1, figures=False)
    assert b.executed == 5 and b.reused == 3
    c = study(QUICK, out, workers=1, figures=False)
    assert c.executed == 0 and c.reused == 8
    assert _runs(out) == _runs(full) and _cells(out) == _cells(full)


def test_study_gives_the_same_numbers_on_every_executor(quick_serial, tmp_path):
    _, full = quick_serial
    study(QUICK, tmp_path / "pool", workers=2, figures=False)
    assert _runs(tmp_path / "pool") == _runs(full)
    assert _cells(tmp_path / "pool") == _cells(full)


def test_study_on_a_dask_local_cluster_matches(quick_serial, tmp_path):
    pytest.importorskip("distributed")
    _, full = quick_serial
    study(QUICK, tmp_path / "dask", scheduler="local", workers=2, figures=False)
    assert _runs(tmp_path / "dask") == _runs(full)
    assert _cells(tmp_path / "dask") == _cells(full)


def test_study_survives_a_killed_dask_worker(quick_serial, tmp_path):
    """A worker process killed mid-study: its tasks are rescheduled, every run is done once
    and the numbers do not change."""
    pytest.importorskip("distributed")
    from discovery.numerics.executor import Dask

    _, full = quick_serial
    killed = []
    with Dask("local", workers=2) as ex:
        pids = ex.client.run(os.getpid)

        def progress(stage, done, total):
            if done >= 1 and not killed:
                pid = sorted(pids.values())[0]
                os.kill(pid, signal.SIGKILL)
                killed.append(pid)

        res = study(QUICK, tmp_path / "kill", executor=ex, progress=progress, figures=False)
    assert killed and res.executed == 8 and len(_files(tmp_path / "kill")) == 8
    assert _runs(tmp_path / "kill") == _runs(full)


def test_study_killed_with_sigkill_resumes_with_every_run_once(quick_serial, tmp_path):
    _, full = quick_serial
    cfg = tmp_path / "quick.toml"
    cfg.write_text((ROOT / "examples" / "study_quick.toml").read_text())
    out = tmp_path / "killed"
    cmd = [
        *VIDI,
        "study",
        "--config",
        str(cfg),
        "--out",
        str(out),
        "--workers",
        "1",
        "--no-figures",
        "--quiet",
    ]
    work = tmp_path / ".killed.vidi-study"  # the runs land here until the study is put in place
    proc = subprocess.Popen(cmd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 300
    while len(_files(work)) < 3 and time.monotonic() < deadline and proc.poll() is None:
        time.sleep(0.05)
    os.kill(proc.pid, signal.SIGKILL)
    proc.wait()
    before = len(_files(work))
    assert 3 <= before < 8, "the study must be killed halfway"
    assert not out.exists(), "a killed study writes nothing into its directory"
    again = subprocess.run(cmd, capture_output=True, text=True, timeout=600)
    assert again.returncode == 0, again.stderr
    runs = _runs(out)
    assert len(_files(out)) == 8 and len(runs) == 8
    assert all(f.stem == json.loads(f.read_text())["key"] for f in _files(out))
    assert f"{8 - before} run now, {before} from earlier files" in again.stdout
    assert runs == _runs(full) and _cells(out) == _cells(full)
    assert not [p for p in (out / "runs").iterdir() if p.name.startswith(".")]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["killed", "quick.toml"]


def test_cli_study_bad_inputs_are_one_line(tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text('[factors]\nselection = ["lasso"]\n')
    for args, words in (
        (["--config", str(bad)], "selection 'lasso' is unknown"),
        (["--config", str(tmp_path / "none.toml")], "does not exist"),
        (
            [
                "--config",
                str(ROOT / "examples" / "study_quick.toml"),
                "--scheduler",
                "tcp://127.0.0.1:9",
            ],
            "cannot reach the Dask scheduler",
        ),
    ):
        p = subprocess.run(
            [*VIDI, "study", *args, "--out", str(tmp_path / "o")],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert p.returncode == 2, p.stderr
        assert words in p.stderr and len(p.stderr.strip().splitlines()) == 1, p.stderr
        # a failed study leaves nothing behind: no directory, no work directory
        assert sorted(q.name for q in tmp_path.iterdir()) == ["bad.toml"], p.stderr


def test_study_refuses_a_directory_that_is_not_a_study(tmp_path):
    (tmp_path / "mine.txt").write_text("notes")
    with pytest.raises(InputError):
        study(QUICK, tmp_path, workers=1)
    assert (tmp_path / "mine.txt").read_text() == "notes"


def test_study_owns_its_directory_whatever_ran_before(tmp_path):
    """An earlier CLI command in the same process (here `vidi report`) does not make the API
    refuse a study directory as another command's results."""
    from discovery._files._io import _RUN, set_run

    out = tmp_path / "s"
    study(
        {
            **QUICK,
            "seeds": 1,
            "factors": {**QUICK["factors"], "force_noise": [0.01], "selection": ["best-subset"]},
        },
        out,
        workers=1,
        figures=False,
    )
    prev = dict(_RUN)
    set_run("report")
    try:
        again = study(
            {
                **QUICK,
                "seeds": 1,
                "factors": {
                    **QUICK["factors"],
                    "force_noise": [0.01],
                    "selection": ["best-subset"],
                },
            },
            out,
            workers=1,
            figures=False,
        )
    finally:
        _RUN.update(prev)
    assert again.reused == 1 and again.executed == 0


def test_runs_are_scheduled_longest_first():
    """Longer records, larger libraries, the pysindy-based methods and refinements cost
    more; the driver runs the most costly first so that no worker ends with one long run."""
    from discovery.vibroimpact.studies.run import run_cost

    base = {"periods": 12, "fs": 1e4, "library": "z, zd", "selection": "best-subset"}
    assert run_cost({**base, "periods": 40}) > run_cost(base)
    assert run_cost({**base, "library": "z, zd, z^2"}) > run_cost(base)
    assert run_cost({**base, "selection": "sr3"}) > run_cost(base)
    assert run_cost({**base, "refine": True}) > run_cost(base)
