"""CSV records from real instruments: encodings, separators, column mapping, sampling
jitter and every refusal as one clear line (discovery.vibroimpact.data.measurement)."""

import codecs

import numpy as np
import pytest

from discovery.errors import InputError
from discovery.vibroimpact.data.measurement import JITTER_LIMIT, Measurement
from discovery.vibroimpact.dynamics.synthetic import synthesize

FS = 20000.0


@pytest.fixture(scope="module")
def rec(paper):
    return synthesize(paper, paper.law, periods=6, fs=FS)


@pytest.fixture(scope="module")
def text(rec):
    return rec.to_csv_text()


def _write(tmp_path, data, name="d.csv"):
    p = tmp_path / name
    if isinstance(data, str):
        data = data.encode("utf-8")
    p.write_bytes(data)
    return p


def _same(m, rec):
    # %.12g text: 12 significant digits
    np.testing.assert_allclose(m.t, rec.t, rtol=1e-11, atol=1e-15)
    np.testing.assert_allclose(m.F, rec.F, rtol=1e-11, atol=1e-6)
    for k in ("w1", "v1", "w2", "v2"):
        np.testing.assert_allclose(m.channels[k], rec.channels[k], rtol=1e-11, atol=1e-15)


def test_plain_round_trip(rec, text, tmp_path):
    m = Measurement.from_csv(_write(tmp_path, text))
    _same(m, rec)
    assert m.notes == ()


@pytest.mark.parametrize("sep", [";", "\t"])
def test_separators_and_bom(rec, text, tmp_path, sep):
    data = codecs.BOM_UTF8 + text.replace(",", sep).encode()
    m = Measurement.from_csv(_write(tmp_path, data))
    _same(m, rec)
    assert m.notes == ()


def test_decimal_comma_with_semicolons(rec, text, tmp_path):
    eu = text.replace(",", ";").replace(".", ",")
    m = Measurement.from_csv(_write(tmp_path, eu))
    _same(m, rec)
    assert m.notes == ("decimal commas read as decimal points",)


def test_utf16_with_bom_and_comments(rec, text, tmp_path):
    data = ("# exported by an instrument\n\n" + text).encode("utf-16")
    m = Measurement.from_csv(_write(tmp_path, data))
    _same(m, rec)
    assert "UTF-16" in m.notes[0]


def test_column_mapping(rec, text, tmp_path):
    p = _write(tmp_path, text.replace("t,F,", "time_s,force_N,", 1))
    with pytest.raises(InputError, match=r"no column t or F .*--columns t=NAME,F=NAME"):
        Measurement.from_csv(p)
    m = Measurement.from_csv(p, columns={"t": "time_s", "F": "force_N"})
    _same(m, rec)
    assert m.notes == ("columns mapped: t <- time_s, F <- force_N",)
    # a mapped column wins over a column that happens to carry our name
    p2 = _write(tmp_path, text.replace("t,F,w1", "t,F,F_raw", 1), "d2.csv")
    m2 = Measurement.from_csv(p2, columns={"w1": "F_raw"})
    np.testing.assert_allclose(m2.channels["w1"], rec.channels["w1"], rtol=1e-11, atol=1e-15)


@pytest.mark.parametrize(
    ("columns", "needle"),
    [
        ({"time": "t"}, "unknown name 'time'"),
        ({"F": "force_N"}, "has no column 'force_N'"),
        ({"t": "t", "F": "t"}, "same column"),
        ({"F": ""}, "give the header"),
        (["t"], "columns must map"),
    ],
)
def test_bad_column_mapping(text, tmp_path, columns, needle):
    with pytest.raises(InputError, match=needle):
        Measurement.from_csv(_write(tmp_path, text), columns=columns)


def _table(t, F):
    return "t,F\n" + "".join(f"{a!r},{b!r}\n" for a, b in zip(t.tolist(), F.tolist(), strict=True))


def test_small_jitter_is_resampled_with_a_note(rec, tmp_path):
    rng = np.random.default_rng(3)
    dt = 1.0 / FS
    t = rec.t + rng.uniform(-0.04, 0.04, rec.t.size) * dt
    m = Measurement.from_csv(_write(tmp_path, _table(t, rec.F)))
    assert any("resampled onto a uniform grid" in n for n in m.notes)
    d = np.diff(m.t)
    assert np.ptp(d) < 1e-9 * dt + 1e-15 and m.t[0] == t[0] and m.t[-1] == t[-1]
    assert m.t.size == t.size
    # the force is the record's, interpolated: where it is smooth it agrees to the jitter
    smooth = np.abs(np.diff(rec.F, prepend=rec.F[0])) < 0.01 * rec.F.max()
    err = np.abs(m.F - rec.F)[smooth].max() / rec.F.max()
    assert err < 0.02


def test_rounding_of_times_is_not_jitter(rec, tmp_path):
    t = np.round(rec.t + 1000.0, 9)  # 1 ns rounding of a late time: 2e-5 of a step
    m = Measurement.from_csv(_write(tmp_path, _table(t, rec.F)))
    assert m.notes == () and np.array_equal(m.t, t)


def test_gap_or_large_jitter_is_refused(rec, tmp_path):
    t = rec.t.copy()
    t[50:] += 1.0 / FS  # one dropped sample
    with pytest.raises(InputError, match=r"not uniformly sampled.*100 % off.*resample it") as e:
        Measurement.from_csv(_write(tmp_path, _table(t, rec.F)))
    assert "\n" not in str(e.value)
    rng = np.random.default_rng(4)
    t = rec.t + rng.uniform(-0.2, 0.2, rec.t.size) / FS
    with pytest.raises(InputError, match=f"up to {100 * JITTER_LIMIT:g} % is resampled"):
        Measurement.from_csv(_write(tmp_path, _table(t, rec.F)))
    with pytest.raises(InputError, match="not uniformly sampled"):
        Measurement(t, rec.F)


@pytest.mark.parametrize(
    ("body", "needle"),
    [
        ("t,F\n0,0\n1,nan\n2,0\n3,0\n", "non-finite value 'nan' at line 3"),
        ("t,F\n0,0\n1,inf\n2,0\n3,0\n", "non-finite value 'inf' at line 3"),
        ("t,F\n0,0\n1,\n2,0\n3,0\n", "column F is empty at line 3"),
        ("t,F\n0,0\n1,abc\n2,0\n3,0\n", "non-numeric value 'abc' at line 3"),
        ("t,F\n0,0\n1\n2,0\n3,0\n", "line 3 has 1 field(s)"),
        ("t,F\n0,0\n1,1e300\n2,0\n3,0\n", "beyond the accepted |F| <= 1e+12 N"),
        ("t,F,w1\n0,0,0\n1,0,5e6\n2,0,0\n3,0,0\n", "beyond the accepted |w1| <= 1000 m"),
        ("t,F\n0,0\n1,0\n1,0\n3,0\n", "duplicate time t = 1 at lines 3 and 4"),
        ("t,F\n0,0\n2,0\n1,0\n3,0\n", "not increasing at line 4"),
        ("t,F,F\n0,0,0\n", "F appear more than once"),
        ("t,F\n", "has a header but no data rows"),
        ("", "is empty"),
        ("# only a comment\n", "is empty"),
        ("time,F\n0,0\n", "no column t"),
        ("t,F\n0,0\n1,0\n", "at least 4 samples"),
        ("t,F\n0\x00,0\n", "NUL bytes"),
    ],
)
def test_malformed_tables_one_line(tmp_path, body, needle):
    with pytest.raises(InputError) as exc:
        Measurement.from_csv(_write(tmp_path, body))
    msg = str(exc.value)
    assert needle in msg and "\n" not in msg and "np.float64" not in msg


def test_non_utf8_directory_missing(tmp_path):
    with pytest.raises(InputError, match=r"not UTF-8 text \(byte 0xe9 at offset 8\); re-save"):
        Measurement.from_csv(_write(tmp_path, b"t,F\n0,0\n\xe9,1\n"))
    with pytest.raises(InputError, match="is a directory; give the CSV file itself"):
        Measurement.from_csv(tmp_path)
    with pytest.raises(InputError, match="does not exist"):
        Measurement.from_csv(tmp_path / "nope.csv")


def test_contact_cut_off_at_the_start_is_named(rec):
    # the record starts inside a contact and ends before the next one: samples above the
    # threshold exist, but no whole contact
    k = np.flatnonzero(rec.F > 0)
    end = int(k[np.flatnonzero(np.diff(k) > 1)[0]]) + 200  # after the first contact
    m = Measurement(rec.t[:end], rec.F[:end], source="cut.csv")
    assert np.sum(m.F > 1e-3 * m.F.max()) >= 16
    with pytest.raises(
        InputError,
        match=r"the only contact in cut\.csv \(\d+ samples above "
        r"the threshold .*cut off at the record's start",
    ):
        m.impulse(0.04)
    with pytest.raises(InputError, match="no sample exceeds the threshold"):
        Measurement(rec.t[:100], np.zeros(100)).impulse(0.04)


def test_a2_forms_force_after_mapping(paper, rec, tmp_path):
    a2 = rec.F / paper.m2 - paper.g
    body = "time;acc\n" + "".join(
        f"{a!r};{b!r}\n" for a, b in zip(rec.t.tolist(), a2.tolist(), strict=True)
    )
    m = Measurement.from_csv(
        _write(tmp_path, body), scenario=paper, columns={"t": "time", "a2": "acc"}
    )
    np.testing.assert_allclose(m.F, rec.F, rtol=0, atol=1e-9 * rec.F.max())
