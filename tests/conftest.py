"""Shared fixtures for the numerical-core tests (session scoped: steady states are reused)."""

import numpy as np
import pytest

from discovery.vibroimpact.dynamics.law_response import impulse_from_steady_state
from discovery.vibroimpact.dynamics.steady_states import steady_state
from discovery.vibroimpact.model.scenario import load_scenario


@pytest.fixture(scope="session")
def paper():
    return load_scenario("paper")


@pytest.fixture(scope="session")
def light():
    return load_scenario("light")


@pytest.fixture(scope="session")
def paper_ss(paper):
    return steady_state(paper, paper.law)


@pytest.fixture(scope="session")
def light_ss(light):
    return steady_state(light, light.law)


@pytest.fixture(scope="session")
def paper_impulse(paper, paper_ss):
    return impulse_from_steady_state(paper, paper.law, paper_ss)


@pytest.fixture
def rng():
    return np.random.default_rng(20240607)
