"""End-to-end tests of ``vidi fit`` (discovery from a CSV record)."""

import csv
import importlib
import json

import pytest

from constraints.errors import SolverError
from discovery.cli import main

FIGURES = ("fit_impulse", "fit_surface", "fit_loop")


@pytest.fixture(scope="module")
def record(tmp_path_factory):
    path = tmp_path_factory.mktemp("fitrec") / "runup.csv"
    assert (
        main(["simulate", "--from-rest", "--periods", "150", "--noise", "0.01", "--out", str(path)])
        == 0
    )
    return path


@pytest.fixture(scope="module")
def fitted(record, tmp_path_factory):
    out = tmp_path_factory.mktemp("fitout") / "fit"
    rc = main(["fit", "--data", str(record), "--library", "poly:2", "--out", str(out)])
    return rc, out


def test_fit_exit_code_and_files(fitted):
    rc, out = fitted
    assert rc == 0
    for name in (
        "summary.json",
        "ranking.csv",
        "model.tex",
        *(f"{f}.{ext}" for f in FIGURES for ext in ("png", "pdf")),
    ):
        assert (out / name).stat().st_size > 0, name
    assert (out / "fit_impulse.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "fit_surface.pdf").read_bytes()[:5] == b"%PDF-"


def test_fit_summary_contents(fitted):
    _, out = fitted
    s = json.loads((out / "summary.json").read_text())
    sel = s["selected"]
    for key in ("terms", "coefficients", "latex", "criteria"):
        assert key in sel
    assert sel["terms"] == ["z", "zd"]  # the run-up record identifies law (11)
    # 150 periods from rest, 1 % noise: coefficients within 3 % (measured 0.2 %)
    assert abs(sel["coefficients"]["z"] / 2.06e8 - 1) < 0.03
    assert abs(sel["coefficients"]["zd"] / 1.28e7 - 1) < 0.03
    assert set(sel["criteria"]) == {"I0", "I1", "I2", "I3", "I4", "I5"}
    assert isinstance(s["ranking"], list) and s["ranking"]
    assert s["ranking"][0]["terms"] == sel["terms"]
    for m in s["ranking"]:
        assert "bic" in m and "cv_error" in m
        assert m["cv_error"] is None  # scored by BIC: no cross-validation run (JSON null)
    cert = s["certificate"]
    for key in ("method", "holds", "worst_violation", "domain"):
        assert key in cert
    assert cert["holds"] is True and cert["worst_violation"] <= 1e-7
    assert cert["domain"]["zeta_max"] > 0 and cert["domain"]["zd_max"] > 0
    assert s["seconds"] > 0
    assert s["command"] == "fit"
    # the selected law's bootstrap intervals, beside the Jacobian standard errors
    sel = s["selected"]
    assert set(sel["intervals"]) == set(sel["terms"]) and sel["interval_level"] == 0.95
    for t in sel["terms"]:
        lo, hi = sel["intervals"][t]
        assert lo < sel["coefficients"][t] < hi
    assert "bootstrap" in sel["interval_method"]


def test_fit_ranking_csv_matches_summary(fitted):
    _, out = fitted
    s = json.loads((out / "summary.json").read_text())
    rows = list(csv.DictReader((out / "ranking.csv").read_text().splitlines()))
    assert len(rows) == len(s["ranking"])
    assert [int(r["rank"]) for r in rows] == list(range(1, len(rows) + 1))
    assert rows[0]["terms"] == " + ".join(s["selected"]["terms"])
    # bic written with 8 significant digits
    for r, m in zip(rows, s["ranking"], strict=True):
        assert float(r["bic"]) == pytest.approx(m["bic"], rel=1e-7)


def test_model_tex_names_the_law(fitted):
    _, out = fitted
    tex = (out / "model.tex").read_text()
    sel = json.loads((out / "summary.json").read_text())["selected"]
    from discovery.vibroimpact.model.law import ForceLaw
    from reports.lawtex import law_equation, term_tex

    # the fitted law's equation, rebuilt from its coefficients (never read as LaTeX)
    assert law_equation(ForceLaw.from_dict(sel["coefficients"])) in tex
    for name, value in sel["coefficients"].items():  # one table row per fitted term
        mant, exp = f"{value:.3e}".split("e")
        assert rf"{term_tex(name)} & ${mant}\cdot 10^{{{int(exp)}}}$" in tex, name


@pytest.mark.slow  # a second full fit, scored by cross-validation: about 1 min
def test_fit_scored_by_cross_validation_reports_it(record, tmp_path):
    out = tmp_path / "cv"
    assert (
        main(
            [
                "fit",
                "--data",
                str(record),
                "--library",
                "poly:2",
                "--score",
                "cv",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    s = json.loads((out / "summary.json").read_text())
    assert s["ranking"]
    for m in s["ranking"]:
        assert 0 <= m["cv_error"] < 1  # relative RMS of held-out impacts
    rows = list(csv.DictReader((out / "ranking.csv").read_text().splitlines()))
    assert [float(r["cv_error"]) for r in rows] == pytest.approx(
        [m["cv_error"] for m in s["ranking"]], rel=1e-5
    )


def _assert_clean_failure(argv, out, capsys, needle=None):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip()
    assert err and "\n" not in err and "Traceback" not in err
    if needle:
        assert needle in err, err
    assert not out.exists()
    assert not list(out.parent.glob(f".{out.name}*"))  # no staged leftovers


@pytest.mark.parametrize(
    "library, needle", [("poly:2+q", "'q'"), ("z,zd,w", "'w'"), ("poly:0", "poly:N")]
)
def test_bad_library_exit_2_without_output(record, tmp_path, capsys, library, needle):
    out = tmp_path / "o"
    _assert_clean_failure(
        ["fit", "--data", str(record), "--library", library, "--out", str(out)], out, capsys, needle
    )


def test_data_without_positions_exit_2_without_output(record, tmp_path, capsys):
    lines = record.read_text().splitlines()
    header = lines[0].split(",")
    keep = [header.index("t"), header.index("F")]
    bad = tmp_path / "tF.csv"
    bad.write_text(
        "\n".join(",".join(line.split(",")[j] for j in keep) for line in lines[:4001]) + "\n"
    )
    out = tmp_path / "o"
    _assert_clean_failure(["fit", "--data", str(bad), "--out", str(out)], out, capsys, "w1 and w2")


def test_bad_max_terms_exit_2(record, tmp_path, capsys):
    out = tmp_path / "o"
    _assert_clean_failure(
        ["fit", "--data", str(record), "--max-terms", "0", "--out", str(out)],
        out,
        capsys,
        "--max-terms",
    )


def test_solver_error_exit_2_one_line(record, tmp_path, capsys, monkeypatch):
    # errors of the constraints package are VidiErrors: a clean exit, never a traceback
    def fail(*args, **kwargs):
        raise SolverError(
            "cvxpy problem ended with status 'infeasible' (solver CLARABEL); "
            "no solution is returned",
            status="infeasible",
            solver="CLARABEL",
        )

    # the module (the package attribute of the same name is the function)
    monkeypatch.setattr(
        importlib.import_module("discovery.vibroimpact.fit.discovery"), "discover", fail
    )
    out = tmp_path / "o"
    _assert_clean_failure(
        ["fit", "--data", str(record), "--out", str(out)], out, capsys, "status 'infeasible'"
    )


def test_library_of_only_plus_exit_2(record, tmp_path, capsys):
    out = tmp_path / "o"
    _assert_clean_failure(
        ["fit", "--data", str(record), "--library", "+", "--out", str(out)], out, capsys
    )


@pytest.mark.parametrize("extra", [["--require", "z"], ["--stability", "3", "--max-terms", "3"]])
def test_regression_options_with_the_named_models_are_refused(record, tmp_path, capsys, extra):
    """Issue 53: --require, --stability and --max-terms were ignored by the contact-models
    fit; each option given is named, before any work."""
    out = tmp_path / "o"
    argv = ["fit", "--data", str(record), "--library", "contact-models", *extra, "--out", str(out)]
    _assert_clean_failure(argv, out, capsys, extra[0])
