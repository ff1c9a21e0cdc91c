"""Property-based tests of the CSV reader (Measurement.from_csv): random well-formed
tables (any separator, with or without a byte-order mark, decimal commas, mapped header
names) read back exactly; random or mutated bytes either load or raise InputError, never
another exception."""

import codecs

import numpy as np
import pytest
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from discovery.errors import InputError
from discovery.vibroimpact.data.measurement import LIMITS, Measurement

SETTINGS = settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
OPTIONAL = ("w1", "v1", "w2", "v2")


@pytest.fixture(scope="module")
def path(tmp_path_factory):
    return tmp_path_factory.mktemp("props") / "rec.csv"


def _values(name, n):
    lim = LIMITS[name][0]
    return st.lists(
        st.floats(min_value=-lim, max_value=lim, allow_nan=False, allow_subnormal=False),
        min_size=n,
        max_size=n,
    )


@st.composite
def tables(draw):
    n = draw(st.integers(4, 40))
    t0 = draw(st.floats(-1e3, 1e3, allow_nan=False))
    dt = draw(st.floats(1e-6, 1.0))
    t = t0 + dt * np.arange(n)
    extra = draw(st.lists(st.sampled_from(OPTIONAL), unique=True, max_size=4))
    cols = {"t": t.tolist(), "F": draw(_values("F", n))}
    for k in extra:
        cols[k] = draw(_values(k, n))
    order = draw(st.permutations(list(cols)))
    sep = draw(st.sampled_from([",", ";", "\t"]))
    comma = sep != "," and draw(st.booleans())
    rename = draw(st.booleans())
    header = {k: (f"{k}_col" if rename else k) for k in order}
    bom = draw(st.booleans())
    return cols, order, sep, comma, header, bom


def _render(cols, order, sep, comma, header, bom):
    def cell(v):
        s = repr(float(v))
        return s.replace(".", ",") if comma else s

    lines = [sep.join(header[k] for k in order)]
    n = len(cols["t"])
    lines += [sep.join(cell(cols[k][i]) for k in order) for i in range(n)]
    data = ("\r\n" if bom else "\n").join(lines) + "\n"
    return (codecs.BOM_UTF8 if bom else b"") + data.encode()


@SETTINGS
@given(tables())
def test_well_formed_tables_round_trip(path, table):
    cols, order, sep, comma, header, bom = table
    path.write_bytes(_render(*table))
    mapping = {k: header[k] for k in order} if header["t"] != "t" else None
    m = Measurement.from_csv(path, columns=mapping)
    assert np.array_equal(m.t, np.array(cols["t"]))
    assert np.array_equal(m.F, np.array(cols["F"]))
    for k in OPTIONAL:
        if k in cols:
            assert np.array_equal(m.channels[k], np.array(cols[k]))
        else:
            assert k not in m.channels
    assert not any("resampled" in n for n in m.notes)


def _load_or_input_error(path, data):
    path.write_bytes(data)
    try:
        Measurement.from_csv(path)
    except InputError as exc:
        msg = str(exc)
        assert msg and "\n" not in msg and "Traceback" not in msg
        return False
    return True


@SETTINGS
@given(st.binary(max_size=300))
@example(b"\xff\xfe\x00\xd8")  # UTF-16 mark, lone surrogate
@example(b"\xfe\xff")
@example(b"t,F\n" + b"0,1e400\n" * 4)
@example(b"t,F\n0,0\n1,0\n2,0\n3,0\n")
@example(b"t;F\n0;1,5,2\n1;0\n2;0\n3;0\n")
@example(b'"t","F"\n"0","1\n')
def test_random_bytes_load_or_raise_input_error(path, data):
    _load_or_input_error(path, data)


@SETTINGS
@given(
    st.lists(st.lists(st.text(max_size=8), max_size=5), max_size=8),
    st.sampled_from([",", ";", "\t"]),
)
@example([['"', "\x1e0"]], ",")  # a quote left open: csv would read on into the next line
def test_random_text_tables(path, rows, sep):
    data = "\n".join(sep.join(r) for r in [["t", "F"], *rows]).encode("utf-8", "surrogatepass")
    _load_or_input_error(path, data)


@SETTINGS
@given(
    tables(),
    st.lists(
        st.tuples(st.integers(0, 10_000), st.binary(min_size=0, max_size=3)), min_size=1, max_size=4
    ),
)
def test_mutated_tables(path, table, edits):
    data = bytearray(_render(*table))
    for pos, repl in edits:
        pos = pos % (len(data) + 1)
        data[pos : pos + 1] = repl
    _load_or_input_error(path, bytes(data))
