"""Counts of the work a run does (:mod:`discovery.numerics.counts`): the same on every
executor, recorded in a command's summary."""

import json

import pytest

from discovery.cli import main
from discovery.numerics import counts
from discovery.numerics.executor import Pool, Serial


def _job(context, n):
    counts.count("evaluations", n)
    counts.count("criteria", context)
    return n * n


@pytest.mark.parametrize("executor", [Serial(), Pool(2)], ids=["serial", "pool"])
def test_a_sweep_counts_its_workers_work_here(executor):
    with counts.counting() as c:
        out = executor.map(_job, [1, 2, 3, 4], context=5)
    assert out == [1, 4, 9, 16]
    assert c["evaluations"] == 10 and c["criteria"] == 20
    assert c["steady_states"] == 0 and set(c) == set(counts.NAMES)


def test_a_command_s_summary_counts_its_own_work_on_any_worker_count(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["simulate", "--periods", "8", "--noise", "0.01", "--out", "D.csv"]) == 0
    got = []
    for w in ("1", "2"):
        argv = ["landscape", "--data", "D.csv", "--grid", "3x3", "--workers", w, "--out", w]
        assert main(argv) == 0
        got.append(json.loads((tmp_path / w / "summary.json").read_text())["counts"])
    # what was asked for is the same; the work done depends on the caches (the second run's
    # steady states come from the first's, in this process and in the workers it forks)
    asked = ("evaluations", "criteria")
    assert [{k: g[k] for k in asked} for g in got] == [{k: got[0][k] for k in asked}] * 2
    assert got[0]["evaluations"] >= 9 and got[0]["criteria"] >= 9
    assert got[0]["steady_states"] >= 1 and got[0]["period_maps"] >= got[0]["steady_states"]


def test_the_ueda_commands_record_no_counts_of_the_other_system(tmp_path, monkeypatch):
    """The counts are the vibro-impact system's units: a Ueda command, which does none of
    that work, records none (it had recorded zeros, as if it had judged no law)."""
    monkeypatch.chdir(tmp_path)
    assert main(["ueda", "simulate", "--periods", "60", "--out", "u.csv"]) == 0
    assert main(["ueda", "discover", "--data", "u.csv", "--model", "negres", "--out", "d"]) == 0
    assert "counts" not in json.loads((tmp_path / "d" / "summary.json").read_text())
