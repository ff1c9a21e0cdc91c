"""The runs every report test reads: one small run of every kind (made once a session),
and the figures their commands drew, kept as matplotlib figures to be read back."""

import os
import re
from pathlib import Path

import pytest

from discovery.cli import main


def _make_runs(d):
    """One small run of every kind in ``d``, on a record whose name tries TeX injection."""
    cwd = os.getcwd()
    os.chdir(d)
    try:
        rec = "r_\\input{etc-passwd}_$x$.csv"
        assert (
            main(["simulate", "--periods", "12", "--noise", "0.01", "--seed", "2", "--out", rec])
            == 0
        )
        scen = d / "evil.toml"
        scen.write_text(
            'name = "\\\\write18{touch pwned} & 100% #1"\n[machine]\nm1 = 1.0e4\n'
            "m2 = 1.0e4\nk1 = 2.75e7\nc1 = 1.0e5\nA = 5.0e5\nfrequency = 25.0\n"
            '[law]\ntext = "2.06e8*z + 1.28e7*zd"\n'
        )
        law = "2.06e8*z + 1.28e7*zd"
        cmds = {
            "verify": ["verify", "--scenario", str(scen), "--data", rec, "--law", law],
            "fit": ["fit", "--data", rec, "--no-refine", "--intervals", "0"],
            "identify": [
                "identify",
                "--data",
                rec,
                "--start",
                "1.8e8*z + 1.1e7*zd",
                "--max-simulations",
                "40",
            ],
            "landscape": ["landscape", "--grid", "3x3", "--workers", "1"],
            "calibrate": ["calibrate", "--data", rec],
            "explain": ["explain", "--data", rec, "--effects", "contact_offset"]
            + ["--max-iterations", "1", "--n-boot", "4", "--intervals", "0"],
        }
        for kind, argv in cmds.items():
            assert main([*argv, "--out", kind]) == 0, kind
        # a fit over two scenarios (two drive amplitudes), each with its record
        low = d / "low.toml"
        low.write_text(scen.read_text().replace("A = 5.0e5", "A = 3.5e5").replace("100% #1", "low"))
        assert (
            main(
                ["simulate", "--scenario", str(low), "--periods", "12", "--noise", "0.01"]
                + ["--seed", "3", "--out", "low.csv"]
            )
            == 0
        )
        fit2 = ["fit", "--scenario", str(scen), "--scenario", str(low), "--data", rec]
        fit2 += ["--data", "low.csv", "--no-refine", "--intervals", "0", "--out", "fit2"]
        assert main(fit2) == 0
        advise = ["advise", "--law", law, "--law", "2.06e8*z + 9e6*zd + 1e9*z*zd"]
        advise += ["--noise", "0.01", "--amplitude", "3e5:6e5", "--frequency", "20:30"]
        assert main([*advise, "--grid", "2x2", "--out", "advise"]) == 0
        _study(d / "study")
        attractor = ["ueda", "attractor", "--periods", "300", "--transient", "50"]
        assert main([*attractor, "--out", "ueda-attractor"]) == 0
        assert main(["ueda", "simulate", "--periods", "120", "--out", "U.csv"]) == 0
        assert (
            main(
                [
                    "ueda",
                    "discover",
                    "--data",
                    "U.csv",
                    "--model",
                    "negres",
                    "--model-periods",
                    "400",
                    "--resamples",
                    "40",
                    "--out",
                    "ueda",
                ]
            )
            == 0
        )
    finally:
        os.chdir(cwd)
    return d


def _study(out):
    """A tiny study (two noise levels, two selection methods) with its figures."""
    from discovery import study
    from reports.vibroimpact.study_figures import study_figures

    factors = {
        "force_noise": [0.01, 0.02],
        "periods": [4],
        "library": ["z, zd, z^2"],
        "selection": ["best-subset", "l1-path"],
        "refine": [False],
    }
    study({"name": "tiny", "seeds": 1, "factors": factors}, out, workers=1, figures=study_figures)


@pytest.fixture(scope="session")
def runs_and_figures(tmp_path_factory):
    """``(directory, {(run, figure file): Figure})``: the runs, and every figure their
    commands saved (the same object, before and after it was written)."""
    from matplotlib.figure import Figure

    from discovery._files import _handoff

    d = tmp_path_factory.mktemp("runs")
    drawn = {}
    save = Figure.savefig

    def keep(fig, fname, *args, **kwargs):
        # a command writes into a staging directory (".fit.vidi-staging.<id>") it then
        # renames to its --out directory: the figure's key is the directory it ends in
        path = Path(fname)
        staged = re.match(r"\.(.+)\.vidi-staging\.", path.parent.name)
        drawn[(staged[1] if staged else path.parent.name, path.name)] = fig
        return save(fig, fname, *args, **kwargs)

    with pytest.MonkeyPatch.context() as mp:
        mp.setattr(Figure, "savefig", keep)
        # every PDF printed here, not by a forked child: the figures are kept in this process
        mp.setattr(_handoff, "in_parallel", lambda: False)
        _make_runs(d)
    return d, drawn


@pytest.fixture(scope="session")
def runs(runs_and_figures):
    """One small run of every kind, on a record whose name tries TeX injection."""
    return runs_and_figures[0]
