"""print(result) reads well for every result: short, the verdict first, the numbers that
matter, the same text in a notebook (``_repr_html_``), a one-line ``repr``."""

import numpy as np
import pytest

import discovery as d
import discovery.ueda as osc
from discovery.vibroimpact.verify import verify

LAW = d.ForceLaw.parse("2.06e8*z + 1.28e7*zd")


@pytest.fixture(scope="module")
def results():
    sc = d.load_scenario("paper")
    rec = d.synthesize(sc, LAW, periods=10, noise=0.01, seed=3)
    out = {
        "verify": verify(sc, rec, LAW),
        "discover": d.discover(sc, rec, refine=False, n_boot_intervals=0),
        "identify": d.identify(sc, rec, d.ForceLaw.parse("1.9e8*z + 1.2e7*zd"), max_simulations=30),
        "landscape": d.landscape(sc, LAW, [1.5e8, 2.06e8, 2.5e8], [1e7, 1.28e7], workers=1),
        "steady": d.steady_state(sc, LAW),
    }
    system = osc.UedaSystem("negres", mu=0.2, gamma=8.0, k=0.0, B=0.35, nu=1.02)
    t, x, _, _ = osc.simulate_record(system, periods=120, noise=0.002, seed=0)
    disc = osc.discover(t, x, 0.35, 1.02)
    out["ueda discover"] = disc
    out["ueda verify"] = osc.verify(disc.model, t, x, periods=300, resamples=20)
    out["response"] = d.response(sc, LAW)
    out["impulse"] = out["response"].impulse
    out["measurement"] = rec
    out["contact samples"] = d.contact_samples(rec)
    out["ranked model"] = out["discover"].ranking[0]
    out["candidate"] = out["ranked model"].candidate
    out["regime"], out["lyapunov"], _ = osc.classify(system, transient=50, periods=60)
    out["periodic orbit"] = osc.periodic_orbit(system, (0.5, 0.0))
    out["basins"] = osc.basins(system, n=2, transient=20, periods=30)
    return out


@pytest.mark.parametrize(
    "name, needles",
    [
        ("verify", ["consistent", "criterion", "I2", "regime measured"]),
        ("discover", ["selected", "term", "std error", "ranking", "certificate"]),
        ("identify", ["identified", "simulations", "z ", "zd"]),
        ("landscape", ["landscape of z, zd on 3x2 points", "min I2"]),
        ("steady", ["steady state P1", "Floquet"]),
        ("ueda discover", ["Discovery", "residual_rms"]),
        ("ueda verify", ["Verification", "energy_distance", "consistent"]),
        ("response", ["response: steady state P1", "impulse over 1 period(s)"]),
        ("impulse", ["impulse over 1 period(s)", "peak", "exact (simulated)"]),
        ("measurement", ["record of 8000 samples", "channels w1, v1, w2, v2", "synthetic"]),
        ("contact samples", ["contact samples of", "impact(s)", "noise"]),
        ("ranked model", ["consistent", "std error", "I2", "verdict"]),
        ("candidate", ["support", "BIC", "value"]),
        ("regime", ["regime chaotic"]),
        ("lyapunov", ["Lyapunov exponents", "+-"]),
        ("periodic orbit", ["periodic orbit P1", "Floquet multipliers", "residual"]),
        ("basins", ["attractor(s) from a 2x2 grid", "% of the grid"]),
    ],
)
def test_print_of_a_result_is_a_short_report(results, name, needles):
    r = results[name]
    text = str(r)
    assert len(text) < 4000 and text.count("\n") < 40, (name, len(text))
    for needle in needles:
        assert needle in text, (name, needle, text)
    assert repr(r).startswith(f"<{type(r).__name__}: ") and "\n" not in repr(r)
    html = r._repr_html_()
    assert html.startswith("<pre") and "&lt;" not in text and text.split("\n")[0][:20] in html


def test_the_discovery_printout_is_small_where_it_was_half_a_megabyte(results):
    assert len(repr(results["discover"])) < 300 and len(str(results["discover"])) < 4000
    assert np.isfinite(results["discover"].selected.criteria["I2"])


# inputs and settings: their dataclass repr is what one would type to make them
_INPUTS = {
    "Tolerances",
    "Scenario",
    "Library",
    "Knobs",
    "NoiseModel",
    "SafeRegion",
    "ConstrainedSparseRegressor",
    "Executor",
    "Result",
    "UedaSystem",
    "UedaMap",
    "RegimeRules",
}


@pytest.mark.parametrize("module", [d, osc])
def test_every_public_result_class_prints_readably(module):
    """A public class is an input (its repr is its constructor call) or prints as text of
    its own (a law, a short report by ``_printing.readable``): no dataclass dump of arrays."""
    import inspect

    for name in module.__all__:
        obj = getattr(module, name)
        if not inspect.isclass(obj) or issubclass(obj, BaseException) or name in _INPUTS:
            continue
        assert obj.__str__ is not object.__str__, f"print() of a {name} is its repr"


# ------------------------------------------------------------------ the fit's printout
def _ranked(terms, regime, value, consistent=True, intervals=None):
    from types import SimpleNamespace

    return SimpleNamespace(
        law=d.ForceLaw.from_dict(dict.fromkeys(terms, 1e8)),
        regime=regime,
        criteria={"I2": value},
        noise_floor={},
        limits={},
        consistent=consistent,
        standard_errors={},
        intervals=intervals,
        verdict="consistent",
    )


def _discovery(ranking, equivalent=()):
    from discovery.vibroimpact.fit.discovery_result import DiscoveryResult

    return DiscoveryResult(
        selected=ranking[0],
        ranking=list(ranking),
        certificate=None,
        estimator=None,
        samples=None,
        measured=None,
        equivalent=list(equivalent),
        seconds=6.0,
    )


def test_the_ranking_stays_in_columns_whatever_the_regime_says():
    """A long regime (nonperiodic, a failure's reason) neither shifts the criterion column
    nor runs the row on: the reason goes on its own indented line below its row."""
    reason = "failed (I2 is undefined: the measured impulse is zero)"
    res = _discovery(
        [
            _ranked(["z", "zd"], "P1", 0.0178),
            _ranked(["z", "z*zd", "zd^2", "z^2"], "P1", 0.0177),
            _ranked(["z"], "nonperiodic", 0.98, consistent=False),
            _ranked(["zd"], reason, 0.981, consistent=False),
        ]
    )
    lines = str(res).splitlines()
    start = next(i for i, ln in enumerate(lines) if ln.startswith("ranking")) + 1
    rows = [ln for ln in lines[start : start + 5] if ln[4:5] == "."]
    assert len(rows) == 4, lines
    assert len({ln.index(" I2 ") for ln in rows}) == 1, rows  # one criterion column
    assert len({ln.index("1", ln.index(" I2 ") + 4) for ln in rows[:2]}) == 1
    assert all(len(ln) < 70 for ln in rows), rows
    below = lines[lines.index(rows[3]) + 1]
    assert below.startswith("      ") and below.strip() == reason


def test_a_law_that_is_no_contact_law_says_why_below_its_row():
    """A consistent law with a negative damper ranks after an inconsistent contact law; its
    row says why."""
    bad = _ranked(["z", "zd"], "P1", 0.016)
    bad.law = d.ForceLaw.parse("2e8*z - 1e6*zd")
    res = _discovery([_ranked(["z", "zd"], "P1", 0.0178), _ranked(["z"], "P1", 0.3, False), bad])
    lines = str(res).splitlines()
    row = next(i for i, ln in enumerate(lines) if ln.startswith("   3. z + zd"))
    assert lines[row + 1] == "      no contact law: " + "; ".join(bad.law.contact_defects())
    assert "negative" in lines[row + 1]
    assert not any("no contact law" in ln for ln in lines[:row])


def test_equivalent_models_and_the_time_read_as_text():
    equivalent = [{"terms": ["z", "z*zd", "zd^2"], "reason": "near-collinear"}]
    text = str(_discovery([_ranked(["z", "zd"], "P1", 0.0178)], equivalent))
    assert "equivalent: z + z*zd + zd^2 (near-collinear)" in text, text
    assert "[" not in text.split("equivalent:")[1].split("\n")[0]
    assert text.splitlines()[-1] == "fitted in 6.0 s"


def test_interval_bounds_print_apart():
    """A narrow interval around a large value keeps digits until its bounds differ."""
    from discovery._api._printing import coefficient_lines, interval_text
    from discovery.wording import interval_digits

    assert interval_text(1.9e8, 2.2e8) == "[1.9e+08, 2.2e+08]"  # wide: 4 digits, as before
    assert interval_text(2.06e8, 2.06001e8) == "[2.06000e+08, 2.06001e+08]"
    assert interval_text(1.279999e7, 1.280002e7) == "[1.279999e+07, 1.280002e+07]"
    assert interval_digits(2.06e8, 2.06e8) == 4 and interval_digits(1.0, 1.0 + 1e-12) == 8
    assert interval_text(None, 1.0) == "[--, 1]"
    (line,) = coefficient_lines({"z": 2.06e8}, {}, {"z": (2.0599e8, 2.0601e8)})[1:]
    assert line.endswith("[2.0599e+08, 2.0601e+08]"), line


def test_the_command_s_interval_line_prints_the_bounds_apart():
    from types import SimpleNamespace

    from discovery.cli._common import coefficients_line

    iv = SimpleNamespace(
        bounds={"z": (2.06e8, 2.06001e8)}, level=0.95, method="bootstrap", n_boot=6
    )
    line = coefficients_line({"z": 2.06e8}, {"z": 7.7e3}, iv)
    assert "z [2.06000e+08, 2.06001e+08]" in line, line


def test_the_explain_printout_shows_a_loss_and_the_moulding_s_mass_beside_the_law(paper):
    """A final model with a mass loss: the law's coefficients, then the loss and the
    moulding's mass refitted with it, each with its interval; a parameter the fit gave no
    standard error reads "--", not "nan"."""
    from types import SimpleNamespace

    from discovery import ForceLaw
    from discovery.cli._common import coefficients_line
    from discovery.cli.explain import _parameters
    from discovery.vibroimpact.explain.effects import Model, effect

    fm = Model(ForceLaw.parse("2e8*z + 1.3e7*zd")).with_effect(effect("mass_loss"), 0.0056)
    fm = fm.__class__(fm.law, {}, fm.effects, {**fm.scenario, "m2": 6767.0})
    iv = SimpleNamespace(
        bounds={
            "z": (1.9e8, 2.1e8),
            "zd": (1.2e7, 1.4e7),
            "loss": (0.005, 0.006),
            "m2": (6e3, 7e3),
        },
        level=0.95,
        method="bootstrap",
        n_boot=30,
    )
    res = SimpleNamespace(final_model=fm, uncertainties={"z": 1e6, "zd": 1e5}, intervals=iv)
    shown = _parameters(res, [paper])
    assert shown == {"z": 2e8, "zd": 1.3e7, "loss": 0.0056, "m2": 6767.0}
    line = coefficients_line(shown, res.uncertainties, iv)
    assert "loss 0.0056 (--)" in line and "m2 6767 (--)" in line and "nan" not in line
    assert "loss [" in line.split("intervals")[1] and "m2 [" in line.split("intervals")[1]
    # without intervals or errors for them, only the law's
    bare = SimpleNamespace(final_model=fm, uncertainties={"z": 1e6}, intervals=None)
    assert list(_parameters(bare, [paper])) == ["z", "zd"]


def test_print_of_an_explain_result_states_the_machine_changes_beside_the_law():
    """``print(result)`` of explain: the final model with what it adds beside its law (a
    mass loss and the moulding's mass refitted with it)."""
    from types import SimpleNamespace

    from discovery import ForceLaw
    from discovery.vibroimpact.explain.effects import Model, effect
    from discovery.vibroimpact.explain.result import ExplainResult

    fm = Model(ForceLaw.parse("2e8*z + 1.3e7*zd")).with_effect(effect("mass_loss"), 0.0056)
    fm = fm.__class__(fm.law, {}, fm.effects, {**fm.scenario, "m2": 6767.0})
    res = SimpleNamespace(
        final_model=fm,
        consistent=True,
        settings={},
        iterations=(),
        dropped=(),
        criteria={},
        noise_floor={},
        limits={},
        stopped_because="the model is consistent",
        seconds=1.0,
    )
    first = ExplainResult._lines(res)[0]
    assert "(m2 = 6767; mass_loss = 0.0056) with mass_loss: consistent" in first, first
