"""The missing-effect workflow for Ueda's oscillators (issue 9, section 3): from negres
without its van der Pol damping x^2 x', the effect is named and the gap shrinks; from the
true terms nothing is added; the catalogue; the CLI end to end and its bad inputs.

Records: the compiled kernel, 200 periods, 40 samples per period, 1 % noise (of x's
range).  The models are simulated for 600 periods (the CLI default is 2000).
"""

import json

import pytest

from discovery.errors import InputError
from discovery.ueda import EFFECTS, UedaSystem, explain
from discovery.ueda.effects import effect, in_bounds
from discovery.ueda.equation_discovery import FORCING, TERMS, simulate_record
from discovery.ueda.explain_loop import DEFAULT_START, parse_terms
from discovery.vibroimpact.explain.effects import Effect, Parameter

NEGRES = UedaSystem.from_model("negres")
TRUE_TERMS = ("x'", "x^3", "x^2 x'")  # the library's order
SIM = {"periods": 600, "resamples": 100}


def _record(seed, system=NEGRES, noise=0.01, periods=200):
    t, x, _, _ = simulate_record(system, periods, 40, noise, seed=seed, transient=100)
    return t, x


@pytest.fixture(scope="module")
def missing_vdp():
    t, x = _record(0)
    return explain(t, x, NEGRES.B, NEGRES.nu, DEFAULT_START, **SIM)


def test_the_catalogue():
    ids = {e.id for e in EFFECTS}
    assert {
        "van_der_pol_damping",
        "linear_damping",
        "cubic_stiffness",
        "quadratic_stiffness",
        "velocity_cubic_damping",
    } <= ids
    for e in EFFECTS:  # the vibro-impact catalogue's dataclasses, this system's terms
        assert isinstance(e, Effect) and all(isinstance(p, Parameter) for p in e.parameters)
        assert set(e.terms) <= set(TERMS) and len(e.parameters) == len(e.terms)
        assert e.explanation and e.signature and e.enters
    vdp = effect("van_der_pol_damping")
    assert vdp.terms == ("x^2 x'",)
    assert in_bounds(vdp, -1.6) and not in_bounds(vdp, 0.1)  # -mu gamma <= 0
    assert not in_bounds(effect("velocity_cubic_damping"), 0.5)
    assert in_bounds(effect("linear_damping"), 0.2) and in_bounds(effect("linear_damping"), -0.2)
    with pytest.raises(InputError):
        effect("friction")


def test_parse_terms():
    assert DEFAULT_START == ("x'", "x^3")
    assert parse_terms("x^3, x'") == ("x'", "x^3")
    assert parse_terms("x^2*x',v,x^3") == TRUE_TERMS
    assert parse_terms("x^2 x', x x'^2") == ("x^2 x'", "x x'^2")
    assert parse_terms("none") == ()
    for bad in ("y", ",", "x^4"):
        with pytest.raises(InputError):
            parse_terms(bad)


def test_missing_van_der_pol_damping_is_named_and_the_gap_shrinks(missing_vdp):
    ex = missing_vdp
    assert ex.effects_added == ("van_der_pol_damping",)
    assert ex.final_terms == TRUE_TERMS
    it = ex.iterations[0]
    ev = it.evidence
    # measured: LM 120, p 6e-28 (gate 0.0033), 91 % of the residual; x'^3 also
    # significant (LM 45, 3 %) but explains far less
    assert ev["p"] < ev["gate"] and ev["share"] > 0.5
    assert it.equivalent == []
    s = {x["effect"]: x for x in it.scores}
    assert s["van_der_pol_damping"]["share"] == max(x["share"] for x in it.scores)
    # the refitted coefficient: -mu gamma = -1.6
    p = it.parameters["x^2 x'"]
    assert abs(p["value"] + 1.6) < 4 * p["stderr"] + 0.02
    # the gap (measured: energy distance 0.70 (start model P6) -> 0.037, floor q95 0.076;
    # weak-form residual 0.143 -> 0.044, its noise floor 0.049)
    assert not it.criteria_before["consistent"]
    g = ex.gap
    assert g["energy_distance"]["ratio"] >= 3
    assert g["energy_distance"]["after"] <= ex.noise_floor["energy_distance_q95"]
    assert (
        g["residual_rms"]["ratio"] >= 3
        or g["residual_rms"]["after"] <= 1.2 * ex.noise_floor["residual_rms"]
    )
    assert ex.consistent and ex.criteria["regime_model"] == ex.criteria["regime_record"]
    assert "consistent" in ex.stopped_because and "no catalogue effect" in ex.stopped_because
    for k, v in {"x'": 0.2, "x^3": -1.0, FORCING: 1.0}.items():
        assert abs(ex.coefficients[k] - v) < 4 * ex.standard_errors[k] + 0.01
    # the last iteration named nothing: nothing significant is left
    assert ex.iterations[-1].effect is None
    assert not any(x["significant"] for x in ex.iterations[-1].scores)
    d = json.loads(json.dumps(_jsonable(ex.as_dict())))
    assert d["effects_added"] == ["van_der_pol_damping"]
    assert {"lm", "p", "gate", "share", "text"} <= set(d["iterations"][0]["evidence"])


def _jsonable(d):
    from discovery._files._io import to_jsonable

    return to_jsonable(d)


def test_no_false_discoveries_from_the_true_terms():
    """Five noisy records (1 %) of negres, started from its true terms: nothing is added.
    (Measured over 100 seeds each at 0.2, 1, 2 and 5 % noise: 0 false discoveries, and
    the missing x^2 x' named in 100/100.)  Whether the refitted true-term model is also
    consistent by simulation is another matter: at 1 % noise the x^2 x' coefficient
    scatters by 1 % (sd 0.016 over 40 seeds) and 6 of 40 fits land on a quasi-periodic
    (beat) attractor instead of the chaotic one (here seed 5); 2/40 at 0.5 %, 0/40 at
    0.2 %.  The loop then stops saying the model is still inconsistent."""
    false = 0
    for seed in range(1, 6):
        t, x = _record(seed)
        ex = explain(t, x, NEGRES.B, NEGRES.nu, TRUE_TERMS, **SIM)
        false += len(ex.effects_added)
        assert ex.final_terms == TRUE_TERMS
        assert len(ex.iterations) == 1 and ex.iterations[0].effect is None
        assert ("is consistent" if ex.consistent else "still inconsistent") in ex.stopped_because
    assert false == 0


def test_from_the_cubic_term_alone_both_dampings_are_named():
    """negres from x^3 alone: the van der Pol damping, then the linear negative
    resistance (the decisions need no simulation)."""
    t, x = _record(0)
    ex = explain(t, x, NEGRES.B, NEGRES.nu, "x^3", simulate=False)
    assert ex.effects_added == ("van_der_pol_damping", "linear_damping")
    assert ex.final_terms == TRUE_TERMS and ex.consistent is None
    assert "energy_distance" not in ex.criteria
    assert ex.gap["residual_rms"]["ratio"] > 3
    # a budget of one addition stops with the linear damping still significant
    one = explain(t, x, NEGRES.B, NEGRES.nu, "x^3", simulate=False, max_iterations=1)
    assert one.effects_added == ("van_der_pol_damping",)
    assert "budget" in one.stopped_because and "linear_damping" in one.stopped_because


def test_duffing_missing_its_damping():
    s = UedaSystem.from_model("duffing")
    t, x = _record(0, s, noise=0.002)
    ex = explain(t, x, s.B, s.nu, "x^3", simulate=False)
    assert ex.effects_added == ("linear_damping",)
    assert abs(ex.coefficients["x'"] + 0.05) < 4 * ex.standard_errors["x'"] + 2e-3
    assert explain(t, x, s.B, s.nu, "x',x^3", simulate=False).effects_added == ()


def test_bad_inputs():
    t, x = _record(0, periods=30)
    with pytest.raises(InputError):
        explain(t, x, NEGRES.B, NEGRES.nu, "x^4")
    with pytest.raises(InputError):
        explain(t, x, NEGRES.B, NEGRES.nu, alpha=0)
    with pytest.raises(InputError):
        explain(t, x, NEGRES.B, NEGRES.nu, effects=["friction"])
    with pytest.raises(InputError):
        explain(t, x, NEGRES.B, -1.0)
    with pytest.raises(InputError):
        explain(t[:10], x[:10], NEGRES.B, NEGRES.nu)


# ------------------------------------------------------------------ CLI
@pytest.fixture
def vidi():
    from discovery.cli import main

    return main


def _write_record(path, seed=0, periods=150):
    t, x = _record(seed, periods=periods)
    path.write_text("t,x\n" + "".join(f"{a:.12g},{b:.12g}\n" for a, b in zip(t, x, strict=True)))


def test_cli_explain(vidi, tmp_path, capsys):
    data = tmp_path / "D.csv"
    _write_record(data)
    out = tmp_path / "res"
    assert (
        vidi(
            [
                "ueda",
                "explain",
                "--data",
                str(data),
                "--model",
                "negres",
                "--model-periods",
                "400",
                "--resamples",
                "50",
                "--out",
                str(out),
            ]
        )
        == 0
    )
    s = json.loads((out / "summary.json").read_text())
    assert {
        "command",
        "forcing",
        "start_terms",
        "final_terms",
        "effects_added",
        "iterations",
        "start_model",
        "final_model",
        "criteria_start",
        "criteria",
        "gap",
        "noise_floor",
        "consistent",
        "stopped_because",
        "catalogue",
        "method",
        "versions",
        "settings",
        "inputs",
    } <= set(s)
    assert s["command"] == "ueda explain" and s["start_terms"] == ["x'", "x^3"]
    assert s["effects_added"] == ["van_der_pol_damping"] and s["consistent"]
    assert s["forcing"] == {"B": 0.35, "nu": 1.02}
    it = s["iterations"][0]
    assert {
        "effect",
        "evidence",
        "scores",
        "criteria_before",
        "criteria_after",
        "parameters",
    } <= set(it)
    assert s["inputs"]["data"]["sha256"] and s["settings"]["start"] == "x',x^3"
    for f in (
        "explain.png",
        "explain.pdf",
        "strobe_record.csv",
        "strobe_start.csv",
        "strobe_final.csv",
    ):
        assert (out / f).exists(), f
    assert "named van_der_pol_damping" in capsys.readouterr().out


def test_cli_explain_bad_inputs_exit_2(vidi, tmp_path, capsys):
    data = tmp_path / "D.csv"
    _write_record(data, periods=30)
    out = str(tmp_path / "o")
    cases = [
        ["--start", "y^2", "--model", "negres"],
        ["--start", "x'", "--effects", "friction", "--model", "negres"],
        ["--alpha", "0", "--model", "negres"],
        [],
    ]  # no forcing
    for extra in cases:
        capsys.readouterr()
        assert vidi(["ueda", "explain", "--data", str(data), *extra, "--out", out]) == 2, extra
        err = capsys.readouterr().err
        assert len(err.strip().splitlines()) == 1 and err.startswith("vidi: error:"), err
        assert "Traceback" not in err
    assert (
        vidi(
            [
                "ueda",
                "explain",
                "--data",
                str(tmp_path / "nope.csv"),
                "--model",
                "negres",
                "--out",
                out,
            ]
        )
        == 2
    )
    assert not (tmp_path / "o").exists()
