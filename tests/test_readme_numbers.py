"""The README's set-up line, demo paragraph and times are rendered from a measured run
(:mod:`tests.survey_readme`): every verdict word follows the run's numbers, and the run
file in docs/_measured times what the README says it times."""

import copy
import hashlib

import pytest

from tests import measured, readme_text, survey_readme

RUN = measured.MEASURED / "readme.jsonl"


@pytest.fixture(scope="module")
def rows():
    return readme_text.read_rows([RUN])


def test_the_saved_run_timed_every_command_of_the_readmes_blocks(rows):
    """A README block changed since the run is a stale time: run the survey again."""
    timed = {(r["block"], r["command"]) for r in rows if r.get("kind") == "command"}
    for name in survey_readme.BLOCKS:
        for line in survey_readme.block(name):
            assert (name, line) in timed, f"README {name} block: {line!r} was not timed"
    assert ("chart", survey_readme.CHART) in timed
    assert any(r.get("kind") == "demo" for r in rows)


def test_the_saved_run_is_a_fresh_install_with_the_test_suite(rows):
    install = readme_text._one(rows, "install")
    assert install["fresh"] and install["seconds"] > sum(install["compile"].values()) > 0
    assert readme_text._one(rows, "test")["outcome"].get("failed", 0) == 0


def test_the_readmes_figures_are_the_runs(rows):
    """The demo's figures in reports/assets are the ones the run's numbers came with."""
    figures = readme_text._one(rows, "demo")["figures"]
    assert set(figures) == set(survey_readme.DEMO_FIGURES.values())
    for name, digest in figures.items():
        path = survey_readme.ASSETS / name
        assert hashlib.sha256(path.read_bytes()).hexdigest() == digest, (
            f"{name} is not the figure of the README's run: python -m tests.survey_readme"
        )


def _demo(rows, **changes):
    """The run's rows with the demo's numbers changed (``part={key: value}``)."""
    out = copy.deepcopy(rows)
    demo = readme_text._one(out, "demo")
    for part, values in changes.items():
        demo[part].update(values)
    return out


def _text(rows):
    """The demo's paragraph as one line."""
    return " ".join(line.strip() for line in readme_text.demo_lines(rows))


def test_the_demo_text_follows_the_verdicts(rows):
    text = _text(rows)
    demo = readme_text._one(rows, "demo")
    assert ("**inconsistent** with the record" in text) != demo["verify"]["consistent"]
    flipped = _demo(rows, verify={"consistent": not demo["verify"]["consistent"]})
    # the original's verdict, flipped: the word follows it
    assert ("**inconsistent** with the record" in _text(flipped)) == demo["verify"]["consistent"]
    nothing = _text(_demo(rows, explain={"named": []}))
    assert "names nothing" in nothing and "**names" not in nothing


def test_an_interval_that_misses_the_truth_is_said_to_miss_it(rows):
    demo = readme_text._one(rows, "demo")
    truth = demo["explain"]["truths"]["zd"]
    moved = _demo(
        rows,
        explain={"intervals": {**demo["explain"]["intervals"], "zd": [1.01 * truth, 1.02 * truth]}},
    )
    text = _text(moved)
    assert "the loading damper's misses it by 1 %" in text
    assert "each holds the truth" not in text


@pytest.mark.parametrize(
    "seconds, said", [(0.84, "0.84 s"), (3.24, "3.2 s"), (14.4, "14 s"), (125, "2 min 5 s")]
)
def test_durations_read_as_a_person_writes_them(seconds, said):
    assert readme_text.duration(seconds) == said


def test_coefficients_in_the_readmes_form():
    assert readme_text.sci(207576065.04) == "2.076e8"
    assert readme_text._short_law("207576065.04*z + 3993209.45*zd; unloading: 4053390.3*zd") == (
        "2.076e8*z + 3.993e6*zd; unloading: 4.053e6*zd"
    )
