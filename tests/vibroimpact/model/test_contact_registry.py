"""The contact-model registry: a model added as one entry of
:data:`~discovery.vibroimpact.model.contact_registry.CONTACT_MODELS` (here a toy linear
spring, registered for one test and removed after it) parses from text, builds its law,
prints, starts and fits on a record, and is named in ``vidi fit --help`` and in the
report, with nothing else changed."""

import math

import pytest

from discovery.cli import main
from discovery.errors import InputError
from discovery.vibroimpact.fit.contact_fit import fit_contact_models
from discovery.vibroimpact.fit.contact_starts import record_samples, regression_start
from discovery.vibroimpact.model.contact_models import (
    ContactModel,
    is_model_text,
    parse_law,
    parse_model,
    same_force,
)
from discovery.vibroimpact.model.contact_registry import CONTACT_MODELS, ContactModelSpec
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import load_scenario
from tests.realistic import reference_record

SPRING = ContactModelSpec(
    "linear-spring",
    ("k",),
    "k z",
    r"k\zeta",
    "a linear spring without damping",
    fixed_n=1.0,
)


@pytest.fixture
def spring(monkeypatch):
    """The toy model registered: the one entry a new model is."""
    monkeypatch.setitem(CONTACT_MODELS, SPRING.name, SPRING)
    return SPRING


def test_the_shipped_models_are_the_registry_s_entries():
    assert list(CONTACT_MODELS) == [
        "kelvin-voigt",
        "hertz-damper",
        "hunt-crossley",
        "lankarani-nikravesh",
        "flores",
    ]
    for name, spec in CONTACT_MODELS.items():
        assert spec.name == name and set(spec.domains) == set(spec.parameters)
        assert spec.impact_scaled == (spec.ratio is not None)
        assert spec.seeded_by is None or not CONTACT_MODELS[spec.seeded_by].seeded_by
        assert str(spec).startswith(f"{name}: {spec.form} (")
    assert "linear-spring" not in CONTACT_MODELS


def test_a_registered_model_parses_builds_its_law_and_prints(spring):
    model = parse_model("Linear-Spring: k=2.06e8")
    assert model == ContactModel("linear-spring", (2.06e8,)) and model.spec is spring
    assert is_model_text("linear-spring: k=1e8")
    assert model.law == ForceLaw.parse("2.06e8*z") == parse_law("linear-spring: k=2.06e8")
    assert str(model) == "linear-spring: k=2.06e+08" and parse_model(model.to_text()) == model
    assert model.params == {"k": 2.06e8, "n": 1.0} and model.names == ["k"]
    assert model.conditions()["(5)"]["holds"] and model.conditions()["(6)"]["holds"]
    assert same_force("linear-spring", model.params) is None
    assert str(spring) == "linear-spring: k z (k): a linear spring without damping"
    with pytest.raises(InputError, match="did you mean 'linear-spring'"):
        parse_law("linear-sprin: k=2e8")
    with pytest.raises(InputError, match="linear-spring takes k=<number>"):
        parse_model("linear-spring: k=2e8, c=1e6")


def test_a_registered_model_starts_fits_and_reports(spring, capsys):
    from reports.contact_models import contact_models_context
    from reports.run import run_document

    sc = load_scenario("paper")
    truth = ContactModel("linear-spring", (2.06e8,))
    meas = reference_record(
        (sc.replace(law=truth.law), truth.law), periods=6, transient=30, seed=1, check=False
    )
    start = regression_start("linear-spring", record_samples(sc, meas))
    assert start.name == "linear-spring" and start.values[0] == pytest.approx(2.06e8, rel=0.1)
    res = fit_contact_models(
        sc, meas, models=("linear-spring",), max_simulations=20, n_boot=0, progress=False
    )
    fit = res.fit("linear-spring")
    assert res.selected == "linear-spring", str(res)
    assert math.isclose(fit.parameters["k"], 2.06e8, rel_tol=0.01) and "linear-spring" in str(res)
    # the report writes its LaTeX form
    doc = run_document({"data": "F.csv", "scenario": {"name": "paper"}}, result=res)
    (row,) = contact_models_context(doc, ".")["rows"]
    assert "linear-spring" in str(row[0]) and str(row[1]) == r"$k\zeta$"
    # and the CLI's help names it among the models --library contact-models fits
    assert main(["fit", "--help"]) == 0
    assert "flores, linear-spring)" in " ".join(capsys.readouterr().out.split())


def test_a_model_left_out_of_the_registry_is_unknown():
    with pytest.raises(InputError, match="unknown contact model 'linear-spring'"):
        ContactModel("linear-spring", (2.06e8,))
    with pytest.raises(InputError, match="unknown contact model"):
        fit_contact_models(load_scenario("paper"), [], models=("linear-spring",))
