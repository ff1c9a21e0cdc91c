"""Every ``vidi ... --help`` works and shows the default of every option that has one.

The parsers are walked as ``discovery.cli`` builds them (each command's ``register``),
nested subcommands (``vidi ueda attractor``) included, so a new option is checked
without touching this file.  The convention: an option with a default says
``(default: VALUE)`` in its help, written ``(default: %(default)s)`` (or ``%(default)g``)
so the text follows the code; a default argparse cannot print (an array of grid points)
is written out and must parse, with the option's own type, to that default.
"""

import argparse
import re

import numpy as np
import pytest

from discovery.cli import _parser, main


def _walk(parser, path=()):
    """``(command words, parser)`` of ``parser`` and of every subcommand below it."""
    yield path, parser
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, sub in action.choices.items():
                yield from _walk(sub, (*path, name))


PARSERS = list(_walk(_parser()))
IDS = [" ".join(p) or "vidi" for p, _ in PARSERS]


def _expanded_help(parser, action):
    """The action's help as ``--help`` prints it (``%(default)s`` etc. filled in)."""
    return parser._get_formatter()._expand_help(action)


def _has_default(action):
    return (
        action.option_strings
        and action.help is not argparse.SUPPRESS
        and action.default is not None
        and action.default is not False
        and action.default is not argparse.SUPPRESS
    )


def _same(shown, action):
    """Does the text ``shown`` (after "default: ") give the action's default?"""
    default = action.default
    if isinstance(default, str):
        return shown == default
    try:
        value = action.type(shown) if callable(action.type) else type(default)(shown)
    except (ValueError, TypeError, argparse.ArgumentTypeError):
        return False
    if isinstance(default, np.ndarray):
        return np.array_equal(np.asarray(value), default)
    return value == default


def test_every_command_is_walked():
    commands = {p[0] for p, _ in PARSERS if p}
    assert {
        "simulate",
        "fit",
        "verify",
        "explain",
        "steady",
        "landscape",
        "identify",
        "ueda",
    } <= commands
    assert {p[1] for p, _ in PARSERS if len(p) == 2 and p[0] == "ueda"} >= {
        "attractor",
        "chart",
        "simulate",
        "discover",
        "explain",
    }


@pytest.mark.parametrize(("path", "parser"), PARSERS, ids=IDS)
def test_help_exits_0(path, parser, capsys):
    assert main([*path, "--help"]) == 0
    out = capsys.readouterr()
    assert out.out.startswith("usage: vidi")
    assert out.err == ""


@pytest.mark.parametrize(("path", "parser"), PARSERS, ids=IDS)
def test_every_default_is_shown(path, parser):
    missing = []
    for action in parser._actions:
        if not _has_default(action):
            continue
        text = " ".join(_expanded_help(parser, action).split())
        # "(default: 0)", "(default: 0, skip)", "(default: x',x^3)"
        shown = [
            c
            for m in re.findall(r"\(default: ([^()]*)\)", text)
            for c in (m, re.split(r"[,;] ", m)[0])
        ]
        if not any(_same(s.strip(), action) for s in shown):
            missing.append(
                f"{'/'.join(action.option_strings)} (default {action.default!r}): {text!r}"
            )
    assert not missing, f"vidi {' '.join(path)}: help without its default:\n  " + "\n  ".join(
        missing
    )


@pytest.mark.parametrize(("path", "parser"), PARSERS, ids=IDS)
def test_help_uses_one_convention(path, parser):
    """``(default: ...)``, not the old ``(20)`` suffix nor argparse's formatter class
    (which would print ``(default: None)`` for options without a default)."""
    from discovery.cli import HelpFormatter

    assert parser.formatter_class is HelpFormatter  # argparse's, with examples as written
    assert parser.epilog is None or parser.epilog.startswith("examples:\n  vidi ")
    for action in parser._actions:
        if action.help in (None, argparse.SUPPRESS) or not action.option_strings:
            continue
        text = _expanded_help(parser, action)
        assert "(default: None)" not in text and "(default: False)" not in text
        if _has_default(action):
            assert not re.search(r"\(\s*[-+]?[\d.e+-]+\s*\)\s*$", text), (
                f"vidi {' '.join(path)} {action.option_strings[0]}: write the default as "
                f"'(default: %(default)s)', not {text!r}"
            )


def test_version_and_plain_vidi(capsys):
    from discovery.cli import main

    assert main(["--version"]) == 0
    assert capsys.readouterr().out.startswith("vidi ")
    assert main([]) == 0  # the overview, not an error
    assert "COMMAND" in capsys.readouterr().out


def test_every_example_in_the_help_parses():
    """The examples printed under each command's help are valid command lines."""
    import shlex

    from discovery.cli import EXAMPLES, _parser

    parser = _parser()
    for path, lines in EXAMPLES.items():
        for line in lines:
            argv = shlex.split(re.split(r"\s{2,}", line)[0])
            assert argv[0] == "vidi" and argv[1 : 1 + len(path.split())] == path.split(), line
            if "COMMAND" not in argv:
                parser.parse_args(argv[1:])  # raises UsageError on a wrong example


def test_help_loads_no_heavy_library():
    """``vidi --help`` builds every parser without numba, cvxpy, sympy, scipy, matplotlib,
    pysindy or jinja2 (their import took 2-3 s; the timing itself is in make bench)."""
    from tests.interpreter import loaded_after

    heavy = ("numba", "cvxpy", "sympy", "scipy", "matplotlib", "pysindy", "jinja2", "sklearn")
    out = loaded_after("from discovery.cli import _parser; _parser()", heavy, timeout=120)
    assert out == [], f"vidi --help imports {','.join(out)}"


def test_a_mistyped_command_or_option_gets_a_did_you_mean(capsys, tmp_path):
    """One line, exit 2, the closest name; an unambiguous prefix is still an option."""
    from discovery.cli import main

    assert main(["fitt"]) == 2
    err = capsys.readouterr().err
    assert "did you mean 'fit'" in err and err.count("\n") == 1
    assert main(["fit", "--dta", "x.csv", "--out", str(tmp_path / "o")]) == 2
    err = capsys.readouterr().err
    assert "unknown option '--dta'" in err and "did you mean '--data'" in err
    assert main(["ueda", "chrt"]) == 2  # a subcommand as a command
    err = capsys.readouterr().err
    assert "unknown command 'chrt' (did you mean 'chart'?)" in err and "vidi ueda --help" in err
    assert main(["ueda", "attractor", "--modle", "negres"]) == 2
    assert "did you mean '--model'" in capsys.readouterr().err
    # a prefix argparse takes: the command goes on to the missing file
    assert main(["fit", "--dat", str(tmp_path / "none.csv"), "--out", str(tmp_path / "o")]) == 2
    assert "does not exist" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize(
    "line, expected",
    [
        (["fitt", "--data", "D.csv", "--out", "x"], "unknown command 'fitt' (did you mean 'fit'?)"),
        (
            ["ueda", "atractor", "--out", "x"],
            "unknown command 'atractor' (did you mean 'attractor'?)",
        ),
    ],
)
def test_a_mistyped_command_is_named_before_the_options_that_follow_it(capsys, line, expected):
    """The options after an unknown command are not checked against the parent's."""
    from discovery.cli import main

    assert main(line) == 2
    err = capsys.readouterr().err
    assert expected in err and "unknown option" not in err and err.count("\n") == 1


def _help_of(path, option):
    parser = dict(PARSERS)[tuple(path)]
    action = parser._option_string_actions[option]
    return " ".join(_expanded_help(parser, action).split())


def test_fit_s_library_and_seed_say_what_they_are():
    assert "Hunt-Crossley terms z^1.5 and z^1.5*zd" in _help_of(["fit"], "--library")
    seed = _help_of(["fit"], "--seed")
    for what in ("stability selection", "noise-floor bootstrap", "coefficient intervals"):
        assert what in seed, seed


@pytest.mark.parametrize(
    "path", [["ueda", c] for c in ("attractor", "simulate", "chart", "discover", "explain")]
)
def test_a_ueda_parameter_shows_each_model_s_default(path):
    """An option whose default is the model's value names that value for each model."""
    from discovery.ueda.system import MODELS

    parser = dict(PARSERS)[tuple(path)]
    for p in ("mu", "gamma", "k", "B", "nu"):
        action = parser._option_string_actions.get(f"--{p}")
        if action is None or action.default is not None:  # chart's grids: their own
            continue
        text = _help_of(path, f"--{p}")
        values = ", ".join(f"{m} {v[p]:g}" for m, v in MODELS.items())
        assert f"(default: the --model's: {values})" in text, (path, p, text)


def test_advise_s_safety_limits_say_they_are_unbounded_by_default():
    for option in ("--max-force", "--max-penetration"):
        assert "(default: none, no bound)" in _help_of(["advise"], option)
