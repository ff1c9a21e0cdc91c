"""Scenario loading and validation."""

import math

import numpy as np
import pytest

from discovery.errors import InputError, LawSyntaxError
from discovery.vibroimpact.model.law import ForceLaw
from discovery.vibroimpact.model.scenario import Scenario, builtin_scenarios, load_scenario

GOOD = """\
name = "bench"

[machine]
m1 = 1.0e4
m2 = 2.0e3
k1 = 2.0e7
c1 = 5.0e4
A = 3.0e5
frequency = 30.0
g = 9.81

[law]
text = "1e8*z + 2e6*zd"
"""


def _write(tmp_path, text, name="s.toml"):
    p = tmp_path / name
    p.write_text(text)
    return p


def _machine_without(key):
    return "\n".join(line for line in GOOD.splitlines() if not line.startswith(f"{key} ="))


def test_builtins_listed_and_load():
    names = builtin_scenarios()
    assert {"paper", "light"} <= set(names)
    for name in names:
        sc = load_scenario(name)
        assert isinstance(sc, Scenario)
        assert sc.name == name
        assert sc.source == f"builtin:{name}"
        assert isinstance(sc.law, ForceLaw)


def test_paper_values():
    sc = load_scenario("paper")
    assert (sc.m1, sc.m2, sc.k1, sc.c1, sc.A, sc.frequency, sc.g) == (
        1.0e4,
        1.0e4,
        2.75e7,
        1.0e5,
        5.0e5,
        25.0,
        9.81,
    )
    assert sc.law == ForceLaw.parse("2.06e8*z + 1.28e7*zd")
    assert sc.period == 0.04
    # rel 1e-15: one multiplication by 2 pi
    assert sc.omega == pytest.approx(2 * math.pi * 25.0, rel=1e-15)
    assert sc.reduced_mass == 5.0e3
    # default start: grid at its static deflection -m1 g / k1, moulding touching it
    w = -1.0e4 * 9.81 / 2.75e7
    np.testing.assert_allclose(sc.initial_state(), [w, 0.0, w, 0.0], rtol=1e-15, atol=0)
    np.testing.assert_allclose(
        sc.params(), [1e4, 1e4, 2.75e7, 1e5, 5e5, 50 * math.pi, 9.81, 0.0, 0.0], rtol=1e-15, atol=0
    )


def test_light_values():
    sc = load_scenario("light")
    assert (sc.m1, sc.m2, sc.frequency) == (5.0e3, 2.0e3, 20.0)
    assert sc.law == ForceLaw.parse("2.0e10*z^1.5 + 5.0e11*z^1.5*zd")


def test_load_scenario_passes_scenario_through():
    sc = load_scenario("paper")
    assert load_scenario(sc) is sc


def test_toml_from_file(tmp_path):
    p = _write(tmp_path, GOOD)
    for sc in (load_scenario(p), load_scenario(str(p)), Scenario.from_toml(p)):
        assert sc.name == "bench"
        assert (sc.m1, sc.m2, sc.k1, sc.c1, sc.A, sc.frequency, sc.g) == (
            1.0e4,
            2.0e3,
            2.0e7,
            5.0e4,
            3.0e5,
            30.0,
            9.81,
        )
        assert sc.law == ForceLaw.parse("1e8*z + 2e6*zd")
        assert sc.source == str(p)


def test_toml_defaults_and_initial(tmp_path):
    text = _machine_without("g").replace('name = "bench"\n', "") + (
        "\n[initial]\nw1 = 0.001\nv1 = -0.5\nw2 = 0.002\nv2 = 0.25\n"
    )
    p = _write(tmp_path, text, "mine.toml")
    sc = load_scenario(p)
    assert sc.g == 9.81
    assert sc.name == "mine"  # default name is the file stem
    np.testing.assert_array_equal(sc.initial_state(), [0.001, -0.5, 0.002, 0.25])


def test_toml_without_law(tmp_path):
    text = GOOD.split("[law]")[0]
    assert load_scenario(_write(tmp_path, text)).law is None


@pytest.mark.parametrize("key", ["m1", "m2", "k1", "c1", "A", "frequency"])
def test_missing_key_is_named(tmp_path, key):
    p = _write(tmp_path, _machine_without(key))
    with pytest.raises(InputError, match=f"missing {key}"):
        load_scenario(p)


@pytest.mark.parametrize(
    ("key", "value"),
    [
        ("m1", "0.0"),
        ("m2", "-2.0e3"),
        ("frequency", "0"),
        ("k1", "-1.0"),
        ("c1", "nan"),
        ("A", "inf"),
        ("g", "-9.81"),
        ("m1", "nan"),
        ("m2", '"heavy"'),
    ],
)
def test_bad_value_is_named(tmp_path, key, value):
    lines = [
        f"{key} = {value}" if line.startswith(f"{key} =") else line for line in GOOD.splitlines()
    ]
    p = _write(tmp_path, "\n".join(lines))
    with pytest.raises(InputError, match=f"scenario {key} "):
        load_scenario(p)


def test_zero_stiffness_and_damping_are_allowed():
    sc = Scenario(m1=1, m2=1, k1=0, c1=0, A=0, frequency=1, g=0)
    np.testing.assert_array_equal(sc.initial_state(), [0, 0, 0, 0])


def test_unknown_key_is_named(tmp_path):
    p = _write(tmp_path, GOOD.replace("g = 9.81", "g = 9.81\nmass3 = 4.0"))
    with pytest.raises(InputError, match="mass3"):
        load_scenario(p)


def test_missing_machine_table(tmp_path):
    with pytest.raises(InputError, match=r"\[machine\]"):
        load_scenario(_write(tmp_path, 'name = "x"\n'))


def test_nonexistent_file(tmp_path):
    missing = tmp_path / "nope.toml"
    with pytest.raises(InputError, match="does not exist") as exc:
        load_scenario(missing)
    assert "paper" in str(exc.value)  # lists the built-ins as alternatives


def test_invalid_toml(tmp_path):
    with pytest.raises(InputError, match="not valid TOML"):
        load_scenario(_write(tmp_path, "[machine\nm1 = 1"))


def test_bad_law_in_file(tmp_path):
    with pytest.raises(LawSyntaxError):
        load_scenario(_write(tmp_path, GOOD.replace("1e8*z + 2e6*zd", "1e8*x")))


def test_bad_initial(tmp_path):
    with pytest.raises(InputError, match="w1, v1, w2, v2"):
        load_scenario(_write(tmp_path, GOOD + "\n[initial]\nw1 = 0.0\nv1 = 0.0\n"))
    with pytest.raises(InputError, match="initial"):
        Scenario(m1=1, m2=1, k1=0, c1=0, A=0, frequency=1, initial=(0, 0, 0))
    with pytest.raises(InputError, match="initial"):
        Scenario(m1=1, m2=1, k1=0, c1=0, A=0, frequency=1, initial=(0, 0, np.nan, 0))


def test_non_numeric_initial_is_input_error():
    with pytest.raises(InputError, match="initial"):
        Scenario(m1=1, m2=1, k1=0, c1=0, A=0, frequency=1, initial=("up", 0, 0, 0))


def test_law_not_a_table_is_input_error(tmp_path):
    text = 'law = "1e8*z"\n' + GOOD.split("[law]")[0]
    with pytest.raises(InputError):
        load_scenario(_write(tmp_path, text))


def test_with_law_and_as_dict():
    sc = load_scenario("paper")
    law = ForceLaw.parse("1e8*z")
    sc2 = sc.with_law(law)
    assert sc2.law == law and sc.law != law
    assert sc2.m1 == sc.m1 and sc2.name == sc.name
    d = sc.as_dict()
    assert d["law"] == "206000000*z + 12800000*zd"
    assert d["m1"] == 1e4 and d["source"] == "builtin:paper"
    assert ForceLaw.parse(d["law"]) == sc.law


def test_numbers_are_coerced_to_float():
    sc = Scenario(m1=1, m2=np.int64(2), k1=3, c1=0, A=0, frequency=np.float32(4))
    assert all(type(getattr(sc, k)) is float for k in ("m1", "m2", "k1", "frequency"))


@pytest.mark.parametrize("value", [True, False, np.bool_(True), "2", None, [1.0]])
def test_booleans_and_text_are_not_numbers(value):
    with pytest.raises(InputError, match="scenario m2 must be a number in kg"):
        Scenario(m1=1, m2=value, k1=3, c1=0, A=0, frequency=4)


@pytest.mark.parametrize(
    ("key", "value", "needle"),
    [
        ("m1", "true", "got a boolean"),
        ("m2", "false", "got a boolean"),
        ("k1", '"2.0e7"', "got text '2.0e7'"),
        ("A", "[1, 2]", "got list"),
        ("frequency", "{ a = 1 }", "got dict"),
        ("c1", "1979-05-27", "got date"),
        ("A", "1e300", "<= 1e+12 N"),
        ("m1", "1e30", "<= 1e+09 kg"),
        ("frequency", "1e9", "<= 100000 Hz"),
        ("g", "inf", "must be finite"),
        ("m1", "-inf", "must be finite"),
    ],
)
def test_toml_types_and_ranges(tmp_path, key, value, needle):
    lines = [
        f"{key} = {value}" if line.startswith(f"{key} =") else line for line in GOOD.splitlines()
    ]
    with pytest.raises(InputError, match=f"scenario {key} ") as exc:
        load_scenario(_write(tmp_path, "\n".join(lines)))
    assert needle in str(exc.value) and "\n" not in str(exc.value)


@pytest.mark.parametrize(
    ("extra", "needle"),
    [
        ("\n[machnie]\nm1 = 1.0\n", "unknown table(s) or key(s) machnie"),
        ("\n[solver]\nrtol = 1e-9\n", "valid are name, [machine], [law], [initial]"),
        ("\n[initial]\nw1 = 0\nv1 = 0\nw2 = 0\nv2 = 0\nw3 = 0\n", "unknown [initial] key(s) w3"),
    ],
)
def test_unknown_tables_and_keys_are_refused(tmp_path, extra, needle):
    with pytest.raises(InputError) as exc:
        load_scenario(_write(tmp_path, GOOD + extra))
    assert needle in str(exc.value)


def test_unknown_law_key_and_bad_law_text(tmp_path):
    with pytest.raises(InputError, match=r"unknown \[law\] key\(s\) txt; valid keys are text"):
        load_scenario(_write(tmp_path, GOOD.replace("text =", "txt =")))
    for bad in ('text = ""', "text = 5", "text = true"):
        with pytest.raises(InputError, match=r"\[law\] needs text"):
            load_scenario(_write(tmp_path, GOOD.replace('text = "1e8*z + 2e6*zd"', bad)))


def test_bad_name_and_initial_types(tmp_path):
    with pytest.raises(InputError, match="name must be non-empty text"):
        load_scenario(_write(tmp_path, GOOD.replace('name = "bench"', "name = 3")))
    text = GOOD + "\n[initial]\nw1 = true\nv1 = 0.0\nw2 = 0.0\nv2 = 0.0\n"
    with pytest.raises(InputError, match="scenario initial w1 must be a number"):
        load_scenario(_write(tmp_path, text))
    with pytest.raises(InputError, match="<= 1000 m"):
        Scenario(m1=1, m2=1, k1=0, c1=0, A=0, frequency=1, initial=(1e6, 0, 0, 0))


def test_directory_non_utf8_empty_and_bom(tmp_path):
    with pytest.raises(InputError, match="is a directory") as exc:
        load_scenario(tmp_path)
    assert "paper" in str(exc.value)
    p = tmp_path / "latin.toml"
    p.write_bytes(GOOD.replace('"bench"', '"b\u00e9nch"').encode("latin-1"))
    with pytest.raises(InputError, match="not UTF-8 text .*re-save it as UTF-8"):
        load_scenario(p)
    with pytest.raises(InputError, match="scenario is empty"):
        load_scenario("")
    p = tmp_path / "bom.toml"
    p.write_bytes(b"\xef\xbb\xbf" + GOOD.encode())
    assert load_scenario(p).name == "bench"


def test_a_scenario_prints_its_machine_with_units():
    """``print(scenario)`` is the machine in lines with units (the optional parts only when
    set); ``repr`` stays what one would type."""
    sc = load_scenario("paper")
    text = str(sc)
    assert text.splitlines()[0] == "scenario 'paper' (builtin:paper)"
    assert "  k1        2.75e+07 N/m" in text and "  frequency 25 Hz" in text
    assert "law       2.06e+08*z + 1.28e+07*zd" in text and "offset" not in text
    assert "offset    0.0001 m" in str(sc.replace(offset=1e-4))
    assert repr(sc).startswith("Scenario(m1=10000.0")
