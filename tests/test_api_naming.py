"""The API says what the CLI says: one name per setting, the same defaults, old names
deprecated (they still work for now, with a DeprecationWarning)."""

import pytest

import discovery
from discovery._api._settings import options_of
from discovery.cli import _parser
from discovery.errors import VidiError
from discovery.vibroimpact.dynamics.synthetic import synthesize


@pytest.fixture(scope="module")
def record(paper):
    return synthesize(paper, paper.law, periods=6, fs=20000, noise=0.01, seed=1)


def _cli_default(command, option):
    sub = next(
        a for a in _parser()._actions if a.__class__.__name__ == "_SubParsersAction"
    ).choices[command]
    return next(a.default for a in sub._actions if option in a.option_strings)


def test_identify_default_method_is_the_clis():
    api = options_of(discovery.identify)["method"]
    assert api == _cli_default("identify", "--method") == "least-squares"


def test_every_seed_is_called_seed():
    for f in (discovery.discover, discovery.explain, discovery.identify, discovery.verify):
        assert "seed" in options_of(f), f.__name__
    assert "max_simulations" in options_of(discovery.explain)


def test_the_old_names_of_seed_and_max_simulations_are_gone(paper, record):
    """``discover(random_state=)`` and ``explain(budget=)`` were deprecated aliases kept
    from before 0.1.0; an unknown keyword is one error naming the keyword."""
    with pytest.raises(VidiError, match="unexpected keyword .random_state."):
        discovery.discover(paper, record, random_state=3)
    with pytest.raises(VidiError, match="unexpected keyword .budget."):
        discovery.explain(paper, record, budget=20)


def test_verify_from_the_package_is_the_function():
    from discovery import verify

    assert callable(verify) and verify is discovery.verify
    assert discovery.VerifyResult.__name__ == "VerifyResult"
